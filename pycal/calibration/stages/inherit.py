"""Inherit stages: copy the values (and intervals) another material's stage found, e.g. the
wet fines take the dry fines' rolling resistance. No runs, no pictures: not a calibration
(`calibrates` False), so reports list it apart and verdicts skip it."""
import math

from ..names import group_label, unit_of_key
from .checks import stage_label
from .kind import StageKind


def normalise(c, st, key, material, mat_cfg, seeds, done):
    """An inherit stage: validated, explicit (module doc)."""
    c.keys(st, key, ["stage", "from", "keys"], ["name"])
    src = st["from"]
    c.keys(src, f"{key}.from", ["material", "stage"], ["key"])
    if (src["material"], src["stage"]) not in done:
        c.fail(f"{key}.from", f"stage {src['stage']} of {src['material']} must run before this one")
    if not isinstance(st["keys"], list) or not st["keys"]:
        c.fail(f"{key}.keys", "must be a non-empty list of config keys")
    return {"kind": "inherit", "label": stage_label(st), "from": dict(src), "keys": list(st["keys"]),
            "responses": [], "parameter_keys": [list(st["keys"])]}


def run(study, material, st):
    """The stage row: a value found for another material, copied with its interval and verdict."""
    src = st["from"]
    row = next((r for r in study.stage_rows if r["material"] == src["material"] and r["stage"] == src["stage"]),
               None)
    params = (row or {}).get("parameters") or []
    if "key" in src:
        params = [p for p in params if src["key"] in p["keys"]]
    base = {"parameters": [], "responses": [], "met": False, "points_count": 0}
    if row is None or len(params) != 1 or not math.isfinite(params[0]["estimate"]):
        why = ("ran no stage called so" if row is None else
               "has several parameters: name one with from.key" if len(params) > 1 else "found no value")
        carried = study.overrides.get(src["material"], {}).get(src.get("key"))
        if row is not None and len(params) <= 1 and isinstance(carried, (int, float)):
            # the stage failed, but an earlier stage of the source calibrated the key: that
            # value (the one the source material carries now) beats the config's guess
            lo_hi = study.intervals.get(src["material"], {}).get(src["key"], (carried, math.nan, math.nan))
            study.set_value(material, st["keys"], carried, lo_hi)
            p = {"label": group_label(st["keys"]), "keys": list(st["keys"]), "estimate": carried,
                 "low": lo_hi[1], "high": lo_hi[2], "tolerance": math.nan,
                 "unit": unit_of_key(st["keys"][0]) or "", "scale": "linear",
                 "band_low": math.nan, "band_high": math.nan}
            return {**base, "parameters": [p], "stop_reason": "inherited from an earlier stage",
                    "message": f"{src['material']} {src['stage']} {why}: took the value {src['material']} "
                               f"carries from an earlier stage ({carried:.4g}), not met"}
        return {**base, "stop_reason": "not inherited",
                "message": f"{src['material']} {src['stage']} {why} (the config value is kept)"}
    p = params[0]
    value = p["estimate"]
    study.set_value(material, st["keys"], value, (p["estimate"], p["low"], p["high"]))
    copied = {**p, "keys": list(st["keys"]), "label": group_label(st["keys"])}
    msg = f"from {src['material']} {src['stage']}"
    if not row["met"]:
        # the closest value the source measured beats the config's guess as a start; it
        # stays marked not met so nobody mistakes it for a calibrated value
        msg += f", which did not meet its tolerance ({row['stop_reason']})"
    return {**base, "parameters": [copied], "met": bool(row["met"]),
            "stop_reason": f"inherited: {row['stop_reason']}", "message": msg}


ORDER = 2
KINDS = (StageKind(name="inherit", normalise=normalise, run=run, calibrates=False),)
