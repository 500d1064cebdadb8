"""Joint stages: 2 - 3 parameter groups moved together against one or more responses (on one
or more rigs), a posterior over them (pycal/calibration/stage_joint.py runs them)."""
from .. import stage_joint
from .kind import StageKind
from .checks import (DEFAULT_POINTS_COUNT, _check_overrides, _check_removed, _lab_angle_exists, _parameter, _response,
                     _rig_response, _target, stage_label)


def normalise(c, st, key, material, mat_cfg, seeds, done):
    """A joint stage: validated, explicit (module doc)."""
    _check_removed(c, st, key)
    c.keys(st, key, ["stage", "responses", "parameters"], ["name", "set", "run_at", "max_runs_count", "lab_dir"])
    _check_overrides(c, st, key, material, mat_cfg)
    if not isinstance(st["parameters"], list) or not 2 <= len(st["parameters"]) <= 3:
        c.fail(f"{key}.parameters", "a joint stage moves a list of 2 or 3 parameter groups")
    if not isinstance(st["responses"], list) or not st["responses"]:
        c.fail(f"{key}.responses", "must be a list of {rig, response, target, rig_overrides}")
    resp = []
    for j, r in enumerate(st["responses"]):
        rk = f"{key}.responses[{j}]"
        c.keys(r, rk, ["rig", "response"], ["target", "rig_overrides"])
        _check_overrides(c, r, rk)
        response = _response(c, r["response"], f"{rk}.response")
        _rig_response(c, r["rig"], response, rk)
        _lab_angle_exists(c, r.get("target") or {}, f"{rk}.target", st.get("lab_dir"))
        target = dict(r.get("target") or ({"value": 0.0, "band_z": 1.0} if response.unit == "z" else {}))
        resp.append({"rig": r["rig"], "response": response.name,
                     "target": _target(c, target, f"{rk}.target", response),
                     "rig_overrides": dict(r.get("rig_overrides") or {})})
    params = [_parameter(c, p, f"{key}.parameters[{j}]", material, mat_cfg, KIND, False)
              for j, p in enumerate(st["parameters"])]
    out = {"kind": "joint", "label": stage_label(st), "responses": resp, "parameters": params,
           "set": dict(st.get("set") or {}), "run_at": dict(st.get("run_at") or {}), "lab_dir": st.get("lab_dir")}
    out["max_runs_count"] = int(c.number(st.get("max_runs_count", DEFAULT_POINTS_COUNT * seeds * len(resp)),
                                         f"{key}.max_runs_count", (len(params) + 1) * seeds * len(resp)))
    out["parameter_keys"] = [p["keys"] for p in params]
    return out


KIND = StageKind(name="joint", normalise=normalise, run=stage_joint.run)
ORDER = 1
KINDS = (KIND,)
