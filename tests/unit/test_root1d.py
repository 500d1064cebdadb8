"""Noise-aware monotone root finding."""
import math
import random

import pytest

from pycal.calibration.root1d import solve_monotone, effective_tolerance, Point


def response(f, noise=0.0, n=3, seed=0):
    rng = random.Random(seed)

    def evaluate(x):
        vals = [f(x) + rng.gauss(0, noise) for _ in range(n)]
        m = sum(vals) / n
        s = math.sqrt(sum((v - m) ** 2 for v in vals) / (n - 1)) if n > 1 else 0.0
        return m, s, n
    return evaluate


def test_increasing_response_is_solved():
    # angle of repose rising with rolling resistance: 20 + 40 * eta
    sol = solve_monotone(response(lambda x: 20 + 40 * x), target=38.0, x0=0.35, lo=0.0, hi=1.0,
                         tolerance=0.5)
    assert sol.met and abs(sol.x - 0.45) < 0.0125 + 1e-9
    assert len(sol.history) <= 6


def test_decreasing_response_is_solved():
    sol = solve_monotone(response(lambda x: 100 * math.exp(-3 * x)), target=30.0, x0=0.1, lo=0.0,
                         hi=2.0, tolerance=0.3)
    assert sol.met and abs(100 * math.exp(-3 * sol.x) - 30) <= 0.3


def test_start_already_good():
    sol = solve_monotone(response(lambda x: 2 * x), target=1.0, x0=0.5, lo=0, hi=1, tolerance=0.01)
    assert sol.met and len(sol.history) == 1


def test_unreachable_target_is_reported():
    sol = solve_monotone(response(lambda x: 20 + 10 * x), target=60.0, x0=0.3, lo=0.0, hi=1.0,
                         tolerance=0.5)
    assert not sol.met and "beyond what the upper bound" in sol.message and sol.x == 1.0


def test_noise_widens_tolerance_and_still_converges():
    sol = solve_monotone(response(lambda x: 20 + 40 * x, noise=2.0, n=3, seed=4), target=38.0,
                         x0=0.2, lo=0.0, hi=1.0, tolerance=0.1, max_evaluations=10)
    assert sol.met
    assert effective_tolerance(sol.point, 0.1) > 0.1


def test_effective_tolerance():
    assert effective_tolerance(Point(0, 1, 3.0, 9), 0.5) == pytest.approx(2.0)
    assert effective_tolerance(Point(0, 1, 0.1, 9), 0.5) == 0.5


def test_known_direction_is_not_fooled_by_noise():
    # a noisy first pair would suggest a falling response; physics says it rises
    calls = iter([(23.7, 11.0, 3), (30.0, 5.0, 3), (42.1, 3.0, 3)])
    seen = []

    def evaluate(x):
        seen.append(x)
        return next(calls)
    sol = solve_monotone(evaluate, target=42.0, x0=0.35, lo=0.02, hi=1.5, tolerance=2.0,
                         increasing=True)
    assert all(b > a for a, b in zip(seen, seen[1:])) and sol.met


def test_slope_estimate_gives_a_newton_second_point():
    # wall friction of the bulk ~ 1.03 x particle-steel friction - 0.1: from 0.5 the
    # known slope lands the second point next to the root (a quarter of the bounds would
    # have gone to 0.79)
    seen = []

    def evaluate(x):
        seen.append(x)
        return 1.03 * x - 0.1 - 0.5, 0.01, 3      # offset from a lab plateau of 0.5
    sol = solve_monotone(evaluate, target=0.0, x0=0.5, lo=0.05, hi=1.2, tolerance=0.03,
                         increasing=True, slope_estimate=1.0)
    assert seen[1] == pytest.approx(0.5 + 0.085)
    assert sol.met and len(sol.history) == 2


def stiffness_rig(refuse_above_pa, seen):
    """M3-dry as measured: the CCS-expansion log ratio rises 0.38 per unit of ln E and
    reaches 0 near E = 2e8 Pa; the rig cannot hold its load above `refuse_above_pa`."""
    from pycal.errors import RunError

    def evaluate(u):
        seen.append(math.exp(u))
        if math.exp(u) > refuse_above_pa:
            raise RunError("load to 3000 Pa: not reached at rest after 8 s")
        return 0.38 * (u - math.log(2e8)), 0.04, 3
    return evaluate


def test_a_refused_point_backs_off_towards_the_last_point_that_ran():
    seen = []
    sol = solve_monotone(stiffness_rig(3e8, seen), target=0.0, x0=math.log(6e6), lo=math.log(1e6),
                         hi=math.log(1e9), tolerance=0.25, first_step=math.log(4.0), increasing=True,
                         show=lambda u: f"{math.exp(u):.3g}")
    assert any(e > 3e8 for e in seen), "the secant step should overshoot into the refused range"
    assert sol.met and 6e7 < math.exp(sol.x) <= 3e8
    assert all(p.x <= math.log(3e8) for p in sol.history)


def test_refusals_until_the_budget_ends_keep_the_best_point_that_ran():
    seen = []
    sol = solve_monotone(stiffness_rig(3e7, seen), target=0.0, x0=math.log(6e6), lo=math.log(1e6),
                         hi=math.log(1e9), tolerance=0.25, first_step=math.log(4.0), increasing=True,
                         max_evaluations=4, show=lambda u: f"{math.exp(u):.3g}")
    assert len(seen) == 4 and not sol.met
    assert math.exp(sol.x) == pytest.approx(max(e for e in seen if e <= 3e7))
    assert "the rig refused" in sol.message and "not reached at rest" in sol.message


def test_a_refused_start_point_raises():
    from pycal.errors import RunError
    with pytest.raises(RunError):
        solve_monotone(stiffness_rig(1e6, []), target=0.0, x0=math.log(6e6), lo=math.log(1e6),
                       hi=math.log(1e9), tolerance=0.25, increasing=True)
