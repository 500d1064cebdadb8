"""One YADE process for one job: `yade -j1 -x -n yade_scripts/<rig>.py job.json`."""
import math
import os
import shutil
import signal
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


# A job's limit is in CPU seconds (RLIMIT_CPU through util-linux's prlimit): a run starved
# of its core on an overloaded machine is slow, not broken. The wall clock only stops a
# run that has not used its CPU time in this many times its limit (a hung process).
WALL_LIMIT_FACTOR = 10.0
CPU_LIMIT_EXIT_CODES = (-signal.SIGXCPU, 128 + signal.SIGXCPU)   # SIGXCPU as Popen / a shell see it


def cpu_limited(cmd, cpu_limit_s):
    """cmd under a CPU-time limit of cpu_limit_s (s): SIGXCPU at the limit, SIGKILL 5 s of
    CPU later; unchanged where prlimit is missing (the wall limit still holds)."""
    prlimit = shutil.which("prlimit")
    if prlimit is None:
        return list(cmd)
    soft = max(1, math.ceil(cpu_limit_s))
    return [prlimit, f"--cpu={soft}:{soft + 5}"] + list(cmd)


def cpu_limit_message(cpu_limit_s):
    return (f"CPU time limit of {cpu_limit_s:g} s reached (--cpu-limit-s; the run itself is not known to "
            "be broken: a stiffer material or a longer procedure needs more)")


def wall_limit_message(cpu_limit_s):
    return (f"no result after {WALL_LIMIT_FACTOR * cpu_limit_s:g} s of wall time ({WALL_LIMIT_FACTOR:g} x "
            f"the CPU limit): the process hung or the machine is far overloaded")


def run_job(job, runs_dir=DEFAULT_RUNS_DIR, timeout_s=3600):
    """Run one job (or return its cached result). timeout_s: its CPU-time limit (s; the
    wall clock allows WALL_LIMIT_FACTOR x that). Raises RunError on failure."""
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
            proc = subprocess.run(die_with_parent(cpu_limited(yade_command(script, tmp / JOB_FILE), timeout_s)),
                                  cwd=tmp, env=yade_env(), stdout=log, stderr=subprocess.STDOUT,
                                  stdin=subprocess.DEVNULL, timeout=WALL_LIMIT_FACTOR * timeout_s)
            rc = proc.returncode
        except subprocess.TimeoutExpired:
            rc = "timeout"
    if rc != 0:
        (tmp / RESULT_FILE).unlink(missing_ok=True)
        if rc == "timeout":
            tail = wall_limit_message(timeout_s)
        elif rc in CPU_LIMIT_EXIT_CODES:
            tail = cpu_limit_message(timeout_s)
        else:
            tail = f"exit code {rc}: {log_tail(tmp / LOG_FILE)}"
        return finish(tmp, final, tail)
    return finish(tmp, final, log_tail(tmp / LOG_FILE))
