"""geometry.scale: every length of the rig x s, the lab's stresses kept, the grains kept.

The expected values are the lab's numbers (docs/lab-tests.md: the 145 x 95 mm cell, its
2 mm gaps, the 0.3 / 0.5 kg ring and lid) times the scale, written here, not read back
from pycal's own rule table."""
import math

import pytest

from pycal.errors import ConfigError
from pycal.jobs import resolve_job
from pycal.rigs import names
from pycal.rigs.scaling import scaled_keys

G = 9.81


def geometry(job):
    return job["rig_config"]["geometry"]


def test_scale_2_doubles_the_cell_and_keeps_the_particles_and_stresses():
    lab = resolve_job("internal_friction", "M3-dry", seed=1)
    big = resolve_job("internal_friction", "M3-dry", {"rig.geometry.scale": 2}, seed=1)
    g, p = geometry(big), big["rig_config"]["procedure"]
    assert g["cell_inner_diameter_m"] == pytest.approx(0.290)
    assert g["cell_height_m"] == pytest.approx(0.190)
    assert g["cell_gap_m"] == pytest.approx(0.004)
    assert g["table_half_width_m"] == pytest.approx(0.30)
    assert p["strike_level_height_m"] == pytest.approx(2 * 0.190 + 0.004)     # both cells and the gap
    assert g["scale"] == 2
    # the particles and the lab's consolidation stresses are those of the lab-size job
    assert big["materials"] == lab["materials"]
    assert p["consolidation_stresses_pa"] == lab["rig_config"]["procedure"]["consolidation_stresses_pa"]
    # speeds, rates and the reading thresholds are kept
    for key in ("tilt_rate_deg_s", "plate_speed_max_m_s", "slide_onset_displacement_m", "dynamic_travel_distance_m"):
        assert p[key] == lab["rig_config"]["procedure"][key], key


@pytest.mark.parametrize("scale", [1.5, 2.0, 3.0])
def test_lid_and_ring_load_the_same_stress_at_every_scale(scale):
    """The lid's dead load on the bulk, m g / (pi D^2 / 4), is the lab's 0.5 kg on the
    145 mm cell at every scale (and the ring's 0.3 kg likewise)."""
    job = resolve_job("wall_friction", "M2", {"rig.geometry.scale": scale}, seed=1)
    g = geometry(job)
    area = math.pi * g["cell_inner_diameter_m"] ** 2 / 4
    lab_area = math.pi * 0.145 ** 2 / 4
    assert g["lid_mass_kg"] * G / area == pytest.approx(0.5 * G / lab_area, rel=1e-9)
    assert g["cell_mass_kg"] * G / area == pytest.approx(0.3 * G / lab_area, rel=1e-9)
    assert g["cell_gap_to_plate_m"] == pytest.approx(0.002 * scale)


def test_pile_rigs_scale_the_cylinder_table_and_clearance_not_the_reading():
    lab = resolve_job("surcharge", "M2", seed=1)
    big = resolve_job("surcharge", "M2", {"rig.geometry.scale": 1.5}, seed=1)
    assert geometry(big)["cell_inner_diameter_m"] == pytest.approx(0.2175)
    assert geometry(big)["table_radius_m"] == pytest.approx(0.45)
    assert big["rig_config"]["procedure"]["lift_clearance_m"] == pytest.approx(0.003)
    for key in ("lift_speed_m_s", "vibration_frequency_hz", "vibration_amplitude_horizontal_m",
                "vibration_duration_s"):
        assert big["rig_config"]["procedure"][key] == lab["rig_config"]["procedure"][key], key
    assert big["rig_config"]["measure"] == lab["rig_config"]["measure"]       # slices of a grain's size


def test_scale_1_is_the_lab_job():
    """A config that says scale 1 builds the job of a config that says nothing (same id)."""
    from pycal.rigs.scaling import apply_scale
    from pycal.configs import load_rig
    cfg = load_rig("fill")                     # the shipped fill says scale 2
    plain = dict(cfg, geometry={k: v for k, v in cfg["geometry"].items() if k != "scale"})
    cfg_1 = dict(cfg, geometry=dict(cfg["geometry"], scale=1))
    assert apply_scale("fill", cfg_1, "f", "k") == apply_scale("fill", plain, "f", "k") == plain
    assert apply_scale("fill", cfg, "f", "k")["geometry"]["cell_inner_diameter_m"] == 2 * plain["geometry"]["cell_inner_diameter_m"]


def test_every_rig_but_the_transfer_scales_a_length():
    for rig in names():
        job = resolve_job(rig, "mixed-dry" if rig in ("aor_mixed", "transfer") else "M2", seed=1)
        if rig == "transfer":
            assert not scaled_keys(job["rig_config"])
            continue
        assert "geometry.cell_inner_diameter_m" in scaled_keys(job["rig_config"]), rig


def test_refusals_name_the_key_and_the_reason():
    with pytest.raises(ConfigError, match=r"--set: rig.geometry.scale=0.5: 0.5 must be >= 1"):
        resolve_job("aor", "M2", {"rig.geometry.scale": 0.5})
    with pytest.raises(ConfigError, match=r"rig transfer cannot be scaled: the transfer rig is the design chute"):
        resolve_job("transfer", "mixed-dry", {"rig.geometry.scale": 2})


def test_a_scene_over_the_step_limit_is_refused_naming_the_scale():
    """At 2 mm/s a cylinder 20x the lab's lifts for ~1000 s of simulated time."""
    with pytest.raises(ConfigError, match=r"geometry.scale"):
        resolve_job("aor", "M2", {"rig.geometry.scale": 20, "rig.numerics.max_estimated_steps_count": 1e7})


def test_docs_name_every_key_the_scale_changes():
    """docs/rigs.md "Geometric scale" lists each key that pycal/rigs/fields.py scales."""
    from pycal import REPO_ROOT
    from pycal.rigs.fields import FIELDS
    text = (REPO_ROOT / "docs" / "rigs.md").read_text()
    section = text.split("### Geometric scale", 1)[1].split("\n### ", 1)[0]
    for key, f in FIELDS.items():
        if f.scales:
            assert f"`{key}`" in section, key
