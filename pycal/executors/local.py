"""Local pool: parallel `yade -j1` processes on this machine (workers = cores by default)."""
from concurrent.futures import ThreadPoolExecutor, as_completed

from ..errors import RunError
from .base import Executor
from .yade_process import run_job


class LocalPool(Executor):
    """Runs jobs as parallel `yade -j1` processes on this machine."""

    name = "local"

    def _execute(self, todo):
        with ThreadPoolExecutor(max_workers=self.workers) as pool:
            futures = {pool.submit(run_job, job, self.runs_dir, self.timeout_s): k for k, job in enumerate(todo)}
            for fut in as_completed(futures):
                try:
                    yield futures[fut], fut.result()
                except RunError as exc:
                    yield futures[fut], exc
