"""A job = rig + material + overrides + seed, resolved into one explicit file.

The resolved job holds every number the rig script uses (no hidden defaults).
Its content hash names its folder, so a job with a complete result is never run
twice and an interrupted study resumes where it stopped. A job whose estimated step
count is above numerics.max_estimated_steps_count is refused here, before anything
is written (pycal.step_estimate).
"""
import copy
import hashlib
import json
from pathlib import Path

import yaml

from . import CONFIG_DIR
from .configs import (parse_yaml_text, load_boundaries_cached, load_material, load_rig, material_names,
                      validate_material, check_rig_keys, _Checker)
from .configs import (SET_DIR, component_value, load_yaml, material_set_names, put_component_value, rig_names,
                      validate_material_set)
from .contact_rules import ContactRuleError, check_job
from .errors import ConfigError
from . import rigs, step_estimate
from .rigs import scaling

JOB_FORMAT = 1


def parse_set(items):
    """['a.b=1', 'c=x'] -> {'a.b': 1, 'c': 'x'}; values are YAML scalars/mappings."""
    out = {}
    for item in items or []:
        if "=" not in item:
            raise ConfigError("--set", item, "must be KEY=VALUE")
        key, value = item.split("=", 1)
        try:
            out[key.strip()] = parse_yaml_text(value)
        except yaml.YAMLError as exc:
            raise ConfigError("--set", key, f"value is not valid YAML: {exc}") from None
    return out


def _set_path(tree, dotted, value, where, may_add=()):
    """Replace an existing key addressed by a dotted path; new keys are errors, except the
    dotted paths in may_add (a rig's optional keys, which a config may leave out)."""
    parts = dotted.split(".")
    node = tree
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        if last and isinstance(node, dict) and dotted in may_add:
            node[part] = value
            return
        if not isinstance(node, dict) or part not in node:
            raise ConfigError(where, dotted, f"no such key to override ({'.'.join(parts[:i + 1])})")
        if last:
            node[part] = value
        else:
            node = node[part]


def override_value(job, key):
    """The value that override `key` addresses in resolved `job`: a key of the job's
    material, or '<component>.<key>' of a material set's component (as resolve_job reads
    them). None for a rig or set key, or a path the job does not have."""
    if key.startswith("rig."):
        return None
    if job.get("material_set") is not None:
        head, _, rest = key.partition(".")
        return component_value(job["materials"], {"from": head, "key": rest})
    return component_value(job["materials"], {"from": job["material"], "key": key})


def resolve_job(rig, material, overrides=None, seed=1, config_dir=CONFIG_DIR):
    """Build the explicit job dict.

    overrides: {'particles.density_kg_m3': 3000, 'rig.procedure.lift_speed_m_s': 0.01}
    Keys starting with 'rig.' change the rig config, all others the material.
    """
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ConfigError("--seed", "seed", f"{seed!r} must be a whole number >= 0")
    # a copy: a subtree override (a dict) is put into the material as it is, and a leaf
    # override below it then writes into it; the caller's dict must not change with it
    overrides = copy.deepcopy(dict(overrides or {}))
    if material in material_set_names(config_dir):
        return resolve_set_job(rig, material, overrides, seed, config_dir)
    rig_cfg = load_rig(rig, config_dir)
    mat = copy.deepcopy(load_material(material, config_dir))
    for key, value in overrides.items():
        if key.startswith("rig."):
            _set_path(rig_cfg, key[4:], value, f"overrides of configs/rigs/{rig}.yaml", rig_optional_keys(rig))
        else:
            _set_path(mat, key, value, f"overrides of configs/materials/{material}.yaml")
    partners = set(material_names(config_dir)) | set(load_boundaries_cached(config_dir))
    with blame_override(overrides, ""):
        validate_material(mat, f"configs/materials/{material}.yaml (with overrides)", partners)
    check_rig_with_overrides(rig, rig_cfg, overrides, config_dir)
    rig_cfg = scale_rig(rig, rig_cfg, overrides)
    return _finish_job(rig, rig_cfg, seed, material, {material: mat}, overrides, config_dir)


def resolve_set_materials(set_name, overrides=None, config_dir=CONFIG_DIR):
    """(materials, set) of a material set with overrides ('<component>.<key>' -> that
    material, any other key -> the set): every component material (in the set's order)
    with the set's cross_interactions written into both materials of each pair, and the
    validated set (components with mass_fraction; cross_interactions). No rig: the part of
    resolve_set_job that `pycal export` shares."""
    set_path = f"configs/{SET_DIR}/{set_name}.yaml"
    raw = load_yaml(Path(config_dir) / SET_DIR / f"{set_name}.yaml")
    known = {m: copy.deepcopy(load_material(m, config_dir)) for m in material_names(config_dir)}
    comps = list(raw.get("components") or {}) if isinstance(raw.get("components"), dict) else []
    overrides = dict(overrides or {})
    set_keys = []
    for key, value in overrides.items():
        head = key.split(".", 1)[0]
        if head in comps and "." in key:
            _set_path(known[head], key.split(".", 1)[1], value, f"overrides of configs/materials/{head}.yaml")
        else:
            set_keys.append(key)
    for key in set_keys:    # after the components': a set override wins over a from_components rule
        _own_carried_key(raw, key, known)
        _set_path(raw, key, overrides[key], f"overrides of {set_path}")
    partners = set(material_names(config_dir)) | set(load_boundaries_cached(config_dir))
    for m in comps:
        if m in known:
            validate_material(known[m], f"configs/materials/{m}.yaml (with overrides)", partners)
    mset = validate_material_set(raw, f"{set_path} (with overrides)" if overrides else set_path, known)
    materials = {m: known[m] for m in mset["components"]}
    for a, pairs in mset["cross_interactions"].items():
        for b, props in pairs.items():
            materials[a]["interactions"][b] = copy.deepcopy(props)
            materials[b]["interactions"][a] = copy.deepcopy(props)
    return materials, mset


def resolve_set_job(rig, set_name, overrides=None, seed=1, config_dir=CONFIG_DIR):
    """Job of a material set (configs/material_sets/<set_name>.yaml) on a rig that
    accepts sets (accepts_material_sets in its descriptor, pycal/rigs/<rig>.py).

    job["material"] = the set's name; job["materials"] = every component material (in
    the set's order) with the set's cross_interactions written into both materials of
    each pair; job["material_set"] = the set (components with mass_percent,
    mass_fraction and, for clump materials, the size classes used; cross_interactions).
    overrides: 'rig.<key>' -> rig config, '<component>.<key>' -> that material
    (e.g. 'M3-wet.interactions.M3-wet.cohesion.force_fraction'), any other key -> the
    set (e.g. 'cross_interactions.M2.M3-wet.cohesion.force_fraction').
    """
    rig_cfg = load_rig(rig, config_dir)
    if not rigs.get(rig).accepts_material_sets:
        takers = [r for r in rig_names(config_dir) if r in rigs.names() and rigs.get(r).accepts_material_sets]
        raise ConfigError("--material", set_name, f"rig {rig} takes one material, and {set_name} is a material set "
                          f"(rigs that take sets: {', '.join(takers) or 'none'}; pycal/rigs/<rig>.py)")
    overrides = dict(overrides or {})      # the job records {} for no overrides (its id depends on it)
    material_overrides = {}
    for key, value in overrides.items():
        if key.startswith("rig."):
            _set_path(rig_cfg, key[4:], value, f"overrides of configs/rigs/{rig}.yaml", rig_optional_keys(rig))
        else:
            material_overrides[key] = value
    materials, mset = resolve_set_materials(set_name, material_overrides, config_dir)
    check_rig_with_overrides(rig, rig_cfg, overrides, config_dir)
    rig_cfg = scale_rig(rig, rig_cfg, overrides)
    return _finish_job(rig, rig_cfg, seed, set_name, materials, overrides, config_dir, material_set=mset)


def rig_optional_keys(rig):
    """Dotted rig keys an override may add although the config leaves them out: the rig's
    optional keys and geometry.scale (every rig's)."""
    return tuple(rigs.get(rig).optional) + (f"geometry.{scaling.SCALE_KEY}",)


def scale_rig(rig, rig_cfg, overrides):
    """The rig config as built at its geometry.scale (pycal/rigs/scaling.py); a refusal
    names '--set rig.geometry.scale=S' when an override set it, else the rig's config."""
    key = f"rig.geometry.{scaling.SCALE_KEY}"
    if key in overrides:
        return scaling.apply_scale(rig, rig_cfg, "--set", f"{key}={overrides[key]!r}")
    return scaling.apply_scale(rig, rig_cfg, f"configs/rigs/{rig}.yaml", f"geometry.{scaling.SCALE_KEY}")


def _own_carried_key(raw, key, known):
    """Before a set override of `key`: a from_components rule that sets `key` (or the
    subtree holding it) is written into the set's cross pair now and dropped, so that the
    override replaces the component's value instead of being replaced by it."""
    rules = raw.get("from_components")
    if not isinstance(rules, list):
        return
    for rule in list(rules):
        to = str(rule.get("to", ""))
        if key == to or key.startswith(to + "."):
            parts = to.split(".")
            pair = raw.get("cross_interactions", {}).get(parts[1], {}).get(parts[2]) if len(parts) >= 4 else None
            if isinstance(pair, dict) and component_value(known, rule) is not None:
                put_component_value(raw, rule, known)
            rules.remove(rule)


def _finish_job(rig, rig_cfg, seed, material, materials, overrides, config_dir, material_set=None):
    """The job dict (one material or a material set) with its job_id."""
    job = {
        "job_format": JOB_FORMAT,
        "rig": rig,
        "script": rig_cfg["script"],
        "seed": seed,
        "material": material,
        "materials": materials,
        "boundaries": copy.deepcopy(load_boundaries_cached(config_dir)),
        "rig_config": rig_cfg,
        "overrides": overrides,
    }
    if material_set is not None:
        job["material_set"] = material_set
    check_contacts(job)
    check_rig_geometry(job)
    job["job_id"] = job_id(job)
    step_estimate.check(job)      # refuses a job that would run for an implausible number of steps
    return job


def check_contacts(job):
    """The job's contact law can realise every pair (pycal.contact_rules), else a ConfigError
    naming the config file and key the value comes from."""
    try:
        check_job(job)
    except ContactRuleError as exc:
        parts = exc.key.split(".")
        if parts[0] == "materials" and len(parts) > 2:
            name = parts[1]
            src = (f"configs/material_sets/{job['material']}.yaml or configs/materials/{name}.yaml"
                   if "material_set" in job else f"configs/materials/{name}.yaml")
            raise ConfigError(src, ".".join(parts[2:]), exc.reason) from None
        if parts[0] == "rig_config":
            raise ConfigError(f"configs/numerics.yaml or configs/rigs/{job['rig']}.yaml", ".".join(parts[2:]),
                              exc.reason) from None
        raise ConfigError(f"job {job['rig']}/{job['material']}", exc.key, exc.reason) from None
    return job


def check_rig_geometry(job):
    """Rig-specific checks of a job that need more than the config's keys (the rig
    descriptor's check_job: a particle larger than the cell, the transfer rig's stream);
    a ConfigError names the rig config's key."""
    desc = rigs.get(job["rig"])
    if desc.check_job is not None:
        desc.check_job(job)
    return job


class blame_override:
    """Context: a ConfigError about a key the user overrode (--set KEY=VALUE) names
    '--set KEY=VALUE' instead of the config file (prefix 'rig.' for rig keys)."""

    def __init__(self, overrides, prefix):
        self.overrides, self.prefix = overrides or {}, prefix

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if isinstance(exc, ConfigError):
            key = self.prefix + exc.field
            hits = [k for k in self.overrides if key == k or key.startswith(k + ".")]
            if hits:
                value = self.overrides[hits[0]]
                raise ConfigError("--set", f"{hits[0]}={value!r}", exc.reason) from None
        return False


def check_rig_with_overrides(rig, rig_cfg, overrides, config_dir):
    """The overridden rig config against its descriptor (units, types, ranges)."""
    with blame_override(overrides, "rig."):
        check_rig_keys(rig_cfg, _Checker(f"configs/rigs/{rig}.yaml (with overrides)"))
        from .configs import load_numerics
        rigs.check_config(rig_cfg, f"configs/rigs/{rig}.yaml (with overrides)",
                          tuple(load_boundaries_cached(config_dir)), tuple(load_numerics(config_dir)))


def canonical_json(obj):
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), allow_nan=False)


def content_digest(job):
    """12 hex of the SHA-256 of the job's canonical JSON (job_id itself excluded)."""
    body = {k: v for k, v in job.items() if k != "job_id"}
    return hashlib.sha256(canonical_json(body).encode()).hexdigest()[:12]


def job_id(job):
    """'<rig>-<material>-s<seed>-<12 hex of the content hash>' (job_id itself excluded)."""
    return f"{job['rig']}-{job['material']}-s{job['seed']}-{content_digest(job)}"
