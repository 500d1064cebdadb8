"""Calibrated values as job overrides: one rule for the study's validation, its
application runs and `pycal run --calibrated`.

A study keeps, per material, the overrides its stages found ({'particles.density_kg_m3':
3772, ...}; summary.json "overrides"). For one material they apply as they are; for a
material set each component's keys are prefixed with its name ('M2.particles...'), except
a component's pairs with another component of the set: those are the set's
cross_interactions, which take component values through the set's `from_components`
rules (configs/material_sets/); a pair key such a rule reads (e.g. M3-wet's
interactions.M2.cohesion.force_fraction, the weight part of the wet fines' hold on gravel)
is kept, so that the rule carries its calibrated value.
"""
import json
from pathlib import Path

from ..errors import ConfigError


def overrides_for_material(study_overrides, material):
    """Job overrides of `material` (a material or a material set) from the study's
    calibrated overrides {material: {key: value}}."""
    from ..configs import load_material_set, material_set_names
    if material not in material_set_names():
        return dict(study_overrides.get(material, {}))
    mset = load_material_set(material)
    comps = mset["components"]
    read = [(r["from"], r["key"]) for r in mset.get("from_components") or []]
    out = {}
    for m in comps:
        for k, v in study_overrides.get(m, {}).items():
            head = k.split(".")
            if (head[0] == "interactions" and len(head) > 1 and head[1] in comps and head[1] != m
                    and not any(f == m and (k == key or k.startswith(key + ".") or key.startswith(k + "."))
                                for f, key in read)):
                continue
            out[f"{m}.{k}"] = v
    return out


def run_overrides(study_overrides, spec):
    """Job overrides of a run after the calibration (a validation prediction or an
    application run): its rig_overrides and the calibrated values of its material (set)."""
    return dict(spec.get("rig_overrides", {}), **overrides_for_material(study_overrides, spec["material"]))


def load_study_overrides(study_dir):
    """The calibrated overrides {material: {key: value}} of a study output folder
    (<runs>/study/<name>/summary.json)."""
    path = Path(study_dir) / "summary.json"
    if not path.is_file():
        raise ConfigError("--calibrated", str(study_dir), "no summary.json there (give a study's output folder, "
                          "e.g. runs/study/zinc_ore)")
    try:
        data = json.loads(path.read_text())
    except ValueError as exc:
        raise ConfigError(str(path), "", f"not valid JSON: {exc}") from None
    if not isinstance(data.get("overrides"), dict):
        raise ConfigError(str(path), "overrides", "missing: not a study summary")
    return data["overrides"]
