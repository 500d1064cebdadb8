"""The values a stage holds while it fits its own: every material key the study
calibrates (or the stage sets) that this stage does not fit, with the value its runs use
and where that value comes from (a stage before it, this stage's `set` / `run_at`, or the
material config's start value), and the stage's rig overrides. Shown in the report."""


def stage_keys(st):
    """Material keys the stage fits or copies (its `parameter_keys`, in order)."""
    return [k for keys in st["parameter_keys"] for k in keys]


def held_values(study, material, st):
    """[{'key', 'value', 'source'}] of stage `st` of `material`, taken when it starts."""
    fitted = set(stage_keys(st))
    studied = [k for s in study.cfg["materials"][material] for k in stage_keys(s)]
    keys = list(dict.fromkeys(studied + list(st.get("set") or {}) + list(st.get("run_at") or {})))
    out = []
    for k in keys:
        if k in fitted:
            continue
        if k in (st.get("run_at") or {}):
            value, source = st["run_at"][k], "run_at of this stage (not carried on)"
        elif k in (st.get("set") or {}):
            value, source = st["set"][k], "set by this stage"
        elif k in study.overrides[material]:
            value, source = study.overrides[material][k], f"calibrated: {study.value_source[material].get(k, '?')}"
        else:
            try:
                value, source = study.current_value(material, k), f"start value (configs/materials/{material}.yaml)"
            except (KeyError, TypeError):
                continue                    # a key a later stage's `set` brings in: not held here
        out.append({"key": k, "value": value, "source": source})
    if st.get("material_set"):                # a set stage: the other components as the study has them
        from ..configs import load_material_set
        for m in load_material_set(st["material_set"])["components"]:
            if m != material:
                out += [{"key": f"{m}.{k}", "value": v, "source": f"calibrated: {study.value_source[m].get(k, '?')}"}
                        for k, v in study.overrides.get(m, {}).items()]
    for r in st["responses"]:
        for k, v in (r.get("rig_overrides") or {}).items():
            where = "of this stage" if st.get("rig") else f"({r['rig']})"    # a one-rig stage, or which rig
            out.append({"key": k, "value": v, "source": f"rig override {where}"})
    return out
