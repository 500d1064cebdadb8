"""Rigs at geometry.scale 2 (real YADE runs): the answers known without the code hold as at 1.

The expected numbers come from the lab's rig (the 145 x 95 mm cell) doubled, written
here, and from mechanics, not from pycal's scale rule:
- the fill: its mass is its count x the particle mass (pi d^3 / 6 x density) and its bulk
  density that mass over the doubled cell's volume, pi 0.29^2 / 4 x 0.19 m3. With fewer of
  its grains at the wall the larger cell packs denser than the lab's (the wall effect of
  five grains across; bench/scaled_rigs.py, M2 start values, seeds 1001 - 1006: solid
  fraction 0.419 +- 0.012 at scale 1, 0.472 +- 0.006 at 2; seed 1: 0.422 / 0.480) and
  stays below random close packing of equal spheres (0.64);
- the confined cell: the plate carries the lab's stress on the doubled cell's area (the
  servo's force is stress x pi 0.29^2 / 4; seed 1 read 4951 / 19803 Pa for 5 / 20 kPa),
  and at rest plate + weight = bottom + wall (Newton);
- the tilt table: a cell of non-rolling spheres on steel of friction 0.2 slides when
  tan(tilt) = 0.2 (seed 1: 0.187, the plate's force ratio 0.187: the loose bed creeps a
  little first, as at scale 1), after the lid servo reached the lab's 12 kPa (11874 Pa).
A wrong scale rule fails them: an unscaled cell volume or plate area reads 8x or 4x, an
unscaled plate or cell carries another stress, a scale that did not reach the rig keeps 80
grains in the cell. (The lid's and ring's masses x s^2 are checked without YADE:
tests/unit/test_rig_scale.py.) About 6.5 CPU minutes in all.
"""
import math

import pytest

from pycal.jobs import resolve_job
from pycal.runner import run_job

pytestmark = pytest.mark.yade

SCALE = 2
D_LAB, H_LAB = 0.145, 0.095                 # the lab's cell (docs/lab-tests.md section 4)
SPHERE_D, DENSITY = 0.025, 2750.0           # M2 start values (configs/materials/M2.yaml)
SEED = 1
RANDOM_CLOSE_PACKING = 0.64
_RUNS = {}


def run(tmp_path_factory, name, rig, overrides, material="M2"):
    if name not in _RUNS:
        job = resolve_job(rig, material, overrides, seed=SEED)
        _RUNS[name] = run_job(job, runs_dir=tmp_path_factory.mktemp(name), timeout_s=1800)
    return _RUNS[name]


def test_fill_at_scale_2_holds_count_times_mass_in_the_doubled_cell(tmp_path_factory):
    lab = run(tmp_path_factory, "fill1", "fill", {"rig.geometry.scale": 1})
    big = run(tmp_path_factory, "fill2", "fill", {"rig.geometry.scale": SCALE})
    particle_kg = DENSITY * math.pi * SPHERE_D ** 3 / 6
    volume = math.pi * (SCALE * D_LAB) ** 2 / 4 * SCALE * H_LAB
    assert big["mass_kg"] == pytest.approx(big["n_particles"] * particle_kg, rel=1e-9)
    assert big["bulk_density_kg_m3"] == pytest.approx(big["mass_kg"] / volume, rel=1e-9)
    assert big["n_particles"] > 6 * lab["n_particles"]              # ~8x the grains (more: the wall effect)
    assert lab["solid_fraction"] + 0.03 < big["solid_fraction"] < RANDOM_CLOSE_PACKING


def test_confined_cell_at_scale_2_carries_the_lab_stress_on_the_doubled_area(tmp_path_factory):
    steps = [5000, 20000]
    r = run(tmp_path_factory, "ccs2", "ccs", {"rig.geometry.scale": SCALE, "rig.procedure.load_steps_pa": steps,
                                              "rig.procedure.pour_height_factor": 2.0})
    area = math.pi * (SCALE * D_LAB) ** 2 / 4
    for k, target in enumerate(steps):
        assert r["plate_force_n"][k] / area == pytest.approx(target, rel=0.02)
        assert abs(r["force_balance_error"][k]) < 2e-3              # Newton at rest
    assert r["n_particles"] > 400


def test_cell_at_scale_2_slides_at_tan_angle_equal_mu_after_the_lab_stress(tmp_path_factory):
    mu = 0.2
    no_roll = {f"interactions.{m}.rolling_resistance_coefficient": 1.0 for m in ("M2", "steel", "pvc")}
    r = run(tmp_path_factory, "wall2", "wall_friction", {
        **no_roll, "interactions.steel.friction_coefficient": mu, "rig.geometry.scale": SCALE,
        "rig.procedure.consolidation_stresses_pa": [12000], "rig.procedure.measure_dynamic_friction": False})
    assert r["stress_reached_pa"][0] == pytest.approx(12000, rel=0.02)
    assert not r["sticks"][0]
    assert abs(r["mu_static"][0] - mu) <= 0.03                      # the rigs' measured resolution
    assert abs(r["plate_force_ratio_onset"][0] - mu) <= 0.03
