"""A study stage's points as a markdown table: the parameter values of each point and each
response's seed mean, SD and count there (from the study's history.csv, in the order run).

    /usr/bin/python3 bench/stage_points.py STUDY_DIR MATERIAL STAGE

STUDY_DIR is a study's output folder (runs/study/zinc_ore). No YADE run. Used for the
stage tables of bench/README.md (e.g. the dry fines' final pass on the surcharge run).
"""
import argparse
import csv
import json
import math
import sys
from pathlib import Path


def stage_points(history_csv, material, stage):
    """[(parameters dict, {response: (mean, sd, n)})] of one stage, points in the order they ran."""
    points = []
    with open(history_csv, newline="") as f:
        for row in csv.DictReader(f):
            if row["material"] != material or row["stage"] != stage:
                continue
            params = json.loads(row["parameters"])
            if not points or points[-1][0] != params or row["response"] in points[-1][1]:
                points.append((params, {}))
            points[-1][1][row["response"]] = (float(row["mean"]), float(row["std"]), int(row["n"]))
    return points


def _fmt(v):
    return "-" if v is None or math.isnan(v) else f"{v:.4g}"


def table(points):
    """The markdown table of stage_points' output: one row per point."""
    if not points:
        return ""
    groups = []                 # keys a stage sets to one value (equal at every point): one column
    for k in points[0][0]:
        same = next((g for g in groups if all(p[g[0]] == p[k] for p, _ in points)), None)
        if same is None:
            groups.append([k])
        else:
            same.append(k)
    responses = list(dict.fromkeys(r for _, rs in points for r in rs))
    lines = ["| point | " + " | ".join(" = ".join(g) for g in groups) + " | "
             + " | ".join(f"{r}: mean (SD; n)" for r in responses) + " |",
             "|---" * (1 + len(groups) + len(responses)) + "|"]
    for i, (params, rs) in enumerate(points, start=1):
        cells = [_fmt(params[g[0]]) for g in groups]
        cells += [f"{_fmt(rs[r][0])} ({_fmt(rs[r][1])}; {rs[r][2]})" if r in rs else "-" for r in responses]
        lines.append(f"| {i} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("study_dir")
    ap.add_argument("material")
    ap.add_argument("stage")
    a = ap.parse_args(argv)
    history = Path(a.study_dir) / "history.csv"
    if not history.is_file():
        print(f"stage_points: {history}: no such file (a study's output folder holds history.csv)", file=sys.stderr)
        return 2
    points = stage_points(history, a.material, a.stage)
    if not points:
        print(f"stage_points: {history}: no point of stage {a.stage!r} of {a.material!r}", file=sys.stderr)
        return 2
    sys.stdout.write(table(points))
    return 0


if __name__ == "__main__":
    sys.exit(main())
