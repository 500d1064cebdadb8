"""2-3 coupled parameters: the posterior over them, sampled with emcee.

One response model (pycal.stats.gp) per output (a scalar response, or one element of a
residual vector) over u in [0, 1]^d. The likelihood of u is that every target lies
within the surrogate's own uncertainty of its mean response:

    log p(u) = sum_k log N(target_k; mean_k(u), var_k(u) + standard_error_k^2)

with a flat prior on the unit box (flat in the parameter, or in its log). emcee's
affine-invariant ensemble sampler draws from it; the estimate is the median of each
parameter, its 95 % interval the 2.5 - 97.5 percentiles, and the correlation matrix
says how the parameters trade off (e.g. friction against adhesion on one wall curve).
"""
from dataclasses import dataclass

import emcee
import numpy as np
from .threads import single_threaded

WALKERS_COUNT = 24
STEPS_COUNT = 600
BURN_COUNT = 200
KEEP_COUNT = 4000


@dataclass
class Posterior:
    """Posterior samples in u ([0, 1]^d) and their summary (estimate = median)."""
    samples_u: np.ndarray
    estimate_u: np.ndarray
    low_u: np.ndarray
    high_u: np.ndarray
    acceptance: float


def log_likelihood(models, targets, standard_errors, U):
    """log p(targets | u) for each row of U (n x d); -inf outside the unit box."""
    U = np.atleast_2d(U)
    out = np.full(len(U), -np.inf)
    inside = np.all((U >= 0.0) & (U <= 1.0), axis=1)
    if inside.any():
        total = np.zeros(int(inside.sum()))
        for m, t, se in zip(models, targets, standard_errors):
            mu, var = m.mean_var(U[inside])
            s2 = var + se ** 2 + 1e-300
            total += -0.5 * (t - mu) ** 2 / s2 - 0.5 * np.log(2 * np.pi * s2)
        out[inside] = total
    return out


@single_threaded
def sample(models, targets, standard_errors, start_u, seed=0, walkers=WALKERS_COUNT, steps=STEPS_COUNT,
           burn=BURN_COUNT, keep=KEEP_COUNT):
    """Posterior over u from the outputs' response models; start_u: where the walkers start."""
    d = models[0].dim
    rng = np.random.default_rng(seed)
    start = np.clip(np.asarray(start_u, dtype=float), 0.02, 0.98)
    p0 = np.clip(start[None, :] + 0.05 * rng.standard_normal((walkers, d)), 0.001, 0.999)
    sampler = emcee.EnsembleSampler(walkers, d, lambda U: log_likelihood(models, targets, standard_errors, U),
                                    vectorize=True)
    sampler.random_state = np.random.RandomState(seed).get_state()
    sampler.run_mcmc(p0, steps, progress=False)
    chain = sampler.get_chain(discard=burn, flat=True)
    if len(chain) > keep:
        chain = chain[rng.choice(len(chain), size=keep, replace=False)]
    low, est, high = np.percentile(chain, [2.5, 50.0, 97.5], axis=0)
    return Posterior(chain, est, low, high, float(np.mean(sampler.acceptance_fraction)))


def correlation(samples):
    """Correlation matrix (d x d) of the parameters over the samples (in their own units)."""
    S = np.asarray(samples, dtype=float)
    if S.shape[1] < 2:
        return np.ones((1, 1))
    return np.corrcoef(S, rowvar=False)
