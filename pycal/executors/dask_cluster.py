"""Dask: each job is one Dask task that runs `yade -j1` on a worker (Debian python3-distributed).

With a scheduler address (`--scheduler tcp://HOST:PORT`) the jobs go to the workers of
that cluster; without one, a local cluster of single-threaded workers starts on this
machine (one per core by default) and stops with the executor.

The task runs the same function as the local pool (`run_job`): the job folder is written
on the worker into the runs folder, which must be one folder that the client and every
worker see at the same path (a shared filesystem), and completes there atomically. So:
- a job whose worker dies is run again on another worker (Dask reschedules the task; a
  job whose workers died 3 times is reported failed);
- a job that fails comes back as a RunError naming its log, as in the local pool;
- when the scheduler goes away, the executor waits for it to come back (reconnect_s) and
  submits the jobs not complete yet; complete jobs are read from the runs folder, so
  running the same command again also resumes where the study stopped;
- the same job gives the same numbers bit for bit as the local pool (same command, one thread).
"""
import atexit
import logging
import os
import re
import signal
import threading
import time
import uuid
from contextlib import contextmanager
from pathlib import Path

from ..errors import ConfigError, PycalError, RunError
from .base import Executor, say
from .jobdirs import DEFAULT_RUNS_DIR, cached_result, host_name
from .yade_process import run_job

_ADDRESS_RE = re.compile(r"^(?:tcp://)?(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+):(\d{1,5})$")


def scheduler_address(text):
    """'tcp://HOST:PORT' (or 'HOST:PORT') -> 'tcp://HOST:PORT'; ConfigError otherwise."""
    m = _ADDRESS_RE.match(str(text).strip())
    if not m or not 0 < int(m.group(2)) < 65536:
        raise ConfigError("--scheduler", text, "not a Dask scheduler address (expected tcp://HOST:PORT, "
                                               "e.g. tcp://node01:8786)")
    return f"tcp://{m.group(1)}:{int(m.group(2))}"


def _distributed():
    try:
        import distributed
    except ImportError:
        raise PycalError("the dask executor needs the Debian package python3-distributed "
                         "(./run.sh install installs it)") from None
    return distributed


@contextmanager
def _quiet_dask():
    """Keep distributed's own log lines off the terminal (pycal says what matters)."""
    loggers = [logging.getLogger(n) for n in ("distributed", "distributed.client", "distributed.core",
                                              "distributed.comm", "tornado")]
    levels = [l.level for l in loggers]
    for l in loggers:
        l.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for l, lev in zip(loggers, levels):
            l.setLevel(lev)


@contextmanager
def _workers_ignore_ctrl_c():
    """Processes started inside ignore Ctrl-C (SIGINT), which the terminal sends to the whole
    process group: the study stops its local cluster itself as it exits, and a worker's
    YADE runs die with it, so an interrupt prints one line, not a traceback per worker."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


def run_on_worker(job, runs_dir, timeout_s):
    """The Dask task: run one job on this worker into the shared runs folder."""
    runs = Path(runs_dir)
    if not runs.is_dir():
        raise RunError(f"{job['job_id']}: the runs folder {runs} does not exist on worker host {host_name()}: "
                       f"it must be one folder shared by the client and every worker (docs/cluster.md)")
    try:
        return run_job(job, runs, timeout_s)
    except RunError as exc:
        raise RunError(f"{exc} [worker host {host_name()}]") from None


class DaskExecutor(Executor):
    """Runs each job as one Dask task on a cluster (scheduler address) or a local cluster."""

    name = "dask"

    def __init__(self, runs_dir=DEFAULT_RUNS_DIR, workers=None, timeout_s=3600, progress=True,
                 scheduler=None, connect_timeout_s=10.0, reconnect_s=600.0, heartbeat_s=60.0):
        super().__init__(runs_dir, workers, timeout_s, progress)
        self.scheduler = scheduler_address(scheduler) if scheduler else None
        self.connect_timeout_s, self.reconnect_s, self.heartbeat_s = connect_timeout_s, reconnect_s, heartbeat_s
        self._client, self._cluster, self._announced = None, None, False
        self.reconnect_count = 0          # times the scheduler went away and came back
        _distributed()
        if self.scheduler:
            self._client = self._connect(self.scheduler, connect_timeout_s)
        atexit.register(self.close)

    @staticmethod
    def _connect(address, timeout_s):
        distributed = _distributed()
        try:
            with _quiet_dask():
                return distributed.Client(address, timeout=timeout_s, set_as_default=False)
        except (OSError, TimeoutError) as exc:
            raise ConfigError("--scheduler", address,
                              f"no Dask scheduler answers there within {timeout_s:g} s; "
                              f"start one (dask scheduler) or leave out --scheduler for a local cluster") from None

    def _ensure_client(self):
        if self._client is None:
            distributed = _distributed()
            with _quiet_dask(), _workers_ignore_ctrl_c():
                self._cluster = distributed.LocalCluster(n_workers=self.workers, threads_per_worker=1,
                                                         processes=True, dashboard_address="127.0.0.1:0",
                                                         silence_logs=logging.ERROR)
                self._client = distributed.Client(self._cluster, set_as_default=False)
        if self.progress and not self._announced:
            self._announced = True
            say(f"Dask dashboard: {self._client.dashboard_link} (worker list: "
                f"{self._client.dashboard_link.rsplit('/', 1)[0]}/info/main/workers.html)")
        return self._client

    def _worker_count(self):
        try:
            return len(self._client.scheduler_info()["workers"])
        except Exception:                      # scheduler unreachable right now: counted as none
            return 0

    def where(self):
        if self.scheduler:
            return f"the Dask scheduler {self.scheduler} ({self._worker_count()} worker(s))"
        return f"a local Dask cluster of {self.workers} single-threaded worker(s)"

    def close(self):
        """Close the client and stop the local cluster (if this executor started one)."""
        client, cluster = self._client, self._cluster
        self._client = self._cluster = None
        with _quiet_dask():
            if client is not None:
                try:
                    client.close(timeout=10)
                except Exception:              # already gone with its scheduler: nothing left to close
                    pass
            if cluster is not None:
                cluster.close(timeout=20)

    def _submit(self, client, job, runs):
        return client.submit(run_on_worker, job, str(runs), self.timeout_s,
                             key=f"{job['job_id']}-{uuid.uuid4().hex[:8]}", pure=False)

    def _as_run_error(self, job, exc):
        if isinstance(exc, RunError):
            return exc
        name = type(exc).__name__
        if name == "KilledWorker":
            return RunError(f"{job['job_id']}: no result (the Dask workers running it died again and again: "
                            f"{exc}; their own logs tell why)")
        hint = ("; workers need the repo root on PYTHONPATH (docs/cluster.md)"
                if isinstance(exc, ImportError) else "")
        return RunError(f"{job['job_id']}: no result on the Dask cluster ({name}: {exc}){hint}")

    def _execute(self, todo):
        runs = Path(os.path.abspath(self.runs_dir))      # the same path on every worker (shared)
        runs.mkdir(parents=True, exist_ok=True)
        client = self._ensure_client()
        pending = {k: self._submit(client, job, runs) for k, job in enumerate(todo)}
        last_news = time.time()
        try:
            while pending:
                lost = False
                for k, fut in list(pending.items()):
                    status = fut.status
                    if status == "finished":
                        del pending[k]
                        result = fut.result()
                        if cached_result(todo[k], runs) is None:
                            result = RunError(f"{todo[k]['job_id']}: completed on a worker but its folder is not "
                                              f"in {runs} here: the runs folder must be shared by the client "
                                              f"and every worker at the same path (docs/cluster.md)")
                        last_news = time.time()
                        yield k, result
                    elif status == "error":
                        del pending[k]
                        last_news = time.time()
                        yield k, self._as_run_error(todo[k], fut.exception())
                    elif status == "cancelled":
                        lost = True
                if lost or client.status in ("closing", "closed"):
                    client = self._reconnect(client, runs, len(pending))
                    pending = {k: self._submit(client, todo[k], runs) for k in pending}
                    last_news = time.time()
                    continue
                if pending and time.time() - last_news > self.heartbeat_s:
                    last_news = time.time()
                    n = self._worker_count()
                    if self.progress:
                        say(f"waiting for {len(pending)} job(s) on {n} Dask worker(s)"
                            + ("" if n else ": no worker is connected; start some (docs/cluster.md)"))
                time.sleep(0.2)
        finally:
            if pending and self._client is not None:
                with _quiet_dask():
                    try:
                        self._client.cancel(list(pending.values()))
                    except Exception:          # scheduler gone: nothing to cancel
                        pass

    def _reconnect(self, client, runs, n_left):
        """Wait for the scheduler to come back; a new client, or RunError."""
        if self._cluster is not None:
            raise RunError(f"the local Dask cluster stopped with {n_left} job(s) not run; complete jobs are kept "
                           f"in {runs}: run the same command again to resume")
        if self.progress:
            say(f"lost the Dask scheduler {self.scheduler}: waiting up to {self.reconnect_s:.0f} s for it to come "
                f"back ({n_left} job(s) to run; complete jobs are kept in {runs})")
        deadline = time.time() + self.reconnect_s
        while time.time() < deadline and client.status == "connecting":
            time.sleep(0.5)                    # the client reconnects by itself for connect_timeout_s
        if client.status != "running":
            with _quiet_dask():
                try:
                    client.close(timeout=2)
                except Exception:              # closing a client whose scheduler is gone may fail: it is gone anyway
                    pass
            client = None
            while time.time() < deadline:
                try:
                    client = self._connect(self.scheduler, min(self.connect_timeout_s, max(1.0, deadline - time.time())))
                    break
                except ConfigError:
                    time.sleep(2.0)
            if client is None:
                self._client = None
                raise RunError(f"lost the Dask scheduler {self.scheduler} and it did not come back within "
                               f"{self.reconnect_s:.0f} s; {n_left} job(s) not run, complete jobs are kept in "
                               f"{runs}: run the same command again to resume")
        self._client = client
        self.reconnect_count += 1
        if self.progress:
            say(f"the Dask scheduler {self.scheduler} is back ({self._worker_count()} worker(s)): "
                f"submitting the {n_left} job(s) not complete yet")
        return client
