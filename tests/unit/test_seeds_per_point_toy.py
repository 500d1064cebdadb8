"""bench/seeds_per_point_toy.py: the toy stages land on their known roots, and two seeds per
point need fewer runs than three on the wall stage's line (the study's seeds_count)."""
import numpy as np

from bench_scripts import load_bench_script


def test_two_seeds_per_point_reach_the_wall_root_with_fewer_runs():
    toy = load_bench_script("seeds_per_point_toy")
    case = toy.CASES_1D["wall"]
    three = [toy.run_1d(case, 3, np.random.default_rng(d)) for d in range(6)]
    two = [toy.run_1d(case, 2, np.random.default_rng(d)) for d in range(6)]
    assert all(abs(r[0] - 0.514) < 0.05 for r in three + two)        # within the tolerance of the root
    assert np.mean([r[4] for r in two]) < np.mean([r[4] for r in three]) - 1.5


def test_the_table_row_counts_met_and_held_draws():
    toy = load_bench_script("seeds_per_point_toy")
    rows = [(0.51, 0.50, 0.52, "interval within tolerance", 9), (0.60, 0.55, 0.65, "run budget spent", 18)]
    row = toy.summarise("wall", 2, rows, 0.514)
    assert row.startswith("| wall | 2 | 13.5 | 1 of 2 | 1 of 2 |")


def test_the_bent_wall_toy_lands_on_its_root_whatever_the_slope_estimate():
    toy = load_bench_script("seeds_per_point_toy")
    assert abs(float(toy._wall_bent(0.555))) < 1e-12 and float(toy._wall_bent(1.0)) > 0.1
    for name in ("wall_bent", "wall_bent_slope06"):
        runs = [toy.run_1d(toy.CASES_1D[name], 2, np.random.default_rng(d)) for d in range(4)]
        assert all(abs(r[0] - 0.555) < 0.05 for r in runs)
