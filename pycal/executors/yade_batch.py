"""yade-batch: YADE's own batch runner, from a parameter table (one line per job).

A table has the columns `description` (the job id) and `jobFile` (the job file, a quoted
absolute path: yade-batch evaluates each value as Python). Every rig script reads its job
file from the table line it is given (yade_scripts/demlib/jobio.py), so the same rig
scripts run by hand, from the local pool, from Dask and from yade-batch.

Two routes:
- `pycal batch-table` writes the job folders (runs/<rig>/<job_id>/job.json) and a table
  that points at them, and prints the yade-batch command; the rig writes result.json
  into each folder, so a later `pycal run` with the same jobs finds them complete.
- `--executor yade-batch` (YadeBatch) writes a table of temporary folders, runs
  yade-batch, reads its per-line status as each line ends and completes each job into
  the runs folder like the local pool. A line that runs longer than the timeout is killed
  and reported; yade-batch itself is stopped if it reports nothing for too long.
"""
import math
import os
import queue
import re
import shlex
import shutil
import signal
import subprocess
import threading
import time
from pathlib import Path

from .. import REPO_ROOT, SCRIPT_DIR
from ..errors import ConfigError, RunError
from ..rig_contract import JOB_FILE, LOG_FILE
from .base import Executor, say
from .jobdirs import (cached_failure, cached_result, create_job_folder, finish, log_tail, prepare_temp,
                      temp_suffix)
from .yade_process import (CPU_LIMIT_EXIT_CODES, WALL_LIMIT_FACTOR, cpu_limit_message, cpu_limited,
                           die_with_parent, wall_limit_message, yade_env, yade_executable)

# yade-batch cuts log paths longer than this (and then cannot write the log)
MAX_LOG_PATH_CHARS = 230
# characters a table value or yade-batch's --log format cannot carry in a path
_BAD_PATH_CHARS = set(" \t\n'\"#$%@\\")
_STATUS_RE = re.compile(r"^#(\d+) \((.+?)\) (done|FAILED)\s+\(exit status (-?\d+)\), duration (\S+)")
_START_RE = re.compile(r"^#(\d+) \((.+?)\) started on")
_KILLED_BY_TIMEOUT = 128 + signal.SIGKILL      # exit code of `timeout --signal=KILL` when it fired


def yade_batch_executable():
    """yade-batch of the same YADE as `yade` ($PYCAL_YADE_BATCH, else `yade-batch`)."""
    return os.environ.get("PYCAL_YADE_BATCH", "yade-batch")


def check_table_path(path, what):
    """An absolute path a yade-batch table or log format can carry, or ConfigError."""
    path = Path(os.path.abspath(path))      # as the user named it (a shared path may be a link)
    bad = sorted(set(str(path)) & _BAD_PATH_CHARS)
    if bad:
        raise ConfigError(what, str(path), f"a yade-batch table cannot carry a path with {' '.join(repr(c) for c in bad)} "
                                           f"in it: choose a folder without them")
    return path


def write_batch_table(path, rows):
    """A yade-batch parameter table: columns description and jobFile (a quoted absolute
    path, as yade.utils.readParamsFromTable evaluates each value). Written atomically."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = ["description jobFile"]
    for desc, job_file in rows:
        if not desc or set(desc) & _BAD_PATH_CHARS:
            raise ConfigError(str(path), "description", f"{desc!r} cannot be a yade-batch description")
        lines.append(f"{desc} '{check_table_path(job_file, 'jobFile')}'")
    tmp = Path(str(path) + ".part")
    tmp.write_text("\n".join(lines) + "\n")
    os.replace(tmp, path)
    return path


def batch_command(table, script, workers, log_format, executable=None):
    """The yade-batch command line: one single-threaded YADE per line, at most `workers`
    at once, each line's log where log_format says ('@' = the line's description)."""
    cmd = [yade_batch_executable(), "-j", str(workers), "--job-threads", "1", "--nice", "0",
           "--disable-pynotify", "--log", str(log_format)]
    if executable:
        cmd += ["--executable", executable]
    return cmd + [str(table), str(script)]


def shell_line(cmd):
    """The command as the user types it, with the repo root on PYTHONPATH."""
    return f"PYTHONPATH={shlex.quote(str(REPO_ROOT))} " + " ".join(shlex.quote(str(c)) for c in cmd)


def _check_log_format(log_format, longest_desc):
    length = len(str(log_format).replace("@", longest_desc))
    if length > MAX_LOG_PATH_CHARS:
        raise ConfigError("--out", str(log_format).split("/@")[0],
                          f"yade-batch cannot write a log path of {length} characters (at most "
                          f"{MAX_LOG_PATH_CHARS}): choose a shorter runs folder")


def prepare_batch_table(jobs, runs_dir, table, workers):
    """For `pycal batch-table`: create the job folders, write the table of the jobs not
    complete yet and return (rows written, complete job ids, refusal messages, command)."""
    rigs = {(j["rig"], j["script"]) for j in jobs}
    if len(rigs) != 1:
        raise ConfigError(str(table), "jobs", "one table runs one rig script")
    (rig, script), = rigs
    runs = check_table_path(runs_dir, "--out")
    table = check_table_path(table, "--table")
    log_format = runs / rig / "@" / LOG_FILE
    _check_log_format(log_format, max(j["job_id"] for j in jobs))
    rows, complete, refused = [], [], []
    for job in jobs:
        if cached_result(job, runs) is not None:
            complete.append(job["job_id"])
        elif cached_failure(job, runs):
            refused.append(cached_failure(job, runs))
        elif job["job_id"] not in {r[0] for r in rows}:
            rows.append((job["job_id"], create_job_folder(job, runs) / JOB_FILE))
    cmd = batch_command(table, SCRIPT_DIR / script, workers, log_format)
    if rows:
        write_batch_table(table, rows)
    return rows, complete, refused, cmd


class YadeBatch(Executor):
    """Runs jobs through yade-batch tables (same scripts, same job files, same results)."""

    name = "yade-batch"
    patience_margin_s = 120.0     # beyond the lines' own timeouts, before a silent yade-batch is stopped

    def where(self):
        return f"yade-batch -j {self.workers}"

    def _execute(self, todo):
        groups = {}
        for k, job in enumerate(todo):
            groups.setdefault((job["rig"], job["script"]), []).append(k)
        for (rig, script), ks in groups.items():
            yield from self._run_group(todo, rig, script, ks)

    def _executable(self):
        """yade under a per-line CPU limit (and a wall limit WALL_LIMIT_FACTOR x that for a hung
        line); both it and YADE die if their parent dies."""
        exe = shutil.which(yade_executable())
        if exe is None:
            raise RunError(f"'{yade_executable()}' not found: install YADE (./run.sh installs it)")
        parts = (["timeout", "--foreground", "--signal=KILL", f"{WALL_LIMIT_FACTOR * self.timeout_s:g}"]
                 + cpu_limited([exe], self.timeout_s))
        setpriv = shutil.which("setpriv")
        if setpriv:
            parts = [setpriv, "--pdeathsig", "KILL", "--"] + parts[:-1] + [setpriv, "--pdeathsig", "KILL", "--", exe]
        if any(set(p) & _BAD_PATH_CHARS for p in parts):
            raise RunError(f"yade path {exe} has characters yade-batch cannot pass on")
        return " ".join(parts)

    def _run_group(self, todo, rig, script, ks):
        runs = check_table_path(self.runs_dir, "--out")
        log_format = runs / rig / f".@{temp_suffix()}" / LOG_FILE
        _check_log_format(log_format, max(todo[k]["job_id"] for k in ks))
        executable = self._executable()
        dirs = {todo[k]["job_id"]: (k, *prepare_temp(todo[k], runs)) for k in ks}
        table = runs / rig / f".batch-{Path(script).stem}{temp_suffix()}"
        write_batch_table(table, [(jid, tmp / JOB_FILE) for jid, (k, tmp, final) in dirs.items()])
        cmd = batch_command(table, SCRIPT_DIR / script, self.workers, log_format, executable)
        env = dict(yade_env(), PYTHONUNBUFFERED="1")
        waves = math.ceil(len(ks) / self.workers)
        patience_s = WALL_LIMIT_FACTOR * self.timeout_s * waves + self.patience_margin_s   # no line outlives its wall limit
        output, lines = [], queue.Queue()
        try:
            proc = subprocess.Popen(die_with_parent(cmd), cwd=runs / rig, env=env, stdin=subprocess.DEVNULL,
                                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                    errors="replace", start_new_session=True)
        except FileNotFoundError:
            table.unlink(missing_ok=True)
            for jid, (k, tmp, final) in dirs.items():
                shutil.rmtree(tmp, ignore_errors=True)
            raise RunError(f"'{cmd[0]}' not found: install YADE (./run.sh installs it)") from None
        reader = threading.Thread(target=_pump, args=(proc.stdout, lines), daemon=True)
        reader.start()
        pending, started = dict(dirs), {}
        deadline = time.time() + patience_s
        try:
            while pending:
                try:
                    line = lines.get(timeout=1.0)
                except queue.Empty:
                    if time.time() > deadline:
                        break
                    continue
                if line is None:                      # yade-batch ended
                    break
                output.append(line)
                m = _START_RE.match(line)
                if m:
                    started[m.group(2)] = time.time()
                    continue
                m = _STATUS_RE.match(line)
                if not m or m.group(2) not in pending:
                    continue
                jid, status = m.group(2), int(m.group(4))
                k, tmp, final = pending.pop(jid)
                elapsed = time.time() - started.get(jid, time.time())
                yield k, self._complete(tmp, final, status, elapsed)
                deadline = time.time() + patience_s
        finally:
            if proc.poll() is None:
                _kill_group(proc)
            proc.wait()
            reader.join(timeout=5)
            table.unlink(missing_ok=True)
        last = " | ".join(l.strip() for l in output[-3:]) or "no output"
        why = (f"yade-batch reported nothing for {patience_s:.0f} s and was stopped" if proc.returncode and
               proc.returncode < 0 else f"yade-batch ended (exit code {proc.returncode}) without a status for this line")
        for jid, (k, tmp, final) in pending.items():
            try:
                yield k, finish(tmp, final, f"{why}; its last output: {last}")
            except RunError as exc:
                yield k, exc

    def _complete(self, tmp, final, status, elapsed):
        """Complete one line from its wait status (as os.system gives it)."""
        code = status >> 8 if status > 0 else status
        if code == _KILLED_BY_TIMEOUT and elapsed >= WALL_LIMIT_FACTOR * self.timeout_s - 2:
            tail = wall_limit_message(self.timeout_s)
        elif code in CPU_LIMIT_EXIT_CODES:
            tail = cpu_limit_message(self.timeout_s)
        elif code:
            tail = f"exit code {code}: {log_tail(tmp / LOG_FILE)}"
        else:
            tail = log_tail(tmp / LOG_FILE)
        try:
            return finish(tmp, final, tail)
        except RunError as exc:
            return exc


def _pump(stream, lines):
    for line in stream:
        lines.put(line.rstrip("\n"))
    lines.put(None)


def _kill_group(proc):
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
