"""Which pile reading is most precise in the parameter's units? (issue 27, item 4)

    /usr/bin/python3 bench/aor_reading.py RUNS_DIR [--choose-seeds 12] [--out table.md]

RUNS_DIR holds aor runs of one material at two rolling-resistance values (e.g.
`pycal run aor --material M2 --set interactions.M2.rolling_resistance_coefficient=0.2 ...
--seeds 24`). Every candidate of pycal.post.aor_readings is computed from each run's
pile_particles.csv with the rig's `measure:` settings of the job. Per candidate and
rolling value: mean and seed SD; the slope of the mean with the rolling resistance;
the precision = pooled seed SD / |slope| (in rolling-resistance units: the smaller, the
fewer seeds a stage needs; seeds needed for a +-0.05 interval ~ (1.96 x precision /
0.05)^2). The reading is chosen on the first --choose-seeds seeds and checked on the rest.
"""
import argparse
import math
import statistics
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from pycal.post.aor import read_positions_csv  # noqa: E402
from pycal.post.aor_readings import READINGS  # noqa: E402
from pycal.runs_index import ok_results  # noqa: E402
from pycal.files import write_text  # noqa: E402

ETA_KEY = "interactions.M2.rolling_resistance_coefficient"


def load(runs_dir, eta_key=ETA_KEY):
    """{(eta, seed): {reading: angle}} over the aor runs of RUNS_DIR."""
    out = {}
    for row, one in ok_results(runs_dir, "aor"):
        eta = one["job"]["overrides"].get(eta_key)
        m = one["job"]["rig_config"]["measure"]
        pos = read_positions_csv(Path(row["folder"]) / "pile_particles.csv")
        out[(eta, one["seed"])] = {name: f(pos, m) for name, f in READINGS.items()}
    return out


def precision(values, seeds):
    """{reading: (means by eta, pooled SD, slope per unit eta, precision in eta units)}."""
    etas = sorted({e for e, _ in values})
    if len(etas) != 2:
        raise SystemExit(f"aor_reading: need runs at two rolling values, found {etas}")
    out = {}
    for name in READINGS:
        groups = {e: [values[(e, s)][name] for s in seeds if (e, s) in values
                      and not math.isnan(values[(e, s)][name])] for e in etas}
        means = {e: statistics.fmean(v) for e, v in groups.items()}
        sds = {e: statistics.stdev(v) for e, v in groups.items()}
        pooled = math.sqrt(sum(sds[e] ** 2 * (len(groups[e]) - 1) for e in etas)
                           / sum(len(groups[e]) - 1 for e in etas))
        slope = (means[etas[1]] - means[etas[0]]) / (etas[1] - etas[0])
        out[name] = (means, sds, {e: len(groups[e]) for e in etas}, pooled, slope,
                     pooled / abs(slope) if slope else math.inf)
    return out


def table(title, prec):
    lines = [f"**{title}**", "", "| reading | mean (SD, n) at each rolling value | pooled seed SD deg | slope deg per unit "
             "| precision (SD / slope) | seeds for +-0.05 |", "|---|---|---|---|---|---|"]
    for name, (means, sds, ns, pooled, slope, p) in sorted(prec.items(), key=lambda kv: kv[1][5]):
        at = "; ".join(f"{e}: {means[e]:.1f} ({sds[e]:.1f}, {ns[e]})" for e in means)
        lines.append(f"| {name} | {at} | {pooled:.2f} | {slope:.1f} | {p:.3f} | {(1.96 * p / 0.05) ** 2:.0f} |")
    return lines + [""]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs")
    ap.add_argument("--choose-seeds", type=int, default=12)
    ap.add_argument("--eta-key", default=ETA_KEY)
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    values = load(args.runs, args.eta_key)
    seeds = sorted({s for _, s in values})
    choose, check = seeds[:args.choose_seeds], seeds[args.choose_seeds:]
    lines = table(f"seeds {choose[0]}-{choose[-1]} (choose)", precision(values, choose))
    if check:
        lines += table(f"seeds {check[0]}-{check[-1]} (check)", precision(values, check))
    # the within-pile scatter of the rig's reading: how far the frame moves the mean
    shifts = [values[k]["rotated_sector_mean"] - values[k]["sector_mean"] for k in values
              if not math.isnan(values[k]["sector_mean"]) and not math.isnan(values[k]["rotated_sector_mean"])]
    lines.append(f"sector_mean - rotated_sector_mean on the same piles: RMS {float(np.sqrt(np.mean(np.square(shifts)))):.2f} "
                 f"deg over {len(shifts)} piles")
    text = "\n".join(lines)
    print(text)
    if args.out:
        write_text(Path(args.out), text + "\n")      # atomic, the project's writer


if __name__ == "__main__":
    main()
