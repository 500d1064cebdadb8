"""Joint fit of several coupled parameters to a vector of residuals (scipy least squares).

Used where one lab curve constrains more than one parameter at once (e.g. the wet
wall-friction curve: its level follows the particle-steel friction, its rise with
consolidation the hysteretic adhesion). The residuals are band z values per lab step
(|z| <= 1: inside the lab band), averaged over seeds, so the target is met when their
RMS is at most the tolerance.

scipy.optimize.least_squares (trust-region reflective, bounded) works on the parameters
scaled to u in [1, 2] within their bounds (u = 1 + (x - lo) / (hi - lo)): scipy's
forward-difference step is relative (h = diff_step x u), so on [1, 2] it is 5-10 % of
each parameter's range whatever its start - large enough to stand above the seed noise
(on [0, 1] the wet wall fit stepped 2 % of the friction range and would have stepped
0.5 % of the pressure-fraction range, which started near its lower bound: measured).
Every evaluated point is rounded to 4 significant digits (a rerun of the same study
asks for the same jobs and hits the cache), and the best point seen is returned: with
noisy responses the optimizer's last point need not be the best. The fit stops as soon
as a point meets the tolerance, or after max_evaluations.
"""
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

MISSING_Z = 5.0   # residual of a lab step the simulation did not reach (failed or cut short)


@dataclass
class JointSolution:
    x: list
    rms: float
    met: bool
    message: str
    history: list = field(default_factory=list)   # [(x list, residual list, rms)]


class _Done(Exception):
    pass


def rms(residuals):
    r = [MISSING_Z if z is None else z for z in residuals]
    return math.sqrt(sum(z * z for z in r) / len(r)) if r else math.inf


def _round(x):
    return float(f"{x:.4g}")


def solve_joint(residuals, x0, lo, hi, tolerance_rms, max_evaluations=10, diff_step=0.05):
    """Minimise the sum of squared residuals(x) over lo <= x <= hi from x0.

    residuals(list of floats) -> list of floats or None (a step not reached: MISSING_Z).
    Returns a JointSolution with the best evaluated point."""
    lo, hi, x0 = [float(v) for v in lo], [float(v) for v in hi], [float(v) for v in x0]
    for a, b, x in zip(lo, hi, x0):
        if not a < b or not a <= x <= b:
            raise ValueError(f"joint fit: start {x} must lie within bounds [{a}, {b}] (a < b)")
    span = [b - a for a, b in zip(lo, hi)]
    history, cache = [], {}

    def to_x(u):
        return [_round(min(b, max(a, a + s * (ui - 1.0)))) for a, b, s, ui in zip(lo, hi, span, u)]

    def fun(u):
        x = to_x(u)
        key = tuple(x)
        if key not in cache:
            if len(history) >= max_evaluations:
                raise _Done(f"{max_evaluations} evaluations spent")
            r = list(residuals(x))
            cache[key] = r
            history.append((x, r, rms(r)))
            if history[-1][2] <= tolerance_rms:
                raise _Done("target met")
        return np.array([MISSING_Z if z is None else z for z in cache[key]], dtype=float)

    # least_squares wants x0 strictly inside the bounds
    u0 = [1.0 + min(1 - 1e-6, max(1e-6, (x - a) / s)) for x, a, s in zip(x0, lo, span)]
    reason = ""
    try:
        out = least_squares(fun, u0, bounds=([1.0] * len(u0), [2.0] * len(u0)), method="trf",
                            diff_step=diff_step, x_scale=1.0, max_nfev=max_evaluations)
        reason = f"optimizer stopped: {out.message}"
    except _Done as exc:
        reason = str(exc)
    best = min(history, key=lambda h: h[2])
    met = best[2] <= tolerance_rms
    msg = (f"RMS band z {best[2]:.3g} <= {tolerance_rms:g}" if met
           else f"RMS band z {best[2]:.3g} > {tolerance_rms:g} after {len(history)} evaluations ({reason})")
    return JointSolution(x=best[0], rms=best[2], met=met, message=msg, history=history)
