"""Executors without YADE: stale temporaries, job folders made for a run by hand, batch
tables, a yade-batch that hangs or dies, Dask failures and an unreachable scheduler.

A fake `yade` (conftest.py: fake_yade) stands in for YADE; Dask runs a real local cluster.
"""
import json
import os
import socket
import stat
import subprocess
import sys
import time

import pytest

from pycal.cli import main
from pycal.errors import ConfigError
from pycal.executors import jobdirs
from pycal.executors.dask_cluster import DaskExecutor, scheduler_address
from pycal.executors.local import LocalPool
from pycal.executors.yade_batch import YadeBatch, prepare_batch_table, write_batch_table
from pycal.jobs import resolve_job


def _dead_pid():
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_stale_temporaries_of_dead_processes_go_live_ones_stay(tmp_path, fake_yade):
    job = resolve_job("fill", "M2", seed=1)
    rig = tmp_path / "runs" / "fill"
    rig.mkdir(parents=True)
    here = jobdirs.host_name()
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        keep = [rig / f".{job['job_id']}.tmp-{here}-{live.pid}",      # a concurrent run on this host
                rig / ".fill-M2-s9-abc.tmp-othernode-12"]             # another host, changed just now
        gone = [rig / f".fill-M2-s3-abc.tmp-{here}-{_dead_pid()}",    # a killed run on this host
                rig / f".fill-M2-s4-abc.tmp-{_dead_pid()}",           # the old name (no host)
                rig / ".fill-M2-s5-abc.tmp-othernode-13"]             # another host, silent for 2 days
        for p in keep + gone:
            p.mkdir()
            (p / "yade.log").write_text("running")
        old = time.time() - 2 * 86400
        for p in (gone[2], gone[2] / "yade.log"):
            os.utime(p, (old, old))
        (rig / f".batch-fill.tmp-{here}-{_dead_pid()}").write_text("description jobFile\n")
        pool = LocalPool(tmp_path / "runs", workers=1, progress=False)
        assert pool.run([job])[0]["n_particles"] == 100
        left = sorted(p.name for p in rig.iterdir())
        assert left == sorted([job["job_id"]] + [p.name for p in keep])
    finally:
        live.kill()
        live.wait()


def test_a_job_listed_twice_runs_once(tmp_path, fake_yade):
    jobs = [resolve_job("fill", "M2", seed=s) for s in (1, 2, 1)]
    pool = LocalPool(tmp_path / "runs", workers=2, progress=False)
    results = pool.run(jobs)
    assert results[0] == results[2] and fake_yade() == 2 and pool.simulated_count == 2


def test_job_write_creates_the_folder_and_prints_the_command(tmp_path, fake_yade, capsys):
    runs = tmp_path / "runs"
    assert main(["job", "fill", "--material", "M2", "--seeds", "2", "--write", "--out", str(runs)]) == 0
    out = capsys.readouterr().out
    for seed in (1, 2):
        job = resolve_job("fill", "M2", seed=seed)
        folder = runs / "fill" / job["job_id"]
        assert json.loads((folder / "job.json").read_text()) == job
        assert f"fake-yade -j1 -x -n {jobdirs.REPO_ROOT}/yade_scripts/fill.py {folder}/job.json" in out
    assert out.count("PYTHONPATH=") == 2


def test_an_incomplete_job_folder_is_run_again_and_replaced(tmp_path, fake_yade):
    """A job folder made for a run by hand that never completed is not a result."""
    job = resolve_job("fill", "M2", seed=1)
    folder = jobdirs.create_job_folder(job, tmp_path / "runs")
    (folder / "yade.log").write_text("killed half way")
    pool = LocalPool(tmp_path / "runs", workers=1, progress=False)
    assert pool.run([job])[0]["n_particles"] == 100 and pool.simulated_count == 1
    assert "fake yade running" in (folder / "yade.log").read_text()
    assert sorted(p.name for p in folder.parent.iterdir()) == [job["job_id"]]


def test_a_refusal_in_a_job_folder_run_by_hand_is_kept(tmp_path, fake_yade):
    job = resolve_job("fill", "M2", seed=1)
    folder = jobdirs.create_job_folder(job, tmp_path / "runs")
    (folder / "rig_failure.txt").write_text("RIG FAILED: no rest after 8 s\n")
    pool = LocalPool(tmp_path / "runs", workers=1, progress=False)
    assert pool.run([job], raise_on_error=False) == [None]
    assert pool.simulated_count == 0 and fake_yade() == 0
    assert "no rest after 8 s" in pool.last_errors[0] and f"delete {folder}" in pool.last_errors[0]


def test_batch_table_refuses_paths_it_cannot_carry(tmp_path):
    with pytest.raises(ConfigError, match="cannot carry a path with ' '"):
        write_batch_table(tmp_path / "t.table", [("a", tmp_path / "my runs" / "job.json")])
    job = resolve_job("fill", "M2", seed=1)
    with pytest.raises(ConfigError, match=r"^--out: .*run@s: a yade-batch table cannot carry"):
        prepare_batch_table([job], tmp_path / "run@s", tmp_path / "t.table", 2)
    assert not (tmp_path / "t.table").exists() and not (tmp_path / "run@s").exists()


def test_batch_table_leaves_out_complete_jobs(tmp_path, fake_yade, capsys):
    runs, table = tmp_path / "runs", tmp_path / "t.table"
    LocalPool(runs, workers=1, progress=False).run([resolve_job("fill", "M2", seed=1)])
    args = ["batch-table", "fill", "--material", "M2", "--seeds", "2", "--out", str(runs), "--table", str(table)]
    assert main(args) == 0
    assert "1 job(s)" in capsys.readouterr().out
    lines = table.read_text().splitlines()
    assert len(lines) == 2 and lines[1].startswith("fill-M2-s2-")
    assert main(args[:5] + ["1"] + args[6:]) == 0                     # --seeds 1: all complete
    assert "nothing to run: 1 job(s) complete" in capsys.readouterr().out


FAKE_BATCH = """#!/bin/sh
case "$FAKE_BATCH_MODE" in
  silent) sleep 60 ;;
  dies) echo "Traceback: something broke"; exit 1 ;;
esac
"""


@pytest.mark.parametrize("mode, why", [("silent", "yade-batch reported nothing for 11 s and was stopped"),
                                       ("dies", "yade-batch ended (exit code 1) without a status for this line")])
def test_yade_batch_that_hangs_or_dies_is_reported_per_job(tmp_path, fake_yade, monkeypatch, mode, why):
    exe = tmp_path / "fake-yade-batch"
    exe.write_text(FAKE_BATCH)
    exe.chmod(exe.stat().st_mode | stat.S_IEXEC)
    monkeypatch.setenv("PYCAL_YADE_BATCH", str(exe))
    monkeypatch.setenv("FAKE_BATCH_MODE", mode)
    ex = YadeBatch(tmp_path / "runs", workers=2, timeout_s=1.0, progress=False)
    ex.patience_margin_s = 1.0
    t0 = time.time()
    assert ex.run([resolve_job("fill", "M2", seed=s) for s in (1, 2)], raise_on_error=False) == [None, None]
    assert time.time() - t0 < 20
    assert len(ex.last_errors) == 2 and all(why in e for e in ex.last_errors), ex.last_errors
    assert all(e.endswith(".failed/yade.log") for e in ex.last_errors)
    assert [p.name for p in (tmp_path / "runs" / "fill").iterdir() if p.name.startswith(".")] == []


def test_dask_failure_comes_back_with_its_log_and_a_refusal_is_kept(tmp_path, fake_yade, monkeypatch):
    jobs = [resolve_job("fill", "M2", seed=s) for s in (1, 2)]
    monkeypatch.setenv("FAKE_MODE", "fail")
    with DaskExecutor(tmp_path / "runs", workers=2, progress=False) as ex:
        assert ex.run(jobs[:1], raise_on_error=False) == [None]
        failed = tmp_path / "runs" / "fill" / f"{jobs[0]['job_id']}.failed"
        assert ex.last_errors[0].startswith(f"{jobs[0]['job_id']}: no result (exit code 3: RIG FAILED: blow-up: "
                                            f"particle 7 left the rig domain); log: {failed / 'yade.log'}")
        assert ex.simulated_count == 1
    monkeypatch.setenv("FAKE_MODE", "refuse")             # new workers: they take the environment when they start
    with DaskExecutor(tmp_path / "runs", workers=2, progress=False) as ex:
        assert ex.run(jobs[1:], raise_on_error=False) == [None]
        assert ex.run(jobs[1:], raise_on_error=False) == [None]
        assert "kept from an earlier run" in ex.last_errors[0]
        assert ex.simulated_count == 1 and fake_yade() == 2


def _closed_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def test_unreachable_scheduler_is_one_line_exit_2_nothing_written(tmp_path, capsys):
    address = f"tcp://127.0.0.1:{_closed_port()}"
    rc = main(["run", "fill", "--material", "M2", "--executor", "dask", "--scheduler", address,
               "--out", str(tmp_path / "runs")])
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert rc == 2 and captured.out == "" and err.count("\n") == 0
    assert err.startswith(f"error: --scheduler: {address}: no Dask scheduler answers there within 10 s")
    assert not (tmp_path / "runs").exists()


def test_scheduler_address_forms():
    assert scheduler_address("node01:8786") == "tcp://node01:8786"
    assert scheduler_address("tcp://10.1.2.3:8786") == "tcp://10.1.2.3:8786"
    for bad in ("node01", "http://node01:8786", "tcp://node01:99999", "tcp://node 1:8786"):
        with pytest.raises(ConfigError, match="not a Dask scheduler address"):
            scheduler_address(bad)


def test_scheduler_needs_the_dask_executor(tmp_path, capsys):
    rc = main(["run", "fill", "--material", "M2", "--scheduler", "tcp://127.0.0.1:8786", "--out", str(tmp_path)])
    assert rc == 2 and "a scheduler address needs --executor dask (not local)" in capsys.readouterr().err


def test_a_relative_runs_folder_works(tmp_path, fake_yade, monkeypatch):
    """`pycal run ... --out runs-here` (a path relative to where the user stands): YADE runs
    inside the job's folder, so the job file must be given to it by an absolute path
    (found by the default sweep: 'job file .../.tmp-.../bench/out/...: cannot read it')."""
    monkeypatch.chdir(tmp_path)
    job = resolve_job("fill", "M2", seed=1)
    (res,) = LocalPool(runs_dir="runs-here", workers=1, progress=False).run([job])
    assert res["bulk_density_kg_m3"] == 1600.0
    assert (tmp_path / "runs-here" / "fill" / job["job_id"] / "result.json").is_file()

