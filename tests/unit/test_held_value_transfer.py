"""bench/held_value_transfer.py: the held-value ends as set overrides, and the paired change by seed."""
import math

import pytest

from bench_scripts import load_bench_script


@pytest.fixture(scope="module")
def hv():
    return load_bench_script("held_value_transfer")


def test_held_entry_and_the_keys_of_each_set(hv):
    label, keys, ends = hv.parse_held("friction=fines.interactions.fines.friction_coefficient;"
                                      "gravel.interactions.fines.friction_coefficient:0.3,0.7")
    assert label == "friction" and ends == (0.3, 0.7)
    assert hv.set_keys(keys, "M3-wet", 0.3) == {"M3-wet.interactions.M3-wet.friction_coefficient": 0.3,
                                                "M2.interactions.M3-wet.friction_coefficient": 0.3}
    with pytest.raises(SystemExit, match="LABEL=KEY"):
        hv.parse_held("no ends here")


def test_paired_change_by_seed(hv):
    base = [{"seed": 1, "x": 10.0}, {"seed": 2, "x": 20.0}, {"seed": 3, "x": 30.0}]
    moved = [{"seed": 2, "x": 21.0}, {"seed": 1, "x": 11.0}, {"seed": 3, "x": 33.0}]
    d, se = hv.paired(base, moved, "x")
    assert d == pytest.approx(5 / 3)
    assert se == pytest.approx(math.sqrt(((1 - 5 / 3) ** 2 * 2 + (3 - 5 / 3) ** 2) / 2) / math.sqrt(3))
