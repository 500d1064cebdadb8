"""pycal.post.compression: stiffness, force balance, log-stress interpolation, band misfit,
comparison with the lab curves and the CSV/PNG outputs (pure Python, no YADE)."""
import csv
import json
import math

import pytest

from pycal.post import compression as c
from pycal.post.lab_curves import targets_from_arrays


def test_secant_stiffness_from_zero_and_between_steps():
    k = c.secant_stiffness([1000.0, 3000.0, 6000.0], [0.01, 0.02, 0.025])
    assert k == pytest.approx([1e5, 2e5, 6e5])


def test_secant_stiffness_undefined_where_strain_does_not_change():
    assert c.secant_stiffness([1000.0, 2000.0], [0.01, 0.01]) == [pytest.approx(1e5), None]


def test_branch_stiffness_unloading_starts_from_the_last_loading_point():
    stress = [10e3, 40e3, 20e3, 5e3]
    strain = [0.05, 0.08, 0.075, 0.07]
    k = c.branch_stiffness(stress, strain, ["loading", "loading", "unloading", "unloading"])
    assert k == pytest.approx([2e5, 1e6, 20e3 / 0.005, 15e3 / 0.005])


def test_force_balance_error():
    assert c.force_balance_error(100.0, 15.0, 110.0, 5.0) == pytest.approx(0.0)
    assert c.force_balance_error(100.0, 15.0, 103.5, 0.0) == pytest.approx(0.1)


def _result(rig="ccs", branch=None):
    stress = [3000.0, 12000.0, 40000.0, 86000.0]
    strain = [0.03, 0.05, 0.07, 0.09]
    h0 = 0.1
    r = {"rig": rig, "material": "M2", "seed": 1, "lab_sample": "gravel_dry",
         "stress_pa": stress, "strain": strain, "branch": branch or ["loading"] * 4,
         "target_stress_pa": stress, "plate_force_n": [s * 0.0165 for s in stress],
         "plate_position_m": [h0 * (1 - e) for e in strain], "initial_height_m": h0,
         "particle_weight_n": 15.0, "bottom_force_n": [s * 0.0165 + 14.0 for s in stress],
         "wall_force_n": [1.0] * 4, "bulk_density_kg_m3": [1000.0, 1020.0, 1040.0, 1060.0],
         "solid_fraction": [0.36, 0.37, 0.38, 0.385]}
    return c.derived_arrays(r)


def test_derived_arrays():
    r = _result()
    assert r["stiffness_pa"][0] == pytest.approx(1e5)
    assert r["force_balance_error"] == pytest.approx([0.0] * 4, abs=1e-12)
    assert r["plate_displacement_m"] == pytest.approx([0.003, 0.005, 0.007, 0.009])
    assert "unloading_stiffness_pa" not in r
    u = _result("ccs_expansion", ["loading", "loading", "unloading", "unloading"])
    u["stress_pa"] = [3000.0, 86000.0, 40000.0, 3000.0]
    c.derived_arrays(u)
    assert u["unloading_stress_pa"] == [40000.0, 3000.0]
    assert len(u["unloading_stiffness_pa"]) == 2


def test_interp_log_stress():
    s, v = [1000.0, 10000.0, 100000.0], [1.0, 2.0, 4.0]
    assert c.interp_log_stress(s, v, 10000.0) == pytest.approx(2.0)
    assert c.interp_log_stress(s, v, math.sqrt(1000.0 * 10000.0)) == pytest.approx(1.5)   # middle in log
    assert c.interp_log_stress(s, v, 104000.0) == pytest.approx(4.0 + 2.0 * math.log(1.04) / math.log(10))
    assert c.interp_log_stress(s, v, 110000.0) is None        # > 5 % beyond the range
    assert c.interp_log_stress(s, v, 900.0) is None
    assert c.interp_log_stress(s, [1.0, None, 4.0], 10000.0) == pytest.approx(2.5)   # None points skipped
    assert c.interp_log_stress(s[::-1], v[::-1], 10000.0) == pytest.approx(2.0)       # any order (unloading)


def test_band_z_uses_the_side_of_the_band():
    assert c.band_z(10.0, 10.0, 5.0, 30.0) == 0.0
    assert c.band_z(30.0, 10.0, 5.0, 30.0) == pytest.approx(1.0)
    assert c.band_z(5.0, 10.0, 5.0, 30.0) == pytest.approx(-1.0)
    assert c.band_z(50.0, 10.0, 5.0, 30.0) == pytest.approx(2.0)


def test_misfit_rms_over_the_lab_steps():
    lab_s = [1000.0, 10000.0, 100000.0]
    value, low, high = [1.0, 2.0, 4.0], [0.5, 1.0, 2.0], [2.0, 4.0, 8.0]
    m = c.misfit(lab_s, value, lab_s, value, low, high)
    assert m["rms_z"] == 0.0 and m["n_points"] == 3 and m["inside_band_count"] == 3
    m = c.misfit(lab_s, high, lab_s, value, low, high)           # on the upper edge everywhere
    assert m["rms_z"] == pytest.approx(1.0)
    m = c.misfit(lab_s, [0.0, 0.0, 0.0], lab_s, value, low, high)  # z = -2 everywhere
    assert m["rms_z"] == pytest.approx(2.0) and m["inside_band_count"] == 0
    # a simulation that stops at 10 kPa leaves the 100 kPa lab step out
    m = c.misfit(lab_s[:2], value[:2], lab_s, value, low, high)
    assert m["n_points"] == 2 and m["n_skipped"] == 1 and m["z"][2] is None
    # NaN lab values (e.g. a step where the lab cell stuck) are skipped
    m = c.misfit(lab_s, value, lab_s, [1.0, float("nan"), 4.0], low, high)
    assert m["n_points"] == 2


def test_compare_against_plain_target_arrays():
    r = _result()
    targets = {"_name": "ccs_x", "_particle_density": 2750.0,
               "bulk_stiffness_pa": targets_from_arrays([3000.0, 86000.0], [1e5, 1e6], [5e4, 5e5], [2e5, 2e6]),
               "solid_fraction": targets_from_arrays([3000.0, 86000.0], [0.36, 0.385], [0.33, 0.355],
                                                     [0.39, 0.415])}
    comps = c.compare(r, targets)
    assert set(comps) == {"bulk_stiffness", "solid_fraction", "bulk_density"}
    assert comps["solid_fraction"]["rms_z"] == pytest.approx(0.0)
    # bulk density target = lab solid fraction x lab particle density
    assert comps["bulk_density"]["lab_value"] == pytest.approx([990.0, 1058.75])
    assert comps["bulk_stiffness"]["z"][0] == pytest.approx(0.0)      # 1e5 at 3 kPa
    assert c.compare(r, {}) == {}


def test_write_outputs_with_the_shipped_lab_curve(tmp_path):
    r = _result()
    r["job"] = {"materials": {"M2": {"lab_sample": "gravel_dry"}}}
    path = tmp_path / "result.json"
    path.write_text(json.dumps(r))
    out = c.write_outputs(str(path))
    names = sorted(p.split("/")[-1] for p in out["files"])
    assert names == ["bulk_density.png", "lab_comparison.csv", "spring_curve.csv", "spring_curve.png",
                     "stiffness.png"]
    assert out["misfits"]["bulk_stiffness"]["lab_curve"] == "ccs_gravel_dry"
    assert out["misfits"]["bulk_stiffness"]["n_points"] == 7    # lab steps 3 - 86 kPa, all covered
    rows = list(csv.DictReader((tmp_path / "spring_curve.csv").open()))
    assert len(rows) == 4 and float(rows[0]["stiffness_pa"]) == pytest.approx(1e5)
    assert "plate_force_n" in rows[0] and "strain_ratio" in rows[0]


def test_write_outputs_without_a_lab_curve(tmp_path):
    r = _result()
    r["lab_sample"] = "sample50_dry"        # no compression curves for this sample
    out = c.write_outputs(r, str(tmp_path), plots=False)
    assert out["misfits"] == {} and [p.split("/")[-1] for p in out["files"]] == ["spring_curve.csv"]
