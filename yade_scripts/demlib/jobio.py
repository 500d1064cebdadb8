"""Job input and result output for rig scripts.

A rig script is run as `yade -j1 -x -n yade_scripts/<rig>.py path/to/job.json`
(or from a yade-batch table with a `jobFile` column). It writes every output into
the folder of the job file; result.json is written last, atomically, and only when
the run succeeded, so a folder with result.json is a complete run.
"""
import csv
import datetime
import json
import os
import platform
import subprocess
import sys
import time
import traceback

_T0 = time.time()
_STARTED = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
_JOB_DIR = None       # folder of the job file being run (load_job), where every output goes


from pycal.contact_rules import law_of_job
from pycal.rig_contract import RESULT_FILE, RIG_FAILURE_FILE, EXIT_RIG_FAILURE, EXIT_ERROR, EXIT_OK


class RigFailure(Exception):
    """The rig cannot give a valid result (blow-up, escape, no rest...)."""


class OverlapLimitExceeded(RigFailure):
    """A contact overlaps more than numerics.max_overlap_fraction x radius: the contact
    law is outside its range (or particles pass through each other). Rigs that can stop
    early with a valid partial result (UCS loading) catch this one."""


def job_path_from_argv():
    """The job file: yade-batch's table column `jobFile`, else the first script argument."""
    try:
        from yade import utils
        utils.readParamsFromTable(jobFile="", noTableOk=True)
        from yade.params import table
        if getattr(table, "jobFile", ""):
            return table.jobFile
    except Exception:
        pass
    args = [a for a in sys.argv[1:] if not a.startswith("-")]
    if not args:
        raise SystemExit("usage: yade -j1 -x -n yade_scripts/<rig>.py path/to/job.json")
    return args[0]


def load_job():
    """(job dict, output folder)."""
    global _JOB_DIR
    path = os.path.abspath(job_path_from_argv())
    with open(path) as f:
        job = json.load(f)
    _JOB_DIR = os.path.dirname(path)
    return job, _JOB_DIR


def job_folder():
    """The folder of the job being run (the current directory if no job file was loaded:
    test scenes)."""
    return _JOB_DIR or os.getcwd()


def _git(*args):
    from pycal import REPO_ROOT
    repo = str(REPO_ROOT)
    try:
        return subprocess.run(["git", "-C", repo] + list(args), capture_output=True, text=True,
                              timeout=10).stdout.strip()
    except Exception:
        return ""


def provenance():
    """YADE version, git commit, threads, host and times of this run."""
    try:
        import yade.config
        yade_version = yade.config.version
    except Exception:
        yade_version = "unknown"
    try:
        from yade import O
        threads, simulated_time, steps = O.numThreads, O.time, O.iter
    except Exception:
        threads = simulated_time = steps = None
    commit = _git("rev-parse", "HEAD") or "unknown"
    dirty = bool(_git("status", "--porcelain", "--untracked-files=no"))
    return {
        "yade_version": yade_version,
        "git_commit": commit,
        "git_dirty": dirty,
        "threads": threads,
        "host": platform.node(),
        "python": platform.python_version(),
        "started_utc": _STARTED,
        "finished_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "wall_time_s": round(time.time() - _T0, 3),
        "simulated_time_s": simulated_time,
        "steps_count": steps,
    }


def _atomic_write(path, text):
    tmp = path + ".part"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def write_csv(out_dir, name, columns, rows):
    """CSV with a header of column names that carry their units (e.g. r_m, z_m)."""
    path = os.path.join(out_dir, name)
    tmp = path + ".part"
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for row in rows:
            w.writerow(row)
    os.replace(tmp, path)
    return path


def write_result(out_dir, job, measurements):
    """result.json = measurements + the contact law that made them + job + provenance. Call once, last."""
    result = dict(measurements)
    result.update({"job_id": job.get("job_id"), "rig": job["rig"], "material": job["material"],
                   "seed": job["seed"], "contact_model": law_of_job(job), "job": job, "provenance": provenance()})
    text = json.dumps(result, indent=1, sort_keys=True, allow_nan=False)
    _atomic_write(os.path.join(out_dir, RESULT_FILE), text)
    print("RESULT written:", os.path.join(out_dir, RESULT_FILE), flush=True)
    return result


def run_rig(main):
    """Run main(job, out_dir) -> measurements dict; on any failure print one clear line
    'RIG FAILED: ...', write no result.json and exit non-zero."""
    out_dir = None
    try:
        job, out_dir = load_job()
        measurements = main(job, out_dir)
        from . import vtk_output
        snapshots = vtk_output.finish()
        if snapshots is not None:
            measurements["vtk_snapshots_count"] = snapshots
        write_result(out_dir, job, measurements)
    except RigFailure as exc:
        print(f"RIG FAILED: {exc}", flush=True)
        if out_dir:
            # the physics' verdict on this job (same job, same seed: same failure); the
            # runner keeps it so that the job is not simulated again
            _atomic_write(os.path.join(out_dir, RIG_FAILURE_FILE), f"RIG FAILED: {exc}\n")
        sys.stdout.flush()
        os._exit(EXIT_RIG_FAILURE)
    except Exception as exc:
        traceback.print_exc()
        print(f"RIG FAILED: {type(exc).__name__}: {exc}", flush=True)
        os._exit(EXIT_ERROR)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(EXIT_OK)
