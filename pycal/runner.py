"""Run jobs in YADE: the stable import path of pycal.executors (kept for its callers).

pycal/executors/__init__.py describes the executors (local pool, yade-batch, Dask) and
pycal/executors/jobdirs.py the layout of the runs folder.
"""
from .rig_contract import JOB_FILE, LOG_FILE, RESULT_FILE, RIG_FAILURE_FILE  # noqa: F401
from .executors import EXECUTOR_NAMES, Executor, make_executor  # noqa: F401
from .executors.jobdirs import (DEFAULT_RUNS_DIR, cached_failure, cached_result,  # noqa: F401
                                clean_stale_temporaries, create_job_folder, job_dir)
from .executors.local import LocalPool  # noqa: F401
from .executors.yade_batch import YadeBatch, write_batch_table  # noqa: F401
from .executors.yade_process import run_job, yade_command, yade_env, yade_executable  # noqa: F401
