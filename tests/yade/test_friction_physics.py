"""Physics of the tilt-table friction rigs and of the cohesion laws (real YADE runs).

Wall-friction jobs go through pycal.jobs.resolve_job + pycal.runner.run_job into a
pytest tmp folder (M2, seed 1, -j1: bit-reproducible). To make the answer known, the
particles cannot roll (rolling resistance 1.0 on every pair: a sphere bed with rolling
resistance 0.35 rolls on the plate below the sliding friction, so its wall friction is
a bulk property, not the contact value); the bed must then slide at tan(angle) = mu of
the particle-steel pair, as long as the contents are stronger than that contact: the
loose struck fill (solid fraction ~0.37) shears inside itself at a stress ratio of
~0.26 - 0.36 (measured: mu = 0.35 read 0.262, mu = 0.5 read 0.365 at 3 kPa, mu = 0 for
the particle pairs read even less), as a lab wall-friction test measures the weaker of
wall and internal friction. So the resolution is tested at mu = 0.1, 0.2, 0.3 on the
fresh fill and at mu = 0.5 after a 40 kPa consolidation (read 0.512).

Bounds, from measurements of these scenes (default law hertz_mindlin, M2 start values
E 2e7 Pa, tilt 2 deg/s, onset 1 mm, travel 10 mm; the first law's figures in brackets):
- resolution: mu = 0.1 read 0.107 (3 kPa), mu = 0.2 read 0.202 / 0.206 (3 / 40 kPa),
  mu = 0.3 read 0.2775 at 3 kPa, mu = 0.5 read 0.504 after 40 kPa [0.512]; the dynamic
  readings are 0.100, 0.199 / 0.200, 0.2995, 0.500 and the plate's force ratio at the
  onset 0.100, 0.200, 0.278, 0.4995 -> |mu_static - mu| <= 0.03 (the issue's resolution);
- on the loose fresh fill (3 kPa) the bed deforms before the cell slides as a block, so
  the static reading can come before mu (0.2775 for 0.3: the cell crept 0.25 mm by 12 deg
  and reached the 1 mm onset at 15.5 deg while the plate's force ratio was 0.278); after a
  40 kPa consolidation it does not (0.304 static, 0.2999 dynamic) -> "dynamic not above
  static" is checked on consolidated steps only;
- no cohesion, mu = 0.2: 0.202 at 3 kPa, 0.206 at 40 kPa -> |rise| <= 0.03;
- hysteretic cohesion (pressure_fraction 0.02 on the particle-steel pair, mu = 0.2):
  0.202 at 3 kPa, 0.291 at 40 kPa [0.296, 0.446] (no cohesion: 0.206) -> rise >= 0.05 and
  >= 0.05 above the cohesionless reading;
- two spheres, the lower one hanging from a fixed one: force_fraction 1.5 holds
  (displacement < 1 mm after 0.5 s), 0.5 parts (> 5 mm); hysteretic with force_fraction
  0.5 parts when not pressed and holds after being pressed with 20 x its weight
  (pressure_fraction 0.1: pull-off 0.5 + 1.9 weights);
- internal friction (M2, seed 1, 3 kPa, a fresh fill per step): frictionless non-rolling
  spheres 0.138 [0.138], start values 0.385 [0.428] -> smooth < 0.25 and rough > smooth +
  0.15; two steps at the same stress are the same simulation (bit for bit).
"""
import json
import os
import subprocess
import textwrap
from pathlib import Path

import pytest

from pycal import REPO_ROOT
from pycal.jobs import resolve_job
from pycal.runner import run_job, yade_env

from documented import assert_documented

pytestmark = pytest.mark.yade

SEED = 1
NO_ROLL = {"interactions.M2.rolling_resistance_coefficient": 1.0,
           "interactions.steel.rolling_resistance_coefficient": 1.0,
           "interactions.pvc.rolling_resistance_coefficient": 1.0}
RESOLUTION = 0.03
HYSTERETIC = {"model": "hysteretic", "force_fraction": 0.05, "pressure_fraction": 0.02,
              "update_interval_s": 0.01}

_RUNS = {}


def wall(tmp_path_factory, name, mu, stresses, cohesion=None):
    """One wall-friction run (cached per session)."""
    if name not in _RUNS:
        o = dict(NO_ROLL)
        o["interactions.steel.friction_coefficient"] = mu
        o["rig.procedure.consolidation_stresses_pa"] = stresses
        if cohesion is not None:
            o["interactions.steel.cohesion"] = cohesion
        job = resolve_job("wall_friction", "M2", o, seed=SEED)
        _RUNS[name] = run_job(job, runs_dir=tmp_path_factory.mktemp(name), timeout_s=900)
    return _RUNS[name]


# mu -> consolidation stresses of the run, and which steps must read mu
CASES = {0.1: ([3000], [0]), 0.2: ([3000, 40000], [0, 1]), 0.3: ([3000], [0]), 0.5: ([3000, 40000], [1])}
CONSOLIDATED_PA = 40000      # from here on the bed slides as a block: dynamic reading not above static


@pytest.mark.parametrize("mu", sorted(CASES))
def test_cell_slides_at_tan_angle_equal_mu(tmp_path_factory, mu):
    stresses, steps = CASES[mu]
    r = wall(tmp_path_factory, f"mu{mu}", mu, stresses)
    for k in steps:
        assert not r["sticks"][k]
        assert abs(r["mu_static"][k] - mu) <= RESOLUTION, (stresses[k], r["mu_static"][k])
        assert abs(r["mu_dynamic"][k] - mu) <= RESOLUTION, (stresses[k], r["mu_dynamic"][k])
        # the plate's own force ratio at the onset tells the same
        assert abs(r["plate_force_ratio_onset"][k] - mu) <= RESOLUTION


@pytest.mark.parametrize("mu", [m for m in sorted(CASES) if max(CASES[m][0]) >= CONSOLIDATED_PA])
def test_dynamic_not_above_static_once_consolidated(tmp_path_factory, mu):
    stresses, steps = CASES[mu]
    r = wall(tmp_path_factory, f"mu{mu}", mu, stresses)
    checked = [k for k in steps if stresses[k] >= CONSOLIDATED_PA]
    assert checked
    for k in checked:
        assert r["mu_dynamic"][k] <= r["mu_static"][k]


def test_no_rise_with_consolidation_without_cohesion(tmp_path_factory):
    r = wall(tmp_path_factory, "mu0.2", 0.2, CASES[0.2][0])
    assert r["stress_pa"] == [3000, 40000]
    assert abs(r["mu_static"][1] - r["mu_static"][0]) <= RESOLUTION
    # the spring curve of both loads was recorded and reached the targets
    assert len(r["spring_curve"]["lid_position_m"]) > 4
    for want, got in zip([3000, 40000], r["stress_reached_pa"]):
        assert abs(got - want) <= 0.02 * want


def test_hysteretic_cohesion_friction_rises_with_consolidation(tmp_path_factory):
    base = wall(tmp_path_factory, "mu0.2", 0.2, CASES[0.2][0])
    r = wall(tmp_path_factory, "hyst", 0.2, CASES[0.2][0], cohesion=HYSTERETIC)
    assert r["mu_static"][1] - r["mu_static"][0] >= 0.05
    assert r["mu_static"][1] - base["mu_static"][1] >= 0.05
    assert_documented(r)              # with cohesion_update_count


# ---------------------------------------------------------------- two spheres

PAIR_SCENE = textwrap.dedent('''
    """Two spheres: A fixed, B hanging below it by a fresh bond (contact.py family of
    the job); optionally B is first pressed up against A with press_weights x its weight."""
    import json, os, sys
    from yade import O, utils, Vector3
    from yade_scripts.demlib.scene import Scene

    def case(job, press):
        sc = Scene(job)
        r = sc.radius
        m = sc.contact.mat_id[job["material"]]
        a = O.bodies.append(utils.sphere((0, 0, 0.2), r, material=m, fixed=True))
        b = O.bodies.append(utils.sphere((0, 0, 0.2 - 2 * r + 1e-6), r, material=m))
        sc.set_timestep()
        w = O.bodies[b].state.mass * sc.g
        O.step()
        if press:      # press up against A, then release slowly (a sudden release rebounds)
            for k in range(41):
                f = press * w * min(1.0, k / 10.0) if k <= 10 else press * w * (40 - k) / 30.0
                O.forces.setPermF(b, Vector3(0, 0, f))
                sc.advance(int(0.01 / O.dt))
            O.forces.setPermF(b, Vector3(0, 0, 0))
        z0 = O.bodies[b].state.pos[2]
        sc.advance(int(0.5 / O.dt))
        return z0 - O.bodies[b].state.pos[2]

    job = json.load(open(sys.argv[1]))
    out = {name: case(j, press) for name, (j, press) in
           ((n, (job["cases"][n]["job"], job["cases"][n]["press"])) for n in job["cases"])}
    json.dump(out, open("pair.json", "w"))
    sys.stdout.flush()
    os._exit(0)
''')



def run_pair_scene(d, cases):
    """Run PAIR_SCENE in folder d on {name: {job, press}}; returns {name: displacement m}."""
    (d / "cases.json").write_text(json.dumps({"cases": cases}))
    (d / "pair.py").write_text(PAIR_SCENE)
    proc = subprocess.run(["yade", "-j1", "-x", "-n", "pair.py", "cases.json", str(REPO_ROOT)], cwd=d,
                          capture_output=True, text=True, timeout=300, env=yade_env())
    out = d / "pair.json"
    assert proc.returncode == 0 and out.is_file(), proc.stdout[-2000:] + proc.stderr[-2000:]
    return json.loads(out.read_text())

@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    d = tmp_path_factory.mktemp("pair")

    def job(coh):
        return resolve_job("wall_friction", "M2", {"interactions.M2.cohesion": coh}, seed=SEED)

    cases = {
        "ff_above": {"job": job({"model": "force_fraction", "force_fraction": 1.5, "adhesive_distance_m": 0.0}),
                     "press": 0},
        "ff_below": {"job": job({"model": "force_fraction", "force_fraction": 0.5, "adhesive_distance_m": 0.0}),
                     "press": 0},
        "hyst_unpressed": {"job": job({"model": "hysteretic", "force_fraction": 0.5, "pressure_fraction": 0.1,
                                       "update_interval_s": 0.005}), "press": 0},
        "hyst_pressed": {"job": job({"model": "hysteretic", "force_fraction": 0.5, "pressure_fraction": 0.1,
                                     "update_interval_s": 0.005}), "press": 20},
    }
    return run_pair_scene(d, cases)


def test_bond_above_weight_holds_below_parts(pair):
    assert pair["ff_above"] < 0.001
    assert pair["ff_below"] > 0.005


def test_hysteretic_bond_grows_with_pressing(pair):
    assert pair["hyst_unpressed"] > 0.005
    assert pair["hyst_pressed"] < 0.001


def test_liquid_bridge_holds_when_stronger_than_weight(tmp_path_factory):
    """Willett bridge between two stand-ins (contact_capillary family): with an effective
    surface tension whose largest bridge force 2 pi R gamma is 3x the weight the lower
    sphere hangs; at 1/3 of the weight it falls."""
    d = tmp_path_factory.mktemp("bridge")
    base = {"interactions.M2.rolling_resistance_coefficient": 0.0,
            "interactions.steel.rolling_resistance_coefficient": 0.0,
            "interactions.pvc.rolling_resistance_coefficient": 0.0,
            "interactions.M3-dry.rolling_resistance_coefficient": 0.0,
            "interactions.M1.rolling_resistance_coefficient": 0.0,
            "moisture_percent_dry_basis": 5.4}
    weight = 2750 * 4.0 / 3.0 * 3.141592653589793 * 0.0125 ** 3 * 9.81
    gamma_for = lambda ratio: ratio * weight / (2 * 3.141592653589793 * 0.0125)   # noqa: E731

    def job(ratio):
        o = dict(base)
        o["interactions.M2.cohesion"] = {"model": "liquid_bridge", "surface_tension_n_m": gamma_for(ratio),
                                         "contact_angle_deg": 0.0, "bridge_liquid_fraction": 0.2,
                                         "coordination_count": 6}
        return resolve_job("wall_friction", "M2", o, seed=SEED)

    cases = {"strong": {"job": job(3.0), "press": 0}, "weak": {"job": job(1.0 / 3.0), "press": 0}}
    res = run_pair_scene(d, cases)
    assert res["strong"] < 0.002
    assert res["weak"] > 0.005


# ---------------------------------------------------------------- internal friction

FRICTIONLESS = {"interactions.M2.friction_coefficient": 0.0, "interactions.pvc.friction_coefficient": 0.0,
                "interactions.M2.rolling_resistance_coefficient": 0.0,
                "interactions.steel.rolling_resistance_coefficient": 0.0,
                "interactions.pvc.rolling_resistance_coefficient": 0.0}
SMOOTH_MAX = 0.25  # measured 0.138 (onset at 7.9 deg, seed 1, 3 kPa); start values 0.428
INTERNAL_SHORT = {"rig.procedure.max_tilt_deg": 50.0}   # a cell that has not travelled by 50 deg sticks


def internal(tmp_path_factory, name, overrides, stresses):
    if name not in _RUNS:
        o = dict(INTERNAL_SHORT, **overrides)
        o["rig.procedure.consolidation_stresses_pa"] = stresses
        job = resolve_job("internal_friction", "M2", o, seed=SEED)
        _RUNS[name] = run_job(job, runs_dir=tmp_path_factory.mktemp(name), timeout_s=900)
    return _RUNS[name]


def test_internal_friction_fresh_fill_per_step_repeats_bit_for_bit(tmp_path_factory):
    """fill_each_step: fresh - the same seed gives the same fill, so two steps at the same
    stress are the same simulation (the shipped cell, free to tip)."""
    r = internal(tmp_path_factory, "internal_start", {}, [3000, 3000])
    assert r["fill_each_step"] == "fresh"
    assert_documented(r)
    assert r["mu_static"][0] == r["mu_static"][1]
    assert r["onset_angle_deg"][0] == r["onset_angle_deg"][1]
    assert r["cell_rotation_onset_deg"][0] == r["cell_rotation_onset_deg"][1]


def test_a_cell_free_to_turn_records_how_far_it_turned(tmp_path_factory):
    """sliding_cell_rotations: free (the shipped rig): the mobile cell tips as it is pushed
    over the contents, and the rig says by how much at the onset; a guided cell
    (blocked) on the same fill reads exactly 0."""
    free = internal(tmp_path_factory, "internal_start", {}, [3000, 3000])
    guided = internal(tmp_path_factory, "internal_guided", {"rig.procedure.sliding_cell_rotations": "blocked"}, [3000])
    assert free["onset_angle_deg"][0] is not None
    assert 0.01 < free["cell_rotation_onset_deg"][0] < 45.0
    assert guided["cell_rotation_onset_deg"] == [0.0]


def test_a_tipping_cell_moves_its_centre_of_mass_before_its_rim(tmp_path_factory):
    """slide_read_at: shear_plane (shipped) reads a turning cell's slide at the centre of its
    bottom rim: a cell that tips forward carries its centre of mass (~70 mm up) ahead of the
    rim on the shear plane, so the same fill (same seed) reaches 1 mm of slide later there,
    after turning further (M3-dry, 5 seeds at friction 0.5: 1.7 - 2.9 deg against 0.5)."""
    com = internal(tmp_path_factory, "internal_turning_com", {"rig.procedure.slide_read_at": "body"}, [3000])
    rim = internal(tmp_path_factory, "internal_start", {}, [3000, 3000])
    assert rim["onset_angle_deg"][0] > com["onset_angle_deg"][0]
    assert rim["cell_rotation_onset_deg"][0] > com["cell_rotation_onset_deg"][0]


def test_internal_friction_of_frictionless_spheres_is_low_and_rises_with_contact_friction(tmp_path_factory):
    """Frictionless, non-rolling spheres shear at a low angle (only the packing's
    geometry resists: sphere packings without contact friction shear at tan ~0.1);
    the start values (particle friction 0.6, rolling 0.35) much later (measured 0.138
    and 0.385, seed 1, 3 kPa)."""
    smooth = internal(tmp_path_factory, "internal_smooth", FRICTIONLESS, [3000])
    rough = internal(tmp_path_factory, "internal_start", {}, [3000, 3000])
    assert smooth["mu_static"][0] < SMOOTH_MAX
    assert rough["mu_static"][0] > smooth["mu_static"][0] + 0.15


def test_static_only_reads_the_same_onset_and_skips_the_hold(tmp_path_factory):
    """measure_dynamic_friction: false ends a step at the onset: the same mu_static to the
    last bit (the hold comes after the reading), no dynamic value, fewer time steps."""
    full = wall(tmp_path_factory, "mu0.3", 0.3, [3000])
    o = dict(NO_ROLL, **{"interactions.steel.friction_coefficient": 0.3,
                         "rig.procedure.consolidation_stresses_pa": [3000],
                         "rig.procedure.measure_dynamic_friction": False})
    static = run_job(resolve_job("wall_friction", "M2", o, seed=SEED),
                     runs_dir=tmp_path_factory.mktemp("static"), timeout_s=900)
    assert static["mu_static"] == full["mu_static"] and full["mu_dynamic"][0] is not None
    assert static["mu_dynamic"] == [None] and static["sticks"] == [False]
    assert static["steps"] < full["steps"]


def test_the_phase_clock_accounts_for_every_time_step(tmp_path_factory):
    """provenance.phase_cpu: the phases' time steps add up to YADE's own count (a stepping
    loop that bypassed the clock would show here), and the tilt phases did step."""
    r = wall(tmp_path_factory, "mu0.2", 0.2, CASES[0.2][0])
    phases = r["provenance"]["phase_cpu"]
    assert sum(p["steps_count"] for p in phases.values()) == r["steps"] == r["provenance"]["steps_count"]
    for name in ("pour", "consolidate", "tilt_static", "tilt_dynamic", "tilt_back"):
        assert phases[name]["steps_count"] > 0 and phases[name]["step_cpu_s"] > 0, name
