"""Runner: caching, atomic completion, failures, yade-batch tables, CLI errors.

A fake `yade` (conftest.py: fake_yade) stands in for YADE so this layer runs in seconds.
"""
import json

import pytest

from pycal import runner
from pycal.cli import main
from pycal.errors import RunError
from pycal.jobs import resolve_job


def test_run_once_then_cached(tmp_path, fake_yade):
    job = resolve_job("fill", "M2", seed=1)
    r1 = runner.run_job(job, tmp_path / "runs")
    r2 = runner.run_job(job, tmp_path / "runs")
    assert r1 == r2 and r1["bulk_density_kg_m3"] == 1600.0
    assert fake_yade() == 1
    d = tmp_path / "runs" / "fill" / job["job_id"]
    assert json.loads((d / "job.json").read_text()) == job
    assert "fake yade running" in (d / "yade.log").read_text()
    assert not list((tmp_path / "runs" / "fill").glob(".*tmp*"))


def test_failure_keeps_log_and_writes_no_result(tmp_path, fake_yade, monkeypatch):
    monkeypatch.setenv("FAKE_MODE", "fail")
    job = resolve_job("fill", "M2", seed=1)
    with pytest.raises(RunError, match="blow-up: particle 7 left the rig domain"):
        runner.run_job(job, tmp_path / "runs")
    assert not (tmp_path / "runs" / "fill" / job["job_id"]).exists()
    failed = tmp_path / "runs" / "fill" / (job["job_id"] + ".failed")
    assert (failed / "yade.log").is_file() and not (failed / "result.json").exists()
    monkeypatch.setenv("FAKE_MODE", "ok")          # a later attempt runs again and succeeds
    assert runner.run_job(job, tmp_path / "runs")["n_particles"] == 100


def test_a_rig_refusal_is_kept_and_not_simulated_again(tmp_path, fake_yade, monkeypatch):
    """A RigFailure (rig_failure.txt) is the physics' verdict on this job: a resumed
    study gets the same failure from the cache instead of paying for the run again."""
    monkeypatch.setenv("FAKE_MODE", "refuse")
    job = resolve_job("fill", "M2", seed=1)
    for _ in range(2):
        with pytest.raises(RunError, match="no rest after 8 s"):
            runner.run_job(job, tmp_path / "runs")
    pool = runner.LocalPool(tmp_path / "runs", workers=2, progress=False)
    assert pool.run([job], raise_on_error=False) == [None]
    assert "kept from an earlier run" in pool.last_errors[0] and pool.simulated_count == 0
    assert fake_yade() == 1


def test_jobio_writes_the_refusal_file(tmp_path):
    """yade_scripts/demlib/jobio.run_rig on a RigFailure: exit 3, no result.json, and
    rig_failure.txt naming the reason (plain python: the rig body is not YADE here)."""
    import subprocess
    import sys
    (tmp_path / "job.json").write_text(json.dumps({"rig": "fill", "material": "M2", "seed": 1}))
    code = ("from yade_scripts.demlib.jobio import run_rig, RigFailure\n"
            "def main(job, out):\n    raise RigFailure('no rest after 8 s')\n"
            "run_rig(main)\n")
    proc = subprocess.run([sys.executable, "-c", code, str(tmp_path / "job.json")], capture_output=True, text=True,
                          env=runner.yade_env())
    assert proc.returncode == 3 and "RIG FAILED: no rest after 8 s" in proc.stdout
    assert (tmp_path / runner.RIG_FAILURE_FILE).read_text().strip() == "RIG FAILED: no rest after 8 s"
    assert not (tmp_path / "result.json").exists()


def test_half_written_result_is_not_a_result(tmp_path, fake_yade, monkeypatch):
    monkeypatch.setenv("FAKE_MODE", "partial")
    job = resolve_job("fill", "M2", seed=1)
    with pytest.raises(RunError):
        runner.run_job(job, tmp_path / "runs")
    assert runner.cached_result(job, tmp_path / "runs") is None


def test_cpu_limit_stops_a_run_that_uses_its_cpu_time(tmp_path, fake_yade, monkeypatch):
    monkeypatch.setenv("FAKE_MODE", "spin")
    job = resolve_job("fill", "M2", seed=1)
    with pytest.raises(RunError, match="CPU time limit of 1 s reached"):
        runner.run_job(job, tmp_path / "runs", timeout_s=1.0)


def test_a_starved_run_is_not_stopped_by_its_cpu_limit(tmp_path, fake_yade, monkeypatch):
    """2 s of wall time without CPU (as a run waiting for a core on an overloaded machine)
    under a 1 s CPU limit completes."""
    monkeypatch.setenv("FAKE_MODE", "sleep_then_ok")
    job = resolve_job("fill", "M2", seed=1)
    assert runner.run_job(job, tmp_path / "runs", timeout_s=1.0)["n_particles"] == 100


def test_a_hung_run_is_stopped_by_the_wall_limit(tmp_path, fake_yade, monkeypatch):
    monkeypatch.setenv("FAKE_MODE", "sleep")
    job = resolve_job("fill", "M2", seed=1)
    with pytest.raises(RunError, match="no result after 1 s of wall time"):
        runner.run_job(job, tmp_path / "runs", timeout_s=0.1)


def test_pool_runs_each_job_once(tmp_path, fake_yade):
    jobs = [resolve_job("fill", "M2", seed=s) for s in (1, 2, 3)]
    pool = runner.LocalPool(tmp_path / "runs", workers=2, progress=False)
    assert len(pool.run(jobs)) == 3
    assert len(pool.run(jobs + jobs)) == 6
    assert fake_yade() == 3


def test_pool_reports_failures(tmp_path, fake_yade, monkeypatch):
    monkeypatch.setenv("FAKE_MODE", "fail")
    pool = runner.LocalPool(tmp_path / "runs", workers=2, progress=False)
    jobs = [resolve_job("fill", "M2", seed=s) for s in (1, 2)]
    with pytest.raises(RunError, match="2 of 2 job"):
        pool.run(jobs)
    assert pool.run(jobs, raise_on_error=False) == [None, None]


def test_batch_table(tmp_path):
    table = tmp_path / "t.table"
    runner.write_batch_table(table, [("a", tmp_path / "a.json"), ("b", tmp_path / "b.json")])
    lines = table.read_text().splitlines()
    # yade-batch evaluates each value as Python: the path is a quoted absolute path
    assert lines[0] == "description jobFile" and lines[1] == f"a '{tmp_path / 'a.json'}'"


def test_cli_bad_material_one_line_exit_2(tmp_path, capsys):
    rc = main(["run", "fill", "--material", "M9", "--out", str(tmp_path / "runs")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and err.count("\n") == 0
    assert err == "error: configs/materials/M9.yaml: unknown material 'M9' (known: M1, M2, M3-dry, M3-wet)"
    assert not (tmp_path / "runs").exists()


def test_cli_bad_override_exit_2(tmp_path, capsys):
    rc = main(["run", "fill", "--material", "M2", "--set", "particles.density_kg_m3=-5",
               "--out", str(tmp_path / "runs")])
    assert rc == 2
    assert "--set: particles.density_kg_m3=-5: -5 must be > 0" in capsys.readouterr().err
    assert not (tmp_path / "runs").exists()


def test_cli_run_with_fake_yade(tmp_path, fake_yade, capsys):
    rc = main(["run", "fill", "--material", "M2", "--seeds", "2", "--replicas", "1", "--out", str(tmp_path / "runs")])
    out = capsys.readouterr().out
    assert rc == 0 and "bulk_density_kg_m3=1600" in out and "over 2 seeds" in out


def test_a_cpu_limit_not_above_zero_is_refused(tmp_path):
    assert main(["run", "fill", "--material", "M2", "--cpu-limit-s", "0", "--out", str(tmp_path / "r")]) == 2
    assert not (tmp_path / "r").exists()
