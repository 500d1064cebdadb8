"""2-3 coupled parameters: the posterior over them, sampled with emcee.

One response model (pycal.stats.gp) per output (a scalar response, or one element of a
residual vector) over u in [0, 1]^d. The likelihood of u is that every target lies
within the surrogate's own uncertainty of its mean response:

    log p(u) = sum_k log N(target_k; mean_k(u), var_k(u) + standard_error_k^2)

(for a target whose standard error was estimated from a few values, dof_k degrees of
freedom: a Student-t with dof_k degrees of freedom and that scale in place of N),
with a flat prior on the unit box (flat in the parameter, or in its log). emcee's
affine-invariant ensemble sampler draws from it; the estimate is the median of each
parameter, its 95 % interval the 2.5 - 97.5 percentiles, and the correlation matrix
says how the parameters trade off (e.g. friction against adhesion on one wall curve).
"""
import math
from dataclasses import dataclass

import emcee
import numpy as np
from scipy.optimize import minimize
from scipy.special import gammaln
from .threads import single_threaded

WALKERS_COUNT = 24
STEPS_COUNT = 400
BURN_COUNT = 150
KEEP_COUNT = 4000
STUCK_NATS = 25.0
MAP_SEARCH_COUNT = 400      # random points tried for the start of the local searches
MAP_STARTS_COUNT = 4


@dataclass
class Posterior:
    """Posterior samples in u ([0, 1]^d) and their summary (estimate = median)."""
    samples_u: np.ndarray
    estimate_u: np.ndarray
    low_u: np.ndarray
    high_u: np.ndarray
    acceptance: float


def log_likelihood(models, targets, standard_errors, U, dofs=None):
    """log p(targets | u) for each row of U (n x d); -inf outside the unit box.
    dofs: per target, the degrees of freedom of its standard error (None / inf: known)."""
    U = np.atleast_2d(U)
    out = np.full(len(U), -np.inf)
    inside = np.all((U >= 0.0) & (U <= 1.0), axis=1)
    if inside.any():
        total = np.zeros(int(inside.sum()))
        dofs = [math.inf] * len(models) if dofs is None else dofs
        for m, t, se, dof in zip(models, targets, standard_errors, dofs):
            mu, var = m.mean_var(U[inside])
            s2 = var + se ** 2 + 1e-300
            if math.isinf(dof):
                total += -0.5 * (t - mu) ** 2 / s2 - 0.5 * np.log(2 * np.pi * s2)
            else:
                total += (gammaln(0.5 * (dof + 1)) - gammaln(0.5 * dof) - 0.5 * np.log(dof * np.pi * s2)
                          - 0.5 * (dof + 1) * np.log1p((t - mu) ** 2 / (dof * s2)))
        out[inside] = total
    return out


@single_threaded
def sample(models, targets, standard_errors, start_u, seed=0, walkers=WALKERS_COUNT, steps=STEPS_COUNT,
           burn=BURN_COUNT, keep=KEEP_COUNT, dofs=None):
    """Posterior over u from the outputs' response models; start_u: points to start the
    search from (one, or rows: e.g. every point run so far).

    The walkers start in a tiny ball around the most likely point (scipy local searches
    from the best few of start_u and the best few of MAP_SEARCH_COUNT random points: a
    posterior pinned by the runs can be narrower than the random points' spacing):
    a posterior pinned by many runs is narrow, and a walker started off it can wander to
    a far corner where the surrogate is merely vague, and stay (measured on the wet wall
    fit). A walker whose median log-probability ends more than STUCK_NATS below the
    others' is dropped as stuck."""
    d = models[0].dim

    def log_p(U):
        return log_likelihood(models, targets, standard_errors, U, dofs)
    rng = np.random.default_rng(seed)
    # the most likely point: local searches from the best few of start_u and random points
    # (the surrogate's vague edges can hold local maxima: one search from one start is not enough)
    near = np.atleast_2d(np.asarray(start_u, dtype=float))
    far = rng.uniform(0.0, 1.0, size=(MAP_SEARCH_COUNT, d))
    tries = np.vstack([near[np.argsort(-log_p(near))[:MAP_STARTS_COUNT]],
                       far[np.argsort(-log_p(far))[:MAP_STARTS_COUNT]]])
    found = [minimize(lambda u: -log_p(u[None, :])[0], np.clip(t, 1e-3, 1 - 1e-3), method="L-BFGS-B",
                      bounds=[(0.0, 1.0)] * d).x for t in tries]
    cand = np.vstack([tries, found])
    start = np.clip(cand[int(np.argmax(log_p(cand)))], 1e-3, 1 - 1e-3)
    p0 = np.clip(start[None, :] + 1e-3 * rng.standard_normal((walkers, d)), 0.0, 1.0)
    sampler = emcee.EnsembleSampler(walkers, d, log_p, vectorize=True)
    sampler.random_state = np.random.RandomState(seed).get_state()
    sampler.run_mcmc(p0, steps, progress=False)
    chain = sampler.get_chain(discard=burn)                  # (steps, walkers, d)
    lp = np.median(sampler.get_log_prob(discard=burn), axis=0)
    good = lp >= np.median(lp) - STUCK_NATS
    flat = chain[:, good, :].reshape(-1, d)
    if len(flat) > keep:
        flat = flat[rng.choice(len(flat), size=keep, replace=False)]
    low, est, high = np.percentile(flat, [2.5, 50.0, 97.5], axis=0)
    return Posterior(flat, est, low, high, float(np.mean(sampler.acceptance_fraction)))


def correlation(samples):
    """Correlation matrix (d x d) of the parameters over the samples (in their own units)."""
    S = np.asarray(samples, dtype=float)
    if S.shape[1] < 2:
        return np.ones((1, 1))
    return np.corrcoef(S, rowvar=False)
