"""Physics layer: short real-YADE scenes built with the same library as the rigs
(demlib.scene.Scene / demlib.contact.ContactModel from a job of pycal.jobs.resolve_job),
each checked against a known answer. Scenes: tests/yade/scenes/*.py.

Run: ./run.sh test tests/yade   (or -m yade). One YADE process at a time, -j1.
"""
import json
import math
import os
import subprocess
from pathlib import Path

import pytest

from pycal.errors import RunError
from pycal.jobs import resolve_job
from pycal.runner import run_job, job_dir, yade_env

from documented import assert_documented

pytestmark = pytest.mark.yade

SCENES = Path(__file__).resolve().parent / "scenes"
G = 9.81


def run_scene(tmp_path, scene, overrides, params, material="M2", timeout=120):
    """Write job.json (library job + test_scene parameters), run the scene, return its JSON."""
    job = resolve_job("fill", material, overrides, seed=1)
    job["test_scene"] = params
    d = Path(tmp_path)
    d.mkdir(parents=True, exist_ok=True)
    (d / "job.json").write_text(json.dumps(job))
    proc = subprocess.run(["yade", "-j1", "-x", "-n", str(SCENES / f"{scene}.py"), "job.json"],
                          cwd=d, capture_output=True, text=True, timeout=timeout,
                          env=yade_env())
    out = d / "measurements.json"
    assert proc.returncode == 0 and out.is_file(), f"{scene} failed:\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}"
    return json.loads(out.read_text())


# ---------------------------------------------------------------- fill rig (real runs)

@pytest.fixture(scope="module")
def fill_pair(tmp_path_factory):
    """The same fill job (M2 start values, seed 1) run twice in two fresh run dirs."""
    job = resolve_job("fill", "M2", seed=1)
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
    """YADE's time step (0.3 x PWaveTimeStep) is what pycal.step_estimate computed from the
    job alone: 0.3 x 0.0125 m / sqrt(6e6 Pa / 2750 kg/m3) = 8.028e-5 s."""
    from pycal.step_estimate import critical_timestep
    job, res, _ = fill_pair
    assert res["timestep_s"] == pytest.approx(critical_timestep(job)[0], rel=1e-9)
    assert res["timestep_s"] == pytest.approx(8.028e-5, rel=1e-3)


def test_fill_is_bit_reproducible(fill_pair):
    """(e) same job, two run dirs, -j1: identical numbers."""
    _, a, b = fill_pair
    for k in ("bulk_density_kg_m3", "n_particles", "mass_kg", "steps", "settle_time_s"):
        assert a[k] == b[k], k


def test_blow_up_is_detected_and_leaves_no_result(tmp_path):
    """(f) particles far too soft for their own weight (Young 1e4 Pa instead of 6e6) pass through
    the table: the overlap guard fails the run with 'blow-up', no result.json."""
    job = resolve_job("fill", "M2", {"contact.youngs_modulus_pa": 1.0e4}, seed=1)
    with pytest.raises(RunError, match="blow-up"):
        run_job(job, tmp_path, timeout_s=300)
    final = job_dir(job, tmp_path)
    assert not final.exists()
    assert not (final / "result.json").exists()
    failed = final.parent / f"{final.name}.failed"
    assert (failed / "yade.log").is_file()
    assert not (failed / "result.json").exists()


# ---------------------------------------------------------------- restitution

@pytest.mark.parametrize("e", [0.3, 0.7])
def test_restitution_on_steel_table(tmp_path, e):
    """(b) v_out / v_in of a particle hitting the steel table = configured restitution
    (Cundall damping a = (1 - e^2) / (1 + e^2)) within 0.05."""
    m = run_scene(tmp_path, "drop", {"contact.restitution": e}, {"impact_speed_m_s": 1.0})
    print("restitution", e, m)
    assert m["contact_steps"] >= 8                      # the contact is resolved in time
    assert m["ratio"] == pytest.approx(e, abs=0.05)


# ---------------------------------------------------------------- sliding onset

@pytest.mark.parametrize("mu", [0.3, 0.5])
@pytest.mark.parametrize("dtan", [-0.03, 0.03])
def test_sliding_onset_on_tilted_table(tmp_path, mu, dtan):
    """(c) a particle that cannot roll slides on the steel table iff tan(t) > mu
    (particle-steel friction). Tilt = gravity vector rotated, ramped over 0.2 s, held 1 s.
    Restitution 0.7 (damping 0.34) so that a slide at tan(t) = mu + 0.03 is clearly visible:
    down-slope acceleration (1 - a) g cos t (tan t - mu) ~ 0.18 m/s^2 -> ~ 9 cm in 1 s."""
    m = run_scene(tmp_path, "incline",
                  {"contact.restitution": 0.7, "interactions.steel.friction_coefficient": mu},
                  {"tan_angle": mu + dtan, "settle_s": 0.1, "ramp_s": 0.2, "hold_s": 1.0})
    print("incline", mu, dtan, m)
    if dtan < 0:
        assert abs(m["slide_total_m"]) < 1e-4, m        # sticks (elastic creep only)
        assert m["ft_over_fn"] == pytest.approx(mu + dtan, abs=0.005)
    else:
        assert m["slide_during_hold_m"] > 0.01, m       # slides and keeps sliding
        assert m["final_speed_m_s"] > 0.01
        assert m["ft_over_fn"] == pytest.approx(mu, abs=0.005)
        # sliding acceleration with Cundall damping (force along the velocity: x (1 - a))
        t, a = math.atan(mu + dtan), m["damping"]
        acc = (1 - a) * G * math.cos(t) * (math.tan(t) - mu)
        assert m["final_speed_m_s"] == pytest.approx(acc * 1.0, rel=0.1)


# ---------------------------------------------------------------- rolling resistance on a wall

ROLL_OVERRIDES = {"interactions.steel.friction_coefficient": 1.0,      # no slip
                  "interactions.steel.rolling_resistance_coefficient": 0.1}


def rolling_stop_distance(v0, eta, g=G):
    """Stop distance of a sphere rolling without slip against a resistive moment M = eta R m g.

    Unknown contact friction force F (opposing the motion), rolling v = omega R:
        m dv/dt = -F,          I domega/dt = F R - M,   I = 2/5 m R^2
        => dv/dt = -M / (R (m + I / R^2)) = -eta g / (1 + 2/5) = -(5/7) eta g
    and d = v0^2 / (2 x (5/7) eta g).  (v0 = 0.5 m/s, eta = 0.1: d = 0.1784 m.)
    """
    return v0 ** 2 / (2.0 * 5.0 / 7.0 * eta * g)


def test_rolling_stop_distance_on_steel_matches_law(tmp_path):
    """(d) the pure rolling law (Newton damping 0) on the steel table: stop distance within
    5 % of rolling_stop_distance(). The steel pair's eta (0.1) is below the particle's own
    (0.35), so the wall side of YADE's min(etaRoll_1 R_1, etaRoll_2 R_2) governs: this
    checks contact.WALL_RADIUS_FACTOR = 2 (facet reference radius 2R, wall etaRoll eta/2)."""
    v0, eta = 0.5, 0.1
    m = run_scene(tmp_path, "roll", ROLL_OVERRIDES, {"launch_speed_m_s": v0, "damping": 0, "max_time_s": 2.0})
    print("rolling undamped", m, "theory", rolling_stop_distance(v0, eta))
    assert m["geom_radius1_m"] == pytest.approx(m["wall_radius_factor"] * m["radius_m"])
    assert m["max_roll_moment_per_fn_m"] == pytest.approx(eta * m["radius_m"], rel=1e-9)
    assert m["max_slip_speed_m_s"] < 0.01 * v0                  # rolled, did not slide
    assert m["stop_distance_m"] == pytest.approx(rolling_stop_distance(v0, eta), rel=0.05)


def test_rolling_with_configured_damping_stops_short(tmp_path):
    """With the configured restitution (e = 0.3 -> Cundall damping a = 0.835) the damping
    also brakes a rolling particle: measured 0.084 m instead of 0.178 m (0.47 x the law,
    i.e. rolling resistance acts ~2.1 x stronger while particles move). Not a law error,
    but calibrated eta values absorb it; pinned here so a change is noticed."""
    v0, eta = 0.5, 0.1
    m = run_scene(tmp_path, "roll", ROLL_OVERRIDES, {"launch_speed_m_s": v0, "damping": "config", "max_time_s": 2.0})
    ratio = m["stop_distance_m"] / rolling_stop_distance(v0, eta)
    print("rolling damped", m, "ratio to law", ratio)
    assert 0.40 < ratio < 0.55
