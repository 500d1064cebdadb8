"""Benchmarks: run a rig job several times in fresh run dirs (nothing cached) and report
wall time, steps, particle count and particle-steps per second (median of the runs).

    ./run.sh bench [NAME ...] [--runs N]      (default: every bench, 3 runs each)

Prints a table and appends one JSON line per bench to bench/results.jsonl.
Runs one YADE process at a time (-j1), like the calibration workers.
A bench = rig + material + overrides + seed: add one line to BENCHES.
"""
import argparse
import datetime
import json
import platform
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from pycal.gitinfo import git_commit  # noqa: E402
from pycal.jobs import resolve_job  # noqa: E402
from pycal.runner import run_job  # noqa: E402

BENCHES = {
    # name: (rig, material, overrides, seed)
    "fill": ("fill", "M2", {}, 1),          # M2 start values (density 2750, E 6e6)
    "aor": ("aor", "M2", {}, 1),            # needs yade_scripts/aor.py
    # mixed -50 mm sample (M1 clumps + M2 + M3-dry), lift at 10 mm/s as in the measurements of issue 7
    "aor_mixed": ("aor_mixed", "mixed-dry", {"rig.procedure.lift_speed_m_s": 0.01}, 1),
    "ccs": ("ccs", "M2", {}, 1),                                     # 7 load steps, start values
    "ucs": ("ucs", "M2", {"rig.procedure.lift_speed_m_s": 0.01}, 1),  # stops at the overlap limit at E 6e6
    "wall_friction": ("wall_friction", "M2", {}, 1),                 # one full friction curve, 7 steps
    "internal_friction": ("internal_friction", "M2", {}, 1),         # 7 steps, a fresh fill each (~8 min)
}

RESULTS = Path(__file__).resolve().parent / "results.jsonl"


def run_bench(name, runs=3):
    rig, material, overrides, seed = BENCHES[name]
    job = resolve_job(rig, material, overrides, seed=seed)
    samples = []
    for k in range(runs):
        d = Path(tempfile.mkdtemp(prefix=f"bench-{name}-"))
        try:
            t0 = time.perf_counter()
            res = run_job(job, d)
            wall = time.perf_counter() - t0
        finally:
            shutil.rmtree(d, ignore_errors=True)
        steps = int(res.get("steps") or sum(res.get("step_steps_count") or [0]))   # compression: load steps only
        n = int(res.get("n_particles", 0))
        yade_wall = res.get("provenance", {}).get("wall_time_s")
        samples.append({"wall_s": wall, "yade_wall_s": yade_wall, "steps": steps, "n_particles": n})
        print(f"  {name} run {k + 1}/{runs}: {wall:.2f} s, {steps} steps, {n} particles", flush=True)
    med = lambda key: statistics.median(s[key] for s in samples)
    wall = med("wall_s")
    steps = med("steps")
    n = med("n_particles")
    row = {
        "bench": name, "rig": rig, "material": material, "overrides": overrides, "seed": seed,
        "job_id": job["job_id"], "runs": runs,
        "wall_s_median": round(wall, 3), "wall_s_min": round(min(s["wall_s"] for s in samples), 3),
        "wall_s_max": round(max(s["wall_s"] for s in samples), 3),
        "yade_wall_s_median": med("yade_wall_s") if all(s["yade_wall_s"] for s in samples) else None,
        "steps": steps, "n_particles_final": n,
        "particle_steps_per_s": round(n * steps / wall, 1) if wall > 0 else None,
        "ms_per_step": round(1000 * wall / steps, 4) if steps else None,
        "git_commit": git_commit(short=True), "host": platform.node(),
        "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    }
    with open(RESULTS, "a") as f:
        f.write(json.dumps(row, sort_keys=True) + "\n")
    return row


def main(argv=None):
    p = argparse.ArgumentParser(prog="bench", description=__doc__.splitlines()[0])
    p.add_argument("names", nargs="*", help=f"benches to run (default all: {', '.join(BENCHES)})")
    p.add_argument("--runs", type=int, default=3, help="runs per bench (median reported, default 3)")
    args = p.parse_args(argv)
    names = args.names or list(BENCHES)
    unknown = [n for n in names if n not in BENCHES]
    if unknown:
        print(f"bench: unknown bench {', '.join(unknown)} (known: {', '.join(BENCHES)})", file=sys.stderr)
        return 2
    if args.runs < 1:
        print("bench: --runs must be >= 1", file=sys.stderr)
        return 2
    rows, failed = [], []
    for name in names:
        try:
            rows.append(run_bench(name, args.runs))
        except Exception as exc:                         # a missing rig script, a failed run
            failed.append(name)
            print(f"bench {name}: FAILED: {exc}", file=sys.stderr)
    if rows:
        hdr = f"{'bench':8} {'runs':>4} {'wall s (median)':>16} {'min-max s':>13} {'steps':>8} " \
              f"{'particles':>9} {'particle-steps/s':>16} {'ms/step':>8}"
        print(hdr)
        print("-" * len(hdr))
        for r in rows:
            print(f"{r['bench']:8} {r['runs']:>4} {r['wall_s_median']:>16.2f} "
                  f"{r['wall_s_min']:>6.2f}-{r['wall_s_max']:<6.2f} {r['steps']:>8.0f} {r['n_particles_final']:>9.0f} "
                  f"{r['particle_steps_per_s'] or 0:>16.0f} {r['ms_per_step'] or 0:>8.3f}")
        print(f"appended {len(rows)} line(s) to {RESULTS.relative_to(ROOT)}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
