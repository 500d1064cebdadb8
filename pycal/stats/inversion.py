"""Invert a one-parameter response model for a target: the estimate and its 95 % interval.

Curves f are drawn from the response model's posterior (pycal.stats.gp) on a grid of u
in [0, 1]; each is crossed with the target, itself drawn from N(target, standard_error^2)
where the target is a mean of its own (a twin's simulated lab value), or from a Student-t
with standard_error_dof degrees of freedom when that standard error was itself
estimated from a few values (a mean of n seeds: n - 1; 3 seeds put the 95 % quantile at
4.30 standard errors, not 1.96), after being made
monotone in the direction physics gives (rearranged: its values sorted) over the
stretch the runs constrain. The crossings
are draws of the parameter that reproduces the target: their median is the estimate,
their 2.5 and 97.5 percentiles the 95 % interval. A draw that does not cross inside
the bounds counts at the bound it points past (share reported: p_below, p_above).

Separately, the lab band range: the parameter values whose mean response lies in
target +- band (what the lab itself cannot tell apart; it does not shrink with runs).
"""
import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import norm, t as student_t
from .threads import single_threaded

GRID_COUNT = 101
WINDOW_MARGIN_U = 0.1      # the stretch made monotone: the runs' range and this much beyond
DRAW_COUNT = 2000


@dataclass
class Inversion:
    """Result of inverting a 1-D response model; u values in [0, 1] (see scales.Scale)."""
    estimate_u: float
    low_u: float
    high_u: float
    p_below: float          # share of draws whose crossing lies below the lower bound
    p_above: float          # share beyond the upper bound
    crossings_u: np.ndarray  # the draws (for the design of the next point)
    band_low_u: float = float("nan")    # lab band range (mean response within target +- band)
    band_high_u: float = float("nan")


def crossings(curves, grid, targets, increasing, window=None):
    """u where each curve (rows of `curves` on `grid`) reaches its target; -inf / +inf when
    it stays above / below it on the whole grid.

    Each curve is made monotone first (its values sorted: monotone rearrangement) within
    `window` (lo, hi) in u, the stretch the runs constrain (default: the whole grid); a
    curve that does not reach its target there gets its first upward crossing beyond it
    (in the direction physics gives). So a curve that wanders far from the runs, where
    the model is vague, cannot move the crossing the runs pin down (found: a far dip of
    a sorted curve moved a wet-cohesion crossing from 1.1 to 4)."""
    F = np.asarray(curves, dtype=float)
    T = np.broadcast_to(np.asarray(targets, dtype=float), (F.shape[0],))
    if not increasing:
        F, T = -F, -T
    if window is None:
        return _sorted_crossings(F, grid, T)
    inside = (grid >= window[0]) & (grid <= window[1])
    out = _sorted_crossings(F[:, inside], grid[inside], T)
    D = F - T[:, None]
    up = (D[:, :-1] < 0) & (D[:, 1:] >= 0)
    frac = np.where(up, -D[:, :-1] / np.where(up, D[:, 1:] - D[:, :-1], 1.0), 0.0)
    xc = grid[:-1][None, :] + frac * np.diff(grid)[None, :]
    for side, beyond in ((np.inf, xc > window[1]), (-np.inf, xc < window[0])):
        rows = out == side
        ok = up & beyond & rows[:, None]
        dist = np.where(ok, np.abs(xc - (window[1] if side > 0 else window[0])), np.inf)
        has = ok.any(axis=1)
        out[has] = xc[has, np.argmin(dist[has], axis=1)]
    return out


def _sorted_crossings(F, grid, T):
    """First crossing of each row of F after sorting it (rows rising with u)."""
    F = np.sort(F, axis=1)
    idx = np.sum(F < T[:, None], axis=1)
    out = np.empty(F.shape[0])
    out[idx == 0] = -np.inf
    out[idx == F.shape[1]] = np.inf
    inside = (idx > 0) & (idx < F.shape[1])
    rows = np.nonzero(inside)[0]
    i1 = idx[inside]
    f0, f1 = F[rows, i1 - 1], F[rows, i1]
    g0, g1 = grid[i1 - 1], grid[i1]
    frac = np.where(f1 > f0, (T[inside] - f0) / np.where(f1 > f0, f1 - f0, 1.0), 0.5)
    out[inside] = g0 + frac * (g1 - g0)
    return out


def target_noise(rng, draws, dof=math.inf):
    """Draws of (target - true mean) / standard error: standard normal when the standard
    error is known, Student-t with `dof` degrees of freedom when it was estimated."""
    return rng.standard_normal(draws) if math.isinf(dof) else rng.standard_t(float(dof), draws)


def target_factor_95(dof=math.inf):
    """Half width of the target's own 95 % range in standard errors: 1.96 for a known
    standard error, the Student-t quantile for an estimated one (4.30 at 2 degrees of freedom)."""
    return float(student_t.ppf(0.975, dof)) if not math.isinf(dof) else float(norm.ppf(0.975))


def _mean_crossing(model, grid, level, increasing):
    m = model.mean(grid[:, None])
    return float(crossings(m[None, :], grid, [level], increasing)[0])


@single_threaded
def invert(model, target, increasing, standard_error=0.0, band=0.0, lo_u=0.0, hi_u=1.0, rng=None,
           draws=DRAW_COUNT, standard_error_dof=math.inf):
    """Inversion of `model` (a 1-D ResponseModel) for `target` (the response's unit) within
    [lo_u, hi_u]: estimate, 95 % interval, shares beyond the bounds and the lab band range.
    increasing: the direction physics gives to the response (True: rises with u);
    standard_error_dof: degrees of freedom of standard_error (inf: known exactly)."""
    rng = np.random.default_rng(0) if rng is None else rng
    grid = np.linspace(lo_u, hi_u, GRID_COUNT)
    curves = model.sample(grid[:, None], draws, rng)
    targets = target + float(standard_error) * target_noise(rng, draws, standard_error_dof)
    ran = model.U[:, 0]
    window = (max(lo_u, float(ran.min()) - WINDOW_MARGIN_U), min(hi_u, float(ran.max()) + WINDOW_MARGIN_U))
    c = crossings(curves, grid, targets, increasing, window=window)
    p_below, p_above = float(np.mean(c == -np.inf)), float(np.mean(c == np.inf))
    c = np.clip(c, lo_u, hi_u)
    low, est, high = np.percentile(c, [2.5, 50.0, 97.5])
    out = Inversion(float(est), float(low), float(high), p_below, p_above, c)
    if band > 0:
        ends = sorted(np.clip([_mean_crossing(model, grid, target - band, increasing),
                               _mean_crossing(model, grid, target + band, increasing)], lo_u, hi_u))
        out.band_low_u, out.band_high_u = float(ends[0]), float(ends[1])
    return out
