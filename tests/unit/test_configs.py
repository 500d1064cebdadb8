"""Config loading and validation: shipped configs load; broken ones name file and field."""
import pytest

from pycal.configs import (load_boundaries, load_material, load_rig, material_names, rig_names,
                           parse_yaml_text)
from pycal.errors import ConfigError

from config_copy import edit

APPLICATION_RIGS = {"transfer"}      # not a copy of a lab test: no lab cell (docs/rigs.md)


def test_shipped_configs_load():
    assert set(material_names()) == {"M1", "M2", "M3-dry", "M3-wet"}
    for m in material_names():
        mat = load_material(m)
        assert mat["contact"]["youngs_modulus_pa"] == 2.0e7      # start value on the Hertz law (docs/contact-models.md)
    for r in rig_names():
        rig = load_rig(r)
        assert "timestep_safety_factor" in rig["numerics"]
        if r in APPLICATION_RIGS:
            continue
        assert rig["geometry"]["cell_inner_diameter_m"] == pytest.approx(0.145)
        assert rig["geometry"]["cell_height_m"] == pytest.approx(0.095)
    b = load_boundaries()
    assert b["steel"]["youngs_modulus_pa"] == 2.38e11 and b["pvc"]["density_kg_m3"] == 1400


def test_start_values_follow_the_method():
    for m in ("M2", "M3-dry", "M3-wet"):
        mat = load_material(m)
        assert mat["particles"]["diameter_m"] == 0.025
        assert mat["particles"]["density_kg_m3"] == 2750
        assert all(p["restitution_coefficient"] == 0.3 for p in mat["interactions"].values())
        assert mat["interactions"][m]["rolling_resistance_coefficient"] == 0.35
    m1 = load_material("M1")
    assert all(p["rolling_resistance_coefficient"] == 0 for p in m1["interactions"].values())
    assert sum(c["mass_percent"] for c in m1["particles"]["size_classes"]) == pytest.approx(30.2)


def test_yaml_reads_exponent_floats():
    assert parse_yaml_text("a: 2.38e11\nb: 1e-3\nc: 6.0e6") == {"a": 2.38e11, "b": 1e-3, "c": 6.0e6}


def test_negative_density_names_file_and_field(cfg):
    edit(cfg / "materials" / "M2.yaml", "density_kg_m3: 2750", "density_kg_m3: -5")
    with pytest.raises(ConfigError) as e:
        load_material("M2", cfg)
    assert str(e.value) == "configs/materials/M2.yaml: particles.density_kg_m3: -5 must be > 0" or \
        str(e.value).endswith("M2.yaml: particles.density_kg_m3: -5 must be > 0")


def test_unknown_key_is_an_error(cfg):
    edit(cfg / "materials" / "M2.yaml", "  poisson_ratio: 0.3", "  poisson_ratio: 0.3\n  restitution: 0.3")
    with pytest.raises(ConfigError, match=r"M2.yaml: contact.restitution: unknown key"):
        load_material("M2", cfg)


def test_unknown_material_lists_known(cfg):
    with pytest.raises(ConfigError, match=r"unknown material 'M9' \(known: M1, M2, M3-dry, M3-wet\)"):
        load_material("M9", cfg)


def test_missing_boundary_partner(cfg):
    edit(cfg / "materials" / "M2.yaml", "  pvc:\n", "  pvc_removed:\n")
    with pytest.raises(ConfigError, match=r"M2.yaml: interactions.pvc: missing"):
        load_material("M2", cfg)


def test_unknown_cohesion_model(cfg):
    edit(cfg / "materials" / "M2.yaml", "cohesion: {model: none}", "cohesion: {model: glue}")
    with pytest.raises(ConfigError, match=r"cohesion.model: 'glue' must be one of"):
        load_material("M2", cfg)


def test_missing_cohesion_parameter(cfg):
    edit(cfg / "materials" / "M3-wet.yaml", "      force_fraction: 0.5\n", "")
    with pytest.raises(ConfigError, match=r"M3-wet.yaml: interactions.M3-wet.cohesion.force_fraction: missing"):
        load_material("M3-wet", cfg)


def test_clump_shares_must_add_up(cfg):
    edit(cfg / "materials" / "M1.yaml", "shape_percent: {rounded: 50,  oblong: 20, slab: 30}",
         "shape_percent: {rounded: 50,  oblong: 20, slab: 20}")
    with pytest.raises(ConfigError, match=r"size_classes\[1\].shape_percent: shares add up to 90"):
        load_material("M1", cfg)


def test_rig_key_without_unit_is_an_error(cfg):
    edit(cfg / "rigs" / "aor.yaml", "lift_speed_m_s: 0.002", "lift_speed: 0.002")
    with pytest.raises(ConfigError, match=r"aor.yaml: procedure.lift_speed: numeric key needs a unit suffix"):
        load_rig("aor", cfg)


def test_rig_unknown_boundary(cfg):
    edit(cfg / "rigs" / "aor.yaml", "cell_material: pvc", "cell_material: glass")
    with pytest.raises(ConfigError, match=r"aor.yaml: geometry.cell_material: unknown boundary 'glass'"):
        load_rig("aor", cfg)


def test_yaml_syntax_error_names_file(cfg):
    (cfg / "materials" / "M2.yaml").write_text("name: M2\n  bad: [")
    with pytest.raises(ConfigError, match=r"M2.yaml: not valid YAML"):
        load_material("M2", cfg)


def test_boundary_negative_modulus(cfg):
    edit(cfg / "boundaries.yaml", "youngs_modulus_pa: 2.55e9", "youngs_modulus_pa: -2.55e9")
    with pytest.raises(ConfigError, match=r"boundaries.yaml: pvc.youngs_modulus_pa: .* must be > 0"):
        load_boundaries(cfg)
