"""CPU and wall time per seed of a rig point, seeds run alone or as replicas of one batch,
with each seed's measurements (for before/after tables: same seeds, mean and standard
error).

    /usr/bin/python3 bench/seed_cost.py RIG --material M2 --seeds 1-8 [--set KEY=VALUE ...]
        [--mode lone|batch|both] [--replicas N] [--label TEXT] [--keys k1,k2]

Every run goes to a fresh temporary runs folder (nothing from the cache), one YADE
process at a time. CPU time = user + system time of the YADE processes (getrusage of the
children), which a loaded machine inflates far less than the wall time; the load average
is recorded next to it. Appends one JSON line per mode to bench/seed_cost.jsonl and
prints a table: per seed the chosen measurements (scalars; a list key gives its
values per step), then mean and standard error over the seeds, CPU s per seed and
seeds per CPU-hour.
"""
import argparse
import datetime
import json
import math
import os
import platform
import resource
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from pycal.gitinfo import git_commit  # noqa: E402
from pycal.jobs import parse_set, resolve_job  # noqa: E402
from pycal.runner import run_job  # noqa: E402

OUT = Path(__file__).resolve().parent / "seed_cost.jsonl"
DEFAULT_KEYS = {"fill": "bulk_density_kg_m3,n_particles", "aor": "aor_mean_deg,n_particles,lift_time_s",
                "surcharge": "aor_mean_deg,surcharge_mean_deg", "ccs": "stress_pa,strain,bulk_density_kg_m3",
                "ccs_expansion": "unloading_stiffness_pa", "ucs": "stress_pa,strain",
                "wall_friction": "mu_static,mu_dynamic", "internal_friction": "mu_static,mu_dynamic"}


def parse_seeds(text):
    """'1-8' or '1,3,5' -> list of ints."""
    out = []
    for part in text.split(","):
        if "-" in part:
            a, b = part.split("-")
            out += list(range(int(a), int(b) + 1))
        else:
            out.append(int(part))
    return out


def children_cpu_s():
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def timed(job):
    """(result, cpu s, wall s) of one job in a fresh runs folder."""
    d = Path(tempfile.mkdtemp(prefix="seedcost-"))
    try:
        c0, t0 = children_cpu_s(), time.perf_counter()
        res = run_job(job, d, timeout_s=24 * 3600)
        return res, children_cpu_s() - c0, time.perf_counter() - t0
    finally:
        shutil.rmtree(d, ignore_errors=True)


def run_mode(rig, material, overrides, seeds, mode, size, layout="side_by_side"):
    """Per-seed results, total CPU s, total wall s, load averages at start and end."""
    load0 = os.getloadavg()
    per_seed, cpu, wall, batches = {}, 0.0, 0.0, []
    if mode == "lone":
        for s in seeds:
            res, c, w = timed(resolve_job(rig, material, overrides, seed=s))
            per_seed[s], cpu, wall = res, cpu + c, wall + w
            print(f"  lone seed {s}: {c:.1f} s CPU, {w:.1f} s wall", flush=True)
    else:
        from pycal import replicas
        for part in replicas.split(seeds, size):
            job = replicas.resolve_batch(rig, material, overrides, part, layout)
            res, c, w = timed(job)
            cpu, wall = cpu + c, wall + w
            batches.append({"seeds": part, "cpu_s": c, "wall_s": w})
            print(f"  batch {part}: {c:.1f} s CPU, {w:.1f} s wall", flush=True)
            for seed, r, msg in replicas.expand(res):
                per_seed[seed] = r
                if msg:
                    print("   ", msg, flush=True)
    return per_seed, cpu, wall, (load0, os.getloadavg()), batches


def values(res, key):
    if res is None:
        return None
    v = res.get(key)
    return v


def stats(xs):
    xs = [x for x in xs if x is not None and not (isinstance(x, float) and math.isnan(x))]
    if not xs:
        return None, None, 0
    m = statistics.fmean(xs)
    se = statistics.stdev(xs) / math.sqrt(len(xs)) if len(xs) > 1 else float("nan")
    return m, se, len(xs)


def table(per_seed, keys, seeds):
    """Lines: per seed the values, then mean +- standard error (list keys per entry)."""
    lines = []
    for s in seeds:
        r = per_seed.get(s)
        cells = []
        for k in keys:
            v = values(r, k)
            if isinstance(v, list):
                cells.append("[" + ", ".join("-" if x is None else f"{x:.4g}" for x in v) + "]")
            else:
                cells.append("FAILED" if r is None else ("-" if v is None else f"{v:.4g}"))
        lines.append(f"  seed {s}: " + "  ".join(f"{k}={c}" for k, c in zip(keys, cells)))
    summary = {}
    for k in keys:
        vs = [values(per_seed.get(s), k) for s in seeds]
        if any(isinstance(v, list) for v in vs):
            n = max(len(v) for v in vs if isinstance(v, list))
            summary[k] = [stats([v[i] if isinstance(v, list) and i < len(v) else None for v in vs]) for i in range(n)]
            cells = ", ".join(f"{m:.4g}+-{se:.2g}" if m is not None else "-" for m, se, _ in summary[k])
            lines.append(f"  {k}: [{cells}]")
        else:
            summary[k] = stats(vs)
            m, se, n = summary[k]
            lines.append(f"  {k}: mean {m:.4g} +- {se:.2g} (standard error, {n} seeds)" if m is not None
                         else f"  {k}: no value")
    return lines, summary


def main(argv=None):
    p = argparse.ArgumentParser(prog="seed_cost", description=__doc__.splitlines()[0])
    p.add_argument("rig")
    p.add_argument("--material", default="M2")
    p.add_argument("--seeds", default="1-8")
    p.add_argument("--set", action="append", metavar="KEY=VALUE")
    p.add_argument("--mode", choices=["lone", "batch", "both"], default="both")
    p.add_argument("--replicas", type=int, default=None, help="seeds per batch (default: all seeds in one)")
    p.add_argument("--layout", choices=["sequential", "side_by_side"], default="sequential",
                   help="replica layout of the batch mode")
    p.add_argument("--keys", default=None, help="result keys to tabulate (comma separated)")
    p.add_argument("--label", default="", help="free text stored with the line (what is being compared)")
    args = p.parse_args(argv)
    seeds = parse_seeds(args.seeds)
    overrides = parse_set(args.set)
    keys = (args.keys or DEFAULT_KEYS.get(args.rig, "n_particles")).split(",")
    size = args.replicas or len(seeds)
    modes = ["lone", "batch"] if args.mode == "both" else [args.mode]
    for mode in modes:
        print(f"{args.rig} {args.material} {overrides} seeds {seeds}: {mode}"
              + (f" ({size} per batch, {args.layout})" if mode == "batch" else ""), flush=True)
        per_seed, cpu, wall, load, batches = run_mode(args.rig, args.material, overrides, seeds, mode, size,
                                                      args.layout)
        lines, summary = table(per_seed, keys, seeds)
        print("\n".join(lines))
        ok = sum(1 for s in seeds if per_seed.get(s) is not None)
        print(f"  CPU {cpu:.1f} s = {cpu / len(seeds):.2f} s per seed ({3600 * len(seeds) / cpu:.0f} seeds per "
              f"CPU-hour); wall {wall:.1f} s; load average {load[0][0]:.1f} -> {load[1][0]:.1f}", flush=True)
        row = {"rig": args.rig, "material": args.material, "overrides": overrides, "seeds": seeds, "mode": mode,
               "replicas_per_batch": size if mode == "batch" else 1, "label": args.label,
               "layout": args.layout if mode == "batch" else None,
               "cpu_s": round(cpu, 3), "cpu_s_per_seed": round(cpu / len(seeds), 3), "wall_s": round(wall, 3),
               "seeds_ok": ok, "batches": batches, "load_average_start": load[0][0], "load_average_end": load[1][0],
               "per_seed": {str(s): {k: values(per_seed.get(s), k) for k in keys + ["steps"]} for s in seeds},
               "summary": summary, "git_commit": git_commit(short=True), "host": platform.node(),
               "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}
        with open(OUT, "a") as f:
            f.write(json.dumps(row, sort_keys=True, default=str) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
