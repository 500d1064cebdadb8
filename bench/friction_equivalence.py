"""Is a cheaper friction-rig setting equivalent? Before/after on the same seeds.

    /usr/bin/python3 bench/friction_equivalence.py RUNS_DIR --rig internal_friction \
        --parameter interactions.M3-dry.friction_coefficient \
        --baseline contact.youngs_modulus_pa=1e8 [--out table.md]

Reads every result.json of RUNS_DIR/<rig>/ (runs made with `pycal run ... --seeds 6`),
groups them by their overrides: the runs whose overrides hold every --baseline KEY=VALUE
are the baseline ("before"), every other set of overrides is a candidate ("after"); runs
pair by the value of --parameter (the calibrated value, two or more values) and seed.
For each parameter value and candidate it prints, per consolidation step and for the
mean over the steps >= 10 kPa (what the friction stages compare with the lab):
mu_static mean and seed SD before and after, the difference of the means and its
standard error (sqrt(SE_before^2 + SE_after^2): the fills of two settings are not the same
packings, so no pairing is assumed), whether the difference is within one and two
standard errors, the steps where the cell stuck, and the median CPU seconds per run
(provenance cpu_time_s) with the ratio after / before.
"""
import argparse
import json
import math
import statistics
import sys
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from pycal.files import write_text  # noqa: E402
from pycal.runs_index import ok_results  # noqa: E402

MIN_STRESS_PA = 10000.0


def parse_value(text):
    """A --baseline value as pycal's --set reads it: a number if it is one (1e8), else YAML."""
    try:
        return float(text)
    except ValueError:
        return yaml.safe_load(text)


def load_runs(runs_dir, rig):
    return [r for _, r in ok_results(runs_dir, rig)]


def key_of(overrides, parameter):
    """The setting of a run: its overrides without the parameter (a hashable string)."""
    return json.dumps({k: v for k, v in sorted(overrides.items()) if k != parameter}, sort_keys=True)


def mean_sd_se(xs):
    xs = [x for x in xs if x is not None]
    if not xs:
        return None, None, None
    m = statistics.fmean(xs)
    sd = statistics.stdev(xs) if len(xs) > 1 else float("nan")
    return m, sd, sd / math.sqrt(len(xs))


def step_values(r):
    """{stress Pa: mu_static or None}, the stage response (mean mu over >= 10 kPa, None if
    a step stuck) and the stuck steps."""
    vals = dict(zip(r["stress_pa"], r["mu_static"]))
    stuck = [s for s, st in zip(r["stress_pa"], r["sticks"]) if st]
    used = [v for s, v in vals.items() if s >= MIN_STRESS_PA]
    mean = statistics.fmean(used) if used and all(v is not None for v in used) and not stuck else None
    return vals, mean, stuck


def compare(before, after):
    """Rows (label, before mean, SD, after mean, SD, diff, SE) per step and the mean."""
    rows = []
    stresses = sorted({s for r in before + after for s in r["stress_pa"]})
    labels = [(f"{s / 1e3:g} kPa", lambda r, s=s: step_values(r)[0].get(s)) for s in stresses]
    labels.append(("mean >= 10 kPa", lambda r: step_values(r)[1]))
    for label, get in labels:
        mb, sdb, seb = mean_sd_se([get(r) for r in before])
        ma, sda, sea = mean_sd_se([get(r) for r in after])
        if mb is None or ma is None:
            rows.append((label, mb, sdb, ma, sda, None, None))
            continue
        rows.append((label, mb, sdb, ma, sda, ma - mb, math.hypot(seb, sea)))
    return rows


def fmt(x, nd=3):
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{nd}f}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs")
    ap.add_argument("--rig", required=True)
    ap.add_argument("--parameter", required=True, help="the calibrated key whose values pair the runs")
    ap.add_argument("--baseline", action="append", default=[], metavar="KEY=VALUE",
                    help="overrides that mark the baseline runs (repeatable)")
    ap.add_argument("--out", default=None, help="also write the table (markdown) here")
    args = ap.parse_args(argv)
    base = {k: parse_value(v) for k, v in (b.split("=", 1) for b in args.baseline)}
    runs = load_runs(args.runs, args.rig)
    groups = {}
    for r in runs:
        ov = r["job"]["overrides"]
        groups.setdefault((ov.get(args.parameter), key_of(ov, args.parameter)), []).append(r)
    lines = [f"| {args.parameter} | setting (overrides) | seeds | response | before mean (SD) | after mean (SD) | "
             f"after - before +- SE | within 1 SE / 2 SE | stuck steps before / after | CPU s per run median "
             f"before / after (ratio) |", "|---|---|---|---|---|---|---|---|---|---|"]
    for (value, setting), members in sorted(groups.items(), key=lambda kv: (kv[0][0], kv[0][1])):
        ov = json.loads(setting)
        if all(ov.get(k) == v for k, v in base.items()):
            continue
        before = next((m for (v, s), m in groups.items() if v == value
                       and all(json.loads(s).get(k) == bv for k, bv in base.items())), None)
        if before is None:
            continue
        seeds = sorted({r["seed"] for r in members} & {r["seed"] for r in before})
        b = [r for r in before if r["seed"] in seeds]
        a = [r for r in members if r["seed"] in seeds]
        cpu_b = statistics.median(r["provenance"]["cpu_time_s"] for r in b)
        cpu_a = statistics.median(r["provenance"]["cpu_time_s"] for r in a)
        stuck_b = sum(len(step_values(r)[2]) for r in b)
        stuck_a = sum(len(step_values(r)[2]) for r in a)
        shown = ", ".join(f"{k}={v}" for k, v in ov.items() if base.get(k) != v and k not in
                          ("rig.procedure.consolidation_stresses_pa",))
        for k, (label, mb, sdb, ma, sda, d, se) in enumerate(compare(b, a)):
            verdict = "-" if d is None else f"{'yes' if abs(d) <= se else 'no'} / {'yes' if abs(d) <= 2 * se else 'no'}"
            lines.append(f"| {value} | {shown if k == 0 else ''} | {len(seeds) if k == 0 else ''} | {label} | "
                         f"{fmt(mb)} ({fmt(sdb)}) | {fmt(ma)} ({fmt(sda)}) | "
                         f"{'-' if d is None else f'{d:+.3f} +- {se:.3f}'} | {verdict} | "
                         + (f"{stuck_b} / {stuck_a} | {cpu_b:.0f} / {cpu_a:.0f} ({cpu_a / cpu_b:.2f}) |" if k == 0
                            else "| |"))
    text = "\n".join(lines)
    print(text)
    if args.out:
        write_text(Path(args.out), text + "\n")      # atomic, the project's writer


if __name__ == "__main__":
    main()
