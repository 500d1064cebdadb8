"""Two-level screening designs: which of k values drives a response, from few runs.

A Plackett-Burman design of N runs (N a multiple of 4, N > k) sets each of the k factors
to its low (-1) or high (+1) level in every run so that every column is balanced (N/2
runs at each level) and every two columns are orthogonal. The main effect of factor j,
the mean response at its high level minus that at its low level, is then

    effect_j = (2 / N) * sum_i x_ij y_i

and every run informs every effect: with a run noise SD s the standard error of an
effect is 2 s / sqrt(N), where a one-at-a-time comparison of n paired seeds per factor
has s sqrt(2 / n) from k n runs (N = 16 runs: SE s / 2; 3 seeds per factor: SE 0.82 s). Interactions are aliased onto the main
effects (a screening design ranks the large main effects; it does not resolve
interactions). The unused columns of the design (N - 1 - k of them) estimate the noise
of an effect directly: their "effects" are pure noise and interactions.

Plackett & Burman (1946), "The design of optimum multifactorial experiments",
Biometrika 33: the generator rows for N = 12, 20, 24; N = 8, 16, 32 are Sylvester
Hadamard matrices.
"""
import numpy as np

# first rows of the cyclic Plackett-Burman designs (+1 / -1), N - 1 columns each
_GENERATORS = {
    12: "++-+++---+-",
    20: "++--++++-+-+----++-",
    24: "+++++-+-++--++--+-+----",
}


def _sylvester(n):
    h = np.array([[1]])
    while len(h) < n:
        h = np.block([[h, h], [h, -h]])
    return h


def design_size(k):
    """The smallest N (multiple of 4, at most 32) with N - 1 >= k columns."""
    for n in (8, 12, 16, 20, 24, 32):
        if n - 1 >= k:
            return n
    raise ValueError(f"a screening design here holds at most 31 factors, asked for {k}")


def plackett_burman(k):
    """N x (N - 1) matrix of +1 / -1 (N = design_size(k)): rows are runs, the first k
    columns are the factors, the rest estimate the noise. Balanced and orthogonal."""
    n = design_size(k)
    if n in _GENERATORS:
        g = np.array([1 if c == "+" else -1 for c in _GENERATORS[n]])
        rows = [np.roll(g, i) for i in range(n - 1)] + [-np.ones(n - 1, dtype=int)]
        return np.array(rows, dtype=int)
    h = _sylvester(n)
    return h[:, 1:].astype(int)        # drop the all-ones column


def main_effects(design, y):
    """Main effect of every column, high minus low mean (y's unit; shape (N - 1,)).
    y: one response per run (N,); a run without a value (nan) is not allowed."""
    x = np.asarray(design, dtype=float)
    y = np.asarray(y, dtype=float)
    if np.any(~np.isfinite(y)):
        raise ValueError("every run of a screening design needs a response")
    n = len(y)
    return (2.0 / n) * (x.T @ y)


def effect_standard_error(effects, k):
    """SE of a main effect from the unused columns k..N-2 (their effects are noise and
    interactions): sqrt(mean of their squares); None if the design has none."""
    noise = np.asarray(effects, dtype=float)[k:]
    if len(noise) == 0:
        return None
    return float(np.sqrt(np.mean(noise ** 2)))
