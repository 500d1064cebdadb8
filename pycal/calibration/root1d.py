"""Noise-aware 1-D root finding for a response that is monotone in one parameter.

Used for rolling resistance from the angle of repose, cohesion from the wet angle,
and any other single parameter whose response rises (or falls) with it.

`evaluate(x)` returns (mean, std, n) of the response over n seeds. A point meets the
target when |mean - target| <= max(tolerance, 2 x std / sqrt(n)): the calibration
is never asked to be tighter than its own seed-to-seed noise.
"""
import math
from dataclasses import dataclass, field


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
                   increasing=None, slope_estimate=None):
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
    """
    if not lo <= x0 <= hi:
        raise ValueError(f"start {x0} outside bounds [{lo}, {hi}]")
    history = []

    def ev(x):
        mean, std, n = evaluate(x)
        p = Point(float(x), float(mean), float(std), int(n))
        history.append(p)
        return p

    def done(p, msg=""):
        return Solution(p.x, p, abs(p.misfit(target)) <= effective_tolerance(p, tolerance), history, msg)

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
                            f"bound {x0} reaches ({p0.mean:.4g})")
    p1 = ev(x1)
    if increasing is None:
        increasing = (p1.mean - p0.mean) * (p1.x - p0.x) >= 0
    a, b = (p0, p1) if p0.x < p1.x else (p1, p0)
    # expand until bracketed
    while len(history) < max_evaluations and not _brackets(a, b, target):
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
                             f"{hi if go_up else lo} reaches ({end.mean:.4g})")
        # secant extrapolation from the two points (x 1.3 to bracket), when their slope has
        # the expected sign; else, or beyond 3 widths, a step of 2 widths
        slope = (b.mean - a.mean) / width if width else 0.0
        step = 2.0 * width
        if slope != 0.0 and (slope > 0) == increasing:
            step = min(max(1.3 * abs((target - end.mean) / slope), 0.5 * width), 3.0 * width)
        if go_up:
            nxt = ev(min(hi, b.x + step))
            a, b = b, nxt
        else:
            nxt = ev(max(lo, a.x - step))
            a, b = nxt, a
    # Illinois regula falsi inside [a, b]: a and b keep opposite misfit signs
    fa, fb = a.misfit(target), b.misfit(target)
    while len(history) < max_evaluations:
        best = min((a, b), key=lambda p: abs(p.misfit(target)))
        if abs(best.misfit(target)) <= effective_tolerance(best, tolerance):
            return done(best)
        x = 0.5 * (a.x + b.x) if fb == fa else b.x - fb * (b.x - a.x) / (fb - fa)
        p = ev(min(max(x, min(a.x, b.x)), max(a.x, b.x)))
        fp = p.misfit(target)
        if fp * fb < 0:
            a, fa = b, fb
        else:
            fa *= 0.5        # Illinois: halve the weight of the end that stayed
        b, fb = p, fp
    best = min(history, key=lambda p: abs(p.misfit(target)))
    return done(best, "" if abs(best.misfit(target)) <= effective_tolerance(best, tolerance)
                else f"not met after {len(history)} evaluations")


def _brackets(a, b, target):
    return (a.mean - target) * (b.mean - target) <= 0
