"""Executors with real YADE runs: the local pool, a real Dask scheduler with workers on
localhost, and real yade-batch (both --executor yade-batch and a table run by hand)
give the same result.json measurements for the same jobs; failures, timeouts and a
killed worker are reported per job.

The reference is the local pool on 2 short fill jobs (M2, seeds 1-2, ~3 s each).
"""
import copy
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from pycal import SCRIPT_DIR
from pycal.cli import main
from pycal.executors.dask_cluster import DaskExecutor
from pycal.executors.jobdirs import job_dir
from pycal.executors.local import LocalPool
from pycal.executors.yade_batch import YadeBatch, write_batch_table
from pycal.executors.yade_process import yade_env
from pycal.jobs import job_id, resolve_job
from scene_runner import LAB_SIZE

pytestmark = [pytest.mark.yade,
              pytest.mark.skipif(shutil.which("yade") is None, reason="yade is not installed")]

SEEDS = (1, 2)


def fill_jobs():
    return [resolve_job("fill", "M2", LAB_SIZE, seed=s) for s in SEEDS]


def measurements(result):
    """Everything a run measured (provenance: host, times, is left out)."""
    return {k: v for k, v in result.items() if k != "provenance"}


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The local pool's results of the 2 fill jobs."""
    pool = LocalPool(tmp_path_factory.mktemp("local") / "runs", workers=2, progress=False)
    results = pool.run(fill_jobs())
    assert pool.simulated_count == 2
    return [measurements(r) for r in results]


# --- Dask: a real scheduler and single-threaded workers on localhost ----------------------

class Cluster:
    """`dask scheduler` + `dask worker` processes on 127.0.0.1, stopped at the end."""

    def __init__(self, folder, n_workers):
        self.folder, self.procs, self.workers, self.n_workers = Path(folder), [], [], n_workers
        self.file = self.folder / "scheduler.json"
        self.env = dict(yade_env(), PYTHONUNBUFFERED="1")
        self.start(port=0)

    def start(self, port):
        """The scheduler (on `port`, 0: any) and n single-threaded workers."""
        self.file.unlink(missing_ok=True)
        self.scheduler = self._start(["scheduler", "--host", "127.0.0.1", "--port", str(port),
                                      "--dashboard-address", "127.0.0.1:0", "--scheduler-file", str(self.file)],
                                     "scheduler.log")
        deadline = time.time() + 60
        while not self.file.is_file() and time.time() < deadline:
            time.sleep(0.2)
        self.address = json.loads(self.file.read_text())["address"]
        registered = self.log_count("Registered to")
        self.workers = []
        for i in range(self.n_workers):  # no nanny: a killed worker stays dead, its job must go elsewhere
            self.workers.append(self._start(["worker", self.address, "--nthreads", "1", "--no-nanny",
                                             "--name", f"w{i}"], f"worker{i}.log"))
        deadline = time.time() + 60
        while time.time() < deadline and self.log_count("Registered to") < registered + self.n_workers:
            time.sleep(0.2)
        assert self.log_count("Registered to") == registered + self.n_workers, "the workers did not register"

    def kill_all(self):
        """The whole cluster dies at once (scheduler first)."""
        for proc in [self.scheduler] + self.workers:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()

    def _start(self, args, log):
        out = open(self.folder / log, "a")
        proc = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_" + args[0]] + args[1:],
                                env=self.env, stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                cwd=self.folder, start_new_session=True)
        self.procs.append(proc)
        return proc

    def log_count(self, text):
        logs = [self.folder / f"worker{i}.log" for i in range(self.n_workers)]
        return sum(p.read_text().count(text) for p in logs if p.is_file())

    def stop(self):
        for proc in reversed(self.procs):
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


@pytest.fixture
def cluster(tmp_path):
    c = Cluster(tmp_path, n_workers=2)
    yield c
    c.stop()


def test_dask_cluster_gives_the_local_pool_numbers(tmp_path, cluster, reference):
    with DaskExecutor(tmp_path / "runs", scheduler=cluster.address, progress=False) as ex:
        results = ex.run(fill_jobs())
        assert ex.simulated_count == 2
        assert [measurements(r) for r in results] == reference          # bit for bit
        again = ex.run(fill_jobs())                                       # complete: from the cache
        assert ex.simulated_count == 2 and [measurements(r) for r in again] == reference


def _processes_in(folder):
    """Processes whose working folder is `folder` (a YADE run of the local pool or a worker)."""
    found = []
    for p in Path("/proc").iterdir():
        try:
            if p.name.isdigit() and os.readlink(p / "cwd") == str(folder):
                found.append(int(p.name))
        except OSError:
            continue
    return found


def test_dask_job_of_a_killed_worker_runs_elsewhere(tmp_path, cluster, reference):
    runs = tmp_path / "runs"
    ex = DaskExecutor(runs, scheduler=cluster.address, progress=False)
    out = {}
    runner = threading.Thread(target=lambda: out.setdefault("results", ex.run(fill_jobs(), raise_on_error=False)))
    runner.start()
    worker_pids = {w.pid for w in cluster.workers}
    victim, deadline = None, time.time() + 120
    while victim is None and time.time() < deadline:       # a job folder in progress names its worker's pid
        for tmp in (runs / "fill").glob(".fill-*.tmp-*") if (runs / "fill").is_dir() else []:
            pid = int(tmp.name.rsplit("-", 1)[1])
            if pid in worker_pids and (tmp / "yade.log").is_file() and _processes_in(tmp):
                victim = (pid, tmp)
        time.sleep(0.1)
    assert victim, "no job started on a worker"
    os.kill(victim[0], signal.SIGKILL)                     # mid-job: its YADE has started
    time.sleep(1.0)
    assert _processes_in(victim[1]) == [], "the YADE run of the killed worker kept running"
    runner.join(timeout=300)
    ex.close()
    assert not runner.is_alive()
    assert ex.last_errors == []
    assert [measurements(r) for r in out["results"]] == reference
    assert victim[1].exists()                              # the dead worker's folder: stale ...
    with LocalPool(runs, progress=False) as pool:          # ... and removed at the next start
        assert [measurements(r) for r in pool.run(fill_jobs())] == reference
        assert pool.simulated_count == 0
    assert not victim[1].exists() and list((runs / "fill").glob(".*tmp*")) == []


def test_dask_study_resumes_when_its_scheduler_restarts(tmp_path, cluster, reference):
    """Scheduler and workers die mid-job and come back on the same address (as a cluster
    job restarts them): the executor waits, submits what is not complete, and gets it all."""
    runs = tmp_path / "runs"
    ex = DaskExecutor(runs, scheduler=cluster.address, progress=False, reconnect_s=120)
    out = {}
    runner = threading.Thread(target=lambda: out.setdefault("results", ex.run(fill_jobs(), raise_on_error=False)))
    runner.start()
    deadline = time.time() + 120
    while time.time() < deadline and not any((p / "yade.log").is_file() for p in (runs / "fill").glob(".fill-*.tmp-*")):
        time.sleep(0.1)
    port = int(cluster.address.rsplit(":", 1)[1])
    cluster.kill_all()
    time.sleep(2.0)
    cluster.start(port=port)
    runner.join(timeout=300)
    ex.close()
    assert not runner.is_alive() and ex.last_errors == [] and ex.reconnect_count == 1
    assert [measurements(r) for r in out["results"]] == reference


def test_local_dask_cluster_gives_the_local_pool_numbers(tmp_path, reference):
    with DaskExecutor(tmp_path / "runs", workers=2, progress=False) as ex:
        assert [measurements(r) for r in ex.run(fill_jobs())] == reference
        assert ex.simulated_count == 2


# --- yade-batch ----------------------------------------------------------------------------

def test_yade_batch_executor_gives_the_local_pool_numbers(tmp_path, reference):
    ex = YadeBatch(tmp_path / "runs", workers=2, progress=False)
    assert [measurements(r) for r in ex.run(fill_jobs())] == reference
    assert ex.simulated_count == 2
    assert list((tmp_path / "runs" / "fill").glob(".*")) == []              # no temporary left
    assert "RESULT written" in (job_dir(fill_jobs()[0], tmp_path / "runs") / "yade.log").read_text()


def _broken(job):
    """A job whose rig crashes at once (its material is missing from the job)."""
    bad = copy.deepcopy(job)
    bad["materials"] = {}
    bad["job_id"] = job_id(bad)
    return bad


def test_yade_batch_reports_a_failed_line_with_its_log(tmp_path, reference):
    good, bad = fill_jobs()[0], _broken(fill_jobs()[1])
    ex = YadeBatch(tmp_path / "runs", workers=2, progress=False)
    results = ex.run([bad, good], raise_on_error=False)
    assert results[0] is None and measurements(results[1]) == reference[0]
    assert len(ex.last_errors) == 1
    failed = tmp_path / "runs" / "fill" / f"{bad['job_id']}.failed"
    msg = ex.last_errors[0]
    assert msg.startswith(f"{bad['job_id']}: no result (exit code 4: ") and msg.endswith(f"; log: {failed / 'yade.log'}")
    tail = msg[len(f"{bad['job_id']}: no result (exit code 4: "):-len(f"); log: {failed / 'yade.log'}")]
    rig_line = tail.split(" | ")[-1]                                       # the rig's own line, from its log
    assert rig_line.startswith("RIG FAILED: ")
    assert rig_line in (failed / "yade.log").read_text()


def test_yade_batch_cpu_limit_is_reported_per_job(tmp_path):
    """A fill (several s of CPU) under a 1 s CPU limit: stopped by its CPU limit."""
    ex = YadeBatch(tmp_path / "runs", workers=2, timeout_s=1.0, progress=False)
    t0 = time.time()
    assert ex.run(fill_jobs()[:1], raise_on_error=False) == [None]
    assert time.time() - t0 < 30
    assert re.fullmatch(r"fill-M2-s1-\w+: no result \(CPU time limit of 1 s reached .*\); log: .*\.failed/yade\.log",
                        ex.last_errors[0]), ex.last_errors[0]


def test_batch_table_run_by_hand_then_pycal_run_is_all_cached(tmp_path, capsys, reference):
    runs, table = tmp_path / "runs", tmp_path / "fill.table"
    args = ["fill", "--material", "M2", "--seeds", "2", "--out", str(runs), "--set", "rig.geometry.scale=1"]
    assert main(["batch-table"] + args + ["--table", str(table), "--workers", "2"]) == 0
    printed = capsys.readouterr().out
    line = next(l.strip() for l in printed.splitlines() if "yade-batch " in l)
    assert line.startswith(f"PYTHONPATH={SCRIPT_DIR.parent} yade-batch -j 2 ")
    # the user runs the printed command, from another folder
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    proc = subprocess.run(line, shell=True, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-2000:]
    assert proc.stdout.count(" done ") == 2, proc.stdout[-2000:]
    assert main(["run"] + args) == 0
    out = capsys.readouterr().out
    assert "2 job(s): 2 cached, 0 simulated" in out
    results = [json.loads((job_dir(j, runs) / "result.json").read_text()) for j in fill_jobs()]
    assert [measurements(r) for r in results] == reference
    # every line's log is in its job folder
    assert all("RESULT written" in (job_dir(j, runs) / "yade.log").read_text() for j in fill_jobs())


def test_every_rig_script_reads_its_job_file_from_a_table_line(tmp_path):
    """One real yade-batch run over every rig script (column !SCRIPT): each line's job file
    is not a job, so each script must say so naming the file it took from its line; a
    line with an empty jobFile is a clear error too."""
    scripts = sorted(p.name for p in SCRIPT_DIR.glob("*.py") if p.name != "__init__.py")
    assert len(scripts) >= 9
    rows = []
    for name in scripts:
        folder = tmp_path / name[:-3]
        folder.mkdir()
        (folder / "job.json").write_text("[]")
        rows.append(f"{name[:-3]} {SCRIPT_DIR / name} '{folder / 'job.json'}'")
    rows.append(f"empty {SCRIPT_DIR / 'fill.py'} ''")
    table = tmp_path / "scripts.table"
    table.write_text("description !SCRIPT jobFile\n" + "\n".join(rows) + "\n")
    proc = subprocess.run(["yade-batch", "-j", "2", "--job-threads", "1", "--disable-pynotify",
                           "--log", str(tmp_path / "@.log"), str(table)], cwd=tmp_path, env=yade_env(),
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-2000:]
    for name in scripts:
        log = (tmp_path / f"{name[:-3]}.log").read_text()
        assert f"RIG FAILED: job file {tmp_path / name[:-3] / 'job.json'}: not a job" in log, (name, log[-1500:])
    log = (tmp_path / "empty.log").read_text()
    assert "RIG FAILED: yade-batch table line" in log and "no jobFile column (or an empty one)" in log, log[-1500:]


def test_a_table_without_job_file_column_is_a_clear_error(tmp_path):
    table = tmp_path / "t.table"
    table.write_text("description seed\nfill 1\n")
    proc = subprocess.run(["yade", "-j1", "-x", "-n", str(SCRIPT_DIR / "fill.py")], cwd=tmp_path,
                          env=dict(yade_env(), YADE_BATCH=f"{table}:2"), capture_output=True, text=True, timeout=120)
    assert proc.returncode == 4
    assert f"RIG FAILED: yade-batch table line {table}:2: cannot read it (NameError" in proc.stdout, proc.stdout[-1500:]
