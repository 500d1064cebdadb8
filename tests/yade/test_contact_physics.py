"""Physics layer: the cell fill on the default law, and the first law (`linear_cundall`, kept
under its own name) against its own known answers, so that its limits stay documented.
Scenes: tests/yade/scenes/*.py (the default law's own tests: test_contact_law.py).
"""
import math

import pytest

from pycal.errors import RunError
from pycal.jobs import resolve_job
from pycal.runner import run_job, job_dir
from scene_runner import LAB_SIZE, run_scene, scene_job

from documented import assert_documented

pytestmark = pytest.mark.yade
G = 9.81
OLD = {"rig.numerics.contact_model": "linear_cundall"}


# ---------------------------------------------------------------- fill rig (real runs)

@pytest.fixture(scope="module")
def fill_pair(tmp_path_factory):
    """The same fill job (M2 start values, seed 1) run twice in two fresh run dirs."""
    job = resolve_job("fill", "M2", LAB_SIZE, seed=1)
    a = run_job(job, tmp_path_factory.mktemp("runs_a"))
    b = run_job(job, tmp_path_factory.mktemp("runs_b"))
    return job, a, b


def test_fill_mass_is_count_times_particle_mass(fill_pair):
    """(a) mass = n x rho_p x 4/3 pi R^3, and bulk density = mass / cell volume."""
    job, res, _ = fill_pair
    mat = job["materials"]["M2"]["particles"]
    m1 = mat["density_kg_m3"] * 4.0 / 3.0 * math.pi * (mat["diameter_m"] / 2) ** 3
    assert res["n_particles"] > 20
    assert res["mass_kg"] == pytest.approx(res["n_particles"] * m1, rel=1e-9)
    geo = job["rig_config"]["geometry"]
    vol = math.pi * geo["cell_inner_diameter_m"] ** 2 / 4 * geo["cell_height_m"]
    assert res["bulk_density_kg_m3"] == pytest.approx(res["mass_kg"] / vol, rel=1e-9)
    assert_documented(res)


def test_time_step_is_the_one_estimated_before_the_run(fill_pair):
    """YADE's time step (0.5 x PWaveTimeStep) is what pycal.step_estimate computed from the
    job alone: 0.5 x 0.0125 m / sqrt(2e7 Pa / 2750 kg/m3) = 7.329e-5 s."""
    from pycal.step_estimate import critical_timestep
    job, res, _ = fill_pair
    assert res["timestep_s"] == pytest.approx(critical_timestep(job)[0], rel=1e-9)
    assert res["timestep_s"] == pytest.approx(7.329e-5, rel=1e-3)


def test_fill_is_bit_reproducible(fill_pair):
    """(e) same job, two run dirs, -j1: identical numbers."""
    _, a, b = fill_pair
    for k in ("bulk_density_kg_m3", "n_particles", "mass_kg", "steps", "settle_time_s"):
        assert a[k] == b[k], k


def test_blow_up_is_detected_and_leaves_no_result(tmp_path):
    """(f) particles far too soft for their own weight (Young 1e4 Pa instead of 6e6) pass through
    the table: the overlap guard fails the run with 'blow-up', no result.json. pycal refuses
    1e4 Pa before a run (pycal/plausible.py), so the job is edited after resolution: the
    guard inside the rig is what is tested."""
    from pycal.jobs import job_id
    job = resolve_job("fill", "M2", LAB_SIZE, seed=1)
    job["materials"]["M2"]["contact"]["youngs_modulus_pa"] = 1.0e4
    job["job_id"] = job_id(job)
    with pytest.raises(RunError, match="blow-up"):
        run_job(job, tmp_path, timeout_s=300)
    final = job_dir(job, tmp_path)
    assert not final.exists()
    assert not (final / "result.json").exists()
    failed = final.parent / f"{final.name}.failed"
    assert (failed / "yade.log").is_file()
    assert not (failed / "result.json").exists()


# ---------------------------------------------------------------- the first law (linear_cundall)

def old_job(e=0.3, extra=None):
    pairs = {f"interactions.{p}.restitution_coefficient": e for p in ("M2", "M1", "M3-dry", "M3-wet", "steel", "pvc")}
    return scene_job({**OLD, **pairs, **(extra or {})})


@pytest.mark.parametrize("e", [0.3, 0.7])
def test_first_law_restitution_by_cundall_damping(tmp_path, e):
    """v_out / v_in on the steel table = restitution within 0.05 (Cundall damping
    a = (1 - e^2) / (1 + e^2): this law has no dashpot). With gravity, damped as well here."""
    m = run_scene(tmp_path, "bounce", old_job(e), {"target": "plate", "impact_speed_m_s": 1.0, "gravity": True})
    assert m["law"] == "linear_cundall"
    assert m["ratio"] == pytest.approx(e, abs=0.05)


def test_first_law_falls_at_one_minus_damping_times_g(tmp_path):
    """Its limit: damping acts on gravity too, so e = 0.3 (a = 0.835) falls at 0.165 g."""
    m = run_scene(tmp_path, "fall", old_job(0.3), {"fall_time_s": 0.3})
    a = (1 - 0.3 ** 2) / (1 + 0.3 ** 2)
    assert m["damping"] == pytest.approx(a)
    assert m["drop_m"] == pytest.approx(0.5 * (1 - a) * G * m["time_s"] ** 2, rel=0.01)


# ---------------------------------------------------------------- rolling (first law)

def rolling_stop_distance(v0, eta, g=G):
    """0.7 v0^2 / (eta g): see test_contact_law.rolling_stop_distance."""
    return 0.7 * v0 ** 2 / (eta * g)


def roll_old(tmp_path, damping):
    from scene_runner import add_material
    job = old_job(0.3, {"interactions.steel.friction_coefficient": 1.0,
                        "interactions.steel.rolling_resistance_coefficient": 0.1})
    add_material(job, "anvil", "M2", {})
    return run_scene(tmp_path, "roll", job, {"anvil_radius_m": 10.0, "anvil_start_arc_m": 0.1,
                                             "launch_speed_m_s": 0.5, "damping": damping, "max_time_s": 2.0})


def test_first_law_rolling_is_exact_without_damping(tmp_path):
    m = roll_old(tmp_path, 0.0)
    assert m["table_distance_m"] == pytest.approx(rolling_stop_distance(0.5, 0.1), rel=0.05)


def test_first_law_rolling_with_its_damping_stops_short(tmp_path):
    """Its limit: with the damping that makes e = 0.3 a rolling particle stops at ~0.47 x the
    law's distance (rolling resistance acts ~2x stronger while particles move). Pinned."""
    m = roll_old(tmp_path, "config")
    ratio = m["table_distance_m"] / rolling_stop_distance(0.5, 0.1)
    assert 0.40 < ratio < 0.55
