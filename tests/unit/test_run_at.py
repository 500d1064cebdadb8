"""A stage's run_at: its runs use other material values (a cheaper stiffness), the
calibrated set does not carry them, and the run_at check runs the stage's rig again with
the calibrated set at the calibrated values. Fake physics (tests/unit/fake_rigs.py)."""
import json

from fake_rigs import FakeRigs, ROLLING_STUDY_HEAD
from pycal.calibration.study import Study
from pycal.jobs import resolve_job

STUDY = "name: runat\n" + ROLLING_STUDY_HEAD.replace(
    "      max_runs_count: 30\n",
    "      max_runs_count: 30\n      run_at: {contact.youngs_modulus_pa: 3.0e7}\n") + "run_at_checks: {seeds_count: 2}\n"


def test_run_at_values_are_used_by_the_stage_only_and_checked_after(tmp_path):
    p = tmp_path / "s.yaml"
    p.write_text(STUDY)
    ex = FakeRigs()
    s = Study(p, ex, tmp_path / "out", log=lambda m: None)
    s.run()
    e_config = resolve_job("aor", "M3-dry")["materials"]["M3-dry"]["contact"]["youngs_modulus_pa"]
    assert e_config != 3.0e7
    stage_jobs = [j for j in ex.asked if j["materials"]["M3-dry"]["contact"]["youngs_modulus_pa"] == 3.0e7]
    check_jobs = [j for j in ex.asked if j["materials"]["M3-dry"]["contact"]["youngs_modulus_pa"] == e_config]
    assert len(stage_jobs) == s.stage_rows[0]["runs_requested"] and len(check_jobs) == 2
    assert "contact.youngs_modulus_pa" not in s.overrides["M3-dry"]
    rolling = s.overrides["M3-dry"]["interactions.M3-dry.rolling_resistance_coefficient"]
    assert {j["materials"]["M3-dry"]["interactions"]["M3-dry"]["rolling_resistance_coefficient"]
            for j in check_jobs} == {rolling}
    summary = json.loads((s.out / "summary.json").read_text())
    (row,) = summary["run_at_checks"]
    assert row["n"] == 2 and row["run_at"] == {"contact.youngs_modulus_pa": 3.0e7}
    assert abs(row["value_mean"] - 38.0) < 3.0        # the fake AoR does not depend on E: the target again
    assert (s.out / "run_at_checks.csv").is_file()
    from pycal.report import write_report
    assert "checked with the calibrated set" in write_report(s.out).read_text()
