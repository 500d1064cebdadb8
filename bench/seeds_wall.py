"""Wall time of K seeds against 1 seed in one `pycal run` call (the command a user types),
fresh runs folder each time (nothing cached).

    /usr/bin/python3 bench/seeds_wall.py RIG [--material M2] [--seeds 1,8] [--runs 3]
        [--set KEY=VALUE ...] [--pycal-arg=--replicas=1 ...] [--label TEXT]

Runs `/usr/bin/python3 -m pycal run RIG --material M --seed 1 --seeds K --out <tmp>` for
each K, --runs times, interleaved (1, K, 1, K, ...), and reports per K the median wall
time, the median CPU time of everything the call ran (pycal and its YADE processes:
getrusage of the children) and the load average; then the ratio of the medians (K
against the first). Appends one JSON line to bench/seeds_wall.jsonl.
"""
import argparse
import datetime
import json
import os
import platform
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from pycal.gitinfo import git_commit  # noqa: E402

OUT = Path(__file__).resolve().parent / "seeds_wall.jsonl"


def children_cpu_s():
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def one_call(rig, material, k, sets, extra):
    d = tempfile.mkdtemp(prefix="seedswall-")
    cmd = [sys.executable, "-m", "pycal", "run", rig, "--material", material, "--seed", "1", "--seeds", str(k),
           "--out", d] + [a for s in sets for a in ("--set", s)] + list(extra)
    load = os.getloadavg()[0]
    c0, t0 = children_cpu_s(), time.perf_counter()
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    wall, cpu = time.perf_counter() - t0, children_cpu_s() - c0
    shutil.rmtree(d, ignore_errors=True)
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr[-2000:]}")
    return {"wall_s": wall, "cpu_s": cpu, "load_average": load}


def main(argv=None):
    p = argparse.ArgumentParser(prog="seeds_wall", description=__doc__.splitlines()[0])
    p.add_argument("rig")
    p.add_argument("--material", default="M2")
    p.add_argument("--seeds", default="1,8", help="seed counts to compare, the first is the reference")
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--pycal-arg", action="append", default=[], help="extra argument of pycal run (e.g. --replicas=1)")
    p.add_argument("--label", default="")
    args = p.parse_args(argv)
    counts = [int(x) for x in args.seeds.split(",")]
    samples = {k: [] for k in counts}
    for r in range(args.runs):
        for k in counts:
            s = one_call(args.rig, args.material, k, args.set, args.pycal_arg)
            samples[k].append(s)
            print(f"run {r + 1}: {k} seed(s): {s['wall_s']:.1f} s wall, {s['cpu_s']:.1f} s CPU, "
                  f"load {s['load_average']:.1f}", flush=True)
    med = {k: {q: statistics.median(x[q] for x in v) for q in ("wall_s", "cpu_s", "load_average")}
           for k, v in samples.items()}
    ref = counts[0]
    for k in counts:
        print(f"{k} seed(s): median wall {med[k]['wall_s']:.1f} s, CPU {med[k]['cpu_s']:.1f} s, "
              f"load {med[k]['load_average']:.1f}; wall ratio to {ref}: {med[k]['wall_s'] / med[ref]['wall_s']:.2f}")
    row = {"rig": args.rig, "material": args.material, "sets": args.set, "pycal_args": args.pycal_arg,
           "label": args.label, "runs": args.runs, "samples": {str(k): v for k, v in samples.items()},
           "median": {str(k): v for k, v in med.items()},
           "wall_ratio": {str(k): med[k]["wall_s"] / med[ref]["wall_s"] for k in counts},
           "cores": os.cpu_count(), "git_commit": git_commit(short=True), "host": platform.node(),
           "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}
    with open(OUT, "a") as f:
        f.write(json.dumps(row, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
