"""pycal.files (atomic writes) and pycal.post.responses (the calibration responses registry)."""
import csv
import json

import pytest

from pycal.calibration.names import group_label, unit_of_key
from pycal.files import write_csv, write_json, write_text
from pycal.post import responses


def test_atomic_writes_leave_no_temporary_file_and_keep_the_old_file_on_error(tmp_path, monkeypatch):
    import os
    p = tmp_path / "sub" / "a.json"
    write_json(p, {"x": 1.5})
    assert json.loads(p.read_text()) == {"x": 1.5}

    def disk_full(src, dst):
        raise OSError("No space left on device")
    monkeypatch.setattr(os, "replace", disk_full)
    with pytest.raises(OSError, match="No space"):
        write_text(p, "half a fi")
    monkeypatch.undo()
    assert json.loads(p.read_text()) == {"x": 1.5}       # the old content stands
    write_csv(tmp_path / "t.csv", ["a_m", "b_pa"], [[1, 2], [3, 4]])
    assert list(csv.reader(open(tmp_path / "t.csv"))) == [["a_m", "b_pa"], ["1", "2"], ["3", "4"]]
    assert sorted(f.name for f in tmp_path.rglob("*")) == ["a.json", "sub", "t.csv"]


def test_responses_have_units_and_unknown_keys_need_a_unit_suffix():
    assert responses.get("aor_mean_deg").unit == "deg"
    assert responses.get("unloading_stiffness_log_ratio").unit == "log_ratio"
    assert responses.get("friction_band_z_mu_static").vector
    fallback = responses.get("surcharge_angle_deg")           # any scalar result key with a unit
    assert fallback.unit == "deg" and fallback.value({"surcharge_angle_deg": 41.0}, None) == 41.0
    assert responses.get("angle") is None
    # lab-curve plots belong to the responses that read lab curves, not to rig names
    assert responses.get("friction_offset_mu_static").lab_plots is not None
    assert responses.get("aor_mean_deg").lab_plots is None


def test_parameter_groups_are_named_for_people():
    keys = ["interactions.M2.rolling_resistance_coefficient", "interactions.steel.rolling_resistance_coefficient",
            "interactions.pvc.rolling_resistance_coefficient"]
    assert group_label(keys) == "rolling resistance (M2, steel, PVC)"
    assert group_label(["contact.youngs_modulus_pa"]) == "Young's modulus"
    assert group_label(["interactions.steel.cohesion.pressure_fraction"]) == "pull-off pressure fraction (steel)"
    assert unit_of_key("particles.density_kg_m3") == "kg_m3" and unit_of_key(keys[0]) == "coefficient"
