"""What every executor shares: the cache/refusal split, counting, errors, progress lines.

A subclass only runs the jobs that are left (`_execute`), yielding each outcome as the
job completes; this base decides what is cached, counts what was simulated, collects
the failures and prints the progress.
"""
import os
import sys
import time
from pathlib import Path

from ..errors import RunError
from .jobdirs import DEFAULT_RUNS_DIR, cached_failure, cached_result, clean_stale_temporaries


def wrapped_chain(executor):
    """The executor and the ones it wraps (`.inner`, e.g. a ReplicaExecutor around a
    LocalPool), outermost first."""
    while executor is not None:
        yield executor
        executor = getattr(executor, "inner", None)


def say(msg):
    print(msg, file=sys.stderr, flush=True)


class Executor:
    """run(jobs, raise_on_error=True) -> results in job order (None for a failed job
    when raise_on_error is False); .simulated_count (jobs really run by YADE, not from
    the cache); .last_errors (messages of the failed jobs of the last run)."""

    name = "executor"

    def __init__(self, runs_dir=DEFAULT_RUNS_DIR, workers=None, timeout_s=3600, progress=True):
        self.runs_dir = Path(runs_dir)
        self.workers = workers or os.cpu_count() or 1
        self.timeout_s = timeout_s
        self.progress = progress
        self.simulated_count = 0
        self.last_errors = []

    # subclasses: yield (index into todo, result dict or RunError) as each job completes
    def _execute(self, todo):
        raise NotImplementedError

    def where(self):
        """Where the jobs run, for the progress line."""
        return f"{self.workers} worker(s)"

    def close(self):
        """Release what the executor started (a local cluster); the default has nothing."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def run(self, jobs, raise_on_error=True):
        """Run jobs; returns results in the order of `jobs`. A job listed twice runs once."""
        results, errors = [None] * len(jobs), []
        first, todo = {}, []
        for i, job in enumerate(jobs):
            if job["job_id"] in first:
                continue
            first[job["job_id"]] = i
            cached = cached_result(job, self.runs_dir)
            if cached is not None:
                results[i] = cached
                continue
            refused = cached_failure(job, self.runs_dir)
            if refused:
                errors.append(refused)
            else:
                todo.append(i)
        clean_stale_temporaries(self.runs_dir, [job["rig"] for job in jobs])
        self.simulated_count += len(todo)
        if self.progress and todo:
            say(f"running {len(todo)} job(s) ({len(first) - len(todo)} cached) on {self.where()}")
        t0 = time.time()
        for done, (k, outcome) in enumerate(self._execute([jobs[i] for i in todo]), start=1):
            i = todo[k]
            if isinstance(outcome, RunError):
                errors.append(str(outcome))
                status = f"FAILED: {outcome}"
            else:
                results[i] = outcome
                status = "ok"
            if self.progress:
                el = time.time() - t0
                eta = el / done * (len(todo) - done)
                say(f"[{done}/{len(todo)}] {jobs[i]['job_id']} {status} "
                    f"(elapsed {el:.0f} s, remaining ~{eta:.0f} s)")
        for i, job in enumerate(jobs):
            if results[i] is None:
                results[i] = results[first[job["job_id"]]]
        self.last_errors = errors
        if errors and raise_on_error:
            raise RunError(f"{len(errors)} of {len(first)} job(s) failed; first: {errors[0]}")
        return results
