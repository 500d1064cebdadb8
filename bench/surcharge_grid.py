"""Does the surcharge tell sliding friction from rolling resistance? (issue 28 item 2)

    /usr/bin/python3 bench/surcharge_grid.py RUNS_DIR --calibrated STUDY_DIR [--material M3-dry] \
        [--frictions 0.3,0.5,0.8] [--rolling 0.05,0.15,0.4] [--seeds 4] [--workers 2] \
        [--amplitudes-mm 0.125,0.5] [--table-only] [--readings] [--out table.md]

Runs `pycal run surcharge` (cached: a stopped grid resumes) with a study's calibrated values
of the material (--calibrated: its output folder, e.g. runs/study/zinc_ore) and the lift speed
the study's AoR stages and predictions use (10 mm/s), over a grid of particle-particle friction
(--frictions, the material's own pair) and rolling resistance (--rolling, set on the material
and on the steel and PVC walls as the study's rolling stage sets it), seeds 1..--seeds.
--amplitudes-mm sets the vibration's horizontal amplitude (mm; the vertical at the rig's ratio, 0.6), an
assumption of the rig (configs/rigs/surcharge.yaml: the lab does not give its vibrator's); without it the
rig's own. Each run's amplitudes are read back from its job's resolved rig config.
One surcharge run gives both angles: the static pile before the vibration (aor_mean_deg, the
AoR stage's response) and after it (surcharge_mean_deg). Prints per grid point the mean and SD
over the seeds of both, how many seeds have an angle after the vibration, the pile height
before and after (m), and the median CPU per run. --readings adds a second table: the other candidate
readings of pycal.post.aor_readings (sector median, sector fit over rotated frames, cone) of each seed's
pile before and after the vibration (pile_particles.csv, surcharge_particles.csv), mean (SD; seeds).
"""
import argparse
import json
import math
import statistics
import subprocess
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
from pycal.calibration.study_config import load_study  # noqa: E402
from pycal.configs import load_numerics  # noqa: E402
from pycal.files import write_text  # noqa: E402
from pycal.post.aor import read_positions_csv  # noqa: E402
from pycal.post.aor_readings import READINGS  # noqa: E402
from pycal.runs_index import ok_results  # noqa: E402

OTHER_READINGS = ("sector_median", "rotated_sector_mean", "cone")

LIFT_SPEED_M_S = 0.01          # as the study's AoR stages and surcharge predictions
SHIPPED_STUDY = ROOT / "configs" / "calibrations" / "zinc_ore.yaml"
AMPLITUDE_KEYS = ("rig.procedure.vibration_amplitude_horizontal_m", "rig.procedure.vibration_amplitude_vertical_m")


def rig_vibration(procedure=None):
    """(frequency Hz, horizontal amplitude m, vertical amplitude m) of a rig config's procedure (default: the
    shipped surcharge rig's)."""
    p = procedure or yaml.safe_load((ROOT / "configs" / "rigs" / "surcharge.yaml").read_text())["procedure"]
    return (p["vibration_frequency_hz"], p["vibration_amplitude_horizontal_m"],
            p["vibration_amplitude_vertical_m"])


def peak_acceleration_g(frequency_hz, amplitude_m):
    """Peak acceleration of a sinusoid, in units of the rigs' g (configs/numerics.yaml): (2 pi f)^2 A / g."""
    return (2 * math.pi * frequency_hz) ** 2 * amplitude_m / load_numerics()["gravity_m_s2"]


def rolling_keys(material):
    """The keys the shipped study's rolling stage of the material sets together (its own or the one it inherits):
    the material's pair and the walls'."""
    for st in load_study(SHIPPED_STUDY)["materials"][material]:
        if st["label"].startswith("rolling_resistance"):
            return list(st["keys"] if st.get("kind") == "inherit" else st["parameter"]["keys"])
    raise KeyError(f"{SHIPPED_STUDY}: no rolling-resistance stage for {material}")


def settings(material, friction, rolling, amplitude_m=None):
    """The --set overrides of one grid point; amplitude_m (horizontal, m) with the vertical at the rig's ratio, or
    None for the rig's own."""
    ov = {"rig.procedure.lift_speed_m_s": LIFT_SPEED_M_S,
          f"interactions.{material}.friction_coefficient": friction}
    ov.update({k: rolling for k in rolling_keys(material)})
    if amplitude_m is not None:
        _, ah, av = rig_vibration()
        ov.update({AMPLITUDE_KEYS[0]: amplitude_m, AMPLITUDE_KEYS[1]: amplitude_m * av / ah})
    return ov


def run_point(runs, calibrated, material, friction, rolling, seeds, workers, amplitude_m=None):
    cmd = [sys.executable, "-m", "pycal", "run", "surcharge", "--material", material, "--calibrated", str(calibrated),
           "--seeds", str(seeds), "--workers", str(workers), "--out", str(runs)]
    for k, v in settings(material, friction, rolling, amplitude_m).items():
        cmd += ["--set", f"{k}={json.dumps(v)}"]
    amp = "the rig's" if amplitude_m is None else f"{1e3 * amplitude_m:g} mm"
    print(f"[grid] friction {friction}, rolling {rolling}, vibration amplitude {amp}: {seeds} seeds", flush=True)
    subprocess.run(cmd, cwd=ROOT, check=True)


def load(runs, material):
    """{(friction, rolling, (frequency Hz, horizontal m, vertical m)): [seed]} of the grid's runs in RUNS_DIR: one dict
    per seed (a job's replica: its measurements, its seed, and the job's CPU seconds shared out over its replicas)."""
    out = {}
    rolling_key = rolling_keys(material)[0]
    for row, r in ok_results(runs, "surcharge", material):
        ov = r["job"].get("overrides") or {}
        if ov.get("rig.procedure.lift_speed_m_s") != LIFT_SPEED_M_S or not row["batch_job_id"]:
            continue
        fr = ov.get(f"interactions.{material}.friction_coefficient")
        rr = ov.get(rolling_key)
        vib = rig_vibration(r["job"]["rig_config"]["procedure"])
        if fr is None or rr is None:
            continue
        seed = {**{k: v for k, v in r.items() if k not in ("job", "provenance")}, "seed": row["seed"],
                "cpu_time_s": row["cpu_time_s"], "measure": r["job"]["rig_config"]["measure"],
                "folder": Path(row["folder"])}
        out.setdefault((fr, rr, vib), []).append(seed)
    return out


def mean_sd(values):
    """(mean, SD) of the finite values, (nan, nan) if none; SD nan below two."""
    v = [x for x in values if x is not None and not (isinstance(x, float) and math.isnan(x))]
    if not v:
        return math.nan, math.nan
    return statistics.mean(v), (statistics.stdev(v) if len(v) > 1 else math.nan)


def fmt(m, sd, digits=1):
    return "-" if math.isnan(m) else (f"{m:.{digits}f}" + ("" if math.isnan(sd) else f" ({sd:.{digits}f})"))


def table(groups):
    """Markdown rows, one per grid point."""
    lines = ["| particle friction | rolling resistance | vibration: horizontal / vertical amplitude, mm (peak "
             "acceleration, g) | seeds | AoR before, deg (SD) | surcharge after, deg (SD) "
             "| seeds with an angle after | left / right after, deg (SD; seeds with an angle) "
             "| pile height before / after, mm | CPU s per run (median) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for (fr, rr, (f, ah, av)), rs in sorted(groups.items()):
        aor = mean_sd([r.get("aor_mean_deg") for r in rs])
        sur = mean_sd([r.get("surcharge_mean_deg") for r in rs])
        with_angle = sum(r.get("surcharge_mean_deg") is not None for r in rs)
        sides = []
        for side in ("left", "right"):
            vals = [r.get(f"surcharge_{side}_deg") for r in rs]
            sides.append(f"{fmt(*mean_sd(vals))}; {sum(v is not None for v in vals)}")
        sides = " / ".join(sides)
        h0 = mean_sd([1e3 * r["pile_height_m"] for r in rs])
        h1 = mean_sd([1e3 * r["surcharge_pile_height_m"] for r in rs])
        cpu = statistics.median(r["cpu_time_s"] for r in rs)
        vib = (f"{1e3 * ah:g} / {1e3 * av:g} ({peak_acceleration_g(f, ah):.2f} / {peak_acceleration_g(f, av):.2f}) "
               f"at {f:g} Hz")
        lines.append(f"| {fr} | {rr} | {vib} | {len(rs)} | {fmt(*aor)} | {fmt(*sur)} | {with_angle} of {len(rs)} "
                     f"| {sides} | {h0[0]:.0f} / {h1[0]:.0f} | {cpu:.0f} |")
    return "\n".join(lines)


def readings(seed):
    """{(reading, "before" | "after"): angle deg} of one seed's pile files."""
    out = {}
    for when, name in (("before", "pile_particles.csv"), ("after", "surcharge_particles.csv")):
        pos = read_positions_csv(Path(seed["folder"]) / name)
        for reading in OTHER_READINGS:
            out[(reading, when)] = READINGS[reading](pos, seed["measure"])
    return out


def readings_table(groups):
    """Markdown rows: per grid point and reading, the angle before and after, mean (SD; seeds with a value)."""
    lines = ["| particle friction | rolling resistance | horizontal amplitude, mm | reading | before, deg (SD; seeds) "
             "| after, deg (SD; seeds) |", "|---|---|---|---|---|---|"]
    for (fr, rr, (_, ah, _)), rs in sorted(groups.items()):
        got = [readings(r) for r in rs]
        for reading in OTHER_READINGS:
            cells = []
            for when in ("before", "after"):
                vals = [g[(reading, when)] for g in got]
                cells.append(f"{fmt(*mean_sd(vals))}; {sum(not math.isnan(v) for v in vals)}")
            lines.append(f"| {fr} | {rr} | {1e3 * ah:g} | {reading} | {cells[0]} | {cells[1]} |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs")
    ap.add_argument("--calibrated", help="a study's output folder (its calibrated values of the material)")
    ap.add_argument("--material", default="M3-dry")
    ap.add_argument("--frictions", default="0.3,0.5,0.8")
    ap.add_argument("--rolling", default="0.05,0.15,0.4")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--amplitudes-mm", default=None,
                    help="horizontal vibration amplitudes, mm (vertical at the rig's ratio); default the rig's own")
    ap.add_argument("--table-only", action="store_true", help="only tabulate the runs already in RUNS_DIR")
    ap.add_argument("--readings", action="store_true", help="also the other pile readings, before and after")
    ap.add_argument("--out", default=None, help="also write the table (markdown) here")
    args = ap.parse_args(argv)
    if not args.table_only:
        if not args.calibrated:
            raise SystemExit("--calibrated: needed to run (the study folder whose calibrated values the grid "
                             "starts from)")
        amplitudes = [None] if not args.amplitudes_mm else [1e-3 * float(a) for a in args.amplitudes_mm.split(",")]
        for amp in amplitudes:
            for fr in (float(f) for f in args.frictions.split(",")):
                for rr in (float(r) for r in args.rolling.split(",")):
                    run_point(args.runs, args.calibrated, args.material, fr, rr, args.seeds, args.workers, amp)
    groups = load(args.runs, args.material)
    text = table(groups)
    if args.readings:
        text += "\n\n" + readings_table(groups)
    print(text)
    if args.out:
        write_text(Path(args.out), text + "\n")


if __name__ == "__main__":
    main()
