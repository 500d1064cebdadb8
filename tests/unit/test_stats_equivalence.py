"""pycal.stats.equivalence on toy numbers with known answers."""
import random

import pytest

from pycal.stats import equivalence as eq


def test_the_interval_uses_students_t():
    low, high = eq.shift_interval(0.0, 1.0, 5)
    assert high == pytest.approx(2.5706, abs=1e-4) and low == pytest.approx(-2.5706, abs=1e-4)
    low, high = eq.shift_interval(1.0, 0.5, 10_000)
    assert (low, high) == (pytest.approx(1.0 - 0.98, abs=1e-3), pytest.approx(1.0 + 0.98, abs=1e-3))
    with pytest.raises(ValueError):
        eq.shift_interval(0.0, 1.0, 0)


def test_paired_shift_of_known_differences():
    mean, se, dof = eq.paired_shift([1.0, 2.0, 3.0, 4.0], [1.1, 2.3, 3.1, 4.3])
    assert mean == pytest.approx(0.2) and dof == 3
    assert se == pytest.approx(0.11547 / 2, abs=1e-5)          # SD of (0.1, 0.3, 0.1, 0.3) = 0.11547
    with pytest.raises(ValueError):
        eq.paired_shift([1.0], [1.0])


def test_the_margin_is_a_fifth_of_the_tolerance_through_the_slope():
    assert eq.margin(0.05, 0.45) == pytest.approx(0.0045)
    assert eq.margin(0.05, -2.0) == pytest.approx(0.02)


def test_a_small_bias_measured_precisely_is_equivalent_a_large_one_measured_badly_is_not():
    precise = eq.judge(0.002, 0.0005, 5, tolerance=0.05, slope=1.0)   # interval [0.0007, 0.0033] in +-0.01
    assert precise["equivalent"]
    noisy = eq.judge(0.0, 0.02, 5, tolerance=0.05, slope=1.0)         # within one SE, interval +-0.05
    assert not noisy["equivalent"]
    edge = eq.judge(0.0, 0.01 / 2.5706, 5, tolerance=0.05, slope=1.0)
    assert edge["high"] == pytest.approx(0.01, abs=1e-6) and edge["low_parameter"] == pytest.approx(-0.01, abs=1e-6)


def test_coverage_on_simulated_paired_seeds():
    """A cheaper setting with no real shift and seed noise SD 0.004 on 6 seeds is judged
    equivalent against a margin of 0.01 nearly always; one with a true shift of 0.012 almost never."""
    rng = random.Random(7)

    def trial(shift):
        base = [rng.gauss(0.5, 0.05) for _ in range(6)]
        after = [b + shift + rng.gauss(0.0, 0.004) for b in base]
        m, se, dof = eq.paired_shift(base, after)
        return eq.judge(m, se, dof, tolerance=0.05, slope=1.0)["equivalent"]

    assert sum(trial(0.0) for _ in range(400)) / 400 > 0.95
    assert sum(trial(0.012) for _ in range(400)) / 400 < 0.05
