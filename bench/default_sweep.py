"""Every shipped rig on every shipped material (and material set, for the rigs that take
sets) at its start values, seeds 1..N: how many runs complete, and why the others did not.

    /usr/bin/python3 bench/default_sweep.py [--seeds 5] [--workers 2] [--runs DIR] [RIG ...]

Runs go through pycal's local pool into DIR (default bench/out/default_sweep; reused, so
an interrupted sweep resumes and a finished one replays from the cache). Prints a table
rig x material (completed / run) and every failure message, and appends one JSON line to
bench/results.jsonl. The goal (issue "hardening"): every run completes.
"""
import argparse
import datetime
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from pycal.configs import load_material, load_rig, material_names, material_set_names, rig_names  # noqa: E402
from pycal.jobs import resolve_job  # noqa: E402
from pycal.runner import LocalPool  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results.jsonl"


def pairs(rigs):
    """(rig, material or set) of every shipped default job: sets for rigs that take them;
    sphere materials for the others (a rig for one material pours spheres)."""
    spheres = [m for m in material_names() if load_material(m)["particles"]["shape"] == "sphere"]
    for rig in rigs:
        names = material_set_names() if load_rig(rig).get("accepts_material_sets") else spheres
        for m in names:
            yield rig, m


def main(argv=None):
    p = argparse.ArgumentParser(prog="default_sweep", description=__doc__.splitlines()[0])
    p.add_argument("rigs", nargs="*", help=f"rigs (default all: {', '.join(rig_names())})")
    p.add_argument("--seeds", type=int, default=5)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--runs", default=str(ROOT / "bench" / "out" / "default_sweep"))
    args = p.parse_args(argv)
    rigs = args.rigs or rig_names()
    bad = [r for r in rigs if r not in rig_names()]
    if bad or args.seeds < 1:
        print(f"default_sweep: unknown rig {', '.join(bad)} or --seeds < 1", file=sys.stderr)
        return 2
    pool = LocalPool(runs_dir=args.runs, workers=args.workers)
    rows, failures = [], []
    t0 = time.time()
    for rig, material in pairs(rigs):
        jobs = [resolve_job(rig, material, seed=s) for s in range(1, args.seeds + 1)]
        results = pool.run(jobs, raise_on_error=False)
        done = sum(r is not None for r in results)
        rows.append({"rig": rig, "material": material, "completed": done, "runs": len(jobs)})
        failures += [f"{rig} {material}: {msg}" for msg in pool.last_errors]
        print(f"{rig:18} {material:10} {done}/{len(jobs)} complete", flush=True)
    total, done = sum(r["runs"] for r in rows), sum(r["completed"] for r in rows)
    print(f"\n{done} of {total} default runs completed ({time.time() - t0:.0f} s)")
    for f in failures:
        print("  FAILED", f)
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    with open(RESULTS, "a") as f:
        f.write(json.dumps({"bench": "default_sweep", "seeds": args.seeds, "rows": rows, "completed": done,
                            "runs": total, "failures": failures, "git_commit": commit,
                            "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")},
                           sort_keys=True) + "\n")
    return 0 if done == total else 1


if __name__ == "__main__":
    sys.exit(main())
