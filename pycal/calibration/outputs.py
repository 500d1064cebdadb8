"""The study's output files in <out>/<study name>/, rewritten (atomically) after every stage.

  calibrated/<material>.yaml  the material config with the calibrated values (loads as a config)
  stages.csv    one row per calibrated parameter: estimate, 95 % interval, tolerance, met,
                stop reason, runs requested/simulated, the response at the estimate vs its
                target, the seed noise (parameter_unit / response_unit columns give the units)
  history.csv   one row per point run: parameters, response mean, std and runs
  runs.csv      one row per run: parameters, seed, response value
  jobs.csv      one row per job asked: section (material/stage, validation/..., application/...),
                rig, seed, job id, status, batch job id (a seed run in a batch: the batch's folder
                holds the result.json and its provenance)
  summary.json  all of the above plus the study config, seeds, YADE versions of the runs
"""
import json
import math
import time

import yaml

from .. import REPO_ROOT
from ..files import finite, write_csv, write_json, write_text
from ..gitinfo import git_commit
from .stages import calibrates

STAGE_COLUMNS = ["material", "stage", "kind", "parameter", "parameter_unit", "keys", "estimate", "interval_low",
                 "interval_high", "tolerance", "met", "stop_reason", "runs_requested", "runs_simulated",
                 "points_count", "elapsed_s", "response", "response_unit", "target", "target_band",
                 "response_at_estimate", "seed_noise_sd", "message", "runs_from_library"]
POINT_COLUMNS = ["material", "stage", "rig", "parameters", "response", "mean", "std", "n", "seeds"]
RUN_COLUMNS = ["material", "stage", "rig", "parameters", "seed", "response", "value"]
JOB_COLUMNS = ["section", "material", "rig", "seed", "job_id", "status", "batch_job_id"]


def _cell(v):
    if isinstance(v, float):
        return "" if math.isnan(v) else f"{v:.6g}"
    if isinstance(v, (list, dict)):
        return json.dumps(v)
    return "" if v is None else v


def stage_table(rows):
    """Rows of stages.csv: one per parameter (a stage without a value: one row)."""
    out = []
    for r in rows:
        resp = r.get("responses") or [{}]
        first = resp[0]
        common = {"material": r["material"], "stage": r["stage"], "kind": r["kind"], "met": r["met"],
                  "stop_reason": r["stop_reason"], "runs_requested": r.get("runs_requested"),
                  "runs_simulated": r.get("runs_simulated"), "points_count": r.get("points_count"),
                  "runs_from_library": r.get("runs_from_library", 0),
                  "elapsed_s": r.get("elapsed_s"), "message": r.get("message", ""),
                  "response": "; ".join(x.get("response", "") for x in resp),
                  "response_unit": first.get("unit", ""), "target": first.get("target", math.nan),
                  "target_band": first.get("band", math.nan),
                  "response_at_estimate": first.get("at_estimate", math.nan),
                  "seed_noise_sd": first.get("noise_sd", math.nan)}
        for p in r["parameters"] or [None]:
            row = dict(common)
            if p:
                row.update({"parameter": p["label"], "parameter_unit": p["unit"], "keys": " ".join(p["keys"]),
                            "estimate": p["estimate"], "interval_low": p["low"], "interval_high": p["high"],
                            "tolerance": p["tolerance"]})
            out.append([_cell(row.get(c, "")) for c in STAGE_COLUMNS])
    return out


def calibration_record(study, material):
    """What calibrated/<material>.yaml's values are: per key the value, its 95 % interval,
    the stage that found it and the config's start value; the keys the study meant to
    calibrate that kept their start value (a stage not run or failed); the study, its
    start, commit and dirty flag."""
    from .held import stage_keys
    prov = getattr(study, "provenance", {})
    calibrated, kept = {}, {}
    for k in dict.fromkeys(k for st in study.cfg["materials"][material] for k in stage_keys(st)):
        try:
            start = _plain(study.start_value(material, k))
        except (KeyError, TypeError):
            start = None
        if k in study.overrides[material]:
            iv = study.intervals[material].get(k)
            calibrated[k] = {"value": _plain(study.overrides[material][k]),
                             "interval_95": [_plain(iv[1]), _plain(iv[2])] if iv else None,
                             "stage": study.value_source[material].get(k), "start_value": start}
        else:
            kept[k] = {"start_value": start, "note": "not calibrated: start value of the config"}
    return {"material": material, "study": study.cfg["name"], "study_config": str(study.config_path),
            "started_utc": prov.get("started_utc"), "git_commit": prov.get("git_commit"),
            "git_dirty": prov.get("git_dirty"), "calibrated": calibrated, "start_values": kept,
            "rig_scales": stage_rig_scales(study.cfg["materials"][material]),
            "rig_scales_note": "each stage's rig at its geometric scale (geometry.scale, 1 = the lab's size; "
                               "docs/rigs.md): the values hold for a bulk of that many grains, not for the lab's cell"}


def stage_rig_scales(stages):
    """{stage label: {rig: geometry.scale}} of the stages that run a rig (the rig config's
    scale, or the stage's rig.geometry.scale override)."""
    from ..configs import load_rig
    from ..rigs.scaling import SCALE_KEY, scale_of
    out = {}
    for st in stages:
        for spec in st["responses"]:                      # none for a stage that runs no rig
            over = spec.get("rig_overrides") or {}
            scale = over.get(f"rig.geometry.{SCALE_KEY}", scale_of(load_rig(spec["rig"])))
            out.setdefault(st["label"], {})[spec["rig"]] = float(scale)
    return out


def _plain(v):
    """A YAML-safe number (NaN -> None)."""
    if isinstance(v, float) and v != v:
        return None
    return float(v) if isinstance(v, float) else v


def write_all(study):
    """Write every output file of the study as it stands."""
    out = study.out
    for m in study.cfg["materials"]:
        write_text(out / "calibrated" / f"{m}.yaml", yaml.safe_dump(study.calibrated_material(m),
                                                                         sort_keys=False))
        write_text(out / "calibrated" / f"{m}.calibration.yaml", yaml.safe_dump(calibration_record(study, m),
                                                                                 sort_keys=False))
    write_csv(out / "stages.csv", STAGE_COLUMNS, stage_table(study.stage_rows))
    write_csv(out / "history.csv", POINT_COLUMNS,
                     [[_cell(p[c]) for c in POINT_COLUMNS] for p in study.points])
    write_csv(out / "runs.csv", RUN_COLUMNS, [[_cell(r[c]) for c in RUN_COLUMNS] for r in study.runs])
    write_csv(out / "jobs.csv", JOB_COLUMNS, [[j[c] for c in JOB_COLUMNS] for j in getattr(study, "jobs", [])])
    summary = {"study": study.cfg["raw"], "config_file": str(study.config_path), "seeds": study.seeds,
               "seed_base": study.seed_base,
               # what the calibration fitted ("calibrated on") and what it predicts with those values
               "calibrated_on": [{"material": r["material"], "stage": r["stage"], "kind": r["kind"],
                                  "responses": [x.get("response") for x in r.get("responses", [])]}
                                 for r in study.stage_rows if calibrates(r["kind"])],
               "predicted": getattr(study, "validation_rows", []),
               "run_at_checks": getattr(study, "run_at_check_rows", []),
               "applied": getattr(study, "application_rows", []),
               "stages": study.stage_rows, "history": study.points,
               "runs": study.runs, "overrides": study.overrides, "intervals": study.intervals,
               "runs_requested": study.runs_requested, "elapsed_s": time.time() - study.t0,
               "yade_versions": sorted(study.yade_versions), "git_commit": git_commit(),
               "provenance": getattr(study, "provenance", {}),
               "value_sources": getattr(study, "value_source", {})}
    write_json(out / "summary.json", finite(summary))
