"""Does the surcharge tell sliding friction from rolling resistance? (issue 28 item 2)

    /usr/bin/python3 bench/surcharge_grid.py RUNS_DIR --calibrated STUDY_DIR [--material M3-dry] \
        [--frictions 0.3,0.5,0.8] [--rolling 0.05,0.15,0.4] [--seeds 4] [--workers 2] \
        [--vibration-scales 1.0] [--table-only] [--out table.md]

Runs `pycal run surcharge` (cached: a stopped grid resumes) with a study's calibrated values
of the material (--calibrated: its output folder, e.g. runs/study/zinc_ore) and the lift speed
the study's AoR stages and predictions use (10 mm/s), over a grid of particle-particle friction
(--frictions, the material's own pair) and rolling resistance (--rolling, set on the material
and on the steel and PVC walls as the study's rolling stage sets it), seeds 1..--seeds.
--vibration-scales multiplies both vibration amplitudes of the rig (configs/rigs/surcharge.yaml: an
assumption, the lab does not give its vibrator's): 1.0 is the rig as shipped.
One surcharge run gives both angles: the static pile before the vibration (aor_mean_deg, the
AoR stage's response) and after it (surcharge_mean_deg). Prints per grid point the mean and SD
over the seeds of both, how many seeds have an angle after the vibration, the pile height
before and after (m), and the median CPU per run.
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
from pycal.files import write_text  # noqa: E402

LIFT_SPEED_M_S = 0.01          # as the study's AoR stages and surcharge predictions
G_M_S2 = 9.81
AMPLITUDE_KEYS = ("rig.procedure.vibration_amplitude_horizontal_m", "rig.procedure.vibration_amplitude_vertical_m")


def rig_vibration():
    """(frequency Hz, horizontal amplitude m, vertical amplitude m) of the shipped surcharge rig."""
    p = yaml.safe_load((ROOT / "configs" / "rigs" / "surcharge.yaml").read_text())["procedure"]
    return (p["vibration_frequency_hz"], p["vibration_amplitude_horizontal_m"],
            p["vibration_amplitude_vertical_m"])


def peak_acceleration_g(frequency_hz, amplitude_m):
    """Peak acceleration of a sinusoid, in units of g: (2 pi f)^2 A / g."""
    return (2 * math.pi * frequency_hz) ** 2 * amplitude_m / G_M_S2


def rolling_keys(material):
    """The keys the study's rolling stage sets together: the material's pair and the walls'."""
    return [f"interactions.{material}.rolling_resistance_coefficient",
            "interactions.steel.rolling_resistance_coefficient",
            "interactions.pvc.rolling_resistance_coefficient"]


def settings(material, friction, rolling, scale=1.0):
    """The --set overrides of one grid point (the amplitudes only when scaled: the shipped rig's runs keep their ids)."""
    ov = {"rig.procedure.lift_speed_m_s": LIFT_SPEED_M_S,
          f"interactions.{material}.friction_coefficient": friction}
    ov.update({k: rolling for k in rolling_keys(material)})
    if scale != 1.0:
        _, ah, av = rig_vibration()
        ov.update({AMPLITUDE_KEYS[0]: ah * scale, AMPLITUDE_KEYS[1]: av * scale})
    return ov


def run_point(runs, calibrated, material, friction, rolling, seeds, workers, scale=1.0):
    cmd = [sys.executable, "-m", "pycal", "run", "surcharge", "--material", material, "--calibrated", str(calibrated),
           "--seeds", str(seeds), "--workers", str(workers), "--out", str(runs)]
    for k, v in settings(material, friction, rolling, scale).items():
        cmd += ["--set", f"{k}={json.dumps(v)}"]
    print(f"[grid] friction {friction}, rolling {rolling}, vibration x{scale}: {seeds} seeds", flush=True)
    subprocess.run(cmd, cwd=ROOT, check=True)


def load(runs, material):
    """{(friction, rolling, vibration scale): [seed]} of the grid's runs in RUNS_DIR: one dict per seed (a job's
    replica: its measurements, its seed, and the job's CPU seconds shared out over its replicas)."""
    _, ah, _ = rig_vibration()
    out = {}
    for path in sorted((Path(runs) / "surcharge").glob("*/result.json")):
        r = json.loads(path.read_text())
        ov = (r.get("job") or {}).get("overrides") or {}
        if r.get("material") != material or ov.get("rig.procedure.lift_speed_m_s") != LIFT_SPEED_M_S:
            continue
        fr = ov.get(f"interactions.{material}.friction_coefficient")
        rr = ov.get(rolling_keys(material)[0])
        scale = round(ov.get(AMPLITUDE_KEYS[0], ah) / ah, 3)
        if fr is None or rr is None:
            continue
        reps = r.get("replicas") or []
        cpu = r["provenance"]["cpu_time_s"] / max(1, len(reps))
        for rep in reps:
            if rep.get("status") == "ok":
                out.setdefault((fr, rr, scale), []).append({**rep["measurements"], "seed": rep["seed"],
                                                            "cpu_time_s": cpu})
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
    f, ah, av = rig_vibration()
    lines = ["| particle friction | rolling resistance | vibration: amplitude scale (peak acceleration horizontal / "
             "vertical, g) | seeds | AoR before, deg (SD) | surcharge after, deg (SD) "
             "| seeds with an angle after | pile height before / after, mm | CPU s per run (median) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for (fr, rr, sc), rs in sorted(groups.items()):
        aor = mean_sd([r.get("aor_mean_deg") for r in rs])
        sur = mean_sd([r.get("surcharge_mean_deg") for r in rs])
        with_angle = sum(r.get("surcharge_mean_deg") is not None for r in rs)
        h0 = mean_sd([1e3 * r["pile_height_m"] for r in rs])
        h1 = mean_sd([1e3 * r["surcharge_pile_height_m"] for r in rs])
        cpu = statistics.median(r["cpu_time_s"] for r in rs)
        vib = f"x{sc:g} ({peak_acceleration_g(f, ah * sc):.2f} / {peak_acceleration_g(f, av * sc):.2f})"
        lines.append(f"| {fr} | {rr} | {vib} | {len(rs)} | {fmt(*aor)} | {fmt(*sur)} | {with_angle} of {len(rs)} "
                     f"| {h0[0]:.0f} / {h1[0]:.0f} | {cpu:.0f} |")
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
    ap.add_argument("--vibration-scales", default="1.0", help="factors on both vibration amplitudes of the rig")
    ap.add_argument("--table-only", action="store_true", help="only tabulate the runs already in RUNS_DIR")
    ap.add_argument("--out", default=None, help="also write the table (markdown) here")
    args = ap.parse_args(argv)
    if not args.table_only:
        if not args.calibrated:
            raise SystemExit("--calibrated: needed to run (the study folder whose calibrated values the grid starts from)")
        for sc in (float(x) for x in args.vibration_scales.split(",")):
            for fr in (float(f) for f in args.frictions.split(",")):
                for rr in (float(r) for r in args.rolling.split(",")):
                    run_point(args.runs, args.calibrated, args.material, fr, rr, args.seeds, args.workers, sc)
    text = table(load(args.runs, args.material))
    print(text)
    if args.out:
        write_text(Path(args.out), text + "\n")


if __name__ == "__main__":
    main()
