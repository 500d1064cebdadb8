"""Material sets (configs/material_sets/), their jobs, and the mixed pile's upper-part angle.

Pure Python: no YADE.
"""
import math
import shutil

import numpy as np
import pytest

from pycal import CONFIG_DIR
from pycal.configs import load_material_set, material_names, material_set_names
from pycal.errors import ConfigError
from pycal.jobs import resolve_job
from pycal.post import aor_mixed

from config_copy import edit




def test_shipped_sets_have_the_lab_fractions_of_the_minus_50_mm_sample():
    assert material_set_names() == ["mixed-dry", "mixed-wet"]
    for name, fines in (("mixed-dry", "M3-dry"), ("mixed-wet", "M3-wet")):
        s = load_material_set(name)
        c = s["components"]
        assert list(c) == ["M1", "M2", fines]
        # docs/lab-tests.md section 2, classes below 50 mm renormalised to 73.7 %
        assert c["M1"]["mass_fraction"] == pytest.approx(3.9 / 73.7)
        assert c["M2"]["mass_fraction"] == pytest.approx((15.7 + 16.8) / 73.7)
        assert c[fines]["mass_fraction"] == pytest.approx((35.5 + 1.8) / 73.7)
        assert sum(x["mass_fraction"] for x in c.values()) == pytest.approx(1.0)
        assert c["M1"]["size_classes"] == ["large_gravel"]


def test_set_job_holds_every_component_with_agreeing_pair_values():
    job = resolve_job("aor_mixed", "mixed-wet", seed=2)
    assert job["material"] == "mixed-wet" and job["job_id"].startswith("aor_mixed-mixed-wet-s2-")
    mats = job["materials"]
    assert list(mats) == ["M1", "M2", "M3-wet"]
    for a in mats:
        for b in mats:
            assert mats[a]["interactions"][b] == mats[b]["interactions"][a], (a, b)
    # docs/method.md: wet fines - gravel = the fines-wall adhesion; M1 rolling 0 on every pair
    assert mats["M2"]["interactions"]["M3-wet"]["cohesion"]["force_fraction"] == 0.3
    assert mats["M1"]["interactions"]["M3-wet"]["cohesion"]["force_fraction"] == 0.3
    assert mats["M2"]["interactions"]["M1"]["rolling_resistance_coefficient"] == 0.0
    assert job["material_set"]["components"]["M1"]["mass_fraction"] == pytest.approx(3.9 / 73.7)


def test_single_material_job_has_no_set_entries():
    job = resolve_job("aor", "M2", seed=3)
    assert set(job) == {"job_format", "rig", "script", "seed", "material", "materials", "boundaries",
                        "rig_config", "overrides", "job_id"}
    assert list(job["materials"]) == ["M2"]
    # the component files' own cross entries stay as they are outside a set
    assert job["materials"]["M2"]["interactions"]["M1"]["rolling_resistance_coefficient"] == 0.35


def test_set_overrides_reach_component_set_and_rig():
    job = resolve_job("aor_mixed", "mixed-wet", {
        "M3-wet.interactions.M3-wet.cohesion.force_fraction": 2.0,
        "cross_interactions.M2.M3-wet.cohesion.force_fraction": 1.0,
        "rig.procedure.lift_speed_m_s": 0.01})
    m = job["materials"]
    assert m["M3-wet"]["interactions"]["M3-wet"]["cohesion"]["force_fraction"] == 2.0
    assert m["M2"]["interactions"]["M3-wet"]["cohesion"]["force_fraction"] == 1.0
    assert m["M3-wet"]["interactions"]["M2"]["cohesion"]["force_fraction"] == 1.0
    assert job["rig_config"]["procedure"]["lift_speed_m_s"] == 0.01
    base = resolve_job("aor_mixed", "mixed-wet")
    assert job["job_id"] != base["job_id"]


def test_rig_for_one_material_rejects_a_set():
    with pytest.raises(ConfigError, match=r"--material: mixed-dry: rig aor takes one "
                                          r"material, and mixed-dry is a material set \(rigs that take sets: aor_mixed, transfer;"):
        resolve_job("aor", "mixed-dry")


def test_bad_overrides_name_file_and_field():
    # a pair value the scene's contact law cannot realise names the pair's files and key and why
    with pytest.raises(ConfigError, match=r"configs/material_sets/mixed-dry.yaml or configs/materials/M1.yaml: "
                                          r"interactions.M2.rolling_resistance_coefficient: 0.35: linear_cundall "
                                          r"takes rolling resistance 0 with clumps"):
        resolve_job("aor_mixed", "mixed-dry", {"cross_interactions.M1.M2.rolling_resistance_coefficient": 0.35,
                                               "rig.numerics.contact_model": "linear_cundall"})
    # the default law realises a rolling resistance with clumps (the member's own radius)
    resolve_job("aor_mixed", "mixed-dry", {"cross_interactions.M1.M2.rolling_resistance_coefficient": 0.35})
    with pytest.raises(ConfigError, match=r"components.M1.mass_percent: 5.0 differs from the sum of its size classes"):
        resolve_job("aor_mixed", "mixed-dry", {"components.M1.mass_percent": 5.0})
    with pytest.raises(ConfigError, match=r"M2.yaml \(with overrides\): particles.density_kg_m3: -1 must be > 0"):
        resolve_job("aor_mixed", "mixed-dry", {"M2.particles.density_kg_m3": -1})
    with pytest.raises(ConfigError, match=r"no such key to override"):
        resolve_job("aor_mixed", "mixed-dry", {"components.M2.colour": "red"})


def test_unknown_key_in_a_set_is_an_error(cfg):
    edit(cfg / "material_sets" / "mixed-dry.yaml", "lab_sample: sample50_dry", "lab_sample: sample50_dry\nlab_smaple: x")
    with pytest.raises(ConfigError, match=r"configs/material_sets/mixed-dry.yaml: lab_smaple: unknown key"):
        load_material_set("mixed-dry", cfg)


def test_missing_pair_is_an_error(cfg):
    edit(cfg / "material_sets" / "mixed-dry.yaml", "  M2:\n    M3-dry:", "  M2:\n    M2:")
    with pytest.raises(ConfigError, match=r"mixed-dry.yaml: cross_interactions.M2.M2: a material with itself"):
        load_material_set("mixed-dry", cfg)
    shutil.copy(CONFIG_DIR / "material_sets" / "mixed-dry.yaml", cfg / "material_sets" / "mixed-dry.yaml")
    text = (cfg / "material_sets" / "mixed-dry.yaml").read_text()
    cut = text.index("  M2:\n    M3-dry:")
    (cfg / "material_sets" / "mixed-dry.yaml").write_text(text[:cut] + text[text.index("assumptions:"):])
    with pytest.raises(ConfigError, match=r"mixed-dry.yaml: cross_interactions.M2.M3-dry: missing"):
        load_material_set("mixed-dry", cfg)


def test_unknown_component_and_sphere_size_classes_are_errors(cfg):
    edit(cfg / "material_sets" / "mixed-dry.yaml", "  M2:\n    mass_percent: 32.5",
         "  M2:\n    mass_percent: 32.5\n    size_classes: [large_gravel]")
    with pytest.raises(ConfigError, match=r"components.M2.size_classes: only for clump materials"):
        load_material_set("mixed-dry", cfg)
    shutil.copy(CONFIG_DIR / "material_sets" / "mixed-dry.yaml", cfg / "material_sets" / "mixed-dry.yaml")
    edit(cfg / "material_sets" / "mixed-dry.yaml", "  M3-dry:\n    mass_percent: 37.3", "  M4:\n    mass_percent: 37.3")
    with pytest.raises(ConfigError, match=r"mixed-dry.yaml: components.M4: unknown material \(known: M1, M2"):
        load_material_set("mixed-dry", cfg)


def test_set_name_must_not_be_a_material(cfg):
    shutil.copy(cfg / "material_sets" / "mixed-dry.yaml", cfg / "material_sets" / "M2.yaml")
    edit(cfg / "material_sets" / "M2.yaml", "name: mixed-dry", "name: M2")
    with pytest.raises(ConfigError, match=r"M2.yaml: name: 'M2' is also a material name"):
        load_material_set("M2", cfg)
    assert "M2" in material_names(cfg)


# ---------------------------------------------------------------- upper-part angle

MEASURE = {"sector_half_width_deg": 45, "silhouette_slice_height_m": 0.0125, "exclude_bottom_m": 0.025,
           "exclude_apex_m": 0.0125, "upper_fit_from_height_fraction": 0.5,
           "upper_silhouette_slice_height_m": 0.00625, "upper_exclude_apex_m": 0.0}


def dihedral_pile(top_deg, flank_deg, height=0.12, knee=0.06, r=0.004, spacing=0.003):
    """Small spheres on an axisymmetric surface: steep (top_deg) above z = knee, flank_deg below."""
    rows = []
    r_knee = (height - knee) / math.tan(math.radians(top_deg))
    r_foot = r_knee + knee / math.tan(math.radians(flank_deg))
    for x in np.arange(-r_foot, r_foot + spacing, spacing):
        for y in np.arange(-r_foot, r_foot + spacing, spacing):
            d = math.hypot(x, y)
            if d <= r_knee:
                z = height - d * math.tan(math.radians(top_deg))
            else:
                z = knee - (d - r_knee) * math.tan(math.radians(flank_deg))
            if z > r:
                rows.append((x, y, z - r, r, "M2", -1))
    return rows


def test_upper_angle_catches_a_dihedral_top():
    whole, upper = aor_mixed.measure(dihedral_pile(57.0, 31.0), MEASURE)
    keys = aor_mixed.result_keys(whole, upper)
    assert keys["aor_upper_sectors_count"] == 4
    assert keys["aor_upper_mean_deg"] == pytest.approx(57.0, abs=4.0)
    assert keys["aor_upper_mean_deg"] > keys["aor_mean_deg"] + 10.0
    cone_w, cone_u = aor_mixed.measure(dihedral_pile(40.0, 40.0), MEASURE)
    k = aor_mixed.result_keys(cone_w, cone_u)
    assert k["aor_upper_mean_deg"] == pytest.approx(k["aor_mean_deg"], abs=4.0)
