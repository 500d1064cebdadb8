"""Validation (pycal.calibration.validation): a prediction runs with the calibrated values,
is compared with the lab band, and a miss names the sensitivity command. Fake physics of
tests/unit/fake_rigs.py: AoR = 20 + 40 x rolling resistance (deg), seed noise 0.5 deg;
the surcharge angle of the fake surcharge rig = 0.6 x the AoR."""
import json

import pytest

from fake_rigs import FakeRigs, ROLLING_STUDY_HEAD, aor_law
from pycal.calibration.study import Study
from pycal.errors import ConfigError

STUDY = """
name: val
""" + ROLLING_STUDY_HEAD + """validation:
  seeds_count: 4
  sensitivity: {relative_step_fraction: 0.2, seeds_count: 2}
  predictions:
    - name: fines_dry_aor_left
      rig: aor
      material: M3-dry
      compare:
        - {response: aor_mean_deg, lab: {table: angle_of_repose, sample: fines_dry, column: left_deg}, band_deg: 2.0}
    - name: fines_dry_surcharge
      rig: surcharge
      material: M3-dry
      sensitivity: true
      sensitivity_extra: [interactions.M3-dry.friction_coefficient]
      compare:
        - {response: surcharge_mean_deg, lab: {table: surcharge, sample: fines_dry, column: left_deg}, band_deg: 2.0}
"""


def surcharge(job):
    return {"surcharge_mean_deg": 0.6 * aor_law(job)}


@pytest.fixture
def study(tmp_path):
    p = tmp_path / "val.yaml"
    p.write_text(STUDY)
    ex = FakeRigs(results={"surcharge": surcharge}, noise={"surcharge_mean_deg": 0.5})
    s = Study(p, ex, tmp_path / "out", log=lambda m: None)
    s.run()
    return s, ex


def test_predictions_use_the_calibrated_values_and_compare_with_the_lab_band(study):
    s, ex = study
    rolling = s.overrides["M3-dry"]["interactions.M3-dry.rolling_resistance_coefficient"]
    assert 20 + 40 * rolling == pytest.approx(38.0, abs=1.0)            # the lab's fines_dry AoR
    aor, sur = s.validation_rows
    # the prediction ran at the calibrated rolling resistance, on its own seeds count
    runs = [j for j in ex.asked if j["rig"] == "surcharge"]
    assert {j["materials"]["M3-dry"]["interactions"]["M3-dry"]["rolling_resistance_coefficient"]
            for j in runs[:4]} == {rolling}
    assert aor["comparisons"][0]["n"] == 4
    # AoR: lab left 38 deg (band 2): inside. Surcharge: 0.6 x ~38 = ~22.8 vs lab 29: a miss by ~3 bands
    assert aor["comparisons"][0]["inside"]
    c = sur["comparisons"][0]
    assert not c["inside"] and c["lab"] == 29.0
    assert c["z"] == pytest.approx((c["sim_mean"] - 29.0) / 2.0)
    assert c["sim_mean"] == pytest.approx(0.6 * (20 + 40 * rolling), abs=1.0)
    # what drives the miss is its own command, not part of the study's runs
    assert sur["sensitivity_command"] == "./run.sh pycal sensitivity fines_dry_surcharge --response surcharge_mean_deg"
    assert "sensitivity_command" not in aor
    assert len(runs) == 4


def test_summary_separates_calibrated_on_from_predicted(study):
    s, _ = study
    summary = json.loads((s.out / "summary.json").read_text())
    assert [c["stage"] for c in summary["calibrated_on"]] == ["rolling_resistance"]
    assert [p["prediction"] for p in summary["predicted"]] == ["fines_dry_aor_left", "fines_dry_surcharge"]
    rows = (s.out / "validation.csv").read_text().splitlines()
    assert rows[0].startswith("prediction,rig,material,response,sim_mean")
    assert (s.out / "plots" / "validation-fines_dry_surcharge.png").is_file()
    from pycal.report import write_report
    html = write_report(s.out).read_text()
    assert "Predicted (validation" in html and "missed" in html and "what drives the miss" in html


def test_a_scalar_comparison_needs_one_band(tmp_path):
    p = tmp_path / "bad.yaml"
    p.write_text(STUDY.replace(", band_deg: 2.0}\n    - name: fines_dry_surcharge", "}\n    - name: fines_dry_surcharge"))
    from pycal.calibration.study_config import load_study
    with pytest.raises(ConfigError, match=r"validation.predictions\[0\].compare\[0\]: a scalar comparison needs one "
                                          r"band_<unit>"):
        load_study(p)


def test_a_calibrated_subtree_with_its_leaves_reaches_the_sets_cross_pairs():
    """A stage switched the fines-steel pair to hysteretic (a whole subtree) and a later stage
    moved its pressure_fraction: through the set's from_components rules the wet fines'
    pairs with gravel and lumps get the switched pair with the moved leaf, and the weight
    part of each pair is the fines' own on that partner (a calibrated one included)."""
    from pycal.calibration.calibrated import overrides_for_material
    from pycal.jobs import resolve_job
    study = {"M3-wet": {"interactions.steel.cohesion": {"model": "hysteretic", "force_fraction": 0.0,
                                                        "pressure_fraction": 0.0, "update_interval_s": 0.01},
                        "interactions.steel.cohesion.pressure_fraction": 0.012,
                        "interactions.M3-wet.friction_coefficient": 0.41,
                        "interactions.M2.cohesion.force_fraction": 7.0,   # read by a rule: applied
                        "interactions.M2.friction_coefficient": 0.99}}   # a pair inside the set: not applied
    job = resolve_job("aor_mixed", "mixed-wet", overrides_for_material(study, "mixed-wet"))
    want = {"model": "hysteretic", "pressure_fraction": 0.012, "update_interval_s": 0.01}
    for coarse, weight_part in (("M1", 0.3), ("M2", 7.0)):       # M1: the config's fines-lumps value
        pair = job["materials"][coarse]["interactions"]["M3-wet"]
        assert pair["cohesion"] == dict(want, force_fraction=weight_part) and pair["friction_coefficient"] == 0.41
        assert job["materials"]["M3-wet"]["interactions"][coarse] == pair
    # no calibrated value: the shipped fines-wall adhesion with the fines-gravel weight part
    job0 = resolve_job("aor_mixed", "mixed-wet")
    steel = job0["materials"]["M3-wet"]["interactions"]["steel"]["cohesion"]
    assert job0["materials"]["M2"]["interactions"]["M3-wet"]["cohesion"] == dict(steel, force_fraction=0.3)


def test_a_set_override_wins_over_the_component_value_it_would_take():
    from pycal.jobs import resolve_job
    job = resolve_job("aor_mixed", "mixed-wet", {"cross_interactions.M2.M3-wet.cohesion.force_fraction": 1.0,
                                                 "M3-wet.interactions.M1.cohesion.force_fraction": 0.2})
    assert job["materials"]["M2"]["interactions"]["M3-wet"]["cohesion"]["force_fraction"] == 1.0
    assert job["materials"]["M1"]["interactions"]["M3-wet"]["cohesion"]["force_fraction"] == 0.2


def test_a_prediction_with_no_value_on_any_seed_is_reported_not_a_crash(tmp_path):
    """A surcharge pile too flat for an angle on every seed (the calibrated fines did this):
    the comparison has n = 0 and misses, the study goes on to write its outputs and plot."""
    p = tmp_path / "val.yaml"
    p.write_text(STUDY)
    ex = FakeRigs(results={"surcharge": lambda job: {"surcharge_mean_deg": None}})
    s = Study(p, ex, tmp_path / "out", log=lambda m: None)
    s.run()
    c = s.validation_rows[1]["comparisons"][0]
    assert c["n"] == 0 and not c["inside"]
    assert (s.out / "plots" / "validation-fines_dry_surcharge.png").is_file()
    assert (s.out / "summary.json").is_file()


def test_a_curve_comparison_is_paired_seed_by_seed(monkeypatch):
    """Curve responses (RMS band z per seed) pair like scalars: per-seed differences, their
    mean and standard error (seed offsets cancel)."""
    from pycal.calibration import validation
    monkeypatch.setattr(validation, "compare_results", lambda results, cmp: {"sim_mean": results[0]["z"]})
    base = {1: {"z": 1.0}, 2: {"z": 5.0}, 3: {"z": 3.0}}
    moved = {1: {"z": 1.5}, 2: {"z": 5.7}, 3: {"z": 3.3}, 4: {"z": 9.0}}
    r = validation.paired_change(moved, base, {"response": validation.CURVE})
    assert r["seeds"] == [1, 2, 3]
    assert r["change"] == pytest.approx(0.5)
    assert r["change_se"] == pytest.approx(0.2 / 3 ** 0.5)


def test_a_sensitivity_extra_key_the_material_lacks_is_a_config_error(tmp_path):
    p = tmp_path / "bad.yaml"
    p.write_text(STUDY.replace("[interactions.M3-dry.friction_coefficient]", "[interactions.M3-dry.stickiness]"))
    from pycal.calibration.study_config import load_study
    with pytest.raises(ConfigError, match=r"sensitivity_extra: interactions.M3-dry.stickiness: not a non-zero "
                                          r"number of M3-dry"):
        load_study(p)


def test_a_leaf_override_does_not_write_into_the_callers_subtree():
    """A stage sets a whole cohesion subtree and a later run moves one leaf below it: the
    job has the moved leaf, the caller's overrides (the study's calibrated values) keep
    theirs, so the next job without that leaf gets the subtree's own value. (The study's
    sensitivity on the wet pile's force_fraction made every later wet run use 0.6.)"""
    from pycal.jobs import resolve_job
    sub = {"model": "hysteretic", "force_fraction": 0.5, "pressure_fraction": 0.05, "update_interval_s": 0.01}
    calibrated = {"interactions.M3-wet.cohesion": sub}
    moved = dict(calibrated, **{"interactions.M3-wet.cohesion.force_fraction": 0.6})
    for material, prefix in (("M3-wet", ""), ("mixed-wet", "M3-wet.")):
        rig = "aor_mixed" if material == "mixed-wet" else "aor"
        over = {prefix + k: v for k, v in moved.items()}
        job = resolve_job(rig, material, over)
        assert job["materials"]["M3-wet"]["interactions"]["M3-wet"]["cohesion"]["force_fraction"] == 0.6
        assert sub["force_fraction"] == 0.5
        job = resolve_job(rig, material, {prefix + k: v for k, v in calibrated.items()})
        assert job["materials"]["M3-wet"]["interactions"]["M3-wet"]["cohesion"]["force_fraction"] == 0.5


def test_a_prediction_shows_its_piles_and_its_values_per_seed(tmp_path):
    """The report's prediction section: the side views of its first 3 seeds (the rig's
    pictures, copied from the job folders) and the compared response per seed beside the
    lab's value."""
    p = tmp_path / "val.yaml"
    p.write_text(STUDY)
    ex = FakeRigs(results={"surcharge": surcharge}, noise={"surcharge_mean_deg": 0.5}, runs_dir=tmp_path / "runs")
    s = Study(p, ex, tmp_path / "out", log=lambda m: None)
    s.run()
    aor, sur = s.validation_rows
    assert [g["file"] for g in aor["gallery"]] == [f"plots/validation-fines_dry_aor_left/seed{k}-pile_side.png"
                                                    for k in aor["seeds"][:3]]
    assert all((s.out / g["file"]).is_file() for g in aor["gallery"] + sur["gallery"])
    assert [x["seed"] for x in aor["seed_values"]] == aor["seeds"]
    mean = sum(x["aor_mean_deg"] for x in aor["seed_values"]) / len(aor["seed_values"])
    assert mean == pytest.approx(aor["comparisons"][0]["sim_mean"])
    from pycal.report import write_report
    html = write_report(s.out).read_text()
    assert "fines_dry_aor_left per seed" in html and "validation-fines_dry_aor_left/seed" in html
