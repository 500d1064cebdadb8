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
import sys
import time
import traceback

_T0 = time.time()
_STARTED = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


from pycal.contact_rules import law_of_job
from pycal.rig_contract import (RESULT_FILE, RIG_FAILURE_FILE, EXIT_RIG_FAILURE, EXIT_ERROR, EXIT_OK,
                                BATCH_SEEDS_KEY)

from . import job_folder as job_folder_state


class RigFailure(Exception):
    """The rig cannot give a valid result (blow-up, escape, no rest...)."""


class NoRestUnderLoad(RigFailure):
    """A load step's stress is not held with the bulk at rest in the allowed time. In a
    confined cell that is a failure; a free pile (UCS) that cannot stand still under a
    load has yielded, and the UCS rig ends its curve there."""


class OverlapLimitExceeded(RigFailure):
    """A contact overlaps more than numerics.max_overlap_fraction x radius: the contact
    law is outside its range (or particles pass through each other). Rigs that can stop
    early with a valid partial result (UCS loading) catch this one."""


class JobFileError(Exception):
    """The job file cannot be found or read (a usage error, not a rig failure)."""


USAGE = "usage: yade -j1 -x -n yade_scripts/<rig>.py path/to/job.json (or a yade-batch table line with a jobFile column)"


def job_path_from_argv():
    """The job file: from yade-batch's table line (column `jobFile`) when YADE runs a
    table line (YADE_BATCH is set), else the first script argument."""
    batch_line = os.environ.get("YADE_BATCH", "")
    if batch_line:
        from yade import utils
        try:
            utils.readParamsFromTable(jobFile="", noTableOk=True)
        except Exception as exc:       # YADE raises NameError, SyntaxError, RuntimeError, OSError...
            raise JobFileError(f"yade-batch table line {batch_line}: cannot read it ({type(exc).__name__}: {exc}); "
                               f"the table has the columns description and jobFile, jobFile a quoted path "
                               f"such as '/abs/runs/fill/<job_id>/job.json'") from None
        from yade.params import table
        path = getattr(table, "jobFile", "")
        if not isinstance(path, str) or not path:
            raise JobFileError(f"yade-batch table line {batch_line}: no jobFile column (or an empty one): "
                               f"each line names its job file ('pycal batch-table' writes such tables)")
        return path
    args = [a for a in sys.argv[1:] if not a.startswith("-")]
    if not args:
        raise JobFileError(USAGE)
    return args[0]


def load_job():
    """(job dict, output folder)."""
    path = os.path.abspath(job_path_from_argv())
    try:
        with open(path) as f:
            job = json.load(f)
    except OSError as exc:
        raise JobFileError(f"job file {path}: cannot read it ({exc.strerror})") from None
    except ValueError as exc:
        raise JobFileError(f"job file {path}: not valid JSON ({exc})") from None
    if not isinstance(job, dict):
        raise JobFileError(f"job file {path}: not a job (a JSON object is expected)")
    job_folder_state.set_folder(os.path.dirname(path))
    return job, job_folder_state.get()


def job_folder():
    """The folder of the job being run (the current directory if no job file was loaded:
    test scenes)."""
    return job_folder_state.get()


def provenance():
    """YADE version, git commit, threads, host and times of this run: wall and CPU time
    (s) of the process, and CPU time and time steps per phase (demlib.phase_clock;
    steps_count is O.iter of the last scene, a fresh-fill rig's earlier scenes are in the
    phases)."""
    try:
        import yade.config
        yade_version = yade.config.version
    except Exception:
        yade_version = "unknown"
    try:
        from yade import O
        threads, simulated_time, steps = O.numThreads, O.time, O.iter
        from .phase_clock import CLOCK
        phases = CLOCK.report()
    except ImportError:                 # outside YADE (unit tests of the writers)
        threads = simulated_time = steps = phases = None
    from pycal.gitinfo import git_commit, git_dirty
    commit, dirty = git_commit(), git_dirty()
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
        "cpu_time_s": round(time.process_time(), 3),
        "phase_cpu": phases,
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
    """result.json = measurements + the contact law that made them + job + provenance. Call once, last.
    A batch job (seeds, demlib.replicas): `seeds` instead of `seed`, the measurements hold `replicas`."""
    result = dict(measurements)
    seed = {BATCH_SEEDS_KEY: job[BATCH_SEEDS_KEY]} if BATCH_SEEDS_KEY in job else {"seed": job["seed"]}
    result.update({"job_id": job.get("job_id"), "rig": job["rig"], "material": job["material"], **seed,
                   "contact_model": law_of_job(job), "job": job, "provenance": provenance()})
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
    except JobFileError as exc:
        print(f"RIG FAILED: {exc}", flush=True)
        os._exit(EXIT_ERROR)
    try:
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
