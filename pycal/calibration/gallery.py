"""Pictures of a stage's simulated samples, for the report: the pictures a rig's runs
write (its descriptor's `pictures`, e.g. the AoR rig's pile_side.png: the side
silhouette with the fitted flanks and every sector's angle) at the point nearest the
estimate and at the lowest and highest values the stage ran, first seed of each point,
copied into <study>/plots/<material>-<stage>/gallery/.
"""
import importlib
import json
import math
from pathlib import Path

from .. import rigs
from ..replicas import result_folder
from .run_pictures import copy_pictures, run_flank_flags, runs_dir_of
from .names import format_params
from .study_config import stage_rigs


def _trace_of(rig):
    """trace_picture of the rig's post-processing module (pycal/post/<post>.py), or None."""
    post = rigs.get(rig).post
    if not post:
        return None
    return getattr(importlib.import_module(f"pycal.post.{post}"), "trace_picture", None)


def _chosen_points(row):
    """[(caption, {key: value})]: the estimate, and for one parameter the interval's ends."""
    params = [p for p in row.get("parameters") or [] if p.get("keys")]
    if not params:
        return []
    est = {p["keys"][0]: p["estimate"] for p in params}
    out = [("at the estimate", est)]
    if len(params) == 1:
        p = params[0]
        out += [("lowest value run", {p["keys"][0]: -math.inf}), ("highest value run", {p["keys"][0]: math.inf})]
    return out


def _points_of(study, material, label, rig):
    """The parameters ({key: value}, rig keys too) of every point the stage ran on `rig`."""
    return [json.loads(k) for (m, s, r, k) in study.point_results if (m, s, r) == (material, label, rig)]


def _nearest(study, material, label, rig, want):
    """The results and parameters of the point nearest `want` ({key: value}; +-inf: the
    highest / lowest value run)."""
    points = _points_of(study, material, label, rig)
    if not points:
        return None, None
    key = next(iter(want))
    if math.isinf(want[key]):
        values = [p for p in points if isinstance(p.get(key), (int, float))]
        if not values:
            return None, None
        pick = (max if want[key] > 0 else min)(values, key=lambda p: p[key])
        return study.nearest_point_results(material, label, rig, {key: pick[key]})
    return study.nearest_point_results(material, label, rig, want)


def stage_pictures(study, material, st, row):
    """[{'file': path relative to the study folder, 'caption': ...}] of the stage's gallery."""
    runs = runs_dir_of(study.executor)
    out, seen = [], set()
    folder = study.out / "plots" / f"{material}-{st['label']}" / "gallery"
    for rig in stage_rigs(st):
        pictures, trace = rigs.get(rig).pictures, _trace_of(rig)
        if not (pictures or trace) or runs is None:
            continue
        for caption, want in _chosen_points(row):
            results, params = _nearest(study, material, st["label"], rig, want)
            if not results or json_key(params) in seen:
                continue
            seen.add(json_key(params))
            r = results[0]
            src = Path(result_folder(r, r["job"], runs))
            shown = format_params(params)
            if trace is not None:
                dest = folder / f"{rig}-{len(out):02d}-tilt_trace.png"
                dest.parent.mkdir(parents=True, exist_ok=True)
                if trace(src, r["job"], dest):
                    out.append({"file": str(dest.relative_to(study.out)), "rig": rig,
                                "caption": f"{rig}, {caption} ({shown}), seed {r['seed']}: slide against tilt"})
            out += copy_pictures(study, src, pictures, rig, folder / f"{rig}-{len(out):02d}-",
                                 f"{rig}, {caption} ({shown}), seed {r['seed']}: ")
    return out


def json_key(params):
    return json.dumps(params, sort_keys=True)


ANGLE_KEYS = ("aor_left_deg", "aor_right_deg", "aor_front_deg", "aor_back_deg", "aor_mean_deg", "aor_sectors_count")


def aor_seed_angles(study, material, st, row):
    """The AoR as the lab reads it, at the point nearest the estimate: per seed the left,
    right, front and back flank angles (deg, None: no angle on that side), their mean, the
    sector count and the doubtful flank fits, and the lab's own left / right of the
    stage's target sample.
    {} for a stage that is not read from a pile."""
    reads = [(r["rig"], r.get("target")) for r in st["responses"] if r["response"] == "aor_mean_deg"]
    points = _chosen_points(row)
    if not reads or not points:
        return {}
    rig, target = reads[0][0], reads[0][1] or {}
    results, params = _nearest(study, material, st["label"], rig, points[0][1])
    if not results:
        return {}
    runs = runs_dir_of(study.executor)
    seeds = [{"seed": r["seed"], **{k: r.get(k) for k in ANGLE_KEYS}, "flank_flags": run_flank_flags(r, runs)}
             for r in results]
    lab = None
    if target.get("sample"):
        from .. import LAB_DIR
        from ..labdata import sample
        try:
            lab_row = sample(target["sample"], study.lab_dir(st) or LAB_DIR)[target.get("test", "angle_of_repose")]
        except Exception:  # noqa: BLE001  (a report never fails on a lab lookup)
            lab_row = None
        if lab_row:
            lab = {"sample": target["sample"], "left_deg": lab_row.get("left_deg"),
                   "right_deg": lab_row.get("right_deg")}
    return {"rig": rig, "point": format_params(params), "seeds": seeds, "lab": lab}
