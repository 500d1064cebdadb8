"""The response model: a Gaussian process fitted to every run of a stage (scikit-learn).

    y = f(u) + e,   e ~ N(0, sd^2) the seed noise,   u in [0, 1]^d (pycal.stats.scales)

f is a straight trend with flat priors on intercept and slopes (a Bayesian linear
regression: the DotProduct kernel) plus a smooth deviation (RBF kernel) of unknown size
and length scale. Those two hyperparameters are not fitted to one best value, which
is overconfident with a handful of points: f is averaged over the line and seven
bends (BENDS), each weighted by its marginal likelihood (Bayesian model averaging, equal
prior weights; scikit-learn fits each), so two points give a line with an honest slope
uncertainty and more points let the curve bend where the data ask for it. The seed noise sd comes from the
runs repeated at the same point (pycal.stats.noise); without repeats it joins the
grid. y keeps its unit (deg, kg/m3, ...): it is standardised inside.

The noise sd is itself estimated from few runs: `sample` draws curves whose spread is
scaled by a draw of sd from its chi-square posterior (degrees of freedom = runs -
distinct points): the Student-t widening a handful of seeds calls for.
"""
import itertools

import numpy as np
from scipy.linalg import solve_triangular
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, DotProduct

from .noise import pooled_noise
from .threads import single_threaded

TREND_PRIOR_VAR = 100.0                   # flat priors: sd 10 x the responses' spread
# the deviation from a line: (variance in the responses' spread squared, length scale in u);
# a large deviation only over a long length: a physical response bends, it does not wiggle
# (a 1.7-spread bump over 0.15 of the bounds made a noisy density stage's interval explode)
BENDS = ((0.03, 0.15), (0.03, 0.3), (0.03, 0.6), (0.3, 0.15), (0.3, 0.3), (0.3, 0.6), (3.0, 0.6))
NOISE_VARS = (0.001, 0.01, 0.1, 1.0)      # without repeated seeds the noise joins the grid
MIN_WEIGHT = 1e-4                         # grid models below this posterior weight are dropped


def _fit_component(X, z, noise_var, bend_var, length):
    """scikit-learn fit of one grid model: (log marginal likelihood, weights alpha, K^-1)."""
    kernel = ConstantKernel(TREND_PRIOR_VAR, "fixed") * DotProduct(1.0, "fixed")
    if bend_var > 0:
        kernel = kernel + ConstantKernel(bend_var, "fixed") * RBF(length, "fixed")
    gp = GaussianProcessRegressor(kernel, alpha=noise_var + 1e-10, optimizer=None, normalize_y=False).fit(X, z)
    L_inv = solve_triangular(gp.L_, np.eye(len(X)), lower=True)
    return float(gp.log_marginal_likelihood_value_), gp.alpha_, L_inv.T @ L_inv


class ResponseModel:
    """A GP of one scalar response y (its unit) over u in [0, 1]^d, fitted to all runs.

    noise_sd: the seed noise (y's unit); noise_dof: its degrees of freedom (0: from the
    grid, no repeated seeds); weights: posterior weight of each grid model kept."""

    @single_threaded
    def __init__(self, U, y, noise_sd=None):
        U = np.asarray(U, dtype=float)
        self.U = U.reshape(len(U), -1)
        self.y = np.asarray(y, dtype=float)
        if len(self.y) != len(self.U) or len(self.y) < 2:
            raise ValueError(f"need at least 2 runs with one u each (got {len(self.y)} values, {len(self.U)} points)")
        self.dim = self.U.shape[1]
        sd, dof = pooled_noise(self.U, self.y)
        known = noise_sd is not None or (dof > 0 and sd > 0)
        if noise_sd is not None:
            sd, dof = float(noise_sd), 0
        self.y_mean = float(np.mean(self.y))
        spread = float(np.std(self.y))
        self.y_scale = spread if spread > 0 else (sd if sd > 0 else 1.0)
        z = (self.y - self.y_mean) / self.y_scale
        self._X = self.U - 0.5                # centred: the trend's intercept is mid-range
        noise_grid = [(sd / self.y_scale) ** 2 + 1e-8] if known else NOISE_VARS
        shapes = [(0.0, 1.0)] + list(BENDS)
        grid = [(nv, bv, length) for nv, (bv, length) in itertools.product(noise_grid, shapes)]
        fits = [_fit_component(self._X, z, *g) for g in grid]
        log_w = np.array([f[0] for f in fits])           # every shape (the line and the bends) equally likely
        w = np.exp(log_w - log_w.max())
        w /= w.sum()
        keep = np.nonzero(w >= MIN_WEIGHT)[0]
        self.weights = w[keep] / w[keep].sum()
        self._noise = np.array([grid[i][0] for i in keep])
        self._bend = np.array([grid[i][1] for i in keep])
        self._length = np.array([grid[i][2] for i in keep])
        self._lengths, self._length_index = np.unique(self._length, return_inverse=True)
        self._alpha = np.stack([fits[i][1] for i in keep])        # (models, runs)
        self._K_inv = np.stack([fits[i][2] for i in keep])        # (models, runs, runs)
        self.noise_sd = float(sd) if known else float(np.sqrt(np.sum(self.weights * self._noise))) * self.y_scale
        self.noise_dof = dof if known else 0
        self.noise_source = ("given" if noise_sd is not None else "repeated seeds") if known else "fitted"
        self.bend_weight = float(np.sum(self.weights[self._bend > 0]))

    # ---- kernels of every grid model at once: arrays (models, len(A), len(B))
    def _k(self, A, B):
        AB = A @ B.T
        trend = TREND_PRIOR_VAR * (1.0 + AB)
        d2 = np.maximum(np.sum(A ** 2, 1)[:, None] + np.sum(B ** 2, 1)[None, :] - 2 * AB, 0.0)
        rbf = np.exp(-0.5 * d2[None, :, :] / self._lengths[:, None, None] ** 2)     # one per length scale
        return trend[None, :, :] + self._bend[:, None, None] * rbf[self._length_index]

    def _latent(self, Us, full_cov):
        """Per grid model: mean (models, n) and variances (models, n) or covariances."""
        Xs = np.asarray(Us, dtype=float).reshape(-1, self.dim) - 0.5
        Ks = self._k(self._X, Xs)                                   # (models, runs, n)
        mean = np.einsum("mrn,mr->mn", Ks, self._alpha)
        KiKs = self._K_inv @ Ks
        if full_cov:
            return mean, self._k(Xs, Xs) - np.swapaxes(Ks, 1, 2) @ KiKs
        prior = TREND_PRIOR_VAR * (1.0 + np.sum(Xs ** 2, 1))[None, :] + self._bend[:, None]
        return mean, np.maximum(prior - np.sum(Ks * KiKs, axis=1), 0.0)

    def mean_var(self, Us):
        """(mean, variance) of f at the points Us (n x d), in y's unit: the uncertainty of
        the mean response over seeds, not of one run."""
        m, v = self._latent(Us, False)
        w = self.weights[:, None]
        mean = np.sum(w * m, axis=0)
        var = np.sum(w * (v + m ** 2), axis=0) - mean ** 2
        return mean * self.y_scale + self.y_mean, np.maximum(var, 0.0) * self.y_scale ** 2

    def mean(self, Us):
        """Posterior mean of f at Us."""
        return self.mean_var(Us)[0]

    def cov(self, Us):
        """(mean, covariance matrix) of f at Us (mixture over the grid)."""
        m, C = self._latent(Us, True)
        w = self.weights[:, None]
        mean = np.sum(w * m, axis=0)
        cov = np.einsum("m,mab->ab", self.weights, C + m[:, :, None] * m[:, None, :]) - np.outer(mean, mean)
        return mean * self.y_scale + self.y_mean, cov * self.y_scale ** 2

    def noise_scale_draws(self, n, rng):
        """n factors sd_draw / sd: 1 when the noise is given or gridded, else sqrt(dof / chi2(dof))."""
        if not self.noise_dof:
            return np.ones(n)
        return np.sqrt(self.noise_dof / rng.chisquare(self.noise_dof, size=n))

    def sample(self, Us, n, rng):
        """n curves of f drawn from the posterior at Us (n x len(Us)): a grid model drawn by
        its weight, then a curve from it, its spread widened by the uncertainty of the
        noise sd itself."""
        which = rng.choice(len(self.weights), size=n, p=self.weights)
        scale = self.noise_scale_draws(n, rng)
        means, covs = self._latent(Us, True)
        out = np.empty((n, means.shape[1]))
        for k in range(len(self.weights)):
            rows = np.nonzero(which == k)[0]
            if not len(rows):
                continue
            C = covs[k]
            w, V = np.linalg.eigh(0.5 * (C + C.T))          # a line's covariance has rank 2: no Cholesky
            Z = rng.standard_normal((len(rows), len(w))) @ (V * np.sqrt(np.clip(w, 0.0, None))).T
            out[rows] = means[k][None, :] + scale[rows, None] * Z
        return out * self.y_scale + self.y_mean

    def describe(self):
        """One line for logs: runs, noise, weight of the bending models."""
        return (f"{len(self.y)} runs, seed noise sd {self.noise_sd:.4g} ({self.noise_source}, "
                f"{self.noise_dof} dof), curved models' weight {self.bend_weight:.2f}")
