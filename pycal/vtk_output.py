"""VTK snapshots for ParaView (`--vtk`): the job side (pure Python).

`pycal run|job|batch-table RIG ... --vtk [INTERVAL_S]` adds to each job

    "vtk": {"interval_s": INTERVAL_S, "folder": "vtk", "recorders": RECORDERS}

so the job (and its content hash, its folder) differs from the same job without snapshots,
and the job folder holds them: every rig writes YADE VTKRecorder snapshots every
INTERVAL_S of simulated time (and one at the end) into <job folder>/vtk/, plus one ParaView
collection per kind that carries the simulated time of each snapshot
(yade_scripts/demlib/vtk_output.py; docs/rigs.md).

A job whose snapshot count could pass MAX_SNAPSHOTS_COUNT (its longest simulated time from
pycal.step_estimate / the interval) is refused with one line naming the interval.
"""
import copy
import math

from .errors import ConfigError

DEFAULT_INTERVAL_S = 0.05
FOLDER = "vtk"
# YADE VTKRecorder recorders: spheres (position, radius `radii`), facets (walls, plates,
# cells), velocity (`linVelVec`, `linVelLen`, `angVelVec`, `angVelLen`), materialId
# (YADE material id: the job's materials and then its boundaries, in the job's order),
# clumpId (-1 for a free sphere, else the lump's body id), mass.
RECORDERS = ["spheres", "facets", "velocity", "materialId", "clumpId", "mass"]
MAX_SNAPSHOTS_COUNT = 20000


def with_vtk(job, interval_s=DEFAULT_INTERVAL_S):
    """A copy of a resolved job that writes VTK snapshots every interval_s (s), with its new
    job_id. ConfigError (exit 2) for an interval that is not > 0 or would write more than
    MAX_SNAPSHOTS_COUNT snapshots at the job's longest simulated time."""
    from .jobs import job_id
    from .step_estimate import estimate
    if isinstance(interval_s, bool) or not isinstance(interval_s, (int, float)) or not (
            math.isfinite(interval_s) and interval_s > 0):
        raise ConfigError("--vtk", "interval_s", f"{interval_s!r} must be a number of seconds > 0")
    longest = estimate(job)["simulated_time_s"]
    if longest / interval_s > MAX_SNAPSHOTS_COUNT:
        raise ConfigError("--vtk", "interval_s", f"{interval_s:g} s would write up to {longest / interval_s:.3g} "
                          f"snapshots over the up to {longest:.3g} s this {job['rig']} job simulates (limit "
                          f"{MAX_SNAPSHOTS_COUNT}): give a larger interval, e.g. --vtk "
                          f"{math.ceil(longest / MAX_SNAPSHOTS_COUNT * 100) / 100:g}")
    out = copy.deepcopy(job)
    out["vtk"] = {"interval_s": float(interval_s), "folder": FOLDER, "recorders": list(RECORDERS)}
    out["job_id"] = job_id(out)
    return out
