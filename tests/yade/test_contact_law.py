"""Physics layer of the default contact law (hertz_mindlin): short real-YADE scenes built
with the rigs' own library (demlib.scene.Scene from a job of pycal.jobs.resolve_job), each
checked against an answer known without the code. Scenes: tests/yade/scenes/*.py."""
import math

import pytest

from pycal import contact_rules
from scene_runner import add_material, run_scene, scene_job

pytestmark = pytest.mark.yade
G = 9.81


def test_default_law_is_hertz_mindlin_without_global_damping():
    job = scene_job()
    assert job["rig_config"]["numerics"]["contact_model"] == "hertz_mindlin"
    assert job["rig_config"]["numerics"]["global_damping_ratio"] == 0.0


def test_free_fall_at_g(tmp_path):
    """No contact: the drop after t is g t^2 / 2 within 0.5 % (leapfrog: exact to dt / t)."""
    m = run_scene(tmp_path, "fall", scene_job(), {"fall_time_s": 0.3})
    assert m["law"] == "hertz_mindlin"
    assert m["drop_m"] == pytest.approx(0.5 * G * m["time_s"] ** 2, rel=0.005)
    assert m["speed_m_s"] == pytest.approx(G * m["time_s"], rel=0.005)


@pytest.mark.parametrize("target", ["plate", "sphere"])
@pytest.mark.parametrize("e", [0.3, 0.6])
def test_bounce_at_the_pair_restitution(tmp_path, target, e):
    """v_out / v_in on the steel table (particle-steel pair) and on a fixed sphere of the
    particle's material (particle-particle pair) = that pair's restitution within 0.02; the
    other pair is given a different value, so the contact must take its own pair's."""
    other = 0.9 if e < 0.5 else 0.2
    pp, pw = (other, e) if target == "plate" else (e, other)
    job = scene_job({"interactions.M2.restitution_coefficient": pp, "interactions.steel.restitution_coefficient": pw})
    m = run_scene(tmp_path, "bounce", job, {"target": target, "impact_speed_m_s": 1.0})
    assert m["contact_steps"] >= 15                      # the collision is resolved in time
    assert m["ratio"] == pytest.approx(e, abs=0.02)


def test_bounce_with_global_damping_is_compensated(tmp_path):
    """A user who adds global damping (0.05, the largest allowed) still gets the configured
    restitution: the dashpot value is raised to make up for it."""
    job = scene_job({"rig.numerics.global_damping_ratio": 0.05})
    m = run_scene(tmp_path, "bounce", job, {"target": "plate", "impact_speed_m_s": 1.0})
    assert m["damping"] == 0.05
    assert m["ratio"] == pytest.approx(0.3, abs=0.02)


def rolling_stop_distance(v0, mu_r, g=G):
    """Stop distance of a sphere rolling without slip against the moment mu_r R m g:
    m dv/dt = -F, I dw/dt = F R - mu_r R m g, I = 2/5 m R^2, v = w R
    => dv/dt = -(5/7) mu_r g, d = v0^2 / (2 (5/7) mu_r g) = 0.7 v0^2 / (mu_r g)."""
    return 0.7 * v0 ** 2 / (mu_r * g)


def test_rolling_stop_distance_on_a_wall_and_on_a_sphere(tmp_path):
    """Two pair values in one scene: mu_r 0.1 on the steel table (a facet), 0.2 with the
    fixed sphere of a second material. Each particle stops within 5 % of the distance of the
    rolling law with its own pair's value, and its contact holds mu_r x its own radius."""
    v0 = 0.5
    job = scene_job({"interactions.steel.friction_coefficient": 1.0,
                     "interactions.steel.rolling_resistance_coefficient": 0.1})
    add_material(job, "anvil", "M2", {"anvil": {"friction_coefficient": 1.0, "rolling_resistance_coefficient": 0.2},
                                      "M2": {"friction_coefficient": 1.0, "rolling_resistance_coefficient": 0.2}})
    job["materials"]["M2"]["interactions"]["anvil"].update({"friction_coefficient": 1.0,
                                                            "rolling_resistance_coefficient": 0.2})
    m = run_scene(tmp_path, "roll", job, {"anvil_radius_m": 10.0, "anvil_start_arc_m": rolling_stop_distance(v0, 0.2),
                                          "launch_speed_m_s": v0, "damping": "config", "max_time_s": 3.0})
    r = m["radius_m"]
    assert m["max_slip_speed_m_s"] < 0.01 * v0                         # rolled, did not slide
    assert m["contacts"]["table"]["max_bend_per_fn_m"] == pytest.approx(0.1 * r, rel=1e-9)
    assert m["contacts"]["anvil"]["max_bend_per_fn_m"] == pytest.approx(0.2 * r, rel=1e-9)
    assert m["table_distance_m"] == pytest.approx(rolling_stop_distance(v0, 0.1), rel=0.05)
    assert m["anvil_distance_m"] == pytest.approx(rolling_stop_distance(v0, 0.2), rel=0.05)


def test_a_1_mm_particle_rolls_to_the_law_too(tmp_path):
    """The rolling and twisting springs scale with k_t R^2: a 1 mm particle is as stable at
    its time step as a 25 mm one and stops at the law's distance (v0 0.1 m/s, mu_r 0.1)."""
    v0 = 0.1
    job = scene_job({"particles.diameter_m": 0.001, "interactions.steel.friction_coefficient": 1.0,
                     "interactions.steel.rolling_resistance_coefficient": 0.1})
    add_material(job, "anvil", "M2", {})
    m = run_scene(tmp_path, "roll", job, {"anvil_radius_m": 10.0, "anvil_start_arc_m": 0.005,
                                          "launch_speed_m_s": v0, "damping": "config", "max_time_s": 0.5})
    assert m["radius_m"] == 0.0005
    assert m["max_slip_speed_m_s"] < 0.01 * v0
    assert m["table_distance_m"] == pytest.approx(rolling_stop_distance(v0, 0.1), rel=0.05)


@pytest.mark.parametrize("mu", [0.3, 0.5])
@pytest.mark.parametrize("dtan", [-0.03, 0.03])
def test_sliding_onset_at_tan_equal_mu(tmp_path, mu, dtan):
    """A particle that cannot roll sits on the steel table; gravity is tilted to t (ramped,
    then held). It sticks for tan t = mu - 0.03 and slides for mu + 0.03, with the tangential
    force at mu x the normal force, accelerating at g (sin t - mu cos t)."""
    job = scene_job({"interactions.steel.friction_coefficient": mu})
    m = run_scene(tmp_path, "incline", job, {"tan_angle": mu + dtan, "settle_s": 0.1, "ramp_s": 0.2, "hold_s": 1.0})
    if dtan < 0:
        assert abs(m["slide_total_m"]) < 1e-4, m                        # sticks (elastic creep only)
        assert m["ft_over_fn"] == pytest.approx(mu + dtan, abs=0.005)
    else:
        assert m["slide_during_hold_m"] > 0.01, m
        assert m["ft_over_fn"] == pytest.approx(mu, abs=0.005)
        t = math.atan(mu + dtan)
        acc = G * (math.sin(t) - mu * math.cos(t))
        # speed gained over the 1 s hold (the slide started during the ramp)
        assert m["final_speed_m_s"] - m["speed_at_hold_m_s"] == pytest.approx(acc * 1.0, rel=0.03)


def test_heap_at_rest_does_not_creep(tmp_path):
    """The AoR rig's pile (~80 particles of 25 mm) at rest moves < 0.1 mm in 2 s more."""
    job = scene_job({"rig.procedure.lift_speed_m_s": 0.01}, rig="aor")
    m = run_scene(tmp_path, "heap", job, {"creep_time_s": 2.0})
    assert m["n_particles"] >= 60
    assert m["max_creep_m"] < 1e-4


def pull(tmp_path, cohesion, press_weights=0.0, material="M2", overrides=None):
    job = scene_job({f"interactions.{material}.cohesion": cohesion, **(overrides or {})}, material=material)
    return run_scene(tmp_path, "pull", job, {"press_weights": press_weights, "hold_time_s": 0.5})


HELD, LET_GO = 1e-3, 0.1        # m fallen in 0.5 s: held (elastic sag only) / let go (free fall: 1.2 m)


@pytest.mark.parametrize("weights, held", [(2.0, True), (0.5, False)])
def test_constant_adhesion_holds_twice_the_weight(tmp_path, weights, held):
    """force_fraction f: pull-off = f x the particle's weight."""
    m = pull(tmp_path, {"model": "force_fraction", "force_fraction": weights, "adhesive_distance_m": 0.0})
    assert (m["fall_m"] < HELD) if held else (m["fall_m"] > LET_GO), m
    if held:
        assert m["adhesion_n"] == pytest.approx(weights * m["weight_n"], rel=1e-9)


@pytest.mark.parametrize("weights, held", [(2.0, True), (0.5, False)])
def test_hysteretic_adhesion_grows_with_the_press(tmp_path, weights, held):
    """hysteretic, force_fraction 0: pull-off = pressure_fraction x the largest compressive
    force. Pressed with 4 weights, pressure_fraction = weights / 4 gives `weights` weights."""
    m = pull(tmp_path, {"model": "hysteretic", "force_fraction": 0.0, "pressure_fraction": weights / 4.0,
                        "update_interval_s": 0.001}, press_weights=4.0)
    assert (m["fall_m"] < HELD) if held else (m["fall_m"] > LET_GO), m


def test_hysteretic_adhesion_without_press_lets_go(tmp_path):
    m = pull(tmp_path, {"model": "hysteretic", "force_fraction": 0.0, "pressure_fraction": 0.5,
                        "update_interval_s": 0.001})
    assert m["fall_m"] > LET_GO, m


@pytest.mark.parametrize("weights, held", [(2.0, True), (0.5, False)])
def test_linear_adhesion_is_stiffness_times_overlap(tmp_path, weights, held):
    """linear s: pull-off = s x k_n x overlap at the largest overlap the contact was pressed to;
    Hertz: k_n x overlap = 1.5 x the force, so after a press of 4 weights it is 6 s weights."""
    m = pull(tmp_path, {"model": "linear", "stiffness_fraction": weights / 6.0, "adhesive_distance_m": 0.0,
                        "update_interval_s": 0.001}, press_weights=4.0)
    assert (m["fall_m"] < HELD) if held else (m["fall_m"] > LET_GO), m


@pytest.mark.parametrize("weights, held", [(2.0, True), (0.5, False)])
def test_liquid_bridge_holds_by_its_surface_tension(tmp_path, weights, held):
    """liquid_bridge (its own law): the largest bridge force 2 pi R gamma cos(theta); gamma
    chosen for `weights` x the particle's weight (rolling resistance 0: that law has none)."""
    job = scene_job(material="M3-wet")
    mat = job["materials"]["M3-wet"]
    r = 0.5 * mat["particles"]["diameter_m"]
    w = mat["particles"]["density_kg_m3"] * 4 / 3 * math.pi * r ** 3 * G
    gamma = weights * w / (2 * math.pi * r)
    zero_rolling = {f"interactions.{p}.rolling_resistance_coefficient": 0.0 for p in mat["interactions"]}
    no_cohesion = {f"interactions.{p}.cohesion": {"model": "none"} for p in mat["interactions"] if p != "M3-wet"}
    m = pull(tmp_path, {"model": "liquid_bridge", "surface_tension_n_m": gamma, "contact_angle_deg": 0.0,
                        "bridge_liquid_fraction": 0.1, "coordination_count": 6.0}, material="M3-wet",
             overrides={**zero_rolling, **no_cohesion})
    assert m["law"] == contact_rules.CAPILLARY_LAW
    assert (m["fall_m"] < HELD) if held else (m["fall_m"] > LET_GO), m


def _check_contacts(m, job):
    """Every contact read at least one update interval after it was made holds its own
    pair's friction, rolling limit mu_r x R (R: the smaller sphere) and constant pull-off
    (force_fraction x the lighter particle's weight)."""
    interval = job["rig_config"]["numerics"]["contact_update_interval_count"]
    mats = job["materials"]
    checked = set()
    for c in m["contacts"]:
        if c["made_real_iter"] > c["read_iter"] - interval:
            continue
        a, b = c["materials"]
        pair = mats[a]["interactions"][b] if a in mats else mats[b]["interactions"][a]
        r = min(x for x in c["radii_m"] if x is not None)
        assert c["friction"] == pytest.approx(pair["friction_coefficient"], rel=1e-9), c
        assert c["max_bend_per_fn_m"] == pytest.approx(pair["rolling_resistance_coefficient"] * r, rel=1e-9), c
        coh = pair["cohesion"]
        pull_off = coh.get("force_fraction", 0.0) if coh["model"] in ("force_fraction", "hysteretic") else 0.0
        lightest = min(x for x in c["masses_kg"] if x is not None)
        assert c["adhesion_n"] == pytest.approx(pull_off * lightest * m["gravity_m_s2"], rel=1e-9, abs=1e-12), c
        assert c["kr"] > 0 if pair["rolling_resistance_coefficient"] > 0 else c["kr"] == 0
        # Mindlin tangential stiffness with both materials' real E and nu (walls flat for Hertz)
        ea, eb = c["young_pa"]
        na, nb = c["poisson"]
        ra, rb = c["radii_m"]
        assert c["kso"] == pytest.approx(
            contact_rules.mindlin_shear_stiffness_coefficient(ea, na, ra, eb, nb, rb), rel=1e-6), c
        for radius, ref in zip(c["radii_m"], c["ref_radii_m"]):
            if radius is None:                                  # a facet: flat for Hertz
                assert ref == pytest.approx(contact_rules.HERTZ_FACET_FACTOR * r, rel=1e-9), c
        checked.add(tuple(sorted((a, b))))
    return checked


def test_every_pair_of_a_fill_reads_back_its_values(tmp_path):
    """M3-dry: adhesion 0.05 on steel but none on PVC, so the cell wall and the table hold
    different values; rolling 0.3 on steel and 0.2 on PVC."""
    job = scene_job({"interactions.steel.rolling_resistance_coefficient": 0.3,
                     "interactions.pvc.rolling_resistance_coefficient": 0.2}, material="M3-dry")
    m = run_scene(tmp_path, "readback", job, {"extra_time_s": 0.05})
    assert _check_contacts(m, job) >= {("M3-dry", "M3-dry"), ("M3-dry", "steel"), ("M3-dry", "pvc")}


def test_mixed_set_reads_back_every_pair(tmp_path):
    """The wet -50 mm sample: M1 lumps (clump members of several radii), M2 and M3-wet
    spheres, steel and PVC: every pair that touched holds its own values."""
    job = resolve_mixed()
    m = run_scene(tmp_path, "readback", job, {"extra_time_s": 0.05}, timeout=600)
    checked = _check_contacts(m, job)
    assert {("M2", "M3-wet"), ("M2", "M2"), ("M3-wet", "M3-wet"), ("M3-wet", "steel")} <= checked
    assert any("M1" in p for p in checked)


def resolve_mixed():
    from pycal.jobs import resolve_job
    return resolve_job("aor_mixed", "mixed-wet", {"cross_interactions.M2.M3-wet.rolling_resistance_coefficient": 0.25},
                       seed=1)
