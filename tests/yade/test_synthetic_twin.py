"""Synthetic twin, short version: the calibration engine recovers a hidden parameter.

Hidden truth: M2 particle density 3600 kg/m3. Its simulated cell-fill bulk density
(mean of seeds 1-2) becomes the target; the study starts from 2750 kg/m3 and must
recover the truth. Real YADE runs (about 8 fills).

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
    hidden = pool.run([resolve_job("fill", "M2", {"particles.density_kg_m3": TRUTH_KG_M3}, seed=s)
                       for s in (1, 2)])
    target, _ = mean_std([r["bulk_density_kg_m3"] for r in hidden])
    cfg = tmp_path / "twin.yaml"
    cfg.write_text(f"""
name: twin
seeds_count: 2
materials:
  M2:
    - {{stage: density, rig: fill, tolerance_percent: 1.0, max_iterations_count: 5,
       target: {{value: {target}}}}}
""")
    study = Study(cfg, pool, tmp_path / "out", log=lambda m: None)
    (row,) = study.run()
    assert row["met"], row
    error = abs(row["value"] - TRUTH_KG_M3) / TRUTH_KG_M3
    print(f"twin: recovered {row['value']:.1f} kg/m3 vs hidden {TRUTH_KG_M3}, error {100 * error:.2f} %, "
          f"{row['evaluations']} iterations")
    assert error < 0.05
