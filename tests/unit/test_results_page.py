"""pycal/results_page.py: the README's results tables come from one study run's record, and
the README's block is the rendering of the committed record (they cannot drift)."""
import csv
import json

import pytest
import yaml

from fake_rigs import FakeRigs, ROLLING_STUDY_HEAD
from pycal import REPO_ROOT
from pycal.calibration.study import Study
from pycal.errors import ConfigError
from pycal import results_page

PREDICTION = {"name": "fines_dry_aor_left", "rig": "aor", "material": "M3-dry",
              "compare": [{"response": "aor_mean_deg", "band_deg": 2.0,
                           "lab": {"table": "angle_of_repose", "sample": "fines_dry", "column": "left_deg"}}]}
STUDY = "name: page\n" + ROLLING_STUDY_HEAD + yaml.safe_dump({"validation": {"seeds_count": 2,
                                                                           "predictions": [PREDICTION]}})


@pytest.fixture
def study_dir(tmp_path):
    p = tmp_path / "page.yaml"
    p.write_text(STUDY)
    out = tmp_path / "runs" / "study"
    s = Study(p, FakeRigs(), out, log=lambda m: None)
    s.run()
    # each job's result.json where a runs folder keeps it: 2 CPU s each, the AoR rig at scale 2
    with open(s.out / "jobs.csv", newline="") as f:
        for row in csv.DictReader(f):
            d = tmp_path / "runs" / row["rig"] / row["job_id"]
            d.mkdir(parents=True, exist_ok=True)
            (d / "result.json").write_text(json.dumps({"provenance": {"cpu_time_s": 2.0},
                                                       "job": {"rig_config": {"geometry": {"scale": 2.0}}}}))
    return s.out


def test_record_and_tables_of_a_study_run(study_dir):
    rec = results_page.record(study_dir, wall_time_s=600.0)
    summary = json.loads((study_dir / "summary.json").read_text())
    stage = summary["stages"][0]
    row = rec["stages"][0]
    assert row["estimate"] == stage["parameters"][0]["estimate"] and row["runs"] == stage["runs_requested"]
    assert rec["runs_count"] == stage["runs_requested"] + 2          # the stage's runs and the 2 prediction seeds
    assert rec["cpu_time_s"] == pytest.approx(2.0 * rec["runs_count"])
    assert rec["rig_scales"] == {"aor": [2.0]}
    text = results_page.render(rec)
    p = stage["parameters"][0]
    assert f"| M3-dry | rolling_resistance | {p['label']} | {p['estimate']:.3g} [{p['low']:.3g}, {p['high']:.3g}]" in text
    assert "10 min wall (measured around the whole command)" in text
    assert "Rig scales: aor 2." in text
    assert "| fines_dry_aor_left | aor_mean_deg |" in text and "| 38 +- 2 |" in text
    assert rec["finished"] and "partial" not in text


def test_a_run_recorded_midway_says_how_far_it_got(study_dir):
    summary = json.loads((study_dir / "summary.json").read_text())
    summary["study"]["materials"]["M3-dry"].append(dict(summary["study"]["materials"]["M3-dry"][0]))  # one stage to go
    summary["predicted"] = []
    (study_dir / "summary.json").write_text(json.dumps(summary))
    rec = results_page.record(study_dir)
    assert (rec["stages_done"], rec["stages_planned"], rec["finished"]) == (1, 2, False)
    assert "**A partial run**: recorded after 1 of 2 stages" in results_page.render(rec)


def test_update_readme_replaces_only_the_block(study_dir, tmp_path):
    readme = tmp_path / "README.md"
    begin = results_page.BEGIN.format(name="page")
    readme.write_text(f"# title\n\n{begin}\nold table\n{results_page.END}\n\n## after\n")
    results_page.main(study_dir, 600.0, update_readme=True, readme=readme, out_dir=tmp_path / "results")
    text = readme.read_text()
    assert text.startswith("# title\n\n") and text.endswith("\n\n## after\n") and "old table" not in text
    rec = json.loads((tmp_path / "results" / "page.json").read_text())
    assert results_page.readme_block(text, "page") == results_page.render(rec)
    with pytest.raises(ConfigError, match="no generated block"):
        results_page.replace_block("no block here", "x", "page")


def test_the_readme_shows_the_committed_record():
    """The README's results block is the rendering of docs/results/zinc_ore.json as committed."""
    path = REPO_ROOT / "docs" / "results" / "zinc_ore.json"
    assert path.is_file(), "docs/results/zinc_ore.json: the shipped run's record (./run.sh pycal results ...)"
    rec = json.loads(path.read_text())
    text = (REPO_ROOT / "README.md").read_text()
    assert results_page.readme_block(text, "zinc_ore") == results_page.render(rec)
