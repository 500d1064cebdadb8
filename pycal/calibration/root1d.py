"""Noise-aware 1-D root finding for a response that is monotone in one parameter.

Used for rolling resistance from the angle of repose, cohesion from the wet angle,
and any other single parameter whose response rises (or falls) with it.

`evaluate(x)` returns (mean, std, n) of the response over n seeds. A point meets the
target when |mean - target| <= max(tolerance, 2 x std / sqrt(n)): the calibration
is never asked to be tighter than its own seed-to-seed noise. `evaluate` raises
RunError when the rig cannot run at x (e.g. a servo that cannot hold its load at a
high stiffness): the search backs off towards the last point that ran.
"""
import math
from dataclasses import dataclass, field

from ..errors import RunError


@dataclass
class Point:
    x: float
    mean: float
    std: float
    n: int

    def misfit(self, target):
        return self.mean - target


@dataclass
class Solution:
    x: float
    point: Point
    met: bool
    history: list = field(default_factory=list)
    message: str = ""


def effective_tolerance(point, tolerance):
    """The tolerance, widened to 2 standard errors of the mean where the noise is larger."""
    if point.n > 1:
        return max(tolerance, 2.0 * point.std / math.sqrt(point.n))
    return tolerance


def solve_monotone(evaluate, target, x0, lo, hi, tolerance, max_evaluations=6, first_step=None,
                   increasing=None, slope_estimate=None, show=lambda x: f"{x:.4g}"):
    """Find x in [lo, hi] with response(x) = target within tolerance.

    Strategy: evaluate the start x0; step towards the target (direction from a second
    point) until the target is bracketed or a bound is reached; then regula falsi
    (Illinois variant) inside the bracket. Stops when a point meets the target, after
    max_evaluations, or when the target lies outside what the bounds can reach (then
    the closest bound is returned with met=False and a message saying so).
    increasing: the response's direction when physics knows it (True/False); None =
    learn it from the first two points (unsafe when the noise is larger than the change).
    slope_estimate: |d response / d x| known from physics (e.g. wall friction of the bulk
    ~ 1.03 x the particle-steel friction): the second point is then a Newton step,
    |misfit| / slope, instead of a quarter of the bounds.
    A point the rig refuses (RunError from evaluate) counts as an evaluation and becomes
    a limit: the next step goes halfway from the last point that ran towards it. A refused
    start point raises. show(x) formats a parameter value for the messages.
    """
    if not lo <= x0 <= hi:
        raise ValueError(f"start {x0} outside bounds [{lo}, {hi}]")
    history, refused = [], []          # points that ran; (x, error) of points that did not

    def ev(x):
        try:
            mean, std, n = evaluate(x)
        except RunError as exc:
            if not history:
                raise
            refused.append((float(x), str(exc)))
            return None
        p = Point(float(x), float(mean), float(std), int(n))
        history.append(p)
        return p

    def evaluations():
        return len(history) + len(refused)

    def done(p, msg=""):
        met = abs(p.misfit(target)) <= effective_tolerance(p, tolerance)
        if refused and not met:
            msg = (msg + "; " if msg else "") + "the rig refused " + ", ".join(
                show(x) for x, _ in refused) + f" ({refused[0][1][:160]})"
        return Solution(p.x, p, met, history, msg)

    def step_to(end, x):
        """x, or halfway from `end` (a point that ran) to the nearest refused point beyond
        it when x reaches that far."""
        beyond = [xr for xr, _ in refused if (xr - end.x) * (x - end.x) > 0]
        if beyond:
            limit = min(beyond, key=lambda xr: abs(xr - end.x))
            if abs(x - end.x) >= abs(limit - end.x):
                return 0.5 * (end.x + limit)
        return x

    p0 = ev(x0)
    if abs(p0.misfit(target)) <= effective_tolerance(p0, tolerance):
        return done(p0)
    step = first_step if first_step is not None else 0.25 * (hi - lo)
    if slope_estimate:
        step = abs(p0.misfit(target)) / abs(slope_estimate)
    if increasing is None:
        # probe a second point to learn the slope's sign
        x1 = min(hi, x0 + step) if x0 + step <= hi else max(lo, x0 - step)
    else:
        # step towards the target
        up = (target > p0.mean) == increasing
        x1 = min(hi, x0 + step) if up else max(lo, x0 - step)
        if x1 == x0:
            return done(p0, f"target {target:.4g} is beyond what the {'upper' if up else 'lower'} "
                            f"bound {show(x0)} reaches ({p0.mean:.4g})")
    p1 = ev(x1)
    while p1 is None and evaluations() < max_evaluations:
        x1 = step_to(p0, x1)
        p1 = ev(x1)
    if p1 is None:
        return done(p0, f"not met after {evaluations()} evaluations")
    if increasing is None:
        increasing = (p1.mean - p0.mean) * (p1.x - p0.x) >= 0
    a, b = (p0, p1) if p0.x < p1.x else (p1, p0)
    # expand until bracketed
    while evaluations() < max_evaluations and not _brackets(a, b, target):
        if abs(b.misfit(target)) <= effective_tolerance(b, tolerance):
            return done(b)
        if abs(a.misfit(target)) <= effective_tolerance(a, tolerance):
            return done(a)
        need_higher = target > max(a.mean, b.mean)
        go_up = need_higher == increasing
        width = b.x - a.x
        end = b if go_up else a
        if (go_up and b.x >= hi) or (not go_up and a.x <= lo):
            bound = "upper" if go_up else "lower"
            return done(end, f"target {target:.4g} is beyond what the {bound} bound "
                             f"{show(hi if go_up else lo)} reaches ({end.mean:.4g})")
        # secant extrapolation from the two points (x 1.3 to bracket), when their slope has
        # the expected sign; else, or beyond 3 widths, a step of 2 widths
        slope = (b.mean - a.mean) / width if width else 0.0
        step = 2.0 * width
        if slope != 0.0 and (slope > 0) == increasing:
            step = min(max(1.3 * abs((target - end.mean) / slope), 0.5 * width), 3.0 * width)
        if go_up:
            nxt = ev(step_to(b, min(hi, b.x + step)))
            if nxt is not None:
                a, b = b, nxt
        else:
            nxt = ev(step_to(a, max(lo, a.x - step)))
            if nxt is not None:
                a, b = nxt, a
    # Illinois regula falsi inside [a, b]: a and b keep opposite misfit signs
    fa, fb = a.misfit(target), b.misfit(target)
    while evaluations() < max_evaluations:
        best = min((a, b), key=lambda p: abs(p.misfit(target)))
        if abs(best.misfit(target)) <= effective_tolerance(best, tolerance):
            return done(best)
        x = 0.5 * (a.x + b.x) if fb == fa else b.x - fb * (b.x - a.x) / (fb - fa)
        p = ev(min(max(x, min(a.x, b.x)), max(a.x, b.x)))
        if p is None:       # refused inside a bracket of points that ran: stop at the best
            break
        fp = p.misfit(target)
        if fp * fb < 0:
            a, fa = b, fb
        else:
            fa *= 0.5        # Illinois: halve the weight of the end that stayed
        b, fb = p, fp
    best = min(history, key=lambda p: abs(p.misfit(target)))
    return done(best, "" if abs(best.misfit(target)) <= effective_tolerance(best, tolerance)
                else f"not met after {evaluations()} evaluations")


def _brackets(a, b, target):
    return (a.mean - target) * (b.mean - target) <= 0
