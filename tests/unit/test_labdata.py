"""labresults/ loader and validation: the shipped data pass, broken copies fail with
an error that names the file and the field."""
import math
import shutil

import numpy as np
import pytest

from pycal import LAB_DIR, labdata
from pycal.errors import ConfigError

WALL = "labresults/curves/wall_friction_fines_dry.csv"


@pytest.fixture
def lab(tmp_path):
    """A copy of labresults/ to break."""
    dst = tmp_path / "labresults"
    shutil.copytree(LAB_DIR, dst, ignore=shutil.ignore_patterns("__pycache__"))
    return dst


def edit(lab, rel, old, new, count=1):
    path = lab / rel
    text = path.read_text()
    assert old in text, f"{old!r} not in {rel}"
    path.write_text(text.replace(old, new, count))


def error_of(lab, **kw):
    with pytest.raises(ConfigError) as exc:
        labdata.load_all(lab, config_dir=None, **kw)
    return exc.value


def test_shipped_data_pass():
    data = labdata.load_all()
    assert set(data["tables"]) == set(labdata.TABLES)
    assert len(data["curves"]) == 14
    assert set(data["samples"]["samples"]) == {"gravel_dry", "fines_dry", "fines_wet",
                                               "sample50_dry", "sample50_wet"}
    for df in data["curves"].values():
        assert list(df["stress_pa"]) == [3000, 6000, 12000, 24000, 40000, 60000, 90000]
        assert set(df["provenance"]) == {"reconstructed"}


def test_copy_passes_and_names_files_relative(lab):
    labdata.load_all(lab, config_dir=None)
    edit(lab, "curves/wall_friction_fines_dry.csv", "mu_static_low", "mu_static_lo")
    err = error_of(lab)
    assert err.file == WALL


def test_missing_column(lab):
    path = lab / "curves/wall_friction_fines_dry.csv"
    lines = [ln.split(",") for ln in path.read_text().splitlines() if not ln.startswith("#")]
    drop = lines[0].index("mu_static_low")
    path.write_text("\n".join(",".join(c for j, c in enumerate(ln) if j != drop) for ln in lines))
    err = error_of(lab)
    assert (err.file, err.field) == (WALL, "mu_static_low") and "missing column" in err.reason


def test_missing_table_column(lab):
    edit(lab, "surcharge.csv", "sample,left_deg,right_deg,provenance", "sample,left_deg,right_deg,source")
    err = error_of(lab)
    assert (err.file, err.field) == ("labresults/surcharge.csv", "source")   # no unit
    edit(lab, "surcharge.csv", ",source,", ",note2_deg,")
    err = error_of(lab)
    assert (err.file, err.field) == ("labresults/surcharge.csv", "provenance")
    assert "missing column" in err.reason


def test_missing_stress_column(lab):
    edit(lab, "curves/ccs_fines_dry.csv", "stress_pa,", "load_pa,")
    err = error_of(lab)
    assert err.file == "labresults/curves/ccs_fines_dry.csv" and err.field == "stress_pa"
    assert "missing column" in err.reason


def test_column_without_unit(lab):
    edit(lab, "boundaries.csv", "density_kg_m3", "density")
    err = error_of(lab)
    assert (err.file, err.field) == ("labresults/boundaries.csv", "density")
    assert "unit suffix" in err.reason


def test_non_numeric_value(lab):
    edit(lab, "curves/wall_friction_fines_dry.csv", "\n12000,0.416,", "\n12000,abc,")
    err = error_of(lab)
    assert (err.file, err.field) == (WALL, "mu_static") and "row 3" in err.reason


def test_stress_not_increasing(lab):
    edit(lab, "curves/wall_friction_fines_dry.csv", "\n24000,", "\n10000,")
    err = error_of(lab)
    assert (err.file, err.field) == (WALL, "stress_pa") and "strictly increasing" in err.reason


def test_bad_provenance(lab):
    edit(lab, "curves/wall_friction_fines_dry.csv", ",reconstructed\n", ",guessed\n")
    err = error_of(lab)
    assert (err.file, err.field) == (WALL, "provenance") and "guessed" in err.reason


def test_negative_density(lab):
    edit(lab, "boundaries.csv", ",1400,", ",-1400,")
    err = error_of(lab)
    assert (err.file, err.field) == ("labresults/boundaries.csv", "density_kg_m3")


def test_negative_bulk_density_in_samples(lab):
    edit(lab, "samples.yaml", "bulk_density_kg_m3: 1601", "bulk_density_kg_m3: -1601")
    err = error_of(lab)
    assert (err.file, err.field) == ("labresults/samples.yaml", "samples.fines_dry.bulk_density_kg_m3")


def test_band_outside_value(lab):
    edit(lab, "curves/wall_friction_fines_dry.csv", "\n3000,0.400,0.350,", "\n3000,0.400,0.420,")
    err = error_of(lab)
    assert (err.file, err.field) == (WALL, "mu_static_low") and "row 1" in err.reason
    edit(lab, "curves/wall_friction_fines_dry.csv", "\n3000,0.400,0.420,0.450", "\n3000,0.400,0.350,0.390")
    assert error_of(lab).field == "mu_static_high"


def test_blank_value_only_where_sticks(lab):
    edit(lab, "curves/internal_friction_fines_wet.csv", "60000,,,,,,,sticks", "60000,,,,,,,slides")
    err = error_of(lab)
    assert err.file == "labresults/curves/internal_friction_fines_wet.csv" and "blank" in err.reason


def test_size_distribution_sum(lab):
    edit(lab, "size_distribution.csv", ",35.5,", ",36.5,")
    err = error_of(lab)
    assert (err.file, err.field) == ("labresults/size_distribution.csv", "mass_percent")
    assert "100" in err.reason


def test_unknown_sample_in_table(lab):
    edit(lab, "angle_of_repose.csv", "fines_dry,38,38", "fines_dryy,38,38")
    err = error_of(lab)
    assert (err.file, err.field) == ("labresults/angle_of_repose.csv", "sample")


def test_sample_curve_must_exist(lab):
    (lab / "curves/ucs_fines_wet.csv").unlink()
    err = error_of(lab)
    assert (err.file, err.field) == ("labresults/samples.yaml", "samples.fines_wet.curves")


def test_material_lab_sample_must_exist(lab, tmp_path):
    (tmp_path / "configs/materials").mkdir(parents=True)
    (tmp_path / "configs/materials/X.yaml").write_text("name: X\nlab_sample: fines_moist\n")
    with pytest.raises(ConfigError) as exc:
        labdata.load_all(lab, config_dir=tmp_path / "configs")
    assert (exc.value.file, exc.value.field) == ("configs/materials/X.yaml", "lab_sample")


def test_measured_curve_drops_in(lab):
    (lab / "curves/wall_friction_fines_dry.csv").write_text(
        "stress_pa,mu_static,mu_static_low,mu_static_high,provenance\n"
        "2500,0.41,0.39,0.43,measured\n80000,0.52,0.50,0.54,measured\n")
    labdata.load_all(lab, config_dir=None)
    c = labdata.target_curve("wall_friction_fines_dry", lab_dir=lab)
    assert c.quantity == "mu_static" and list(c.stress_pa) == [2500, 80000]
    assert list(c.provenance) == ["measured", "measured"]


def test_target_curve():
    c = labdata.target_curve("wall_friction_fines_dry", "mu_static")
    assert c.value[0] == pytest.approx(0.40) and c.value[-1] == pytest.approx(0.50)
    assert np.all(c.low <= c.value) and np.all(c.value <= c.high)
    with pytest.raises(ConfigError) as exc:
        labdata.target_curve("wall_friction_fines_dry")        # two quantities: must choose
    assert "mu_dynamic" in str(exc.value)
    wet = labdata.target_curve("internal_friction_fines_wet", "mu_static")
    assert list(wet.outcome[-2:]) == ["sticks", "sticks"] and math.isnan(wet.value[-1])
    gravel = labdata.target_curve("internal_friction_gravel_dry")
    assert set(gravel.outcome) == {"sticks"}
    with pytest.raises(ConfigError):
        labdata.target_curve("no_such_curve")


def test_sample():
    s = labdata.sample("fines_wet")
    assert s["bulk_density_kg_m3"] == 1146 and s["moisture_percent_dry_basis"] == 5.4
    assert s["solid_fraction"] == pytest.approx(1146 / 2750)
    assert (s["angle_of_repose"]["left_deg"], s["angle_of_repose"]["right_deg"]) == (38, 42)
    assert s["surcharge"]["right_deg"] == 36
    assert labdata.sample("sample50_wet")["angle_of_repose"]["front_deg"] == 32
    with pytest.raises(ConfigError) as exc:
        labdata.sample("fines_moist")
    assert exc.value.field == "samples.fines_moist"


def test_aor_target_deg():
    assert labdata.aor_target_deg("gravel_dry") == 42.0
    assert labdata.aor_target_deg("fines_wet", "surcharge") == 35.0
    with pytest.raises(ConfigError):
        labdata.aor_target_deg("fines_dry", "tilt")
