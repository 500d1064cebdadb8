"""Rerun a study's own jobs with one setting changed, and compare seed by seed (a lever
measured on exactly the runs a stage made).

    /usr/bin/python3 bench/rerun_with.py RUNS_DIR --rig internal_friction --material M3-wet \
        --set rig.procedure.tilt_rate_deg_s=5.0 --out runs/bench_wet_tilt [--seeds 1-9]

Every lone job of the rig and material in RUNS_DIR (pycal.runs_index; every seed there) is rebuilt from its
recorded overrides (the rebuilt job id must equal the recorded one: the same job), run
again with the --set overrides added, and compared: per run the stage responses
--response (default `friction_angle_offset_deg`: a stage response of pycal.post.responses, a
vector one as its mean over the steps, or a scalar result key) and mu_static per step, the
time steps (the cost: CPU seconds of one job vary with the machine's load, its time steps
do not) and the CPU seconds as recorded, and per group of equal overrides the paired difference and its standard
error. Output: the table on stdout.
"""
import argparse
import json
import math
import statistics
import sys
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from pycal.executors.local import LocalPool  # noqa: E402
from pycal.jobs import resolve_job  # noqa: E402
from pycal.runs_index import job_files  # noqa: E402


def rebuilt(job_file, extra):
    """(the job rebuilt from job.json's overrides, the same job with `extra` added)."""
    j = json.loads(Path(job_file).read_text())
    same = resolve_job(j["rig"], j["material"], dict(j["overrides"]), seed=j["seed"])
    if same["job_id"] != j["job_id"]:
        raise SystemExit(f"{job_file}: rebuilt as {same['job_id']}, not the same job (configs changed since?)")
    return same, resolve_job(j["rig"], j["material"], dict(j["overrides"], **extra), seed=j["seed"])


def time_steps(result):
    """The run's time steps, all phases (provenance.phase_cpu): its cost, the same on a quiet
    or a loaded machine (the CPU seconds of one job vary by up to 1.45x between two main
    jobs on this machine, the steps not at all)."""
    return sum(ph["steps_count"] for ph in result["provenance"]["phase_cpu"].values())


def _fmt(values):
    return "/".join("-" if v is None else f"{v:.3f}" for v in values)


def seed_list(text):
    """'1-9' -> {1, ..., 9}; '1,4,7' -> {1, 4, 7}."""
    if "-" in text:
        first, last = (int(v) for v in text.split("-", 1))
        return set(range(first, last + 1))
    return {int(v) for v in text.split(",")}


def response(result, name):
    """A stage response (pycal.post.responses; a vector one, e.g. friction_band_z_mu_static,
    as the mean over its steps) or a scalar result key."""
    from pycal import LAB_DIR
    from pycal.post import responses
    r = responses.get(name)
    if r is None:
        return result.get(name)
    value = r.value(result, LAB_DIR)
    if r.vector:
        got = [v for v in value if v is not None]
        return sum(got) / len(got) if got else math.nan
    return value


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs")
    ap.add_argument("--rig", required=True)
    ap.add_argument("--material", required=True)
    ap.add_argument("--set", action="append", required=True, metavar="KEY=VALUE")
    ap.add_argument("--out", required=True)
    ap.add_argument("--response", default="friction_angle_offset_deg")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seeds", default=None, help="only these seeds: FIRST-LAST or a comma list (default: every seed)")
    args = ap.parse_args(argv)
    extra = {k: yaml.safe_load(v) for k, v in (s.split("=", 1) for s in args.set)}
    files = job_files(args.runs, args.rig, args.material)
    if args.seeds:
        wanted = seed_list(args.seeds)
        files = [f for f in files if json.loads(f.read_text())["seed"] in wanted]
    pairs = [rebuilt(f, extra) for f in files]
    before = LocalPool(runs_dir=args.runs, workers=1, progress=False).run([b for b, _ in pairs])   # cached
    after = LocalPool(runs_dir=args.out, workers=args.workers).run([a for _, a in pairs])
    groups = {}
    for (b_job, _), b, a in zip(pairs, before, after):
        rb, ra = response(b, args.response), response(a, args.response)
        cb, ca = time_steps(b), time_steps(a)
        key = json.dumps({k: v for k, v in b_job["overrides"].items() if not isinstance(v, (dict, list))},
                         sort_keys=True)
        groups.setdefault(key, []).append((rb, ra, cb, ca))
        per_step = ""
        if isinstance(b.get("mu_static"), list):
            per_step = f"; mu_static {_fmt(b['mu_static'])} -> {_fmt(a['mu_static'])}"
        print(f"seed {b_job['seed']}: {args.response} {rb:.4g} -> {ra:.4g}; time steps {cb:.4g} -> {ca:.4g} "
              f"({ca / cb:.2f}); CPU {b['provenance']['cpu_time_s']:.0f} -> {a['provenance']['cpu_time_s']:.0f} s{per_step}")
    for key, rows in groups.items():
        d = [ra - rb for rb, ra, _, _ in rows]
        se = statistics.stdev(d) / math.sqrt(len(d)) if len(d) > 1 else math.nan
        sd = statistics.stdev([r[0] for r in rows]) if len(rows) > 1 else math.nan
        print(f"{key}\n  n {len(d)}: before {statistics.fmean(r[0] for r in rows):.4g} (seed SD {sd:.3g}), after "
              f"{statistics.fmean(r[1] for r in rows):.4g}; paired difference {statistics.fmean(d):+.3g} +- {se:.2g}; "
              f"time steps after / before, median {statistics.median(r[3] / r[2] for r in rows):.2f}")


if __name__ == "__main__":
    main()
