"""Where a study's CPU time goes: per section (stage, prediction, application run), per rig
and per phase of the rigs.

    /usr/bin/python3 bench/cost_profile.py STUDY_DIR [--runs RUNS_DIR] [--out profile.md]

STUDY_DIR is a study's output folder (runs/study/zinc_ore): its jobs.csv lists every job
the study asked (section, rig, seed, job id, batch job id); the runs are read through
pycal.runs_index (`pycal runs RUNS_DIR --study STUDY_DIR`). Each job's folder in RUNS_DIR
(default: the study folder's grandparent, i.e. runs/) holds its result.json, whose
provenance gives the process's CPU time (cpu_time_s), wall time, simulated time, time
steps and the CPU time and steps per phase (phase_cpu: pour, strike, consolidate,
settle_before_tilt, tilt_static, tilt_dynamic, tilt_back, outputs, outside_phases ...;
step_cpu_s is the part inside YADE's time steps, the rest is Python between them: rest
checks, servo, records). A seed run in a batch (replicas) gets its share of the batch.
A job asked twice (a cached point) counts once. Failed jobs have no provenance: counted,
not timed. Results written before phase_cpu existed show only their totals.
"""
import argparse
import csv
import statistics
import sys
from collections import defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from pycal.files import write_text  # noqa: E402
from pycal.runs_index import runs_with_results  # noqa: E402


def load(study_dir, runs_dir):
    """[(run {'section', 'rig'}, result or None, share of its YADE process's cost)], one per distinct
    job the study asked for (pycal.runs_index; a run two sections asked for counts in the first).
    A replica's result carries its batch's provenance and seeds: its share is one of them."""
    rows = []
    for r, result in runs_with_results(runs_dir, study_dir):
        if not r["stage"]:
            continue
        run = {"section": r["stage"].split(";")[0], "rig": r["rig"]}
        if result is None:
            rows.append((run, None, 1.0))
            continue
        rows.append((run, result, 1.0 / len(result["provenance"].get("batch_seeds") or [None])))
    return rows


def table(title, head, rows):
    out = [f"### {title}", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return out + [""]


def stage_elapsed(study_dir):
    """{section: wall s} of the stages from the study's stages.csv (its own clock)."""
    path = Path(study_dir) / "stages.csv"
    if not path.is_file():
        return {}
    with open(path) as f:
        return {f"{r['material']}/{r['stage']}": float(r["elapsed_s"]) for r in csv.DictReader(f)
                if r.get("elapsed_s")}


def profile(rows, elapsed=None):
    by_section = defaultdict(lambda: {"jobs": 0, "failed": 0, "cpu": 0.0, "per_run": []})
    by_rig = defaultdict(lambda: {"jobs": 0, "cpu": 0.0, "steps": 0.0, "sim": 0.0})
    by_phase = defaultdict(lambda: defaultdict(lambda: [0.0, 0.0, 0.0]))
    for j, r, share in rows:
        s = by_section[j["section"]]
        s["jobs"] += 1
        if r is None:
            s["failed"] += 1
            continue
        p = r.get("provenance") or {}
        cpu = (p.get("cpu_time_s") or 0.0) * share
        s["cpu"] += cpu
        s["per_run"].append(cpu)
        g = by_rig[j["rig"]]
        g["jobs"] += 1
        g["cpu"] += cpu
        g["steps"] += (p.get("steps_count") or 0) * share
        g["sim"] += (p.get("simulated_time_s") or 0.0) * share
        for name, v in (p.get("phase_cpu") or {}).items():
            acc = by_phase[j["rig"]][name]
            acc[0] += v["cpu_s"] * share
            acc[1] += v["step_cpu_s"] * share
            acc[2] += v["steps_count"] * share
    total = sum(s["cpu"] for s in by_section.values()) or 1.0
    out = [f"Total CPU {total:.0f} s ({total / 3600:.2f} CPU-h) over {sum(s['jobs'] for s in by_section.values())} "
           "distinct jobs.", ""]
    elapsed = elapsed or {}
    out += table("Per section", ["section", "jobs", "failed", "CPU s", "share", "CPU s per run, median",
                                 "stage wall s (study clock)"],
                 [(k, s["jobs"], s["failed"], f"{s['cpu']:.0f}", f"{s['cpu'] / total:.1%}",
                   f"{statistics.median(s['per_run']):.1f}" if s["per_run"] else "-",
                   f"{elapsed[k]:.0f}" if k in elapsed else "-")
                  for k, s in by_section.items()])
    out += table("Per rig", ["rig", "jobs", "CPU s", "share", "CPU s per job", "time steps (M)", "simulated s"],
                 [(k, g["jobs"], f"{g['cpu']:.0f}", f"{g['cpu'] / total:.1%}", f"{g['cpu'] / max(1, g['jobs']):.1f}",
                   f"{g['steps'] / 1e6:.2f}", f"{g['sim']:.0f}")
                  for k, g in sorted(by_rig.items(), key=lambda kv: -kv[1]["cpu"])])
    for rig, phases in by_phase.items():
        rig_cpu = sum(v[0] for v in phases.values()) or 1.0
        out += table(f"Phases of {rig}", ["phase", "CPU s", "share of the rig", "of it in time steps", "steps (M)",
                                          "us per step"],
                     [(name, f"{v[0]:.0f}", f"{v[0] / rig_cpu:.1%}", f"{v[1] / v[0]:.0%}" if v[0] else "-",
                       f"{v[2] / 1e6:.2f}", f"{1e6 * v[1] / v[2]:.0f}" if v[2] else "-")
                      for name, v in sorted(phases.items(), key=lambda kv: -kv[1][0])])
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("study_dir")
    ap.add_argument("--runs", default=None, help="runs directory (default: STUDY_DIR/../..)")
    ap.add_argument("--out", default=None, help="also write the tables (markdown) here")
    args = ap.parse_args(argv)
    study = Path(args.study_dir)
    if not (study / "jobs.csv").is_file():
        raise SystemExit(f"cost_profile: {study / 'jobs.csv'}: no such file (a study output folder written by "
                         "./run.sh calibrate)")
    text = profile(load(study, Path(args.runs) if args.runs else study.parent.parent), stage_elapsed(study))
    print(text)
    if args.out:
        write_text(Path(args.out), text + "\n")      # atomic, the project's writer


if __name__ == "__main__":
    main()
