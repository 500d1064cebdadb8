"""Replay a study's one-parameter stages from its runs.csv: the interval after each point.

    /usr/bin/python3 bench/stage_replay.py STUDY_DIR [--config configs/calibrations/zinc_ore.yaml]
        [--out-of-reach-factor F]

STUDY_DIR is a study's output folder (runs/study/zinc_ore). Each 1-D stage's runs are fed,
point by point in the order they ran, to the same decision the study made
(pycal.calibration.stage_1d.decide_step, the stage's target, tolerance and budget from the config):
estimate, 95 % interval, interval half-width / tolerance, the stop reason and the next point
it asks for. No YADE run. The limits a refused point sets are not replayed (a stage with a
refused point shows the bounds' view). --out-of-reach-factor F replays every stage as if it
had `out_of_reach_factor: F` (pycal.stats.stopping, rule 3; default: each stage's own). Used
to find runs a stage spent without learning (bench/README.md, "Runs a stage spent without
learning").
"""
import argparse
import csv
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from pycal.calibration.stage_1d import decide_step  # noqa: E402
from pycal.calibration.study import Study  # noqa: E402
from pycal.stats.scales import Scale  # noqa: E402


class _NoRuns:
    """An executor that runs nothing (the Study only reads its config and targets)."""
    workers = 1

    def run(self, *a, **k):
        raise RuntimeError("stage_replay runs no job")


def points_of(rows, key, per_point):
    """[(x, [responses])] in the order they ran: consecutive runs of one value, per_point at a time."""
    out = []
    for r in rows:
        x = json.loads(r["parameters"])[key]
        if out and out[-1][0] == x and len(out[-1][1]) < per_point:
            out[-1][1].append(float(r["value"]))
        else:
            out.append((x, [float(r["value"])]))
    return out


def replay(study, rows, out=print, out_of_reach_factor=None):
    for mat, stages in study.cfg["materials"].items():
        for st in stages:
            if st["kind"] in ("joint", "inherit"):
                continue
            p, n = st["parameter"], len(study.seeds)
            tgt = study.targets[(mat, st["label"])][0]
            mine = [r for r in rows if r["material"] == mat and r["stage"] == st["label"]]
            scale = Scale(*p["bounds"], log=p["scale"] == "log")
            out(f"## {mat} {st['label']} (tolerance {p['tolerance']:g}{' %' if p['tolerance_is_percent'] else ''}, "
                f"budget {st['max_runs_count']} runs)")
            xs, ys = [], []
            for x, vals in points_of(mine, p["keys"][0], n):
                xs += [x] * len(vals)
                ys += vals
                line = f"  {x:.4g}: {np.mean(vals):.4g} (n {len(xs)})"
                if len(set(xs)) >= 2:
                    factor = out_of_reach_factor if out_of_reach_factor is not None else st["out_of_reach_factor"]
                    s = decide_step(p, scale, xs, ys, tgt, st["max_runs_count"] - len(xs), n,
                                    out_of_reach_factor=factor)
                    hw = max(s.estimate - s.low, s.high - s.estimate)
                    nxt = "-" if s.next_x is None else f"{s.next_x:.4g}"
                    line += (f" -> {s.estimate:.4g} [{s.low:.4g}, {s.high:.4g}], half-width / tolerance "
                             f"{hw / s.tolerance:.2f}, stop: {s.stop or '-'}, next {nxt}")
                out(line)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("study_dir", type=Path)
    ap.add_argument("--config", type=Path, default=Path(__file__).resolve().parent.parent
                    / "configs" / "calibrations" / "zinc_ore.yaml")
    ap.add_argument("--out-of-reach-factor", type=float, default=None)
    a = ap.parse_args(argv)
    runs_csv = a.study_dir / "runs.csv"
    if not runs_csv.is_file():
        print(f"{runs_csv}: not found (a study's output folder has runs.csv)", file=sys.stderr)
        return 2
    with open(runs_csv, newline="") as fh:
        rows = list(csv.DictReader(fh))
    with tempfile.TemporaryDirectory() as tmp:
        replay(Study(a.config, _NoRuns(), tmp, log=lambda *_: None), rows, out_of_reach_factor=a.out_of_reach_factor)
    return 0


if __name__ == "__main__":
    sys.exit(main())
