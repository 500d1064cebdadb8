"""Screening designs on toy responses with known effects."""
import numpy as np
import pytest

from pycal.stats import screening


@pytest.mark.parametrize("k", [1, 3, 7, 8, 11, 12, 15, 16, 19, 20, 23, 24, 31])
def test_design_is_balanced_and_orthogonal(k):
    x = screening.plackett_burman(k)
    n = len(x)
    assert n % 4 == 0 and x.shape[1] == n - 1 >= k
    assert set(np.unique(x)) == {-1, 1}
    assert np.all(x.sum(axis=0) == 0)                 # N/2 runs at each level
    assert np.array_equal(x.T @ x, n * np.eye(n - 1))  # every two columns orthogonal


def test_design_sizes():
    assert [screening.design_size(k) for k in (1, 7, 8, 11, 12, 15, 19, 23, 24)] == [8, 8, 12, 12, 16, 16, 20, 24, 32]
    with pytest.raises(ValueError):
        screening.design_size(32)


def test_linear_effects_recovered_exactly():
    """y = 5 + sum_j b_j x_j / 2: the effect (high minus low) of factor j is b_j."""
    b = np.array([4.0, -2.0, 0.0, 0.5, 10.0, 0.0, -7.0, 1.0, 0.0, 3.0])
    x = screening.plackett_burman(len(b))
    y = 5.0 + x[:, :len(b)] @ b / 2.0
    eff = screening.main_effects(x, y)
    assert np.allclose(eff[:len(b)], b)
    assert np.allclose(eff[len(b):], 0.0)
    assert screening.effect_standard_error(eff, len(b)) == pytest.approx(0.0, abs=1e-12)


def test_noise_columns_estimate_the_effect_standard_error():
    """Run noise SD s: the SE of an effect is 2 s / sqrt(N); the noise columns find it."""
    rng = np.random.default_rng(3)
    k, s = 9, 3.0
    x = screening.plackett_burman(k)          # N = 12, 2 noise columns
    n = len(x)
    ses, errors = [], []
    for _ in range(2000):
        y = x[:, :k] @ np.arange(k) + rng.normal(0.0, s, n)
        eff = screening.main_effects(x, y)
        errors.append(eff[:k] - 2.0 * np.arange(k))
        ses.append(screening.effect_standard_error(eff, k) ** 2)
    assert np.std(np.ravel(errors)) == pytest.approx(2 * s / np.sqrt(n), rel=0.05)
    assert np.sqrt(np.mean(ses)) == pytest.approx(2 * s / np.sqrt(n), rel=0.05)


def test_missing_response_refused():
    x = screening.plackett_burman(3)
    with pytest.raises(ValueError):
        screening.main_effects(x, [1.0] * 7 + [np.nan])
