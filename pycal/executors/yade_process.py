"""One YADE process for one job: `yade -j1 -x -n yade_scripts/<rig>.py job.json`."""
import os
import shutil
import subprocess
from pathlib import Path

from .. import REPO_ROOT, SCRIPT_DIR
from ..errors import RunError
from ..rig_contract import JOB_FILE, LOG_FILE, RESULT_FILE
from .jobdirs import DEFAULT_RUNS_DIR, cached_failure, cached_result, finish, log_tail, prepare_temp


def yade_executable():
    """The YADE program: $PYCAL_YADE, else `yade` on PATH (read at each run, so a worker's
    own environment decides)."""
    return os.environ.get("PYCAL_YADE", "yade")


def yade_env():
    """Environment of a YADE run: one thread (bit-reproducible) and the repo root on
    PYTHONPATH (rig scripts import `yade_scripts.demlib` and `pycal` as packages)."""
    path = os.pathsep.join([str(REPO_ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])
    return dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=path)


def yade_command(script, job_file):
    """The exact command line of one run (single-threaded for bit-reproducibility)."""
    return [yade_executable(), "-j1", "-x", "-n", str(script), str(job_file)]


def die_with_parent(cmd):
    """cmd prefixed so that the child is killed when the process that started it dies
    (a killed pool or Dask worker leaves no YADE running on its own); unchanged where
    util-linux's setpriv is missing."""
    setpriv = shutil.which("setpriv")
    return [setpriv, "--pdeathsig", "KILL", "--"] + list(cmd) if setpriv else list(cmd)


def run_job(job, runs_dir=DEFAULT_RUNS_DIR, timeout_s=3600):
    """Run one job (or return its cached result). Raises RunError on failure."""
    runs_dir = Path(runs_dir).resolve()     # YADE runs in the job's folder: a relative path would not hold there
    cached = cached_result(job, runs_dir)
    if cached is not None:
        return cached
    refused = cached_failure(job, runs_dir)
    if refused:
        raise RunError(refused)
    script = SCRIPT_DIR / job["script"]
    if not script.is_file():
        raise RunError(f"{job['rig']}: rig script {script} does not exist")
    exe = yade_executable()
    if shutil.which(exe) is None:
        raise RunError(f"'{exe}' not found: install YADE (./run.sh installs it)")
    tmp, final = prepare_temp(job, runs_dir)
    with open(tmp / LOG_FILE, "w") as log:
        try:
            proc = subprocess.run(die_with_parent(yade_command(script, tmp / JOB_FILE)), cwd=tmp, env=yade_env(),
                                  stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                  timeout=timeout_s)
            rc = proc.returncode
        except subprocess.TimeoutExpired:
            rc = "timeout"
    if rc != 0:
        (tmp / RESULT_FILE).unlink(missing_ok=True)
        tail = f"timeout after {timeout_s:g} s" if rc == "timeout" else f"exit code {rc}: {log_tail(tmp / LOG_FILE)}"
        return finish(tmp, final, tail)
    return finish(tmp, final, log_tail(tmp / LOG_FILE))
