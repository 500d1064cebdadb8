"""Where a friction stage's tilt time goes, read from the tilt traces its jobs recorded
(tilt_record.csv), and what a longer pre-tilt would save if the trace stayed the same.

    /usr/bin/python3 bench/tilt_time_split.py RUNS_DIR --rig internal_friction --material M3-wet \
        [--seeds 1-18] [--pre-tilt-fractions 0.5,0.7]

Per job and consolidation step (simulated seconds): the static tilt up to the onset
(slide_onset_displacement_m) or to the end of the hold at max_tilt_deg; after the onset
the time spent holding an angle and the time spent tilting on between holds (restarts at
tilt_restart_rate_deg_s). For each --pre-tilt-fractions f: the static tilt time the
pre-tilt rate would take over if it ran until f x the onset distance instead of
pre_tilt_slide_fraction x it (the stretch of the trace between the two slides, at
pre_tilt_rate_deg_s instead of tilt_rate_deg_s). That is a projection on an unchanged
trace, not a measurement: a faster tilt may move the onset; bench/rerun_with.py measures
it on the same jobs. Also the phase CPU (provenance.phase_cpu) summed over the jobs.
Reads job folders only; runs nothing.
"""
import argparse
import csv
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from rerun_with import seed_list  # noqa: E402
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from pycal.runs_index import job_files  # noqa: E402


def step_traces(job_dir):
    """{step index: [(t s, tilt deg, slide m), ...]} from the job's tilt_record.csv."""
    out = {}
    with open(job_dir / "tilt_record.csv") as f:
        for row in csv.DictReader(f):
            out.setdefault(int(row["step_index_count"]), []).append(
                (float(row["time_s"]), float(row["tilt_deg"]), float(row["slide_displacement_m"])))
    return out


def split_step(trace, proc, fractions):
    """(static s, hold s, restart s, {f: static s saved}) of one step's trace."""
    onset_d = proc["slide_onset_displacement_m"]
    end = next((i for i, (_, _, x) in enumerate(trace) if x >= onset_d), len(trace) - 1)
    static = trace[end][0] - trace[0][0]
    hold = restart = 0.0
    for (t1, a1, _), (t2, a2, _) in zip(trace[end:], trace[end + 1:]):
        if a2 > a1 + 1e-9:
            restart += t2 - t1
        else:
            hold += t2 - t1
    saved = {}
    rate, pre_rate = proc["tilt_rate_deg_s"], proc["pre_tilt_rate_deg_s"]
    i1 = next((i for i, (_, _, x) in enumerate(trace) if x >= proc["pre_tilt_slide_fraction"] * onset_d), end)
    for f in fractions:
        i2 = min(end, next((i for i, (_, a, x) in enumerate(trace) if x >= f * onset_d or a >= proc["max_tilt_deg"]),
                           end))
        saved[f] = max(0.0, trace[i2][0] - trace[i1][0]) * (1.0 - rate / pre_rate) if pre_rate > rate else 0.0
    return static, hold, restart, saved


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs")
    ap.add_argument("--rig", required=True)
    ap.add_argument("--material", required=True)
    ap.add_argument("--seeds", default=None, help="FIRST-LAST or a comma list (default: every job)")
    ap.add_argument("--pre-tilt-fractions", default="0.5,0.7")
    a = ap.parse_args(argv)
    fractions = [float(v) for v in a.pre_tilt_fractions.split(",")]
    wanted = seed_list(a.seeds) if a.seeds else None
    tot = {"static": 0.0, "hold": 0.0, "restart": 0.0}
    saved = {f: 0.0 for f in fractions}
    cpu, jobs, steps = {}, 0, 0
    for job_file in job_files(a.runs, a.rig, a.material, status="ok"):
        job_dir = job_file.parent
        job = json.loads(job_file.read_text())
        if wanted is not None and job["seed"] not in wanted:
            continue
        result = json.loads((job_dir / "result.json").read_text())
        proc = job["rig_config"]["procedure"]
        for name, ph in result["provenance"].get("phase_cpu", {}).items():
            cpu[name] = cpu.get(name, 0.0) + ph["cpu_s"]
        jobs += 1
        for trace in step_traces(job_dir).values():
            static, hold, restart, sv = split_step(trace, proc, fractions)
            tot["static"] += static
            tot["hold"] += hold
            tot["restart"] += restart
            for f in fractions:
                saved[f] += sv[f]
            steps += 1
    if not jobs:
        raise SystemExit(f"no finished {a.rig} job of {a.material} in {a.runs}")
    print(f"{jobs} jobs, {steps} steps of {a.rig} {a.material}: simulated s of static tilt {tot['static']:.1f}, "
          f"after the onset holding {tot['hold']:.1f}, tilting on between holds {tot['restart']:.1f}")
    for f in fractions:
        print(f"  pre-tilt until {f:g} x the onset distance: {saved[f]:.1f} s of static tilt saved "
              f"({100 * saved[f] / tot['static']:.0f} %) on an unchanged trace")
    total = sum(cpu.values())
    print("  CPU s by phase: " + ", ".join(f"{k} {v:.0f} ({100 * v / total:.0f} %)"
                                           for k, v in sorted(cpu.items(), key=lambda kv: -kv[1]) if v >= 0.01 * total))
    return 0


if __name__ == "__main__":
    sys.exit(main())
