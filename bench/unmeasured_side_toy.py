"""Which side of the interval to measure first: the old rule (the lower side first) against
the new one (the side the model bridges farther) on a toy of the wet cohesion stage.

    /usr/bin/python3 bench/unmeasured_side_toy.py [--draws 100] [--budget 36]

Toy: response = -10 + 36 (x / 0.1)^2 deg (flat near 0, rising to +26 at 0.1, as the main job's
wet internal-friction angle offset against the pull-off pressure fraction), seed noise 7 deg,
target 0 (root 0.0527), tolerance 0.02, 3 runs per point, start 0.1 then 0 (as the stage),
then pycal.stats.sequential.step_1d until it stops. Prints, per rule, the mean runs, how
many draws met the tolerance, how many intervals hold the root, and the RMS estimate error.
Pure maths, no YADE (a few seconds per 10 draws).
"""
import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from pycal.stats import stopping  # noqa: E402
from pycal.stats.scales import Scale, round_significant  # noqa: E402
from pycal.stats.sequential import step_1d  # noqa: E402

ROOT = 0.1 * math.sqrt(10 / 36)


def response(x):
    return -10 + 36 * (x / 0.1) ** 2


def lower_side_first(estimate, low, high, points):
    """The rule before 2026-12-03: the lower side whenever it has no point inside the interval."""
    if not any(low <= x <= estimate for x in points):
        return -1
    if not any(estimate <= x <= high for x in points):
        return 1
    return 0


def run_stage(draw, budget):
    """(runs, met, interval holds the root, estimate) of one simulated stage."""
    rng = np.random.default_rng(draw)
    xs, ys = [], []

    def point(x):
        for _ in range(3):
            xs.append(x)
            ys.append(response(x) + 7 * rng.standard_normal())
    point(0.1)
    point(0.0)
    while True:
        st = step_1d(Scale(0.0, 0.5), xs, ys, 0.0, True, tolerance=0.02, band=5.0,
                     runs_left=budget - len(xs), runs_per_point=3)
        if st.stop:
            return len(xs), st.stop == stopping.WITHIN, st.low <= ROOT <= st.high, st.estimate
        point(round_significant(st.next_x))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=100)
    ap.add_argument("--budget", type=int, default=36)
    a = ap.parse_args(argv)
    new_rule = stopping.unmeasured_side
    print("| rule | runs (mean) | met | interval holds the root | RMS estimate error |")
    print("|---|---|---|---|---|")
    for name, rule in (("lower side first (old)", lower_side_first), ("wider bridge first (new)", new_rule)):
        stopping.unmeasured_side = rule
        try:
            res = [run_stage(d, a.budget) for d in range(a.draws)]
        finally:
            stopping.unmeasured_side = new_rule
        rms = math.sqrt(np.mean([(r[3] - ROOT) ** 2 for r in res]))
        print(f"| {name} | {np.mean([r[0] for r in res]):.1f} | {sum(r[1] for r in res)} of {a.draws} | "
              f"{sum(r[2] for r in res)} | {rms:.4f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
