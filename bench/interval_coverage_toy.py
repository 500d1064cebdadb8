"""How often a one-parameter stage's 95 % interval holds the root, at a fixed design, on
the curved toy of bench/unmeasured_side_toy.py (no sequential stop: the model alone).

    /usr/bin/python3 bench/interval_coverage_toy.py [--draws 100] [--design 0.1,0,0.03,0.05,0.07]
        [--extra-bends]

3 runs per point, seed noise 7 deg, response -10 + 36 (x / 0.1)^2 deg on bounds [0, 0.5],
target 0 (root 0.0527). Prints the coverage, the mean half-width and the mean estimate
error (bias). --extra-bends adds two large short bends (variance 3.0 at length 0.15 and
0.3 in u) to the response model's grid (pycal.stats.gp.BENDS) for this run only.
Pure maths, no YADE.
"""
import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import pycal.stats.gp as gp  # noqa: E402
from pycal.stats.scales import Scale  # noqa: E402
from pycal.stats.sequential import step_1d  # noqa: E402
from unmeasured_side_toy import ROOT, response  # noqa: E402  (one toy curve for both benches)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=100)
    ap.add_argument("--design", default="0.1,0,0.03,0.05,0.07")
    ap.add_argument("--extra-bends", action="store_true")
    a = ap.parse_args(argv)
    if a.extra_bends:
        gp.BENDS = gp.BENDS + ((3.0, 0.15), (3.0, 0.3))
    design = [float(v) for v in a.design.split(",")]
    hits, half, err = 0, [], []
    for d in range(a.draws):
        rng = np.random.default_rng(d)
        xs = [x for x in design for _ in range(3)]
        ys = [response(x) + 7 * rng.standard_normal() for x in xs]
        st = step_1d(Scale(0.0, 0.5), xs, ys, 0.0, True, tolerance=0.02, runs_left=0)
        hits += st.low <= ROOT <= st.high
        half.append(0.5 * (st.high - st.low))
        err.append(st.estimate - ROOT)
    print(f"design {design}, {'extra bends' if a.extra_bends else 'shipped bends'}: the interval holds the root "
          f"in {hits} of {a.draws}; mean half-width {np.mean(half):.4f}; mean estimate - root {np.mean(err):+.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
