"""Synthetic twin, short version: the calibration engine recovers a hidden parameter.

Hidden truth: M2 particle density 3600 kg/m3. Its simulated cell-fill bulk density
(mean of seeds 101-102, seeds the study never runs) becomes the target; the study starts from 2750 kg/m3 and must
recover the truth and an interval that holds it. Real YADE runs (at most 10 fills).

Bound: a fill is chaotic, so every change of density reshuffles the packing (seed-to-
seed spread of the bulk density ~4.4 %, standard error with 2 seeds ~3 %); the
recovered density can only be as good as that: within 5 % of the truth, while the
start value is 24 % off.
"""

import pytest

from pycal.calibration.study import Study
from pycal.jobs import resolve_job
from pycal.post import mean_std
from pycal.runner import LocalPool

pytestmark = pytest.mark.yade

TRUTH_KG_M3 = 3600.0


def test_density_twin_recovers_hidden_value(tmp_path):
    pool = LocalPool(tmp_path / "runs", workers=2, progress=False)
    hidden = pool.run([resolve_job("fill", "M2", {"particles.density_kg_m3": TRUTH_KG_M3, "rig.geometry.scale": 1}, seed=s)
                       for s in (101, 102)])
    target, sd = mean_std([r["bulk_density_kg_m3"] for r in hidden])
    se = sd / 2 ** 0.5                     # the target is itself a mean of 2 fills
    cfg = tmp_path / "twin.yaml"
    cfg.write_text(f"""
name: twin
seeds_count: 2
materials:
  M2:
    - stage: density
      rig: fill
      rig_overrides: {{rig.geometry.scale: 1}}
      target: {{value: {target}, standard_error_kg_m3: {se}}}
      parameter: {{bounds: [1500.0, 9000.0], tolerance_kg_m3: 150.0}}
      max_runs_count: 10
""")
    study = Study(cfg, pool, tmp_path / "out", log=lambda m: None)
    (row,) = study.run()
    p = row["parameters"][0]
    error = abs(p["estimate"] - TRUTH_KG_M3) / TRUTH_KG_M3
    print(f"twin: recovered {p['estimate']:.1f} kg/m3 [{p['low']:.1f}, {p['high']:.1f}] vs hidden {TRUTH_KG_M3}, "
          f"error {100 * error:.2f} %, {row['runs_requested']} runs, {row['stop_reason']}")
    assert error < 0.05
    assert p["low"] <= TRUTH_KG_M3 <= p["high"]
