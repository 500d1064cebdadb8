"""The contact rules (pycal.contact_rules): formulas with known answers, and the pairs a
law cannot realise refused when the job is made, naming the file, the key and the reason."""
import math

import pytest

from pycal import contact_rules as rules
from pycal.errors import ConfigError
from pycal.jobs import resolve_job


def test_restitution_needs_no_compensation_without_damping():
    assert rules.restitution_input(0.3, 0.0) == 0.3


def test_restitution_compensation_undoes_the_damping_factor():
    """Cundall damping a scales a bounce by sqrt((1 - a) / (1 + a)) (e.g. a = 0.05: 0.9512);
    the input times that factor is the asked restitution."""
    a = 0.05
    e_in = rules.restitution_input(0.3, a)
    assert e_in * math.sqrt(0.95 / 1.05) == pytest.approx(0.3, rel=1e-12)
    assert rules.restitution_input(0.99, a) == 1.0          # capped: no dashpot at all


def test_rolling_radius_is_the_particles_own_on_a_wall_and_the_smaller_between_spheres():
    assert rules.rolling_radius(0.0125, None) == 0.0125
    assert rules.rolling_radius(None, 0.004) == 0.004
    assert rules.rolling_radius(0.0125, 0.004) == 0.004


def test_mindlin_shear_stiffness_of_equal_spheres():
    """Mindlin: k_t = 8 G* sqrt(R* delta), 1/G* = 2 (2 - nu) / G for one material, R* = R/2."""
    e, nu, r = 6e6, 0.3, 0.0125
    g = e / (2 * (1 + nu))
    expect = 8 * g / (2 * (2 - nu)) * math.sqrt(r / 2)
    assert rules.mindlin_shear_stiffness_coefficient(e, nu, r, e, nu, r) == pytest.approx(expect, rel=1e-12)
    # a rigid flat wall: G* = G / (2 - nu), R* = R
    wall = rules.mindlin_shear_stiffness_coefficient(e, nu, r, 1e30, nu, None)
    assert wall == pytest.approx(8 * g / (2 - nu) * math.sqrt(r), rel=1e-9)


def test_moment_stiffness_keeps_the_rotation_frequency_per_particle_size():
    """k_r / I must scale like k_t / m whatever the size: the rotation frequency of a 1 mm
    particle relative to its translation frequency equals that of a 25 mm one."""
    e, nu, rho = 6e6, 0.3, 2750

    def freq_ratio(r):
        m = rho * 4 / 3 * math.pi * r ** 3
        kt = rules.reference_tangential_stiffness(e, nu, r)
        kr = rules.moment_stiffness(1.0, kt, r)
        return math.sqrt(kr / (0.4 * m * r * r)) / math.sqrt(kt / m)

    assert freq_ratio(0.0005) == pytest.approx(freq_ratio(0.0125), rel=1e-9)
    assert freq_ratio(0.0125) == pytest.approx(math.sqrt(2.5), rel=1e-9)


def test_default_job_runs_on_hertz_mindlin():
    job = resolve_job("fill", "M2")
    assert rules.check_job(job) == "hertz_mindlin"
    assert job["rig_config"]["numerics"]["contact_model"] == "hertz_mindlin"


def test_contact_model_changes_the_job_id():
    a = resolve_job("fill", "M2")
    b = resolve_job("fill", "M2", {"rig.numerics.contact_model": "linear_cundall"})
    assert a["job_id"] != b["job_id"]


def test_unknown_contact_model_is_refused():
    with pytest.raises(ConfigError, match=r"--set: rig.numerics.contact_model='dem': "
                                          r"'dem' must be one of hertz_mindlin, linear_cundall"):
        resolve_job("fill", "M2", {"rig.numerics.contact_model": "dem"})


def test_adhesive_distance_cannot_be_realised_on_hertz_mindlin():
    with pytest.raises(ConfigError, match=r"configs/materials/M3-wet.yaml: interactions.steel.cohesion."
                                          r"adhesive_distance_m: 0.001 > 0 cannot be realised: the Hertz-Mindlin"):
        resolve_job("fill", "M3-wet", {"interactions.steel.cohesion.adhesive_distance_m": 0.001})


def test_first_law_takes_one_restitution_per_scene():
    with pytest.raises(ConfigError, match=r"restitution_coefficient: 0.5 differs from .*linear_cundall realises "
                                          r"one restitution per scene"):
        resolve_job("fill", "M2", {"rig.numerics.contact_model": "linear_cundall",
                                   "interactions.steel.restitution_coefficient": 0.5})


def test_first_law_has_no_linear_cohesion():
    coh = {"model": "linear", "stiffness_fraction": 0.1, "adhesive_distance_m": 0.0, "update_interval_s": 0.01}
    with pytest.raises(ConfigError, match=r"interactions.steel.cohesion.model: 'linear' cannot be combined with "
                                          r"the linear_cundall law"):
        resolve_job("fill", "M2", {"rig.numerics.contact_model": "linear_cundall", "interactions.steel.cohesion": coh})
    resolve_job("fill", "M2", {"interactions.steel.cohesion": coh})          # the default law has it


def test_liquid_bridge_with_rolling_resistance_names_the_pair():
    bridge = {"model": "liquid_bridge", "surface_tension_n_m": 1.8, "contact_angle_deg": 0.0,
              "bridge_liquid_fraction": 0.1, "coordination_count": 6.0}
    others = {f"interactions.{p}.cohesion": {"model": "none"} for p in ("M1", "M2", "M3-dry", "steel", "pvc")}
    with pytest.raises(ConfigError, match=r"configs/materials/M3-wet.yaml: interactions.M3-wet.rolling_resistance_"
                                          r"coefficient: 0.35: the liquid-bridge law \(viscoelastic_capillary\) has "
                                          r"no rolling resistance"):
        resolve_job("fill", "M3-wet", {"interactions.M3-wet.cohesion": bridge, **others})


def test_liquid_bridge_with_another_cohesion_names_the_pair():
    bridge = {"model": "liquid_bridge", "surface_tension_n_m": 1.8, "contact_angle_deg": 0.0,
              "bridge_liquid_fraction": 0.1, "coordination_count": 6.0}
    with pytest.raises(ConfigError, match=r"configs/materials/M3-wet.yaml: interactions.steel.cohesion.model: "
                                          r"'force_fraction' cannot be combined with the viscoelastic_capillary law"):
        resolve_job("fill", "M3-wet", {"interactions.M3-wet.cohesion": bridge})


def test_global_damping_beyond_the_limit_is_refused():
    with pytest.raises(ConfigError, match=r"numerics.yaml or configs/rigs/fill.yaml: global_damping_ratio: 0.2 "
                                          r"must be within 0 - 0.05"):
        resolve_job("fill", "M2", {"rig.numerics.global_damping_ratio": 0.2})
