"""The runs folder: where a job's files live and when a job counts as done.

    runs/<rig>/<job_id>/                          a job folder: job.json, yade.log, CSV/PNG and,
                                                  once the run succeeded, result.json (written last)
    runs/<rig>/.<job_id>.tmp-<host>-<pid>/        a run in progress (renamed to <job_id>/ when complete)
    runs/<rig>/<job_id>.failed/                   last failed attempt, kept for its log (never a result)

A job folder with result.json is complete and never run again, if that result is the
job's own and whole (result_problem); a result that is not is moved to
runs/quarantine/<rig>/ with a warning and the job runs again. A job folder without it
(written by `pycal job --write` or `pycal batch-table`, then run by hand or by yade-batch)
is not a result: it is run again, unless the rig refused the job there (rig_failure.txt).
A rig refusal is the physics' verdict on the job (same job, same seed: same failure) and
is kept; a crash, a timeout or a kill is not. Temporary names carry the host and the pid
of the process that owns them, so the stale ones of dead processes can be removed
without touching those of a live concurrent process (on this host or another).
"""
import json
import os
import re
import shutil
import socket
import time
from pathlib import Path

from .. import REPO_ROOT
from ..errors import RunError
from ..rig_contract import JOB_FILE, LOG_FILE, RESULT_FILE, RIG_FAILURE_FILE

DEFAULT_RUNS_DIR = REPO_ROOT / "runs"
# A temporary of another host is removed when nothing in it changed for this long: no job
# runs that long without writing (the default timeout per job is 1 h).
STALE_REMOTE_S = 24 * 3600.0
_TEMP_RE = re.compile(r"^\..+\.tmp-(?:(?P<host>.+)-)?(?P<pid>\d+)$")


def host_name():
    """This machine's name as used in temporary names (no '/' in it)."""
    return socket.gethostname().replace("/", "_") or "localhost"


def temp_suffix():
    """'.tmp-<host>-<pid>': the end of every temporary name this process writes."""
    return f".tmp-{host_name()}-{os.getpid()}"


def job_dir(job, runs_dir):
    return Path(runs_dir) / job["rig"] / job["job_id"]


def failed_dir(job, runs_dir):
    return failed_dir_of(job_dir(job, runs_dir))


def failed_dir_of(final):
    return Path(str(final) + ".failed")


def result_problem(result, job):
    """Why a parsed result.json is not `job`'s whole result, or None: it must be a JSON
    object, name the job's id, hold the job itself (the same content hash) and every key
    the rig's descriptor requires (pycal/rigs/<rig>.py; a batch: its replicas)."""
    from .. import rigs
    from ..jobs import content_digest
    from ..rig_contract import BATCH_SEEDS_KEY
    if not isinstance(result, dict):
        return "not a JSON object"
    if result.get("job_id") != job["job_id"]:
        return f"it is the result of job {result.get('job_id')!r}, not of {job['job_id']}"
    if not isinstance(result.get("job"), dict) or content_digest(result["job"]) != content_digest(job):
        return "the job it holds is not this folder's job (content hash differs)"
    if BATCH_SEEDS_KEY in job:
        needed = ("rig", "provenance", "replicas")
    else:
        needed = rigs.get(job["rig"]).required_result_keys()
    missing = [k for k in needed if k not in result]
    if missing:
        return f"incomplete (no {', '.join(missing)})"
    return None


def quarantine(folder, runs_dir, why):
    """Move a job folder whose result cannot be trusted to runs/quarantine/<rig>/ (kept for
    a look, never read as a result) and print one warning line naming the file."""
    import sys
    stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
    dest = Path(runs_dir) / "quarantine" / folder.parent.name / f"{folder.name}-{stamp}-{os.getpid()}"
    dest.parent.mkdir(parents=True, exist_ok=True)
    os.replace(folder, dest)
    print(f"warning: {folder / RESULT_FILE}: {why}; moved to {dest}; the job runs again", file=sys.stderr,
          flush=True)
    return dest


def cached_result(job, runs_dir):
    """The result of a complete job, or None. A result.json that is not the job's whole
    result (result_problem: unreadable, another job's, incomplete) is quarantined and the
    job counts as not run."""
    folder = job_dir(job, runs_dir)
    path = folder / RESULT_FILE
    if not path.is_file():
        return None
    try:
        result = json.loads(path.read_text())
    except (ValueError, UnicodeDecodeError) as exc:
        why = f"not valid JSON ({exc})"
    else:
        why = result_problem(result, job)
        if why is None:
            return result
    quarantine(folder, runs_dir, why)
    return None


def job_file_is(folder, job):
    """True when folder/job.json holds exactly `job` (a job file by hand or a garbage one: False)."""
    from ..jobs import canonical_json
    try:
        return canonical_json(json.loads((Path(folder) / JOB_FILE).read_text())) == canonical_json(job)
    except (OSError, ValueError, UnicodeDecodeError, TypeError):
        return False


def cached_failure(job, runs_dir):
    """The message of a job the rig refused before (RigFailure), or None. Looks in the
    last failed attempt (<job_id>.failed/) and in a job folder run by hand or by yade-batch."""
    for folder in (failed_dir(job, runs_dir), job_dir(job, runs_dir)):
        path = folder / RIG_FAILURE_FILE
        if path.is_file() and not (folder / RESULT_FILE).is_file():
            return (f"{job['job_id']}: no result ({path.read_text().strip()}; kept from an earlier run: "
                    f"delete {folder} to run it again); log: {folder / LOG_FILE}")
    return None


def write_json_atomic(path, data):
    tmp = Path(str(path) + ".part")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=True))
    os.replace(tmp, path)


def prepare_temp(job, runs_dir):
    """A fresh temporary folder holding job.json: (temporary folder, final folder)."""
    final = job_dir(job, runs_dir)
    tmp = final.parent / f".{final.name}{temp_suffix()}"
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir(parents=True)
    write_json_atomic(tmp / JOB_FILE, job)
    return tmp, final


def create_job_folder(job, runs_dir):
    """The final job folder with job.json, for a run by hand or by yade-batch (the rig
    writes result.json there last). Created whole (through a temporary rename) or kept
    as it is when its job.json is the job's (else replaced). Returns its path."""
    final = job_dir(job, runs_dir)
    if (final / JOB_FILE).is_file() and job_file_is(final, job):
        return final
    tmp, _ = prepare_temp(job, runs_dir)
    if final.exists():                 # an empty or broken folder, or a job file not the job's: replace it
        shutil.rmtree(final)
    os.replace(tmp, final)
    return final


def finish(tmp, final, log_tail):
    """Move a run folder into place if it wrote result.json; else keep it as .failed and
    raise RunError naming the log."""
    if (tmp / RESULT_FILE).is_file():
        if (final / RESULT_FILE).is_file():    # finished concurrently by another process: keep theirs
            shutil.rmtree(tmp)
        else:
            if final.exists():                 # an incomplete folder (by hand / yade-batch): replace it
                old = final.parent / f".{final.name}.old{temp_suffix()}"
                os.replace(final, old)
                os.replace(tmp, final)
                shutil.rmtree(old, ignore_errors=True)
            else:
                os.replace(tmp, final)
        shutil.rmtree(failed_dir_of(final), ignore_errors=True)   # an earlier failed attempt: done now
        return json.loads((final / RESULT_FILE).read_text())
    failed = final.parent / f"{final.name}.failed"
    if failed.exists():
        shutil.rmtree(failed)
    os.replace(tmp, failed)
    raise RunError(f"{final.name}: no result ({log_tail}); log: {failed / LOG_FILE}")


def log_tail(log_path, n=3):
    """The last lines of a YADE log that tell why it failed (RIG FAILED / Error lines first)."""
    try:
        lines = [l for l in Path(log_path).read_text(errors="replace").splitlines() if l.strip()]
    except OSError:
        return "no log"
    errors = [l for l in lines if "RIG FAILED" in l or "Error" in l]
    return " | ".join((errors or lines)[-n:]) or "empty log"


def pid_alive(pid):
    """True when a process with this pid runs on this host (a reused pid counts as alive,
    a zombie, dead but not reaped yet, does not)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return True                     # no /proc: trust the signal test
    return stat.rsplit(")", 1)[-1].split()[0] != "Z"


def _newest_change(path):
    try:
        times = [path.stat().st_mtime] + ([p.stat().st_mtime for p in path.iterdir()] if path.is_dir() else [])
    except OSError:
        return time.time()
    return max(times)


def clean_stale_temporaries(runs_dir, rigs):
    """Remove the temporary folders and files under runs/<rig>/ whose owner is gone: on
    this host, a process id that no longer runs; on another host (a shared runs folder),
    nothing changed for STALE_REMOTE_S. Returns the removed paths."""
    here, removed = host_name(), []
    for rig in sorted(set(rigs)):
        folder = Path(runs_dir) / rig
        if not folder.is_dir():
            continue
        for entry in folder.iterdir():
            m = _TEMP_RE.match(entry.name)
            if not m:
                continue
            host, pid = m.group("host"), int(m.group("pid"))
            if host in (None, here):
                stale = not pid_alive(pid)
            else:
                stale = time.time() - _newest_change(entry) > STALE_REMOTE_S
            if stale:
                if entry.is_dir():
                    shutil.rmtree(entry, ignore_errors=True)
                else:
                    entry.unlink(missing_ok=True)
                removed.append(entry)
    return removed
