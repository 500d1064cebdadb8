"""pycal.runs_index and `pycal runs`: a runs folder written by hand with every kind of job
folder (a lone run, a batch with a failed replica, a rig's refusal, a job not run yet, a
failed attempt with and without a result since, a temporary), read back as one row per seed."""
import json

import pandas as pd
import pytest

from pycal import runs_index
from pycal.cli import main


def job(rig, job_id, seed=None, seeds=None, material="M2", **overrides):
    j = {"job_id": job_id, "rig": rig, "material": material, "overrides": overrides}
    j.update({"seeds": seeds} if seeds else {"seed": seed})
    return j


def folder(runs, rig, name, job_=None, result=None, refusal=None):
    d = runs / rig / name
    d.mkdir(parents=True)
    if job_ is not None:
        (d / "job.json").write_text(json.dumps(job_))
    if result is not None:
        (d / "result.json").write_text(json.dumps(result))
    if refusal is not None:
        (d / "rig_failure.txt").write_text(refusal)
    return d


def lone_result(j, cpu, **measurements):
    return {"job_id": j["job_id"], "rig": j["rig"], "material": j["material"], "seed": j["seed"], "job": j,
            "contact_model": "hertz_mindlin", **measurements,
            "provenance": {"cpu_time_s": cpu, "wall_time_s": cpu + 1, "git_commit": "abc", "yade_version": "2023.02a"}}


@pytest.fixture
def runs(tmp_path):
    runs = tmp_path / "runs"
    a = job("fill", "fill-M2-s1-aaa", 1, **{"particles.density_kg_m3": 3000.0})
    folder(runs, "fill", a["job_id"], a, lone_result(a, 12.0, bulk_density_kg_m3=1500.0, n_particles=80))
    b = job("aor", "aor-M2-s1x2-bbb", seeds=[1, 2])
    folder(runs, "aor", b["job_id"], b, {
        "job_id": b["job_id"], "rig": "aor", "material": "M2", "job": b, "contact_model": "hertz_mindlin",
        "provenance": {"cpu_time_s": 100.0, "git_commit": "abc"},
        "replicas": [{"seed": 1, "status": "ok", "measurements": {"aor_mean_deg": 40.0},
                      "simulated_time_s": 3.0, "steps_count": 10},
                     {"seed": 2, "status": "failed", "failure": "no rest after 5 s"}]})
    c = job("fill", "fill-M2-s2-ccc", 2)
    folder(runs, "fill", c["job_id"], c, refusal="blew up: max speed 80 m/s")
    d = job("fill", "fill-M2-s3-ddd", 3)
    folder(runs, "fill", d["job_id"], d)                                       # written, not run
    folder(runs, "fill", a["job_id"] + ".failed", a)                           # superseded by its result
    e = job("fill", "fill-M3-dry-s1-eee", 1, material="M3-dry")
    folder(runs, "fill", e["job_id"] + ".failed", e)
    folder(runs, "fill", ".fill-M2-s4-fff.tmp-vm-123", job("fill", "fill-M2-s4-fff", 4))
    study = runs / "study" / "s"
    study.mkdir(parents=True)
    (study / "jobs.csv").write_text(
        "section,material,rig,seed,job_id,status,batch_job_id\n"
        "M2/density,M2,fill,1,fill-M2-s1-aaa,ok,\n"
        "M2/density_recheck,M2,fill,1,fill-M2-s1-aaa,ok,\n"
        "M2/rolling_resistance,M2,aor,1,aor-M2-s1-lone1,ok,aor-M2-s1x2-bbb\n"
        "M2/rolling_resistance,M2,aor,2,aor-M2-s2-lone2,failed,aor-M2-s1x2-bbb\n"
        "M2/wall_friction,M2,wall_friction,1,wall_friction-M2-s1-ggg,failed,\n")
    return runs


def test_one_row_per_seed_with_status_cpu_share_and_values(runs):
    df = runs_index.runs_table(runs).set_index("job_id")
    assert sorted(df.index) == ["aor-M2-s1x2-bbb-s1", "aor-M2-s1x2-bbb-s2", "fill-M2-s1-aaa", "fill-M2-s2-ccc",
                                "fill-M2-s3-ddd", "fill-M3-dry-s1-eee"]
    assert df["status"].to_dict() == {"aor-M2-s1x2-bbb-s1": "ok", "aor-M2-s1x2-bbb-s2": "failed",
                                      "fill-M2-s1-aaa": "ok", "fill-M2-s2-ccc": "refused",
                                      "fill-M2-s3-ddd": "pending", "fill-M3-dry-s1-eee": "failed"}
    assert df.loc["aor-M2-s1x2-bbb-s1", "cpu_time_s"] == 50.0              # half of its batch of two
    assert df.loc["aor-M2-s1x2-bbb-s1", "aor_mean_deg"] == 40.0
    assert df.loc["aor-M2-s1x2-bbb-s1", "folder"].endswith("aor/aor-M2-s1x2-bbb/s1")
    assert "no rest after 5 s" in df.loc["aor-M2-s1x2-bbb-s2", "message"]
    assert df.loc["fill-M2-s1-aaa", "cpu_time_s"] == 12.0 and df.loc["fill-M2-s1-aaa", "bulk_density_kg_m3"] == 1500.0
    assert df.loc["fill-M2-s1-aaa", "set.particles.density_kg_m3"] == 3000.0
    assert pd.isna(df.loc["fill-M2-s2-ccc", "set.particles.density_kg_m3"])
    assert df.loc["fill-M2-s2-ccc", "message"] == "blew up: max speed 80 m/s"
    assert runs_index.parameter_columns(df) == ["set.particles.density_kg_m3"]


def test_the_study_names_the_stages_that_asked_and_the_runs_it_lacks(runs):
    df = runs_index.runs_table(runs, study_dir=runs / "study" / "s").set_index("job_id")
    assert df.loc["fill-M2-s1-aaa", "stage"] == "M2/density;M2/density_recheck"
    assert df.loc["aor-M2-s1x2-bbb-s1", "stage"] == "M2/rolling_resistance"      # found through its batch
    assert df.loc["fill-M2-s3-ddd", "stage"] == ""
    assert df.loc["wall_friction-M2-s1-ggg", "status"] == "missing"
    only = runs_index.runs_table(runs, study_dir=runs / "study" / "s", rig="fill", material="M2")
    assert set(only["rig"]) == {"fill"} and set(only["material"]) == {"M2"}


def test_ok_results_and_job_files(runs):
    got = runs_index.ok_results(runs, "aor")
    assert [(row["seed"], res["aor_mean_deg"], res["job"]["seed"]) for row, res in got] == [(1, 40.0, 1)]
    files = runs_index.job_files(runs, "fill", "M2")
    assert [f.parent.name for f in files] == ["fill-M2-s1-aaa", "fill-M2-s2-ccc", "fill-M2-s3-ddd"]
    assert [f.parent.name for f in runs_index.job_files(runs, "fill", "M2", status="ok")] == ["fill-M2-s1-aaa"]


def test_an_empty_folder_is_an_empty_table(tmp_path):
    df = runs_index.runs_table(tmp_path)
    assert df.empty and list(df.columns) == runs_index.ID_COLUMNS


def test_pycal_runs_prints_counts_and_writes_the_csv(runs, tmp_path, capsys):
    out = tmp_path / "t" / "runs.csv"
    assert main(["runs", str(runs), "--study", str(runs / "study" / "s"), "--csv", str(out)]) == 0
    text = capsys.readouterr().out
    assert "fill M2: 1 ok, 1 pending, 1 refused; CPU 12 s" in text and "7 runs, CPU 62 s" in text
    back = pd.read_csv(out)
    assert len(back) == 7 and "aor_mean_deg" in back.columns and not list(tmp_path.glob("t/*.part"))
    assert main(["runs", str(runs), "--status", "refused"]) == 0
    assert "fill-M2-s2-ccc" in capsys.readouterr().out


def test_pycal_runs_refuses_a_missing_folder_in_one_line(tmp_path, capsys):
    assert main(["runs", str(tmp_path / "nope")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "no such folder" in err
    assert main(["runs", str(tmp_path), "--study", str(tmp_path)]) == 2
    assert "no jobs.csv" in capsys.readouterr().err
