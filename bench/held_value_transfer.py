"""Does a held value matter for the design answer? The study's transfer runs (dry and wet -50 mm ore)
at both ends of a held value's plausible range, paired by seed with the runs as calibrated.

    /usr/bin/python3 bench/held_value_transfer.py RUNS_DIR --out runs/bench_held \
        --held 'particle friction=fines.interactions.fines.friction_coefficient:0.3,0.7' \
        [--held ...] [--workers 2] [--table-only] [--table table.md]

RUNS_DIR is a main job's runs folder (its application's transfer jobs, every seed). A --held entry is
'LABEL=KEY[;KEY...]:LOW,HIGH': each KEY is a component key of the material sets, where the word `fines`
stands for the set's fines (M3-dry in mixed-dry, M3-wet in mixed-wet) and `gravel` for M2; both ends are
run on the same seeds as the main job's (bench/rerun_with.py rebuilds each job with the keys added), into
--out (cached). Prints per set, held value and end: the impact stress on the footprint (kPa) and the
holdup 1 s after the feed stops (kg), mean (SD), the paired change from the runs as calibrated with its
standard error, and the seed SE of the runs as calibrated, so that a change can be set beside it.
"""
import argparse
import json
import math
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from rerun_with import rebuilt  # noqa: E402
from transfer_holdup import SETS, GRAVEL, jobs_of  # noqa: E402
from pycal.executors.jobdirs import cached_result  # noqa: E402
from pycal.executors.local import LocalPool  # noqa: E402
from pycal.files import write_text  # noqa: E402

RESPONSES = (("impact_stress_pa", "impact stress, kPa", 1e-3), ("holdup_mass_kg", "holdup, kg", 1.0))


def parse_held(text):
    """'LABEL=KEY;KEY:LOW,HIGH' -> (label, [keys], (low, high))."""
    try:
        label, rest = text.split("=", 1)
        keys, ends = rest.rsplit(":", 1)
        low, high = (float(x) for x in ends.split(","))
    except ValueError:
        raise SystemExit(f"--held {text!r}: must be LABEL=KEY[;KEY...]:LOW,HIGH") from None
    return label.strip(), [k.strip() for k in keys.split(";")], (low, high)


def set_keys(keys, fines, value):
    """The overrides of one end in a set whose fines are `fines`."""
    return {k.replace("fines", fines, 2).replace("gravel", GRAVEL, 2): value for k in keys}


def paired(base, moved, key):
    """(mean change, its SE) over the seeds both have."""
    by_seed = {r["seed"]: r[key] for r in base if r.get(key) is not None}
    diffs = [r[key] - by_seed[r["seed"]] for r in moved if r.get(key) is not None and r["seed"] in by_seed]
    if len(diffs) < 2:
        return math.nan, math.nan
    return statistics.mean(diffs), statistics.stdev(diffs) / math.sqrt(len(diffs))


def mean_sd_se(values):
    v = [x for x in values if x is not None]
    if len(v) < 2:
        return (v[0] if v else math.nan), math.nan, math.nan
    sd = statistics.stdev(v)
    return statistics.mean(v), sd, sd / math.sqrt(len(v))


def sweep(runs, out, helds, workers, run=True):
    """{(set, label, end): results}, end None = the main job's own runs (as calibrated)."""
    table = {}
    for material_set, fines in SETS.items():
        files = jobs_of(runs, material_set)
        base = [cached_result(json.loads(Path(f).read_text()), runs) for f in files]
        table[(material_set, None, None)] = [r for r in base if r is not None]
        for label, keys, ends in helds:
            for end in ends:
                jobs = [rebuilt(f, set_keys(keys, fines, end))[1] for f in files]
                if run:
                    print(f"[held] {material_set}: {label} = {end} ({len(jobs)} seeds)", flush=True)
                    res = LocalPool(runs_dir=out, workers=workers, progress=False).run(jobs, raise_on_error=False)
                else:
                    res = [cached_result(j, out) for j in jobs]
                table[(material_set, label, end)] = [r for r in res if r is not None]
    return table


def rows(table):
    lines = ["| set | held value = end | seeds | " + " | ".join(
        f"{name}: mean (SD) | change from as calibrated (+- SE)" for _, name, _ in RESPONSES) +
        " | seed SE as calibrated |", "|---" * (3 + 2 * len(RESPONSES) + 1) + "|"]
    for (material_set, label, end), res in table.items():
        base = table[(material_set, None, None)]
        cells, se_cells = [], []
        for key, _, factor in RESPONSES:
            m, sd, _ = mean_sd_se([factor * r[key] for r in res if r.get(key) is not None])
            cells.append(f"{m:.3g} ({sd:.2g})")
            if label is None:
                cells.append("-")
                se_cells.append(f"{factor * mean_sd_se([r.get(key) for r in base])[2]:.2g}")
            else:
                d, se = paired(base, res, key)
                cells.append(f"{factor * d:+.3g} (+- {factor * se:.2g})")
        name = "as calibrated (the main job's runs)" if label is None else f"{label} = {end:g}"
        lines.append(f"| {material_set} | {name} | {len(res)} | " + " | ".join(cells) + " | "
                     + (", ".join(se_cells) if se_cells else "") + " |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", help="a main job's runs folder (its transfer jobs)")
    ap.add_argument("--out", required=True, help="runs folder for the moved jobs")
    ap.add_argument("--held", action="append", required=True, help="LABEL=KEY[;KEY...]:LOW,HIGH")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--table-only", action="store_true")
    ap.add_argument("--table", default=None, help="also write the table (markdown) here")
    args = ap.parse_args(argv)
    helds = [parse_held(h) for h in args.held]
    text = rows(sweep(args.runs, args.out, helds, args.workers, run=not args.table_only))
    print(text)
    if args.table:
        write_text(Path(args.table), text + "\n")


if __name__ == "__main__":
    main()
