"""Executors: run jobs in YADE (`yade -j1 -x -n yade_scripts/<rig>.py job.json`), one
process per job, on this machine (local), through YADE's batch runner (yade-batch) or on a
Dask cluster (dask). They share one interface:

    run(jobs, raise_on_error=True) -> results in job order (None for a failed job when
        raise_on_error is False); .simulated_count; .last_errors; close()

jobdirs     - the runs folder: job folders, complete/failed/refused jobs, temporaries
yade_process- one YADE process for one job (run_job)
base        - the cache/refusal split, counting, errors and progress every executor shares
local, yade_batch, dask_cluster - the three executors
"""
from ..errors import ConfigError
from .base import Executor
from .jobdirs import DEFAULT_RUNS_DIR

EXECUTOR_NAMES = ("local", "yade-batch", "dask")


def executor_class(name):
    if name == "local":
        from .local import LocalPool
        return LocalPool
    if name == "yade-batch":
        from .yade_batch import YadeBatch
        return YadeBatch
    if name == "dask":
        from .dask_cluster import DaskExecutor
        return DaskExecutor
    raise ConfigError("--executor", name, f"unknown executor (known: {', '.join(EXECUTOR_NAMES)})")


def make_executor(name="local", scheduler=None, **kw):
    """An executor by name; `scheduler` (a Dask scheduler address) only for 'dask'."""
    cls = executor_class(name)
    limit = kw.get("timeout_s")
    if limit is not None and not limit > 0:
        raise ConfigError("--cpu-limit-s", str(limit), "must be > 0 (CPU seconds per job)")
    if scheduler:
        if name != "dask":
            raise ConfigError("--scheduler", scheduler, f"a scheduler address needs --executor dask (not {name})")
        kw["scheduler"] = scheduler
    return cls(**kw)


def add_executor_args(s, default_workers="cores"):
    """--executor, --scheduler, --workers, --cpu-limit-s (pycal run and pycal calibrate)."""
    s.add_argument("--executor", default="local", choices=EXECUTOR_NAMES,
                   help="where the YADE runs go: local processes (default), yade-batch tables, or a Dask "
                        "cluster (docs/cluster.md)")
    s.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                   help="Dask scheduler of a running cluster (with --executor dask; without it a local "
                        "cluster of single-threaded workers starts on this machine)")
    s.add_argument("--workers", type=int, default=None,
                   help=f"parallel YADE processes (default: {default_workers}); with --scheduler the "
                        f"cluster's workers decide")
    s.add_argument("--cpu-limit-s", "--timeout-s", dest="timeout_s", type=float, default=3600.0,
                   help="CPU-time limit per job in seconds (a starved run on a loaded machine is not stopped; "
                        "one that used no CPU for 10x this long is); --timeout-s is the old name")
    s.add_argument("--replicas", type=int, default=None, metavar="N",
                   help="seeds per YADE process (a batch job, pycal.replicas); 1 turns replicas off. Default: "
                        "the seeds spread over the workers, for the rigs that have replicas")
    s.add_argument("--replica-layout", default="sequential", choices=["sequential", "side_by_side"],
                   help="a batch's seeds one after the other in one YADE process (default: the same numbers "
                        "as lone runs, bit for bit) or side by side in one scene")
