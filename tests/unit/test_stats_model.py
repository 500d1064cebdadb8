"""pycal.stats: scales, seed noise and the GP response model on toy data with known answers."""
import math

import numpy as np
import pytest

from pycal.stats.gp import ResponseModel
from pycal.stats.noise import pooled_noise
from pycal.stats.scales import Scale, round_significant


def test_scales_map_bounds_to_the_unit_interval_linear_and_log():
    s = Scale(0.02, 1.5)
    assert s.to_unit(0.02) == pytest.approx(0.0) and s.to_unit(1.5) == pytest.approx(1.0)
    assert float(s.from_unit(s.to_unit(0.37))) == pytest.approx(0.37)
    e = Scale(1e6, 1e9, log=True)
    assert float(e.to_unit(math.sqrt(1e6 * 1e9))) == pytest.approx(0.5)      # geometric middle
    assert float(e.from_unit(1 / 3)) == pytest.approx(1e7)
    with pytest.raises(ValueError):
        Scale(0.0, 1.0, log=True)
    assert round_significant(2.3456789e7) == 2.346e7


def test_pooled_noise_is_the_within_point_spread():
    x = [0.1, 0.1, 0.1, 0.5, 0.5]
    y = [1.0, 2.0, 3.0, 10.0, 12.0]       # within-point sums of squares 2 and 2, dof 2 + 1
    sd, dof = pooled_noise(np.array(x)[:, None], y)
    assert dof == 3 and sd == pytest.approx(math.sqrt(4 / 3))
    assert pooled_noise(np.array([[0.1], [0.2]]), [1.0, 2.0])[1] == 0


def test_model_of_a_straight_line_recovers_it_and_its_noise():
    rng = np.random.default_rng(5)
    u = np.repeat(np.linspace(0.1, 0.9, 5), 4)
    y = 20 + 40 * u + 3.0 * rng.standard_normal(len(u))
    m = ResponseModel(u[:, None], y)
    assert m.noise_source == "repeated seeds" and m.noise_dof == 15
    assert 2.0 < m.noise_sd < 4.2          # 15 degrees of freedom: within ~30 % of 3
    mean, var = m.mean_var(np.array([[0.5]]))
    assert mean[0] == pytest.approx(40.0, abs=2.0)
    # the mean over 20 runs is known to about 3 / sqrt(20) = 0.67 deg, not to one run's 3 deg
    assert 0.3 < math.sqrt(var[0]) < 1.5


def test_more_runs_shrink_the_uncertainty_of_the_mean():
    rng = np.random.default_rng(2)
    sds = []
    for seeds in (2, 8):
        u = np.repeat([0.2, 0.5, 0.8], seeds)
        y = 5 + 10 * u + rng.standard_normal(len(u))
        sds.append(math.sqrt(ResponseModel(u[:, None], y).mean_var(np.array([[0.5]]))[1][0]))
    assert sds[1] < 0.75 * sds[0]


def test_curved_response_is_followed_between_the_points():
    u = np.repeat(np.linspace(0.0, 1.0, 9), 3)
    f = lambda v: 45 - 25 * np.exp(-4 * v)
    y = f(u) + 0.3 * np.random.default_rng(3).standard_normal(len(u))
    m = ResponseModel(u[:, None], y)
    grid = np.linspace(0.05, 0.95, 10)
    assert np.max(np.abs(m.mean(grid[:, None]) - f(grid))) < 0.8      # a straight line misses by ~5 deg
    assert m.bend_weight > 0.9


def test_noise_without_repeated_seeds_is_fitted():
    u = np.linspace(0, 1, 12)
    y = 3 * u + 0.5 * np.random.default_rng(4).standard_normal(12)
    m = ResponseModel(u[:, None], y)
    assert m.noise_source == "fitted" and 0.2 < m.noise_sd < 1.0


def test_samples_are_reproducible_and_spread_like_the_posterior():
    u = np.repeat([0.2, 0.6], 3)
    y = np.array([10.0, 11.0, 9.0, 20.0, 21.0, 19.0])
    m = ResponseModel(u[:, None], y)
    a = m.sample(np.array([[0.4]]), 4000, np.random.default_rng(0))
    b = m.sample(np.array([[0.4]]), 4000, np.random.default_rng(0))
    assert np.array_equal(a, b)
    mean, var = m.mean_var(np.array([[0.4]]))
    assert np.mean(a) == pytest.approx(mean[0], abs=0.1)
    # the noise sd is known from 4 degrees of freedom only: draws spread wider than the plug-in sd
    assert np.std(a) > math.sqrt(var[0])
