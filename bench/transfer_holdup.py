"""What keeps ore on the transfer plate? The study's own transfer runs, dry and wet, with one setting changed
at a time (issue 28: "the wet transfer holds up more than the dry").

    /usr/bin/python3 bench/transfer_holdup.py RUNS_DIR --out runs/bench_transfer [--workers 2] [--table-only]

RUNS_DIR is a main job's runs folder: its transfer jobs (mixed-dry and mixed-wet, the application's seeds).
Each variant of VARIANTS rebuilds those jobs from their job.json with the variant's overrides added
(bench/rerun_with.py: the same jobs, the same seeds) and runs them into --out (cached: a stopped sweep
resumes). Prints per set and variant, mean (SD) over the seeds: the holdup 1 s after the feed stops (kg, and
per seed), the mean mass on the plate over the steady window (kg), the outflow ratio, the impact stress on the
footprint (kPa), how many seeds plugged, the median CPU per run (s).
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
from pycal.executors.jobdirs import cached_result  # noqa: E402
from pycal.executors.local import LocalPool  # noqa: E402
from pycal.files import write_text  # noqa: E402
from pycal.runs_index import job_files  # noqa: E402

SETS = {"mixed-dry": "M3-dry", "mixed-wet": "M3-wet"}   # the set and its fines
GRAVEL = "M2"
STEEP = 0.6                      # above tan 30 deg = 0.577: a single particle can neither roll nor slide down the plate


def _steel(component, key):
    return f"{component}.interactions.steel.{key}"


def no_roll(fines):
    """Fines and gravel that cannot roll down the plate alone (rolling resistance on steel 0.6)."""
    return {_steel(fines, "rolling_resistance_coefficient"): STEEP, _steel(GRAVEL, "rolling_resistance_coefficient"): STEEP}


def no_roll_no_slide(fines):
    """... nor slide (friction on steel 0.7 as well)."""
    return {**no_roll(fines), _steel(fines, "friction_coefficient"): 0.7, _steel(GRAVEL, "friction_coefficient"): 0.7}


def plate_adhesion(job, pressure_fraction):
    """The wet fines' adhesion to the plate (the pressure part of the fines-steel pull-off) set to
    `pressure_fraction`, the wet fines' hold on gravel and lumps kept as the job has it (the set copies the
    fines-steel law to those pairs: their pressure part is written back)."""
    extra = {_steel("M3-wet", "cohesion.pressure_fraction"): pressure_fraction}
    for coarse in ("M1", GRAVEL):
        held = job["materials"][coarse]["interactions"]["M3-wet"]["cohesion"]["pressure_fraction"]
        pair = "M1.M3-wet" if coarse == "M1" else "M2.M3-wet"
        extra[f"cross_interactions.{pair}.cohesion.pressure_fraction"] = held
    return extra


# name -> (sets it applies to, overrides(job, fines) -> dict)
VARIANTS = {
    "as calibrated (the main job's runs)": (tuple(SETS), lambda job, fines: {}),
    "plate at 20 deg": (tuple(SETS), lambda job, fines: {"rig.geometry.plate_inclination_deg": 20.0}),
    "rolling resistance on steel 0.6 (fines, gravel)": (tuple(SETS), lambda job, fines: no_roll(fines)),
    "... and friction on steel 0.7": (tuple(SETS), lambda job, fines: no_roll_no_slide(fines)),
    "wet plate adhesion 0.05 (the wall stage's bound)": (("mixed-wet",), lambda job, fines: plate_adhesion(job, 0.05)),
    "wet plate adhesion 0.1": (("mixed-wet",), lambda job, fines: plate_adhesion(job, 0.1)),
    "wet plate adhesion 0.2": (("mixed-wet",), lambda job, fines: plate_adhesion(job, 0.2)),
    "wet plate adhesion 0.2, rolling 0.6, friction 0.7": (
        ("mixed-wet",), lambda job, fines: {**plate_adhesion(job, 0.2), **no_roll_no_slide(fines)}),
}


def jobs_of(runs, material_set):
    """The study's transfer jobs of a set (job.json files), by seed."""
    files = job_files(runs, "transfer", material_set)
    if not files:
        raise SystemExit(f"{runs}/transfer: no transfer job of {material_set} (a main job's runs folder?)")
    return files


def sweep(runs, out, workers, run=True):
    """{(set, variant): (results, failed seeds count)} of every variant's runs: the main job's own jobs from RUNS_DIR
    (cached there), the changed ones in `out`; run=False reads only what is cached."""
    table = {}
    for material_set, fines in SETS.items():
        files = jobs_of(runs, material_set)
        for name, (sets, overrides) in VARIANTS.items():
            if material_set not in sets:
                continue
            jobs = [rebuilt(f, overrides(json.loads(Path(f).read_text()), fines))[1] for f in files]
            where = out if overrides(json.loads(Path(files[0]).read_text()), fines) else runs
            if run:
                print(f"[sweep] {material_set}: {name} ({len(jobs)} seeds)", flush=True)
                results = LocalPool(runs_dir=where, workers=workers, progress=False).run(jobs, raise_on_error=False)
            else:
                results = [cached_result(j, where) for j in jobs]
            ok = [r for r in results if r is not None]
            table[(material_set, name)] = (ok, len(results) - len(ok))
    return table


def mean_sd(values, scale=1.0, digits=3):
    """'mean (SD)' of the finite values x scale; '-' if none."""
    v = [scale * x for x in values if x is not None and not (isinstance(x, float) and math.isnan(x))]
    if not v:
        return "-"
    sd = f" ({statistics.stdev(v):.{digits}f})" if len(v) > 1 else ""
    return f"{statistics.mean(v):.{digits}f}{sd}"


def rows(table):
    """Markdown table, one row per set and variant."""
    lines = ["| set | variant | seeds | holdup, kg: mean (SD) | per seed | on the plate over the steady window, kg | "
             "outflow / inflow | impact stress, kPa | plugged | CPU per run, s |", "|---" * 10 + "|"]
    for (material_set, name), (ok, failed) in table.items():
        def get(key):
            return [r.get(key) for r in ok]
        seeds = f"{len(ok)}" + (f" ({failed} failed)" if failed else "")
        per_seed = ", ".join(f"{r['holdup_mass_kg']:.3f}" for r in ok)
        cpu = f"{statistics.median(r['provenance']['cpu_time_s'] for r in ok):.0f}" if ok else "-"
        plugged = f"{sum(bool(r.get('plugged')) for r in ok)} of {len(ok)}"
        lines.append(f"| {material_set} | {name} | {seeds} | {mean_sd(get('holdup_mass_kg'))} | {per_seed} | "
                     f"{mean_sd(get('on_plate_mass_mean_kg'))} | {mean_sd(get('outflow_ratio'), digits=2)} | "
                     f"{mean_sd(get('impact_stress_pa'), 1e-3, 1)} | {plugged} | {cpu} |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", help="a main job's runs folder (its transfer jobs)")
    ap.add_argument("--out", required=True, help="runs folder for the variants' jobs")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--table-only", action="store_true", help="only tabulate the runs already there")
    ap.add_argument("--table", default=None, help="also write the table (markdown) here")
    args = ap.parse_args(argv)
    text = rows(sweep(args.runs, args.out, args.workers, run=not args.table_only))
    print(text)
    if args.table:
        write_text(Path(args.table), text + "\n")


if __name__ == "__main__":
    main()
