"""The next point: where new runs most shrink the uncertainty near the target.

Adding n runs at a candidate c lowers the posterior variance of the mean response f
at every point a by cov(a, c)^2 / (var(c) + sd^2 / n) (a Gaussian process update that
does not depend on the values the runs will give). The candidate chosen maximises
that reduction averaged over where the parameter is likely to be: the crossings of a
1-D inversion, or samples of a posterior. Near the target a point narrows the
interval directly; a point farther out pins the slope when the slope is what is
uncertain: the criterion weighs both (targeted variance reduction, as in Picheny et
al. 2010 for contour finding).
"""
import numpy as np
from .threads import single_threaded

CANDIDATE_COUNT = 41
REFERENCE_COUNT = 25
AVOID_MIN_U = 0.03          # smallest ball ruled out around a refused point
DISTANCE_SCALE_U = 0.2        # a far candidate keeps exp(-d^2 / 2 0.2^2) of its gain: far points pin a line, but a DEM response need not stay one that far
LOCAL_MIN_U = 0.2        # candidates reach at least this far (in u) beyond the likely crossings


def variance_reduction(model, reference_u, candidates_u, runs_count):
    """Mean reduction of var f over the reference points for each candidate (y's unit^2)."""
    R = np.asarray(reference_u, dtype=float).reshape(-1, model.dim)
    C = np.asarray(candidates_u, dtype=float).reshape(-1, model.dim)
    _, cov = model.cov(np.vstack([R, C]))
    cross = cov[:len(R), len(R):]
    var_c = np.diag(cov)[len(R):]
    return np.mean(cross ** 2, axis=0) / (var_c + model.noise_sd ** 2 / runs_count)


@single_threaded
def next_point_1d(model, crossings_u, lo_u, hi_u, runs_count):
    """u in [lo_u, hi_u] of the next point of a 1-D stage (runs_count runs there)."""
    c = np.clip(crossings_u, lo_u, hi_u)
    ref = np.quantile(c, np.linspace(0.02, 0.98, REFERENCE_COUNT))
    # candidates around the likely crossings only: a far point would pin the slope of a
    # straight line, which is where a curved response misleads (measured on toy curves)
    a, b = np.quantile(c, [0.025, 0.975])
    reach = max(0.5 * (b - a), LOCAL_MIN_U)
    cand = np.linspace(max(lo_u, a - reach), min(hi_u, b + reach), CANDIDATE_COUNT)
    gain = variance_reduction(model, ref[:, None], cand[:, None], runs_count)
    if DISTANCE_SCALE_U:
        est = float(np.median(c))
        gain = gain * np.exp(-0.5 * ((cand - est) / DISTANCE_SCALE_U) ** 2)
    return float(cand[int(np.argmax(gain))])


@single_threaded
def next_point_nd(models, samples_u, runs_count, rng, avoid=()):
    """u (d,) of the next point of a joint stage: the candidate (drawn from the posterior
    samples inside the box of the 95 % marginal intervals, plus the posterior median) that
    most reduces the variance of every output, each output's reduction relative to its
    current variance at the samples (and, as in 1-D, a far candidate keeps
    exp(-d^2 / 2 DISTANCE_SCALE_U^2) of its gain). avoid:
    (centre, radius) balls in u around points the rig refused: no candidate there."""
    S = np.asarray(samples_u, dtype=float)
    ref = S[rng.choice(len(S), size=min(len(S), 60), replace=False)]
    cand = np.vstack([np.median(S, axis=0)[None, :], S[rng.choice(len(S), size=min(len(S), 80), replace=False)]])
    # points go where the intervals are: inside the box of the 2.5 - 97.5 % marginals
    low, high = np.percentile(S, 2.5, axis=0), np.percentile(S, 97.5, axis=0)
    cand = cand[np.all((cand >= low[None, :]) & (cand <= high[None, :]), axis=1)]
    for centre, radius in avoid:
        cand = cand[np.linalg.norm(cand - np.asarray(centre)[None, :], axis=1) > radius]
    if not len(cand):
        return None
    score = np.zeros(len(cand))
    for m in models:
        _, var_ref = m.mean_var(ref)
        score += variance_reduction(m, ref, cand, runs_count) / (np.mean(var_ref) + 1e-300)
    if DISTANCE_SCALE_U:
        dist = np.linalg.norm(cand - np.median(S, axis=0)[None, :], axis=1)
        score = score * np.exp(-0.5 * (dist / DISTANCE_SCALE_U) ** 2)
    return cand[int(np.argmax(score))]
