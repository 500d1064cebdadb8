"""Application runs (pycal.calibration.application): design runs with the calibrated values,
reported with the seed spread. Fake physics (tests/unit/fake_rigs.py): AoR = 20 + 40 x
rolling resistance; a fake transfer whose impact stress is 1e5 Pa x the gravel-fines
rolling resistance of the set (a cross pair, which the set takes from the fines through
its from_components rules) and which plugs on even seeds."""
import json

import pytest

from fake_rigs import FakeRigs, ROLLING_STUDY_HEAD
from pycal.calibration.study import Study
from pycal.errors import ConfigError

STUDY = """
name: app
""" + ROLLING_STUDY_HEAD + """application:
  seeds_count: 3
  runs:
    - name: chute_dry
      rig: transfer
      material: mixed-dry
      responses: [impact_stress_pa, plugged]
"""


def transfer(job):
    eta = job["materials"]["M2"]["interactions"]["M3-dry"]["rolling_resistance_coefficient"]
    return {"impact_stress_pa": 1e5 * eta, "plugged": job["seed"] % 2 == 0}


def run_study(tmp_path, text=STUDY):
    p = tmp_path / "app.yaml"
    p.write_text(text)
    s = Study(p, FakeRigs(results={"transfer": transfer}), tmp_path / "out", log=lambda m: None)
    s.run()
    return s


def test_application_runs_with_the_calibrated_values_and_reports_the_seed_spread(tmp_path):
    s = run_study(tmp_path)
    rolling = s.overrides["M3-dry"]["interactions.M3-dry.rolling_resistance_coefficient"]
    assert rolling != 0.35                                         # the stage moved it from its start value
    (row,) = s.application_rows
    impact, plugged = row["responses"]
    assert row["seeds"] == [1, 2, 3]
    assert impact["n"] == 3 and impact["mean"] == pytest.approx(1e5 * rolling) and impact["sd"] == pytest.approx(0)
    assert plugged["kind"] == "flag" and (plugged["true_count"], plugged["n"]) == (1, 3)   # seed 2 only
    summary = json.loads((s.out / "summary.json").read_text())
    assert summary["applied"][0]["name"] == "chute_dry"
    assert (s.out / "application.csv").read_text().splitlines()[0].startswith("name,rig,material,response,mean")
    assert (s.out / "plots" / "application.png").is_file()
    from pycal.report import write_report
    html = write_report(s.out).read_text()
    assert "Application (design runs" in html and "1 of 3 seeds" in html


def test_application_section_errors_name_the_key(tmp_path):
    from pycal.calibration.study_config import load_study
    p = tmp_path / "bad.yaml"
    p.write_text(STUDY.replace("      responses: [impact_stress_pa, plugged]\n", "      responses: []\n"))
    with pytest.raises(ConfigError, match=r"application.runs\[0\].responses: must be a non-empty list"):
        load_study(p)
