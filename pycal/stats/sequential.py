"""One step of a sequential calibration: from the runs so far to "stop (why)" or "run here next".

Pure inference, no runs (the driver in pycal.calibration runs the rigs): the runs so
far (every seed of every point) -> response model(s) -> inversion or posterior ->
stop rule -> next point. Values in the parameters' own units (x); the models work on
u in [0, 1] (pycal.stats.scales).
"""
import math
from dataclasses import dataclass, field

import numpy as np

from . import design, posterior, stopping
from .gp import ResponseModel
from .inversion import invert
from .noise import group_rows
from .threads import single_threaded

FIRST_STEP_U = 0.25      # second point without a slope estimate: a quarter of the bounds


@dataclass
class Step1D:
    """Where a 1-D stage stands (x: the parameter's unit)."""
    estimate: float
    low: float
    high: float
    tolerance: float
    p_below: float
    p_above: float
    band_low: float
    band_high: float
    stop: str = None          # a pycal.stats.stopping reason, or None
    next_x: float = None      # where to run next (None when stopping)
    model: object = None      # the ResponseModel (for plots)


def second_point_u(u0, y0, target, increasing, slope_per_u=None, lo_u=0.0, hi_u=1.0, step_u=FIRST_STEP_U):
    """The second point of a stage, from the first: a Newton step when physics gives the
    slope (response unit per unit of u), else step_u towards the target (the direction
    physics gives the response)."""
    if slope_per_u:
        u1 = u0 + (target - y0) / slope_per_u
        return float(np.clip(u1, max(lo_u, u0 - 0.5), min(hi_u, u0 + 0.5)))
    up = (target > y0) == bool(increasing)
    u1 = u0 + step_u if up else u0 - step_u
    if not lo_u <= u1 <= hi_u:          # at a bound: step the other way instead (the slope still shows)
        u1 = float(np.clip(u1, lo_u, hi_u))
        if abs(u1 - u0) < 1e-9:
            u1 = u0 - step_u if up else u0 + step_u
    return float(np.clip(u1, lo_u, hi_u))


@single_threaded
def step_1d(scale, x, y, target, increasing, tolerance=None, tolerance_percent=None, standard_error=0.0,
            band=0.0, runs_left=None, runs_per_point=3, lo_u=0.0, hi_u=1.0, seed=0, standard_error_dof=math.inf,
            out_of_reach_factor=None):
    """Decide after the runs (x, y) of a 1-D stage (at least two distinct x).

    tolerance: in x's unit, or tolerance_percent of the estimate; lo_u, hi_u: the bounds
    in use (narrower than the scale's when the rig refused a point); out_of_reach_factor:
    stop when the tolerance is out of reach in runs_left (pycal.stats.stopping, rule 3)."""
    u = scale.to_unit(np.asarray(x, dtype=float))
    model = ResponseModel(u[:, None], y)
    inv = invert(model, target, increasing, standard_error=standard_error, band=band, lo_u=lo_u, hi_u=hi_u,
                 rng=np.random.default_rng(seed), standard_error_dof=standard_error_dof)
    est, low, high = (float(scale.from_unit(v)) for v in (inv.estimate_u, inv.low_u, inv.high_u))
    tol = tolerance if tolerance is not None else abs(est) * tolerance_percent / 100.0
    edge = 0.01 * (hi_u - lo_u)
    xa, ya = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    points = [(float(v), float(np.mean(ya[xa == v]))) for v in np.unique(xa)]
    stop = stopping.stop_reason(est, low, high, tol, inv.p_below, inv.p_above,
                                ran_at_lower=bool(np.any(u <= lo_u + edge)),
                                ran_at_upper=bool(np.any(u >= hi_u - edge)),
                                runs_left=runs_left, runs_next=runs_per_point, points_count=len(np.unique(u)),
                                points=[v for v, _ in points], runs_done=len(xa),
                                out_of_reach_factor=out_of_reach_factor)
    out = Step1D(est, low, high, tol, inv.p_below, inv.p_above,
                 float(scale.from_unit(inv.band_low_u)) if band else float("nan"),
                 float(scale.from_unit(inv.band_high_u)) if band else float("nan"), stop=stop, model=model)
    if stop is None:
        side = stopping.unmeasured_side(est, low, high, [v for v, _ in points])
        if (side and stopping.within_tolerance(est, low, high, tol)
                and inv.p_below <= stopping.BOUND_SHARE and inv.p_above <= stopping.BOUND_SHARE):
            # precise enough on paper, but no point ran inside the interval on that side of
            # the estimate: run there, halfway (in u) between the estimate and that end
            out.next_x = float(scale.from_unit(0.5 * (inv.estimate_u + (inv.low_u if side < 0 else inv.high_u))))
        else:
            out.next_x = float(scale.from_unit(design.next_point_1d(model, inv.crossings_u, lo_u, hi_u,
                                                                    runs_per_point)))
    return out


@dataclass
class StepND:
    """Where a joint stage stands: per parameter (x units) estimate, interval, tolerance."""
    estimate: list
    low: list
    high: list
    tolerance: list
    correlation: list
    samples: np.ndarray = None                       # posterior samples, x units
    stop: str = None
    next_x: list = None
    models: list = field(default_factory=list)
    acceptance: float = float("nan")


@single_threaded
def step_nd(scales, X, Y, targets, standard_errors, tolerances, runs_left=None, runs_per_point=3,
            avoid_x=(), seed=0, standard_error_dofs=None, **sampler_kw):
    """Decide after the runs of a joint stage.

    X: runs x d parameters (x units); Y: runs x outputs (NaN where a run gave no value);
    targets, standard_errors (and their degrees of freedom, standard_error_dofs; None:
    known exactly): per output; tolerances: per parameter, (value, is_percent)."""
    X = np.asarray(X, dtype=float)
    Y = np.asarray(Y, dtype=float).reshape(len(X), -1)
    U = np.column_stack([s.to_unit(X[:, j]) for j, s in enumerate(scales)])
    dofs_in = [math.inf] * Y.shape[1] if standard_error_dofs is None else standard_error_dofs
    models, tgt, ses, dofs = [], [], [], []
    for k in range(Y.shape[1]):
        ok = np.isfinite(Y[:, k])
        if ok.sum() >= 2 and len(group_rows(U[ok])) >= 2:
            models.append(ResponseModel(U[ok], Y[ok, k]))
            tgt.append(targets[k])
            ses.append(standard_errors[k])
            dofs.append(dofs_in[k])
    if not models:
        raise ValueError("no output has values at two distinct points")
    post = posterior.sample(models, tgt, ses, np.unique(U, axis=0), seed=seed, dofs=dofs, **sampler_kw)
    S = np.column_stack([s.from_unit(post.samples_u[:, j]) for j, s in enumerate(scales)])
    est = [float(v) for v in np.median(S, axis=0)]
    low = [float(v) for v in np.percentile(S, 2.5, axis=0)]
    high = [float(v) for v in np.percentile(S, 97.5, axis=0)]
    tols = [t if not pct else abs(e) * t / 100.0 for (t, pct), e in zip(tolerances, est)]
    within = all(stopping.within_tolerance(e, lo, hi, t) for e, lo, hi, t in zip(est, low, high, tols))
    out = StepND(est, low, high, tols, posterior.correlation(S).tolist(), samples=S, models=models,
                 acceptance=post.acceptance)
    # measured, not bridged: some point ran inside the box of the intervals
    inside = bool(np.any(np.all((X >= np.array(low)[None, :]) & (X <= np.array(high)[None, :]), axis=1)))
    if within and not inside and not (runs_left is not None and runs_left < runs_per_point):
        out.next_x = est                 # run the estimate itself
    elif within and len(np.unique(U, axis=0)) >= len(scales) + stopping.MIN_POINTS - 1:
        out.stop = stopping.WITHIN
    elif runs_left is not None and runs_left < runs_per_point:
        out.stop = stopping.BUDGET
    else:
        # a refused point rules out a ball: half its distance to the nearest point that ran
        avoid = []
        for a in avoid_x:
            ua = np.array([s.to_unit(a[j]) for j, s in enumerate(scales)])
            avoid.append((ua, max(design.AVOID_MIN_U, 0.5 * float(np.min(np.linalg.norm(U - ua[None, :], axis=1))))))
        nxt = design.next_point_nd(models, post.samples_u, runs_per_point, np.random.default_rng(seed), avoid=avoid)
        if nxt is None:
            out.stop = "every candidate point lies next to a point the rig refused"
        else:
            out.next_x = [float(s.from_unit(v)) for s, v in zip(scales, nxt)]
    return out
