"""The checks every stage kind's config shares (pycal/calibration/stages/<kind>.py): the
parameter groups, responses, targets, overrides and material sets of a stage in a study config,
each error naming the file, the dotted key and the reason."""
import copy

from ...errors import ConfigError
from ...post import responses as responses_mod
from ..names import group_label, unit_of_key

DENSITY_KEY = "particles.density_kg_m3"
DEFAULT_POINTS_COUNT = 8          # a stage's default run budget: this many points' worth of runs
LAB_ANGLE_TESTS = {"aor_mean_deg": "angle_of_repose",   # response -> the lab table its angle comes from
                   "surcharge_mean_deg": "surcharge"}

REMOVED = {
    "max_iterations_count": "replaced by max_runs_count (a run budget: every seed counts)",
    "max_seeds_count": "no longer used: the design adds runs where they shrink the interval",
    "tolerance_deg": "the lab band is now target.band_deg; the stop rule is parameter.tolerance_<unit>",
    "tolerance_mu": "the lab band is now target.band_mu; the stop rule is parameter.tolerance_<unit>",
    "tolerance_log_ratio": "the lab band is now target.band_log_ratio; the stop rule is parameter.tolerance_<unit>",
    "tolerance_percent": "the lab band is now target.band_percent; the stop rule is parameter.tolerance_<unit>",
    "tolerance_rms_z": "joint stages: responses[].target.band_z, and each parameter's tolerance_<unit>",
}


def stage_label(st):
    """The name of a stage in outputs and `inherit`: its `name`, else its kind."""
    return st.get("name", st["stage"])


def _check_removed(c, data, key):
    for k in data:
        if k in REMOVED:
            c.fail(f"{key}.{k}" if key else k, REMOVED[k])


def _material_has(mat_cfg, dotted):
    node = mat_cfg
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return False
        node = node[part]
    return True


def _parameter(c, p, key, material, mat_cfg, kind, one_d):
    """A validated, explicit parameter group of a stage of `kind` (a StageKind: its default keys,
    scale and response direction)."""
    if not isinstance(p, dict):
        c.fail(key, "must be a mapping (keys, bounds, tolerance_<unit>, ...)")
    tol_keys = [k for k in p if k.startswith("tolerance_")]
    optional = ["keys", "start", "scale", "label"] + (["response_increases", "response_slope_estimate"] if one_d else [])
    c.keys(p, key, ["bounds"] + ([] if kind.default_keys else ["keys"]), optional + tol_keys)
    keys = p.get("keys", list(kind.default_keys) or None)
    if not isinstance(keys, list) or not keys or not all(isinstance(k, str) for k in keys):
        c.fail(f"{key}.keys", "must be a non-empty list of config keys")
    for k in keys:
        if not _material_has(mat_cfg, k):
            c.fail(f"{key}.keys", f"{k}: no such key in configs/materials/{material}.yaml "
                                  f"(with the stages' `set` so far)")
    units = {unit_of_key(k) for k in keys}
    if len(units) != 1 or None in units:
        c.fail(f"{key}.keys", f"{keys}: all keys of a group need the same unit suffix")
    unit = units.pop()
    if len(tol_keys) != 1 or tol_keys[0] not in (f"tolerance_{unit}", "tolerance_percent"):
        c.fail(f"{key}.tolerance_{unit}", f"give the stop rule's tolerance once, in the parameter's unit: "
                                          f"tolerance_{unit} (or tolerance_percent of the estimate)"
                                          + (f"; found {', '.join(tol_keys)}" if tol_keys else ""))
    tol = c.number(p[tol_keys[0]], f"{key}.{tol_keys[0]}", 0, lo_open=True)
    b = p["bounds"]
    if not isinstance(b, list) or len(b) != 2:
        c.fail(f"{key}.bounds", "must be [lo, hi]")
    lo, hi = (c.number(v, f"{key}.bounds") for v in b)
    if not lo < hi:
        c.fail(f"{key}.bounds", f"{b}: need lo < hi")
    scale = p.get("scale", "log" if kind.log_scale else "linear")
    c.string(scale, f"{key}.scale", ["linear", "log"])
    if scale == "log" and lo <= 0:
        c.fail(f"{key}.bounds", f"{b}: a log scale needs bounds > 0")
    if "start" in p:
        c.number(p["start"], f"{key}.start")
        if not lo <= p["start"] <= hi:
            c.fail(f"{key}.start", f"{p['start']} outside bounds {b}")
    out = {"keys": list(keys), "bounds": [float(lo), float(hi)], "start": p.get("start"), "scale": scale,
           "unit": unit, "tolerance": float(tol), "tolerance_is_percent": tol_keys[0] == "tolerance_percent",
           "tolerance_key": tol_keys[0], "label": p.get("label") or group_label(keys)}
    if one_d:
        inc = p.get("response_increases", kind.response_increases)
        if not isinstance(inc, bool):
            c.fail(f"{key}.response_increases", "must be true or false: the direction physics gives the "
                                                "response (the noise must not decide)")
        out["increasing"] = inc
        slope = p.get("response_slope_estimate")
        if slope is not None and not c.number(slope, f"{key}.response_slope_estimate") > 0:
            c.fail(f"{key}.response_slope_estimate", f"{slope}: must be > 0 (|d response / d parameter|)")
        out["slope"] = slope
    return out


def _target(c, t, key, response):
    """A validated target spec (the value itself is read from the lab data by the study)."""
    t = {} if t is None else t
    if not isinstance(t, dict):
        c.fail(key, "must be a mapping: {value: X} or {sample: KEY, test: NAME}, with optional band_<unit>")
    unit = response.unit
    allowed = ["value", "sample", "test", f"band_{unit}", "band_percent", f"standard_error_{unit}",
               "standard_error_seeds_count"]
    for k in t:
        if k not in allowed:
            hint = (f" (this response is in {unit}: band_{unit}, standard_error_{unit})"
                    if k.startswith(("band_", "standard_error_")) else "")
            c.fail(f"{key}.{k}", f"unknown key{hint}; allowed: {', '.join(allowed)}")
    has_lab = {"sample", "test"} <= set(t)
    if "value" in t:
        c.number(t["value"], f"{key}.value")
        if "sample" in t or "test" in t:
            c.fail(key, "give either value or sample + test, not both")
    elif not has_lab and response.name != "bulk_density_kg_m3":
        c.fail(key, f"needs value (or sample + test for an angle); only bulk_density_kg_m3 defaults to the "
                    f"material's lab sample")
    if has_lab and response.name not in LAB_ANGLE_TESTS:
        c.fail(f"{key}.sample", f"a lab sample's angle is a target of {' or '.join(LAB_ANGLE_TESTS)} only, "
                                f"not {response.name}")
    if has_lab and t["test"] != LAB_ANGLE_TESTS[response.name]:
        c.fail(f"{key}.test", f"{response.name} reads the lab's {LAB_ANGLE_TESTS[response.name]} angle, "
                              f"not {t['test']!r}")
    for k in (f"band_{unit}", "band_percent", f"standard_error_{unit}"):
        if k in t:
            c.number(t[k], f"{key}.{k}", 0)
    if "standard_error_seeds_count" in t:
        n = t["standard_error_seeds_count"]
        if isinstance(n, bool) or not isinstance(n, int) or n < 2:
            c.fail(f"{key}.standard_error_seeds_count", f"{n!r} must be a whole number >= 2 (a standard error "
                                                         f"needs two values)")
        if f"standard_error_{unit}" not in t:
            c.fail(f"{key}.standard_error_seeds_count", f"goes with standard_error_{unit}, which is missing")
    if f"band_{unit}" in t and "band_percent" in t:
        c.fail(f"{key}.band_percent", f"give band_{unit} or band_percent, not both")
    if "band_percent" in t and "value" in t and t["value"] == 0:
        c.fail(f"{key}.band_percent", "a band in percent of a zero target is zero: give band_" + unit)
    return dict(t)


def _response(c, name, key):
    r = responses_mod.get(name) if isinstance(name, str) else None
    if r is None:
        c.fail(key, f"{name!r}: not a known response ({', '.join(responses_mod.RESPONSES)}) nor a result key "
                    f"with a unit suffix")
    return r


def _rig_response(c, rig, response, key):
    """The stage's rig has a descriptor and a config, and gives `response` (a named
    response the descriptor lists, or one of its result keys)."""
    from ... import rigs
    from ...configs import rig_names
    if rig not in rig_names() or rig not in rigs.names():
        c.fail(f"{key}.rig", f"{rig!r}: unknown rig{rigs.nearest(rig, rigs.names())} (rigs: {', '.join(rigs.names())})")
    desc = rigs.get(rig)
    if response.name in responses_mod.RESPONSES:
        if response.name not in desc.responses:
            c.fail(f"{key}.response", f"rig {rig} does not give {response.name} (it gives: "
                   f"{', '.join(desc.responses) or 'no named response'}; pycal/rigs/{rig}.py)")
    elif response.name not in desc.result_keys:
        hint = rigs.nearest(response.name, desc.result_keys)
        c.fail(f"{key}.response", f"{response.name!r} is not a result key of rig {rig}{hint} "
               f"(its keys: {', '.join(desc.result_keys)})")


def _lab_angle_exists(c, target, key, lab_dir):
    """A target {sample, test} names a lab sample with that test's angles (labresults/)."""
    if not {"sample", "test"} <= set(target):
        return
    from ... import LAB_DIR
    from ...labdata import aor_target_deg
    try:
        aor_target_deg(target["sample"], target["test"], lab_dir or LAB_DIR)
    except ConfigError as exc:
        c.fail(f"{key}.sample", f"{target['sample']!r} / {target['test']!r}: {exc}")


def _check_overrides(c, st, key, material=None, mat_cfg=None):
    """rig_overrides only rig keys; `set` only existing material keys (applied to mat_cfg,
    the material as the study has changed it so far)."""
    for k, v in (st.get("set", {}) or {}).items():
        if str(k).startswith("rig."):
            c.fail(f"{key}.set.{k}", "only material keys may be set here (rig keys: rig_overrides)")
        if mat_cfg is not None:
            if not _material_has(mat_cfg, k):
                c.fail(f"{key}.set.{k}", f"no such key in configs/materials/{material}.yaml")
            *head, last = k.split(".")
            node = mat_cfg
            for part in head:
                node = node[part]
            node[last] = copy.deepcopy(v)
    for k in st.get("rig_overrides", {}) or {}:
        if not str(k).startswith("rig."):
            c.fail(f"{key}.rig_overrides.{k}", "only rig keys (rig.procedure...) may be overridden here")
    run_at = st.get("run_at", {}) or {}
    if not isinstance(run_at, dict):
        c.fail(f"{key}.run_at", "must be a mapping of material keys to the values this stage runs at")
    for k, v in run_at.items():
        if str(k).startswith("rig."):
            c.fail(f"{key}.run_at.{k}", "only material keys here (rig keys: rig_overrides)")
        if mat_cfg is not None and not _material_has(mat_cfg, k):
            c.fail(f"{key}.run_at.{k}", f"no such key in configs/materials/{material}.yaml")


def _material_set(c, st, key, material):
    """A stage's material_set: a set of configs/material_sets/ with `material` as a
    component, on a rig that takes sets."""
    from ... import rigs
    from ...configs import load_material_set, material_set_names
    name = st["material_set"]
    if not isinstance(name, str) or name not in material_set_names():
        c.fail(f"{key}.material_set", f"{name!r}: no such material set (configs/material_sets: "
                                      f"{', '.join(material_set_names())})")
    comps = load_material_set(name)["components"]
    if material not in comps:
        c.fail(f"{key}.material_set", f"{name} has no component {material} (its components: {', '.join(comps)}): "
                                      f"the stage moves {material}'s keys")
    if st.get("run_at"):
        c.fail(f"{key}.run_at", "not with material_set (the run_at check reruns a stage on its material alone)")
    if st.get("rig") in rigs.names() and not rigs.get(st["rig"]).accepts_material_sets:
        c.fail(f"{key}.material_set", f"rig {st['rig']} takes one material, not a set (pycal/rigs/{st['rig']}.py)")
