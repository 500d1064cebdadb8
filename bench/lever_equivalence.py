"""The cheaper rig settings measured so far, judged again by practical equivalence
(pycal/stats/equivalence.py): taken when the 95 % interval of the paired shift of the stage's
response lies within +- 20 % of the stage's tolerance, converted into the response's units
with the stage's measured slope.

    /usr/bin/python3 bench/lever_equivalence.py STUDY_DIR [--out FILE.md]

STUDY_DIR: a study's output folder (runs/study/zinc_ore): each stage's slope is the least-squares
slope of its response on its parameter over every run of that stage (bench/stage_points.py
--linear-fit); a stage that study has not run yet takes the slope recorded with the lever.
The shifts are the ones measured on the same seeds and recorded in bench/README.md ("Levers
measured on the same seeds", `bench/friction_equivalence.py` and `bench/rerun_with.py`):
mean, standard error and degrees of freedom (paired: seeds - 1; unpaired: 2 x seeds - 2).
"""
import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from pycal.files import write_text  # noqa: E402
from pycal.stats.equivalence import judge  # noqa: E402
from stage_points import linear_fit  # noqa: E402

WALL = {"material": "M2", "stage": "wall_friction", "response": "friction_offset_mu_static",
        "parameter": "steel friction", "tolerance": 0.05, "recorded_slope": None}
WET = {"material": "M3-wet", "stage": "cohesion", "response": "friction_angle_offset_deg",
       "parameter": "pressure_fraction", "tolerance": 0.02,
       # (26.08 - (-11.04)) deg / 0.1: the stage's first points at 0.1 and 0 (main job 5bbeaad, seeds 1-6)
       "recorded_slope": 371.0}
# (stage, lever, setting, shift mean, SE, degrees of freedom, how measured, taken by the old rule)
LEVERS = [
    (WALL, "tilt 5 deg/s instead of 2", "steel 0.5", 0.0030, 0.0012, 5, "paired, seeds 1-6, 0a6ba6b", "no"),
    (WALL, "tilt 5 deg/s instead of 2", "steel 0.3", 0.0052, 0.0003, 5, "paired, seeds 1-6, 0a6ba6b", "no"),
    (WALL, "E 2e7 instead of 1e8 Pa", "steel 0.5", -0.018, 0.017, 10, "unpaired, seeds 1-6, 9b2830c", "no"),
    (WALL, "E 2e7 instead of 1e8 Pa", "steel 0.3", -0.013, 0.009, 6, "unpaired, seeds 1-4, 9b2830c", "no"),
    (WALL, "E 2e7 and static only", "steel 0.5", -0.051, 0.014, 10, "unpaired, seeds 1-6, 9b2830c", "no"),
    (WALL, "E 2e7 and static only", "steel 0.3", -0.013, 0.008, 6, "unpaired, seeds 1-4, 9b2830c", "no"),
    (WET, "tilt 5 deg/s instead of 2", "pressure_fraction 0.1", 0.03, 0.01, 2, "paired, seeds 1-3, 1b406d0", "yes"),
    (WET, "tilt 5 deg/s instead of 2", "pressure_fraction 0", 0.06, 0.08, 2, "paired, seeds 4-6, 1b406d0", "yes"),
    (WET, "tilt 5 deg/s instead of 2", "pressure_fraction 0.0222", 0.06, 0.08, 2, "paired, seeds 7-9, 1b406d0", "yes"),
]


def slope_of(stage, study_dir):
    """(slope, where it comes from) of a stage's response per unit of its parameter."""
    runs_csv = Path(study_dir) / "runs.csv"
    if runs_csv.is_file():
        fit = linear_fit(runs_csv, stage["material"], stage["stage"]).get(stage["response"])
        if fit and len(fit[1]) == 1:
            keys, b, se, _, n = fit
            return b[0], f"{b[0]:.3g} +- {se[0]:.2g} ({n} runs of {Path(study_dir).name})"
    if stage["recorded_slope"] is None:
        raise SystemExit(f"lever_equivalence: {runs_csv} has no runs of {stage['material']} {stage['stage']}")
    return stage["recorded_slope"], f"{stage['recorded_slope']:.3g} (recorded)"


def table(study_dir):
    head = ["stage", "lever", "at", "shift (95 % interval), response units", "margin +-", "in parameter units",
            "slope", "measured", "taken before", "equivalent"]
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    slopes = {}
    for stage, lever, at, mean, se, dof, how, before in LEVERS:
        key = (stage["material"], stage["stage"])
        if key not in slopes:
            slopes[key] = slope_of(stage, study_dir)
        slope, where = slopes[key]
        j = judge(mean, se, dof, stage["tolerance"], slope)
        out.append(f"| {stage['material']} {stage['stage']} (+-{stage['tolerance']:g} {stage['parameter']}) | {lever} "
                   f"| {at} | {mean:+.4g} [{j['low']:+.4g}, {j['high']:+.4g}] | {j['margin']:.3g} | "
                   f"[{j['low_parameter']:+.3g}, {j['high_parameter']:+.3g}] | {where} | {how} | {before} | "
                   f"**{'yes' if j['equivalent'] else 'no'}** |")
    return "\n".join(out) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("study_dir")
    ap.add_argument("--out", default=None, help="also write the table (markdown) here")
    a = ap.parse_args(argv)
    text = table(a.study_dir)
    print(text)
    if a.out:
        write_text(Path(a.out), text)


if __name__ == "__main__":
    main()
