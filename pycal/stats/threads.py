"""Numerical work on one thread: the matrices here are small, and the cores belong to
the YADE runs (BLAS threads on a loaded machine cost more than they give: measured
3x slower on 2 busy cores)."""
import functools

from threadpoolctl import threadpool_limits


def single_threaded(fn):
    """Run fn with BLAS/OpenMP limited to one thread."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with threadpool_limits(1):
            return fn(*args, **kwargs)
    return wrapper
