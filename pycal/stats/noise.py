"""Seed noise estimated from the runs themselves.

Runs repeated at the same parameter point differ only by their random fill (seed);
their pooled within-point variance estimates the seed noise whatever the shape of
the response curve (pure error, no model needed). Its degrees of freedom, runs minus
distinct points, say how well the noise itself is known.
"""
import numpy as np


def group_rows(X, decimals=12):
    """Indices of the distinct rows of X (N x d): list of index arrays, in first-seen order."""
    X = np.asarray(X, dtype=float)
    X = X.reshape(len(X), -1)
    keys = [tuple(np.round(row, decimals)) for row in X]
    groups = {}
    for i, k in enumerate(keys):
        groups.setdefault(k, []).append(i)
    return [np.array(v) for v in groups.values()]


def pooled_noise(X, y):
    """(sd, dof): pooled within-point standard deviation of y (its unit) and its degrees
    of freedom (runs - distinct points); (nan, 0) when no point has two runs."""
    X = np.asarray(X, dtype=float).reshape(len(y), -1)
    y = np.asarray(y, dtype=float)
    ss, dof = 0.0, 0
    for idx in group_rows(X):
        if len(idx) > 1:
            v = y[idx]
            ss += float(np.sum((v - v.mean()) ** 2))
            dof += len(idx) - 1
    if dof == 0:
        return float("nan"), 0
    return float(np.sqrt(ss / dof)), dof
