"""A study stage's points as a markdown table: the parameter values of each point and each
response's seed mean, SD and count there (from the study's history.csv, in the order run).

    /usr/bin/python3 bench/stage_points.py STUDY_DIR MATERIAL STAGE [--linear-fit]

STUDY_DIR is a study's output folder (runs/study/zinc_ore). No YADE run. Used for the
stage tables of bench/README.md (e.g. the dry fines' final pass on the surcharge run).
--linear-fit adds, per response, a straight-line fit over every seed's run of the stage
(runs.csv): the change per unit of each parameter with its standard error, and the
residual SD (a local picture of what the response follows; the stage's own model is a GP).
"""
import argparse
import csv
import json
import math
import sys
from pathlib import Path

import numpy as np


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


def key_groups(param_dicts):
    """The parameter keys in groups that hold one value at every point (the keys a stage sets
    to one value, e.g. the rolling resistance on the material and on each wall): one column each."""
    groups = []
    for k in param_dicts[0]:
        same = next((g for g in groups if all(p[g[0]] == p[k] for p in param_dicts)), None)
        if same is None:
            groups.append([k])
        else:
            same.append(k)
    return groups


def table(points):
    """The markdown table of stage_points' output: one row per point."""
    if not points:
        return ""
    groups = key_groups([p for p, _ in points])
    responses = list(dict.fromkeys(r for _, rs in points for r in rs))
    lines = ["| point | " + " | ".join(" = ".join(g) for g in groups) + " | "
             + " | ".join(f"{r}: mean (SD; n)" for r in responses) + " |",
             "|---" * (1 + len(groups) + len(responses)) + "|"]
    for i, (params, rs) in enumerate(points, start=1):
        cells = [_fmt(params[g[0]]) for g in groups]
        cells += [f"{_fmt(rs[r][0])} ({_fmt(rs[r][1])}; {rs[r][2]})" if r in rs else "-" for r in responses]
        lines.append(f"| {i} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def linear_fit(runs_csv, material, stage):
    """{response: (keys, slopes, standard errors, residual SD, runs)}: least squares of each
    response on the stage's parameters (one column per group of keys set to one value)
    over every run with a value."""
    rows = {}
    with open(runs_csv, newline="") as f:
        for row in csv.DictReader(f):
            if row["material"] == material and row["stage"] == stage and row["value"] not in ("", "nan"):
                rows.setdefault(row["response"], []).append((json.loads(row["parameters"]), float(row["value"])))
    out = {}
    for response, runs in rows.items():
        keys = [g[0] for g in key_groups([p for p, _ in runs])]
        X = np.array([[1.0] + [p[k] for k in keys] for p, _ in runs])
        y = np.array([v for _, v in runs])
        dof = len(y) - X.shape[1]
        if dof < 1:
            continue
        b = np.linalg.lstsq(X, y, rcond=None)[0]
        s2 = float(np.sum((y - X @ b) ** 2)) / dof
        se = np.sqrt(np.diag(s2 * np.linalg.inv(X.T @ X)))
        out[response] = (keys, b[1:].tolist(), se[1:].tolist(), math.sqrt(s2), len(y))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("study_dir")
    ap.add_argument("material")
    ap.add_argument("stage")
    ap.add_argument("--linear-fit", action="store_true", help="slopes per parameter from every run (runs.csv)")
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
    if a.linear_fit:
        for response, (keys, b, se, sd, n) in linear_fit(Path(a.study_dir) / "runs.csv", a.material, a.stage).items():
            slopes = "; ".join(f"{k} {v:+.4g} +- {e:.2g}" for k, v, e in zip(keys, b, se))
            print(f"\n{response} ({n} runs): per unit of {slopes}; residual SD {sd:.3g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
