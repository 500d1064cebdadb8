"""bench/stage_points.py: a stage's points from a study's history.csv, as a markdown table."""
import csv
import json

import pytest

from bench_scripts import load_bench_script


@pytest.fixture(scope="module")
def sp():
    return load_bench_script("stage_points")


def _history(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["material", "stage", "rig", "parameters", "response", "mean", "std", "n", "seeds"])
        for material, stage, params, response, mean, std, n in rows:
            w.writerow([material, stage, "surcharge", json.dumps(params), response, mean, std, n, "[1, 2]"])


def test_a_point_asked_twice_in_a_row_is_two_points_and_other_stages_are_left_out(sp, tmp_path):
    a, b = {"mu": 0.5, "eta": 0.2, "eta_wall": 0.2}, {"mu": 0.6, "eta": 0.2, "eta_wall": 0.2}
    _history(tmp_path / "history.csv", [
        ("M3-dry", "final", a, "aor_mean_deg", 38.0, 3.0, 2), ("M3-dry", "final", a, "surcharge_mean_deg", 25.0, 9.0, 2),
        ("M3-dry", "other", a, "aor_mean_deg", 99.0, 0.0, 2),
        ("M3-dry", "final", a, "aor_mean_deg", 40.0, 1.0, 2), ("M3-dry", "final", a, "surcharge_mean_deg", "nan", "nan", 0),
        ("M3-dry", "final", b, "aor_mean_deg", 37.0, 2.0, 2)])
    pts = sp.stage_points(tmp_path / "history.csv", "M3-dry", "final")
    assert [p for p, _ in pts] == [a, a, b]
    assert pts[1][1]["aor_mean_deg"] == (40.0, 1.0, 2)
    md = sp.table(pts)
    # keys set to one value at every point share a column
    assert md.splitlines()[0] == ("| point | mu | eta = eta_wall | aor_mean_deg: mean (SD; n) | "
                                  "surcharge_mean_deg: mean (SD; n) |")
    assert "| 2 | 0.5 | 0.2 | 40 (1; 2) | - (-; 0) |" in md and "| 3 | 0.6 | 0.2 | 37 (2; 2) | - |" in md


def test_a_folder_without_history_or_without_the_stage_is_refused_with_exit_2(sp, tmp_path, capsys):
    assert sp.main([str(tmp_path), "M3-dry", "final"]) == 2
    assert "history.csv: no such file" in capsys.readouterr().err
    _history(tmp_path / "history.csv", [("M2", "density", {"rho": 3000.0}, "bulk_density_kg_m3", 1600.0, 10.0, 2)])
    assert sp.main([str(tmp_path), "M3-dry", "final"]) == 2
    assert "no point of stage 'final'" in capsys.readouterr().err


def test_the_linear_fit_recovers_known_slopes_per_parameter(sp, tmp_path):
    """runs.csv of a stage whose response is exactly 10 + 20 mu + 60 eta: slopes 20 and 60, SD 0;
    the wall key set to eta's value at every run is one parameter, not a second column."""
    with open(tmp_path / "runs.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["material", "stage", "rig", "parameters", "seed", "response", "value"])
        for i, (mu, eta) in enumerate([(0.2, 0.1), (0.5, 0.1), (0.3, 0.3), (0.6, 0.25), (0.4, 0.05)]):
            p = json.dumps({"mu": mu, "eta": eta, "eta_wall": eta})
            w.writerow(["M3-dry", "final", "surcharge", p, i + 1, "surcharge_mean_deg", 10 + 20 * mu + 60 * eta])
            w.writerow(["M3-dry", "final", "surcharge", p, i + 1, "aor_mean_deg", "nan"])
    fit = sp.linear_fit(tmp_path / "runs.csv", "M3-dry", "final")
    keys, b, se, sd, n = fit["surcharge_mean_deg"]
    assert keys == ["mu", "eta"] and n == 5
    assert b == pytest.approx([20.0, 60.0]) and sd == pytest.approx(0.0, abs=1e-9)
    assert "aor_mean_deg" not in fit                   # no run with a value
