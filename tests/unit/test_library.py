"""pycal.library and `pycal library`: rows with what their job hashes, a lone run and a
batch's replica at one point sharing a point_id, export and import between runs folders,
rows of other configs marked not current, bad files refused in one line."""
import json

import pandas as pd
import pytest

from pycal import library
from pycal.cli import main
from pycal.jobs import resolve_job
from pycal.replicas import batch_job


def write(runs, job, result):
    d = runs / job["rig"] / job["job_id"]
    d.mkdir(parents=True)
    (d / "job.json").write_text(json.dumps(job))
    (d / "result.json").write_text(json.dumps(result))


def lone(runs, overrides, seed, bulk):
    job = resolve_job("fill", "M2", overrides, seed=seed)
    write(runs, job, {"job_id": job["job_id"], "rig": "fill", "material": "M2", "seed": seed, "job": job,
                      "contact_model": "hertz_mindlin", "bulk_density_kg_m3": bulk,
                      "provenance": {"cpu_time_s": 10.0, "git_commit": "abc", "yade_version": "2023.02a"}})
    return job


@pytest.fixture
def runs(tmp_path):
    runs = tmp_path / "runs"
    lone(runs, {"particles.density_kg_m3": 3000.0}, 1, 1500.0)
    lone(runs, {"particles.density_kg_m3": 3000.0}, 2, 1510.0)
    lone(runs, {"particles.density_kg_m3": 3300.0}, 1, 1650.0)
    batch = batch_job(resolve_job("fill", "M2", {"particles.density_kg_m3": 3000.0}, seed=3), [3, 4])
    write(runs, batch, {"job_id": batch["job_id"], "rig": "fill", "material": "M2", "job": batch,
                        "contact_model": "hertz_mindlin", "provenance": {"cpu_time_s": 20.0},
                        "replicas": [{"seed": s, "status": "ok", "measurements": {"bulk_density_kg_m3": 1490.0 + s},
                                      "simulated_time_s": 1.0, "steps_count": 10} for s in (3, 4)]})
    return runs


def test_rows_carry_the_point_their_job_hashes(runs):
    df = library.library_rows(runs)
    assert len(df) == 5 and set(df["source"]) == {"runs"}
    by_point = df.groupby("point_id")["seed"].apply(sorted).to_dict()
    assert sorted(by_point.values()) == [[1], [1, 2, 3, 4]]          # the replicas join the lone runs' point
    at = df[df["seed"] == 4].iloc[0]
    assert at["bulk_density_kg_m3"] == 1494.0 and at["cpu_time_s"] == 10.0
    assert json.loads(at["overrides_json"]) == {"particles.density_kg_m3": 3000.0}
    assert library.current_flags(df) == [True] * 5


def test_a_row_of_other_configs_is_not_current(runs):
    df = library.library_rows(runs)
    df.loc[0, "point_id"] = "000000000000"                           # as if another rig config had run it
    df.loc[1, "overrides_json"] = json.dumps({"particles.no_such_key": 1.0})
    assert library.current_flags(df)[:2] == [False, False]


def test_export_and_import_carry_the_rows_once(runs, tmp_path, capsys):
    out = tmp_path / "lib.csv"
    assert main(["library", str(runs), "--export", str(out)]) == 0
    other = tmp_path / "laptop"
    other.mkdir()
    assert main(["library", str(other), "--import", str(out)]) == 0
    assert main(["library", str(other), "--import", str(out)]) == 0  # again: nothing new
    text = capsys.readouterr().out
    assert "5 rows read, 5 new" in text and "5 rows read, 0 new" in text
    df = library.library_rows(other)
    assert len(df) == 5 and set(df["source"]) == {"imported: lib.csv"}
    assert main(["library", str(other)]) == 0
    assert "fill M2: 5 rows at 2 points, 5 current" in capsys.readouterr().out
    assert not list(tmp_path.rglob("*.part"))


def test_bad_library_files_are_refused_in_one_line(runs, tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    pd.DataFrame({"rig": ["fill"]}).to_csv(bad, index=False)
    assert main(["library", str(runs), "--import", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "needs the columns" in err
    cols = {c: ["x"] for c in library.KEY_COLUMNS}
    pd.DataFrame({**cols, "overrides_json": ["[1, 2]"]}).to_csv(bad, index=False)
    assert main(["library", str(runs), "--import", str(bad)]) == 2
    assert "not a JSON mapping" in capsys.readouterr().err
    assert not (runs / library.LIBRARY_FILE).exists()                # nothing half-written
    assert main(["library", str(tmp_path / "nope")]) == 2
