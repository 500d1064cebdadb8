"""One-parameter stages: one parameter group moved until one response of one rig meets its
target (pycal/calibration/stage_1d.py runs them). Five kinds, which differ only in their
defaults: density (keys particles.density_kg_m3, response bulk_density_kg_m3, log scale, the
response increasing and proportional to the parameter), rolling_resistance, cohesion,
stiffness (log scale) and friction."""
from .. import stage_1d
from .kind import StageKind
from .checks import (DEFAULT_POINTS_COUNT, DENSITY_KEY, _check_overrides, _check_removed, _lab_angle_exists,
                     _material_set, _parameter, _response, _rig_response, _target, stage_label)


def normalise(c, st, key, material, mat_cfg, seeds, done):
    """A one-parameter stage: validated, explicit (module doc)."""
    kind = BY_NAME[st["stage"]]
    _check_removed(c, st, key)
    c.keys(st, key, ["stage", "rig", "parameter"] + ([] if kind.default_response else ["response"]),
           ["name", "response", "target", "rig_overrides", "run_at", "set", "max_runs_count", "lab_dir",
            "out_of_reach_factor", "material_set"])
    _check_overrides(c, st, key, material, mat_cfg)
    if "material_set" in st:
        _material_set(c, st, key, material)
    response = _response(c, st.get("response", kind.default_response), f"{key}.response")
    _rig_response(c, st["rig"], response, key)
    _lab_angle_exists(c, st.get("target") or {}, f"{key}.target", st.get("lab_dir"))
    if response.vector:
        c.fail(f"{key}.response", f"{response.name} is a vector (one value per lab step): a joint stage's response")
    out = {"kind": kind.name, "label": stage_label(st), "rig": st["rig"], "response": response.name,
           "target": _target(c, st.get("target"), f"{key}.target", response),
           "rig_overrides": dict(st.get("rig_overrides") or {}), "set": dict(st.get("set") or {}),
           "run_at": dict(st.get("run_at") or {}), "lab_dir": st.get("lab_dir"),
           "material_set": st.get("material_set"),
           "parameter": _parameter(c, st["parameter"], f"{key}.parameter", material, mat_cfg, kind, True),
           "response_proportional": kind.proportional}
    out["responses"] = [{"rig": out["rig"], "response": out["response"], "target": out["target"],
                         "rig_overrides": out["rig_overrides"]}]
    out["parameter_keys"] = [out["parameter"]["keys"]]
    out["max_runs_count"] = int(c.number(st.get("max_runs_count", DEFAULT_POINTS_COUNT * seeds),
                                         f"{key}.max_runs_count", 2 * seeds))
    # give up when the tolerance is out of reach in the budget (pycal.stats.stopping, rule 3);
    # below 1 it would stop stages that can still be met
    factor = st.get("out_of_reach_factor")
    out["out_of_reach_factor"] = None if factor is None else c.number(factor, f"{key}.out_of_reach_factor", 1.0)
    return out


def _kind(name, **defaults):
    return StageKind(name=name, normalise=normalise, run=stage_1d.run, **defaults)


ORDER = 0
KINDS = (_kind("density", default_keys=(DENSITY_KEY,), default_response="bulk_density_kg_m3", log_scale=True,
               response_increases=True, proportional=True),
         _kind("rolling_resistance"), _kind("cohesion"), _kind("stiffness", log_scale=True), _kind("friction"))
BY_NAME = {k.name: k for k in KINDS}
