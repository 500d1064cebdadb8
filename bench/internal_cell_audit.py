"""Why does the internal-friction cell read high? One suspect changed at a time (issue 28).

    /usr/bin/python3 bench/internal_cell_audit.py RUNS_DIR [--material M3-dry] \
        [--frictions 0.1,0.5] [--rolling 0.35,0.7] [--seeds 5] [--suspects all] [--without-baseline] \
        [--workers 1] [--table-only] [--out table.md]

Runs `pycal run internal_friction` (cached: a stopped audit resumes) at the settings the
dry fines' internal-friction stage ran until it left the study (STAGE_SETTINGS below: 12 and
90 kPa, static onset only, the faster tilts; and E 1e8 Pa, the calibrated stiffness), for
every particle friction in
--frictions (and every rolling resistance in --rolling, set on the material and on the
steel and PVC walls as the study's rolling stage sets it; without --rolling the material's
start value) and every suspect below, on seeds 1..--seeds, then prints per suspect,
friction and rolling resistance: mu_static per consolidation step and the stage's response
(the mean offset from the lab curve over the steps >= 10 kPa,
pycal.post.friction.friction_offset) with their
seed SD, the change against the baseline (the rig as shipped: since 2026-12-04 the cell
free to tip, read at its rim; before, the guided cell) +- its standard error (the fills
differ, so unpaired), and the median CPU per run.

The suspects (each alone, on the rig as shipped; docs/rigs.md "internal_friction"):
  guided          the mobile cell may not turn (procedure.sliding_cell_rotations: blocked,
                  slide_read_at: body): the rig until 2026-12-04
  rotations_free  the mobile cell may turn, its slide read at its centre of mass
                  (slide_read_at: body): tipping reads as sliding
  lid_free        the lid rests free on the contents instead of being joined to the cell
  fine_rim        128 facets instead of 32 round both cells (rim vertices pinch particles)
  onset_3mm       the onset read at 3 mm of slide instead of 1 mm
  gap_6mm         6 mm between the cells instead of 2 mm (strike level moved with it)
  force_drive     a horizontal force W tan(angle) on the mobile cell under vertical gravity
                  instead of the tilted table (the case study's own DEM model)

(`turning_read_at_rim` in the tables run before commit 59fcda9, free to turn and read at the
rim, is the baseline since: it is not a suspect of its own, which would run the baseline twice.)
"""
import argparse
import functools
import json
import math
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))
from friction_equivalence import fmt, mean_sd_se, step_values  # noqa: E402
from pycal.calibration.study_config import load_study  # noqa: E402
from pycal.files import write_text  # noqa: E402
from pycal.post.friction import friction_offset  # noqa: E402
from pycal.runs_index import ok_results  # noqa: E402

STUDY = ROOT / "configs" / "calibrations" / "zinc_ore.yaml"
STAGE_SETTINGS = {                 # the dry fines' internal-friction stage as it last ran (af07e0c)
    "rig.procedure.consolidation_stresses_pa": [12000, 90000],
    "rig.procedure.measure_dynamic_friction": False,
    "rig.procedure.pre_tilt_rate_deg_s": 20.0,
    "rig.procedure.tilt_rate_deg_s": 5.0,
    "rig.procedure.pre_tilt_slide_fraction": 0.5,
}
ROLLING_STAGE = "rolling_resistance"   # the study's stage whose parameter keys set one rolling resistance
YOUNGS_MODULUS_PA = 1e8            # the stiffness the study's friction stages run at (the stiffness stage's bound)

SUSPECTS = {
    "baseline": {},
    "guided": {"rig.procedure.sliding_cell_rotations": "blocked", "rig.procedure.slide_read_at": "body"},
    "rotations_free": {"rig.procedure.sliding_cell_rotations": "free", "rig.procedure.slide_read_at": "body"},
    "lid_free": {"rig.procedure.lid_during_tilt": "free"},
    "fine_rim": {"rig.geometry.cell_facet_segments_count": 128},
    "onset_3mm": {"rig.procedure.slide_onset_displacement_m": 0.003},
    "gap_6mm": {"rig.geometry.cell_gap_m": 0.006, "rig.procedure.strike_level_height_m": 0.196},
    "force_drive": {"rig.procedure.shear_drive": "force_ramp"},
}


@functools.lru_cache(maxsize=None)
def rolling_keys(material):
    """The keys the study's rolling-resistance stage sets together (the material's own first,
    then the walls'; read once per material: settings() asks for them for every run it classifies)."""
    for stage in load_study(STUDY)["materials"][material]:
        if stage.get("label") == ROLLING_STAGE:
            return tuple(stage["parameter"]["keys"])
    raise SystemExit(f"{STUDY}: no stage {ROLLING_STAGE!r} for {material}")


def settings(material, friction, suspect, rolling=None):
    """The --set overrides of one audit point (rolling None: the material's start value)."""
    ov = dict(STAGE_SETTINGS)
    ov["contact.youngs_modulus_pa"] = YOUNGS_MODULUS_PA
    ov[f"interactions.{material}.friction_coefficient"] = friction
    if rolling is not None:
        ov.update({k: rolling for k in rolling_keys(material)})
    ov.update(SUSPECTS[suspect])
    return ov


def run_point(runs, material, friction, suspect, seeds, workers, rolling=None):
    cmd = [sys.executable, "-m", "pycal", "run", "internal_friction", "--material", material,
           "--seeds", str(seeds), "--workers", str(workers), "--out", str(runs)]
    for k, v in settings(material, friction, suspect, rolling).items():
        cmd += ["--set", f"{k}={json.dumps(v)}"]
    print(f"[audit] {suspect} at friction {friction}, rolling {'start value' if rolling is None else rolling}: "
          f"{seeds} seeds", flush=True)
    subprocess.run(cmd, cwd=ROOT, check=True)


def suspect_of(overrides, material):
    """(suspect, friction, rolling resistance or None) of a run's overrides (None: not an audit run)."""
    fr = overrides.get(f"interactions.{material}.friction_coefficient")
    rr = overrides.get(rolling_keys(material)[0])
    for name in SUSPECTS:
        if fr is not None and overrides == settings(material, fr, name, rr):
            return name, fr, rr
    return None


def load(runs, material):
    """{(suspect, friction, rolling): [result]} of the audit's runs in RUNS_DIR."""
    out = {}
    for _, r in ok_results(runs, "internal_friction", material):
        key = suspect_of(r["job"].get("overrides") or {}, material)
        if key:
            out.setdefault(key, []).append(r)
    return out


def offset(r):
    """The stage response of one run (None when it cannot be read)."""
    try:
        return friction_offset(r)
    except ValueError:
        return None


def table(groups):
    """Markdown rows: per friction, rolling resistance and suspect, mu_static per step, the
    offset, the change against the baseline at the same friction and rolling resistance."""
    stresses = sorted({s for rs in groups.values() for r in rs for s in r["stress_pa"]})
    head = ("| particle friction | rolling resistance | suspect | seeds | " + " | ".join(f"mu_static {s / 1e3:g} kPa" for s in stresses)
            + " | offset from the lab (SD) | change vs baseline +- SE | cell turned at the onset, deg (mean) "
            "| CPU s per run (median) |")
    lines = [head, "|" + "---|" * (8 + len(stresses))]
    points = sorted({(f, rr) for _, f, rr in groups}, key=lambda p: (p[0], -1.0 if p[1] is None else p[1]))
    for fr, rr in points:
        base = groups.get(("baseline", fr, rr), [])
        mb, _, seb = mean_sd_se([offset(r) for r in base])
        for name in SUSPECTS:
            rs = groups.get((name, fr, rr))
            if not rs:
                continue
            cells = []
            for s in stresses:
                m, sd, _ = mean_sd_se([step_values(r)[0].get(s) for r in rs])
                cells.append(f"{fmt(m)} ({fmt(sd)})")
            m, sd, se = mean_sd_se([offset(r) for r in rs])
            change = "-" if name == "baseline" or m is None or mb is None else \
                f"{m - mb:+.3f} +- {math.hypot(se, seb):.3f}"
            turns = [a for r in rs for a in (r.get("cell_rotation_onset_deg") or []) if a is not None]
            turned = f"{statistics.mean(turns):.2f}" if turns else "-"      # runs before 91c6321 did not record it
            cpu = statistics.median(r["provenance"]["cpu_time_s"] for r in rs)
            stuck = sum(len(step_values(r)[2]) for r in rs)
            lines.append(f"| {fr} | {'start' if rr is None else rr} | {name}{f' ({stuck} stuck steps)' if stuck else ''} | {len(rs)} | "
                         + " | ".join(cells) + f" | {fmt(m)} ({fmt(sd)}) | {change} | {turned} | {cpu:.0f} |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs")
    ap.add_argument("--material", default="M3-dry")
    ap.add_argument("--frictions", default="0.1,0.5")
    ap.add_argument("--rolling", default=None, help="rolling resistances, comma list (default: the material's start value)")
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--suspects", default="all", help="comma list of " + ", ".join(SUSPECTS))
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--without-baseline", action="store_true",
                    help="run only the suspects named (a sweep of one cell; the change column then reads '-')")
    ap.add_argument("--table-only", action="store_true", help="only tabulate the runs already in RUNS_DIR")
    ap.add_argument("--out", default=None, help="also write the table (markdown) here")
    args = ap.parse_args(argv)
    names = list(SUSPECTS) if args.suspects == "all" else ["baseline"] + [
        s for s in args.suspects.split(",") if s != "baseline"]
    if args.without_baseline:
        names.remove("baseline")
    unknown = [s for s in names if s not in SUSPECTS]
    if unknown:
        raise SystemExit(f"--suspects: unknown {', '.join(unknown)} (known: {', '.join(SUSPECTS)})")
    frictions = [float(f) for f in args.frictions.split(",")]
    rollings = [float(r) for r in args.rolling.split(",")] if args.rolling else [None]
    if not args.table_only:
        for fr in frictions:
            for rr in rollings:
                for name in names:
                    run_point(args.runs, args.material, fr, name, args.seeds, args.workers, rr)
    text = table(load(args.runs, args.material))
    print(text)
    if args.out:
        write_text(Path(args.out), text + "\n")


if __name__ == "__main__":
    main()
