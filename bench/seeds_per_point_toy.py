"""Seeds per point: 3 against 2 on toy stages with the study's noise (issue 27 item 5).

    /usr/bin/python3 bench/seeds_per_point_toy.py [--draws 20] [--cases wall,wall_noisy,aor,cohesion,wet_wall]

Each toy runs the study's own decisions (pycal.stats.sequential: the second point, then
step_1d / step_nd until a stop rule) on a response known in closed form, with Gaussian
seed noise, from the stage's start, with its tolerance and run budget; the only change
between the two rows of a case is the number of seeds run at each point. Prints, per case
and seeds count: mean runs to the stop, how many draws met the tolerance, how many 95 %
intervals hold the true value, and the RMS and largest estimate error (parameter units).
Pure maths, no YADE (about a minute per case at 20 draws).

Cases (responses as the main jobs measured them):
- wall: mu_bulk - lab = x - 0.514 (slope 1 per unit of particle-steel friction, the start 0.5
  reads 0.014 low: M2's wall stage), seed SD 0.02, tolerance 0.05, budget 18, Newton second point;
- wall_noisy: the same with seed SD 0.04 (the dry fines' wall cell at particle friction 0.5);
- aor: AoR = 48 - 28 exp(-2.5 x) deg against rolling resistance x, target 38, seed SD 4 deg,
  tolerance 0.05, budget 36 (the rolling stages);
- cohesion: a cell that starts to hang on: 90 / (1 + exp(-(x - 0.1) / 0.02)) - 30 deg against
  the pull-off pressure fraction, target 0, seed SD 8 deg, tolerance 0.02, budget 18;
- wall_bent, wall_bent_slope06: the wall cell as two main jobs measured it (b7c959b, seed bases 1 and
  101): mu_bulk - lab = 0.6 (x - 0.555) up to x = 0.65, slope 0.35 above, seed SD 0.03; the Newton
  second point assumes the config's slope 1.0, or the measured 0.6 (2 seeds per point in both rows);
- wet_wall: the joint stage over fines-steel friction f and adhesion p: mu(s) = f + 3e-4 p s at
  12 / 40 / 90 kPa, lab 0.40 + 3.5e-6 s (truth f 0.40, p 0.01167), seed SD 0.01, tolerances
  0.05 / 0.004, budget 36, start (0.5, 0.005) and a tenth of the bounds per parameter.
"""
import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from pycal.stats import stopping  # noqa: E402
from pycal.stats.scales import Scale, round_significant  # noqa: E402
from pycal.stats.sequential import second_point_u, step_1d, step_nd  # noqa: E402


def _wall_bent(x):
    """The measured wall-cell response (mu offset) against particle-steel friction x: slope 0.6
    through the root 0.555 up to the knee 0.65, 0.35 above."""
    x = np.asarray(x, dtype=float)
    return np.where(x < 0.65, 0.6 * (x - 0.555), 0.6 * (0.65 - 0.555) + 0.35 * (x - 0.65))


CASES_1D = {   # name: response, scale, start, target, seed SD, tolerance, budget, truth, slope (per unit of x) or None
    "wall": (lambda x: x - 0.514, Scale(0.05, 1.2), 0.5, 0.0, 0.02, 0.05, 18, 0.514, 1.0),
    "wall_noisy": (lambda x: x - 0.514, Scale(0.05, 1.2), 0.5, 0.0, 0.04, 0.05, 18, 0.514, 1.0),
    "aor": (lambda x: 48 - 28 * np.exp(-2.5 * x), Scale(0.02, 1.5), 0.35, 38.0, 4.0, 0.05, 36,
            -math.log(10 / 28) / 2.5, None),
    "cohesion": (lambda x: 90 / (1 + np.exp(-(x - 0.1) / 0.02)) - 30, Scale(0.0, 0.5), 0.1, 0.0, 8.0, 0.02, 18,
                 0.1 + 0.02 * math.log(30 / 60), None),
    "wall_bent": (_wall_bent, Scale(0.05, 1.2), 0.5, 0.0, 0.03, 0.05, 18, 0.555, 1.0),
    "wall_bent_slope06": (_wall_bent, Scale(0.05, 1.2), 0.5, 0.0, 0.03, 0.05, 18, 0.555, 0.6),
}
STRESSES_PA = np.array([12000.0, 40000.0, 90000.0])
WET_TRUTH = (0.40, 3.5e-6 / 3e-4)


def run_1d(case, seeds, rng):
    """One toy 1-D stage: (estimate, low, high, stop, runs)."""
    f, scale, x0, target, sd, tol, budget, _, slope = case
    xs, ys = [], []

    def run(x):
        x = round_significant(x)
        xs.extend([x] * seeds)
        ys.extend(f(x) + sd * rng.standard_normal(seeds))

    run(x0)
    slope_u = slope * (scale.hi - scale.lo) if slope else None
    run(float(scale.from_unit(second_point_u(float(scale.to_unit(x0)), float(np.mean(ys)), target, True, slope_u))))
    while True:
        st = step_1d(scale, xs, ys, target, True, tolerance=tol, runs_left=budget - len(xs), runs_per_point=seeds)
        if st.stop:
            return st.estimate, st.low, st.high, st.stop, len(xs)
        if xs.count(round_significant(st.next_x)) >= 3 * seeds:
            return st.estimate, st.low, st.high, stopping.REPEATS, len(xs)
        run(st.next_x)


def run_wet_wall(seeds, rng, budget=36):
    """One toy wet-wall joint stage: ([estimates], [lows], [highs], stop, runs)."""
    scales = [Scale(0.05, 1.2), Scale(0.0, 0.05)]
    X, Y = [], []

    def run(x):
        x = [round_significant(v) for v in x]
        for _ in range(seeds):
            X.append(x)
            Y.append(x[0] + 3e-4 * x[1] * STRESSES_PA + 0.01 * rng.standard_normal(len(STRESSES_PA)))

    start = [0.5, 0.005]
    run(start)
    for j, s in enumerate(scales):          # one step per parameter, a tenth of its bounds inwards
        u = [float(sc.to_unit(v)) for sc, v in zip(scales, start)]
        u[j] += 0.1 if u[j] <= 0.5 else -0.1
        run([float(sc.from_unit(v)) for sc, v in zip(scales, u)])
    lab = 0.40 + 3.5e-6 * STRESSES_PA
    while True:
        st = step_nd(scales, X, Y, list(lab), [0.0] * len(lab), [(0.05, False), (0.004, False)],
                     runs_left=budget - len(X), runs_per_point=seeds, seed=len(X))
        if st.stop:
            return st.estimate, st.low, st.high, st.stop, len(X)
        run(st.next_x)


def summarise(name, seeds, results, truth):
    """One table row from the draws of a case."""
    est = np.array([r[0] for r in results], dtype=float).reshape(len(results), -1)
    low = np.array([r[1] for r in results], dtype=float).reshape(est.shape)
    high = np.array([r[2] for r in results], dtype=float).reshape(est.shape)
    truth = np.array(truth, dtype=float).reshape(1, -1)
    held = np.all((low <= truth) & (truth <= high), axis=1).sum()
    met = sum(r[3] == stopping.WITHIN for r in results)
    err = est - truth
    rms = " / ".join(f"{v:.4f}" for v in np.sqrt(np.mean(err ** 2, axis=0)))
    worst = " / ".join(f"{v:.4f}" for v in np.max(np.abs(err), axis=0))
    runs = np.mean([r[4] for r in results])
    return f"| {name} | {seeds} | {runs:.1f} | {met} of {len(results)} | {held} of {len(results)} | {rms} | {worst} |"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=20)
    ap.add_argument("--cases", default="wall,wall_noisy,aor,cohesion,wet_wall")
    ap.add_argument("--seeds", default="3,2", help="seeds per point to compare (default 3,2)")
    args = ap.parse_args(argv)
    print("| case | seeds per point | runs to the stop, mean | met | interval holds the truth | RMS error | largest error |")
    print("|---|---|---|---|---|---|---|")
    for name in args.cases.split(","):
        for seeds in (int(v) for v in args.seeds.split(",")):
            if name == "wet_wall":
                res = [run_wet_wall(seeds, np.random.default_rng(d)) for d in range(args.draws)]
                truth = WET_TRUTH
            else:
                res = [run_1d(CASES_1D[name], seeds, np.random.default_rng(d)) for d in range(args.draws)]
                truth = CASES_1D[name][7]
            print(summarise(name, seeds, res, truth), flush=True)


if __name__ == "__main__":
    main()
