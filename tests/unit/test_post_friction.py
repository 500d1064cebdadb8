"""pycal.post.friction: seed statistics, lab comparison (bands, sticking steps), outputs."""
import csv
import json
import math

import pytest

from pycal.post import friction


def result(seed, mu_s, mu_d, sticks=None, stress=(3000, 40000, 86000), rig="wall_friction"):
    n = len(stress)
    return {"rig": rig, "material": "M2", "seed": seed, "stress_pa": list(stress),
            "mu_static": list(mu_s), "mu_dynamic": list(mu_d),
            "sticks": list(sticks or [False] * n), "max_tilt_deg": [30.0] * n,
            "job": {"materials": {"M2": {"lab_sample": "gravel_dry"}}}}


def test_seed_summary_mean_std_and_sticking():
    rs = [result(1, [0.40, 0.50, None], [0.38, 0.48, None], sticks=[False, False, True]),
          result(2, [0.44, 0.52, 0.60], [0.40, 0.50, 0.55])]
    s = friction.seed_summary(rs)
    assert s["stress_pa"] == [3000, 40000, 86000]
    assert s["mu_static_mean"][0] == pytest.approx(0.42)
    assert s["mu_static_std"][0] == pytest.approx(math.sqrt(2) * 0.02)
    assert s["mu_static_n"][2] == 1 and s["mu_static_mean"][2] == pytest.approx(0.60)
    assert s["sticks_ratio"] == [0.0, 0.0, 0.5]
    assert s["n_seeds"] == [2, 2, 2]


def test_compare_inside_band_is_small_misfit_and_outcomes():
    s = friction.seed_summary([result(1, [0.40, 0.50, None], [0.40, 0.50, None], sticks=[False, False, True])])
    t = friction.targets_from_arrays([3000, 40000, 86000], [0.40, 0.50, float("nan")],
                                     [0.35, 0.45, float("nan")], [0.45, 0.55, float("nan")])
    assert t["outcome"] == ["slides", "slides", "sticks"]
    c = friction.compare(s, {"mu_static": t})["mu_static"]
    assert c["rms_z"] == pytest.approx(0.0, abs=1e-12)
    assert c["n_points"] == 2 and c["inside_band_count"] == 2
    assert c["outcome_mismatch_count"] == 0 and c["outcome_compared_count"] == 3
    # one band width too high everywhere -> rms z = 1; a slide where the lab sticks is a mismatch
    s2 = friction.seed_summary([result(1, [0.45, 0.55, 0.7], [0.45, 0.55, 0.7])])
    c2 = friction.compare(s2, {"mu_static": t})["mu_static"]
    assert c2["rms_z"] == pytest.approx(1.0)
    assert c2["outcome_mismatch_count"] == 1


def test_compare_interpolates_in_log_stress():
    s = friction.seed_summary([result(1, [0.3, 0.5], [0.3, 0.5], stress=(10000, 100000))])
    t = friction.targets_from_arrays([math.sqrt(1e9)], [0.4], [0.3], [0.5])
    c = friction.compare(s, {"mu_static": t})["mu_static"]
    assert c["sim_at_lab"][0] == pytest.approx(0.4)


def test_write_outputs_csv_png(tmp_path):
    rs = [result(1, [0.40, 0.50, 0.52], [0.38, 0.48, 0.50]), result(2, [0.42, 0.50, 0.50], [0.40, 0.47, 0.49])]
    paths = []
    for r in rs:
        p = tmp_path / f"r{r['seed']}.json"
        p.write_text(json.dumps(r))
        paths.append(str(p))
    t = friction.targets_from_arrays([3000, 40000, 86000], [0.40, 0.50, 0.50], [0.35, 0.45, 0.45],
                                     [0.45, 0.55, 0.55])
    out = friction.write_outputs(paths, str(tmp_path / "out"), targets={"mu_static": t, "mu_dynamic": t,
                                                                        "_name": "test"})
    names = sorted(p.rsplit("/", 1)[1] for p in out["files"])
    assert names == ["friction_vs_stress.csv", "friction_vs_stress.png", "lab_comparison.csv"]
    rows = list(csv.DictReader(open(tmp_path / "out" / "friction_vs_stress.csv")))
    assert len(rows) == 3 and float(rows[0]["mu_static_mean"]) == pytest.approx(0.41)
    assert rows[0]["lab_mu_static"] == "0.4"
    assert out["misfits"]["mu_static"]["n_points"] == 3
    assert out["misfits"]["mu_static"]["lab_curve"] == "test"


def test_lab_curve_of_the_shipped_data():
    """The shipped lab curves load (when pandas is there) and a sticking lab step counts."""
    pytest.importorskip("pandas")
    t = friction.load_targets("internal_friction", "fines_wet")
    assert t["_name"] == "internal_friction_fines_wet"
    assert "sticks" in t["mu_static"]["outcome"]
    assert friction.load_targets("wall_friction", "no_such_sample") == {}


def test_mixed_rigs_rejected(tmp_path):
    with pytest.raises(ValueError):
        friction.write_outputs([result(1, [0.4] * 3, [0.4] * 3), result(2, [0.4] * 3, [0.4] * 3, rig="ccs")],
                               str(tmp_path))


def test_friction_offset_is_mean_sim_minus_lab_above_the_low_stress_steps():
    t = {"mu_static": friction.targets_from_arrays([3000, 12000, 40000, 86000], [0.40, 0.45, 0.50, 0.50],
                                                   [0.35, 0.40, 0.45, 0.45], [0.45, 0.50, 0.55, 0.55])}
    r = result(1, [0.10, 0.55, 0.52], [0.1, 0.5, 0.5], stress=(3000, 40000, 86000))
    # 3 kPa is below min_stress_pa: (0.05 + 0.02) / 2
    assert friction.friction_offset(r, "mu_static", targets=t) == pytest.approx(0.035)
    # a stress between two lab steps: the lab value is interpolated in log stress
    r2 = result(1, [0.5], [0.5], stress=(math.sqrt(12000 * 40000),))
    assert friction.friction_offset(r2, "mu_static", targets=t) == pytest.approx(0.5 - 0.475)


def test_friction_offset_counts_a_sticking_step_high_and_skips_lab_sticks():
    t = {"mu_static": friction.targets_from_arrays([12000, 40000, 86000], [0.50, 0.60, float("nan")],
                                                   [0.4, 0.5, float("nan")], [0.6, 0.7, float("nan")])}
    r = result(1, [0.50, None, 0.9], [0.5, None, 0.9], sticks=[False, True, False], stress=(12000, 40000, 86000))
    # 86 kPa: the lab sticks there -> left out; 40 kPa sticks in the simulation -> STICKS_MU
    assert friction.friction_offset(r, "mu_static", targets=t) == pytest.approx((0.0 + friction.STICKS_MU - 0.6) / 2)
    with pytest.raises(ValueError, match="no simulated step"):
        friction.friction_offset(result(1, [0.4], [0.4], stress=(3000,)), "mu_static", targets=t)
    with pytest.raises(ValueError, match="no lab curve"):
        friction.friction_offset(r, "mu_dynamic", targets=t)


def test_friction_offset_reads_the_lab_curve_of_the_material():
    # gravel_dry wall friction: plateau 0.50 from 30 kPa (labresults/curves/wall_friction_gravel_dry.csv)
    r = result(1, [0.51, 0.52], [0.5, 0.5], stress=(40000, 86000))
    assert friction.friction_offset(r, "mu_static") == pytest.approx(0.015, abs=1e-6)


def test_dynamic_friction_timed_near_vertical_is_not_a_value():
    """At a held angle near 90 deg a = g (sin t - mu cos t) loses mu: tan t / cos t blow up
    (a real internal-friction run read 1.6e16). Such steps give no mu_dynamic."""
    r = result(1, [0.5, 0.6], [0.45, 1.6e16], stress=(12000, 40000))
    r["dynamic_angle_deg"] = [26.0, 90.0]
    s = friction.seed_summary([r])
    assert s["mu_dynamic_mean"] == [0.45, None] and s["mu_dynamic_n"] == [1, 0]
    assert friction.dynamic_value(r, 1) is None and friction.dynamic_value(r, 0) == 0.45


def test_friction_angle_offset_counts_hanging_on_as_90_deg_on_both_sides():
    """The wet fines' lab cell slides up to 40 kPa and hangs on from 60 kPa: a simulated
    cell that slides at 86 kPa is 90 deg - atan(mu) short there; one that hangs on is not."""
    t = {"mu_static": friction.targets_from_arrays([12000, 40000, 60000, 86000], [0.56, 0.70, float("nan"),
                                                                                  float("nan")],
                                                   [0.43, 0.5, float("nan"), float("nan")],
                                                   [0.72, 1.0, float("nan"), float("nan")])}
    stress = (3000, 12000, 40000, 86000)
    sliding = result(1, [0.9, 0.56, 0.70, 0.80], [0.5] * 4, stress=stress)
    expected = (0.0 + 0.0 + (90.0 - math.degrees(math.atan(0.80)))) / 3 * -1
    assert friction.friction_angle_offset_deg(sliding, targets=t) == pytest.approx(expected)
    hangs = result(1, [0.9, 0.56, 0.70, None], [0.5] * 4, sticks=[False, False, False, True], stress=stress)
    assert friction.friction_angle_offset_deg(hangs, targets=t) == pytest.approx(0.0)
    # between the last sliding lab step (40 kPa, 35 deg) and the first that hangs on (60 kPa,
    # 90 deg) the lab angle is interpolated in log(stress): more cohesion keeps raising it
    at_50 = result(1, [0.70], [0.5], stress=(50000,))
    lab_50 = 35.0 + (90.0 - 35.0) * math.log(50000 / 40000) / math.log(60000 / 40000)
    assert friction.friction_angle_offset_deg(at_50, targets=t) == pytest.approx(
        math.degrees(math.atan(0.70)) - lab_50, abs=0.05)


def test_tilt_trace_draws_one_line_per_step(tmp_path):
    from pycal.post.friction import write_tilt_trace
    rec = tmp_path / "tilt_record.csv"
    rec.write_text("step_index_count,time_s,tilt_deg,slide_displacement_m,cell_gap_m,plate_force_x_n,"
                   "plate_force_y_n,plate_force_z_n\n0,0.1,1.0,0.0001,0.002,0,0,-1\n0,0.2,2.0,0.0012,0.002,0,0,-1\n"
                   "1,0.1,1.0,0.0000,0.002,0,0,-1\n1,0.2,3.0,0.0011,0.002,0,0,-1\n")
    out = write_tilt_trace(rec, tmp_path / "t.png", 0.001, [12000, 90000])
    assert out and (tmp_path / "t.png").stat().st_size > 1000
    (tmp_path / "empty.csv").write_text(rec.read_text().splitlines()[0] + "\n")
    assert write_tilt_trace(tmp_path / "empty.csv", tmp_path / "e.png") is None
