"""Run jobs: one YADE process per job (`yade -j1 -x -n yade_scripts/<rig>.py job.json`).

Layout under a runs directory:
    runs/<rig>/<job_id>/            complete: job.json, result.json, yade.log, CSV/PNG
    runs/<rig>/.<job_id>.tmp-<pid>/ in progress (renamed when complete)
    runs/<rig>/<job_id>.failed/     last failed attempt, kept for its log (never read as a result)

A job whose folder has result.json is never run again. Neither is a job the rig itself
refused (RigFailure: no rest, blow-up; <job_id>.failed/rig_failure.txt): the same job
and seed fail the same way, so a resumed study does not pay for it twice. A crash, a
timeout or a kill is not kept as a verdict: that job runs again. Executors share one
interface, `run(jobs) -> list of results`, so a cluster executor can be added
without touching the calibration code.
"""
import json
import os
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path

from . import REPO_ROOT, SCRIPT_DIR
from .errors import RunError
from .rig_contract import JOB_FILE, LOG_FILE, RESULT_FILE, RIG_FAILURE_FILE

YADE = os.environ.get("PYCAL_YADE", "yade")
DEFAULT_RUNS_DIR = REPO_ROOT / "runs"


def job_dir(job, runs_dir):
    return Path(runs_dir) / job["rig"] / job["job_id"]


def cached_result(job, runs_dir):
    """The result of a complete job, or None."""
    path = job_dir(job, runs_dir) / RESULT_FILE
    if path.is_file():
        return json.loads(path.read_text())
    return None




def cached_failure(job, runs_dir):
    """The message of a job the rig refused before (RigFailure), or None."""
    failed = Path(str(job_dir(job, runs_dir)) + ".failed")
    path = failed / RIG_FAILURE_FILE
    if path.is_file():
        return (f"{job['job_id']}: no result ({path.read_text().strip()}; kept from an earlier run: "
                f"delete {failed} to run it again); log: {failed / LOG_FILE}")
    return None


def _write_json_atomic(path, data):
    tmp = Path(str(path) + ".part")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=True))
    os.replace(tmp, path)


def _prepare(job, runs_dir):
    final = job_dir(job, runs_dir)
    tmp = final.parent / f".{final.name}.tmp-{os.getpid()}"
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir(parents=True)
    _write_json_atomic(tmp / JOB_FILE, job)
    return tmp, final


def _finish(tmp, final, log_tail):
    """Move a run folder into place if it wrote result.json; else keep it as .failed."""
    if (tmp / RESULT_FILE).is_file():
        if final.exists():           # finished concurrently by another process: keep theirs
            shutil.rmtree(tmp)
        else:
            os.replace(tmp, final)
        return json.loads((final / RESULT_FILE).read_text())
    failed = final.parent / f"{final.name}.failed"
    if failed.exists():
        shutil.rmtree(failed)
    os.replace(tmp, failed)
    raise RunError(f"{final.name}: no result ({log_tail}); log: {failed / LOG_FILE}")


def _log_tail(log_path, n=3):
    try:
        lines = [l for l in Path(log_path).read_text(errors="replace").splitlines() if l.strip()]
    except OSError:
        return "no log"
    errors = [l for l in lines if "RIG FAILED" in l or "Error" in l]
    return " | ".join((errors or lines)[-n:])


def yade_env():
    """Environment of a YADE run: one thread (bit-reproducible) and the repo root on
    PYTHONPATH (rig scripts import `yade_scripts.demlib` and `pycal` as packages)."""
    path = os.pathsep.join([str(REPO_ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])
    return dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=path)


def yade_command(script, job_file):
    """The exact command line of one run (single-threaded for bit-reproducibility)."""
    return [YADE, "-j1", "-x", "-n", str(script), str(job_file)]


def run_job(job, runs_dir=DEFAULT_RUNS_DIR, timeout_s=3600):
    """Run one job (or return its cached result). Raises RunError on failure."""
    cached = cached_result(job, runs_dir)
    if cached is not None:
        return cached
    refused = cached_failure(job, runs_dir)
    if refused:
        raise RunError(refused)
    script = SCRIPT_DIR / job["script"]
    if not script.is_file():
        raise RunError(f"{job['rig']}: rig script {script} does not exist")
    tmp, final = _prepare(job, runs_dir)
    env = yade_env()
    with open(tmp / LOG_FILE, "w") as log:
        try:
            proc = subprocess.run(yade_command(script, tmp / JOB_FILE), cwd=tmp, env=env,
                                  stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                  timeout=timeout_s)
            rc = proc.returncode
        except subprocess.TimeoutExpired:
            rc = "timeout"
        except FileNotFoundError:
            shutil.rmtree(tmp)
            raise RunError(f"'{YADE}' not found: install YADE (./run.sh installs it)") from None
    if rc != 0:
        (tmp / RESULT_FILE).unlink(missing_ok=True)
        tail = f"timeout after {timeout_s} s" if rc == "timeout" else f"exit code {rc}: {_log_tail(tmp / LOG_FILE)}"
        return _finish(tmp, final, tail)
    return _finish(tmp, final, _log_tail(tmp / LOG_FILE))


class LocalPool:
    """Runs jobs as parallel `yade -j1` processes (workers = cores by default)."""

    def __init__(self, runs_dir=DEFAULT_RUNS_DIR, workers=None, timeout_s=3600, progress=True):
        self.runs_dir = Path(runs_dir)
        self.workers = workers or os.cpu_count() or 1
        self.timeout_s = timeout_s
        self.progress = progress
        self.simulated_count = 0     # jobs actually run by YADE (not from the cache), for the study's cost table
        self.last_errors = []        # messages of the jobs that failed in the last run()

    def run(self, jobs, raise_on_error=True):
        """Run jobs; returns results in the order of `jobs` (None for a failed job
        when raise_on_error is False)."""
        results = [None] * len(jobs)
        todo, errors = [], []
        for i, job in enumerate(jobs):
            cached = cached_result(job, self.runs_dir)
            refused = cached_failure(job, self.runs_dir) if cached is None else None
            if cached is not None:
                results[i] = cached
            elif refused:
                errors.append(refused)
            else:
                todo.append(i)
        t0, done = time.time(), 0
        self.simulated_count += len(todo)
        if self.progress and todo:
            _say(f"running {len(todo)} job(s) ({len(jobs) - len(todo)} cached) on {self.workers} worker(s)")
        with ThreadPoolExecutor(max_workers=self.workers) as pool:
            futures = {pool.submit(run_job, jobs[i], self.runs_dir, self.timeout_s): i for i in todo}
            for fut in as_completed(futures):
                i = futures[fut]
                done += 1
                try:
                    results[i] = fut.result()
                    status = "ok"
                except RunError as exc:
                    errors.append(str(exc))
                    status = f"FAILED: {exc}"
                if self.progress:
                    el = time.time() - t0
                    eta = el / done * (len(todo) - done)
                    _say(f"[{done}/{len(todo)}] {jobs[i]['job_id']} {status} "
                         f"(elapsed {el:.0f} s, remaining ~{eta:.0f} s)")
        self.last_errors = errors
        if errors and raise_on_error:
            raise RunError(f"{len(errors)} of {len(jobs)} job(s) failed; first: {errors[0]}")
        return results


class YadeBatch:
    """Runs jobs through a yade-batch table (same script, same job files, same results)."""

    def __init__(self, runs_dir=DEFAULT_RUNS_DIR, workers=None, timeout_s=3600, progress=True):
        self.runs_dir = Path(runs_dir)
        self.workers = workers or os.cpu_count() or 1
        self.timeout_s = timeout_s
        self.progress = progress
        self.simulated_count = 0     # jobs actually run by YADE (not from the cache), for the study's cost table
        self.last_errors = []        # messages of the jobs that failed in the last run()

    def run(self, jobs, raise_on_error=True):
        results = [cached_result(j, self.runs_dir) for j in jobs]
        refused = {i: cached_failure(jobs[i], self.runs_dir) for i, r in enumerate(results) if r is None}
        errors = [msg for msg in refused.values() if msg]
        todo = [i for i, msg in refused.items() if not msg]
        self.simulated_count += len(todo)
        by_script = {}
        for i in todo:
            by_script.setdefault(jobs[i]["script"], []).append(i)
        for script, idx in by_script.items():
            dirs = {i: _prepare(jobs[i], self.runs_dir) for i in idx}
            table = self.runs_dir / f".batch-{os.getpid()}-{Path(script).stem}.table"
            write_batch_table(table, [(jobs[i]["job_id"], dirs[i][0] / JOB_FILE) for i in idx])
            cmd = [YADE + "-batch", "-j", str(self.workers), "--job-threads", "1",
                   "--log", str(self.runs_dir / ".batch-logs" / "$.log"), "--disable-pynotify",
                   str(table), str(SCRIPT_DIR / script)]
            (self.runs_dir / ".batch-logs").mkdir(parents=True, exist_ok=True)
            if self.progress:
                _say(f"yade-batch: {len(idx)} job(s) of {script}")
            subprocess.run(cmd, cwd=self.runs_dir, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL,
                           timeout=self.timeout_s * max(1, len(idx)),
                           env=yade_env())
            for i in idx:
                tmp, final = dirs[i]
                blog = self.runs_dir / ".batch-logs" / f"{jobs[i]['job_id']}.log"
                if blog.is_file():
                    shutil.copy(blog, tmp / LOG_FILE)
                try:
                    results[i] = _finish(tmp, final, _log_tail(tmp / LOG_FILE))
                except RunError as exc:
                    errors.append(str(exc))
            table.unlink(missing_ok=True)
        self.last_errors = errors
        if errors and raise_on_error:
            raise RunError(f"{len(errors)} job(s) failed; first: {errors[0]}")
        return results


def write_batch_table(path, rows):
    """A yade-batch parameter table: columns description and jobFile."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = ["description jobFile"] + [f"{desc} {Path(f).resolve()}" for desc, f in rows]
    path.write_text("\n".join(lines) + "\n")


EXECUTORS = {"local": LocalPool, "yade-batch": YadeBatch}


def make_executor(name="local", **kw):
    if name not in EXECUTORS:
        raise RunError(f"unknown executor {name!r} (known: {', '.join(EXECUTORS)})")
    return EXECUTORS[name](**kw)


def _say(msg):
    print(msg, file=sys.stderr, flush=True)
