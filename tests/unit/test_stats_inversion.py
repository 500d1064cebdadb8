"""pycal.stats.inversion: the estimate lands on the known answer and the 95 % interval
contains it in about 95 % of random noisy draws (and a broken interval would not)."""
import math

import numpy as np
import pytest

from pycal.stats.gp import ResponseModel
from pycal.stats.inversion import crossings, invert, target_factor_95

DRAWS = 150          # binomial sd of a 95 % coverage over 150 draws: 1.8 % (fixed seeds: deterministic)


def coverage(f, design_u, seeds, noise_sd, target, truth_u, target_se=0.0, increasing=True, draws=DRAWS):
    """(coverage, coverage of the same intervals halved, median width) over noisy draws."""
    rng = np.random.default_rng(2026)
    hits = hits_half = 0
    widths = []
    for k in range(draws):
        u = np.repeat(design_u, seeds)
        y = f(u) + noise_sd * rng.standard_normal(len(u))
        t = target + target_se * rng.standard_normal()       # a target that is itself a mean (a twin's)
        inv = invert(ResponseModel(u[:, None], y), t, increasing, standard_error=target_se,
                     rng=np.random.default_rng(k), draws=800)
        hits += inv.low_u <= truth_u <= inv.high_u
        half = 0.25 * (inv.high_u - inv.low_u)
        hits_half += inv.estimate_u - half <= truth_u <= inv.estimate_u + half
        widths.append(inv.high_u - inv.low_u)
    return hits / draws, hits_half / draws, float(np.median(widths))


def test_crossings_of_known_curves():
    grid = np.linspace(0, 1, 11)
    curves = np.array([grid * 10, 10 - grid * 10, grid * 10])
    c = crossings(curves, grid, [2.5, 2.5, 20.0], increasing=True)
    assert c[0] == pytest.approx(0.25)
    assert c[2] == np.inf                      # never reaches 20 within the bounds
    c = crossings(curves[1:2], grid, [2.5], increasing=False)
    assert c[0] == pytest.approx(0.75)
    # a noisy curve is rearranged (sorted) before crossing: one crossing, not three
    wiggly = np.array([[0.0, 3.0, 1.0, 2.0, 4.0]])
    assert crossings(wiggly, np.linspace(0, 1, 5), [2.5], True)[0] == pytest.approx(0.625)


def test_estimate_lands_on_the_root_of_a_linear_response():
    rng = np.random.default_rng(7)
    u = np.repeat([0.2, 0.4, 0.6, 0.8], 3)
    y = 20 + 40 * u + 0.5 * rng.standard_normal(len(u))
    inv = invert(ResponseModel(u[:, None], y), 38.0, True)
    assert inv.estimate_u == pytest.approx(0.45, abs=0.01)
    assert inv.low_u < 0.45 < inv.high_u and inv.high_u - inv.low_u < 0.05
    assert inv.p_below == 0 and inv.p_above == 0


def test_estimate_lands_on_the_root_of_a_falling_curve():
    u = np.repeat(np.linspace(0.0, 1.0, 6), 3)
    f = lambda v: 100 * np.exp(-3 * v)
    y = f(u) * (1 + 0.01 * np.random.default_rng(8).standard_normal(len(u)))
    inv = invert(ResponseModel(u[:, None], y), 30.0, increasing=False)
    assert inv.estimate_u == pytest.approx(-math.log(0.3) / 3, abs=0.02)


def test_a_target_beyond_the_bounds_is_said_so():
    u = np.repeat([0.5, 0.9, 1.0], 3)
    y = 20 + 10 * u + 0.3 * np.random.default_rng(9).standard_normal(len(u))
    inv = invert(ResponseModel(u[:, None], y), 60.0, True)
    assert inv.p_above > 0.975 and inv.estimate_u == 1.0


def test_lab_band_range_is_where_the_mean_response_is_within_the_band():
    u = np.repeat([0.2, 0.4, 0.6, 0.8], 3)
    y = 20 + 40 * u + 0.2 * np.random.default_rng(10).standard_normal(len(u))
    inv = invert(ResponseModel(u[:, None], y), 38.0, True, band=2.0)
    assert inv.band_low_u == pytest.approx(0.40, abs=0.01) and inv.band_high_u == pytest.approx(0.50, abs=0.01)


def test_coverage_on_a_straight_line():
    """AoR-like: 20 + 40 u deg, seed noise 3 deg, 4 points x 3 seeds; root at u = 0.45."""
    cov, cov_half, width = coverage(lambda u: 20 + 40 * u, np.array([0.2, 0.35, 0.5, 0.65]), 3, 3.0, 38.0, 0.45)
    print(f"straight line: coverage {cov:.3f} (halved interval {cov_half:.3f}), median width {width:.3f}")
    assert 0.90 <= cov <= 0.99
    assert cov_half <= cov - 0.05   # an interval half as wide loses coverage: the test can tell
    assert width < 0.35


def test_coverage_on_a_saturating_curve():
    """45 - 25 exp(-3 u), noise 2, 4 points x 3 seeds not centred on the root (0.43)."""
    truth = -math.log((45 - 38) / 25) / 3
    cov, cov_half, width = coverage(lambda u: 45 - 25 * np.exp(-3 * u), np.array([0.1, 0.3, 0.45, 0.6]), 3,
                                    2.0, 38.0, truth)
    print(f"saturating curve: coverage {cov:.3f} (halved interval {cov_half:.3f}), median width {width:.3f}")
    assert 0.90 <= cov <= 0.99
    assert cov_half <= cov - 0.05


def test_the_targets_own_95_percent_range_is_the_table_value():
    """Student-t quantiles from the tables: 4.303 (2 degrees of freedom), 2.262 (9); normal 1.960."""
    assert target_factor_95(2) == pytest.approx(4.303, abs=1e-3)
    assert target_factor_95(9) == pytest.approx(2.262, abs=1e-3)
    assert target_factor_95() == pytest.approx(1.960, abs=1e-3)


def test_a_standard_error_estimated_from_three_seeds_needs_the_student_t():
    """A twin's target is the mean of 3 seeds and its standard error the sample SD / sqrt(3):
    with a well-pinned curve the interval is the target's, and only a Student-t with 2
    degrees of freedom covers the truth 95 % of the time (a normal draw: 81 % in theory,
    P(|t_2| < 1.96); 77 % measured on these draws)."""
    rng = np.random.default_rng(7)
    u = np.repeat(np.array([0.3, 0.4, 0.5, 0.6]), 4)
    hits = {2: 0, math.inf: 0}
    for k in range(DRAWS):
        y = 20 + 40 * u + 0.3 * rng.standard_normal(len(u))
        seeds = 38.0 + 4.0 * rng.standard_normal(3)            # the 3 target seeds around the truth (u 0.45)
        se = float(np.std(seeds, ddof=1) / math.sqrt(3))
        model = ResponseModel(u[:, None], y)
        for dof in hits:
            inv = invert(model, float(seeds.mean()), True, standard_error=se, standard_error_dof=dof,
                         rng=np.random.default_rng(k), draws=800)
            hits[dof] += inv.low_u <= 0.45 <= inv.high_u
    cov_t, cov_normal = hits[2] / DRAWS, hits[math.inf] / DRAWS
    print(f"target SE from 3 seeds: coverage {cov_t:.3f} with the Student-t, {cov_normal:.3f} with a normal")
    assert 0.90 <= cov_t <= 0.99
    assert cov_normal <= 0.88


def test_coverage_when_the_target_is_itself_a_noisy_mean():
    """A twin's target is the mean of a few seeds: its standard error must widen the interval."""
    cov, _, _ = coverage(lambda u: 20 + 40 * u, np.array([0.3, 0.45, 0.6]), 4, 2.0, 38.0, 0.45, target_se=1.5)
    print(f"noisy target: coverage {cov:.3f}")
    assert 0.90 <= cov <= 0.99
