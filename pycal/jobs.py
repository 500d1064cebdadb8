"""A job = rig + material + overrides + seed, resolved into one explicit file.

The resolved job holds every number the rig script uses (no hidden defaults).
Its content hash names its folder, so a job with a complete result is never run
twice and an interrupted study resumes where it stopped.
"""
import copy
import hashlib
import json

import yaml

from . import CONFIG_DIR
from .configs import (parse_yaml_text, load_boundaries_cached, load_material, load_rig, material_names,
                      validate_material, check_rig_keys, _Checker)
from .errors import ConfigError

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


def _set_path(tree, dotted, value, where):
    """Replace an existing key addressed by a dotted path; new keys are errors."""
    parts = dotted.split(".")
    node = tree
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        if not isinstance(node, dict) or part not in node:
            raise ConfigError(where, dotted, f"no such key to override ({'.'.join(parts[:i + 1])})")
        if last:
            node[part] = value
        else:
            node = node[part]


def resolve_job(rig, material, overrides=None, seed=1, config_dir=CONFIG_DIR):
    """Build the explicit job dict.

    overrides: {'particles.density_kg_m3': 3000, 'rig.procedure.lift_speed_m_s': 0.01}
    Keys starting with 'rig.' change the rig config, all others the material.
    """
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ConfigError("--seed", "seed", f"{seed!r} must be a whole number >= 0")
    rig_cfg = load_rig(rig, config_dir)
    mat = copy.deepcopy(load_material(material, config_dir))
    overrides = dict(overrides or {})
    for key, value in overrides.items():
        if key.startswith("rig."):
            _set_path(rig_cfg, key[4:], value, f"overrides of configs/rigs/{rig}.yaml")
        else:
            _set_path(mat, key, value, f"overrides of configs/materials/{material}.yaml")
    partners = set(material_names(config_dir)) | set(load_boundaries_cached(config_dir))
    validate_material(mat, f"configs/materials/{material}.yaml (with overrides)", partners)
    check_rig_keys(rig_cfg, _Checker(f"configs/rigs/{rig}.yaml (with overrides)"))
    job = {
        "job_format": JOB_FORMAT,
        "rig": rig,
        "script": rig_cfg["script"],
        "seed": seed,
        "material": material,
        "materials": {material: mat},
        "boundaries": copy.deepcopy(load_boundaries_cached(config_dir)),
        "rig_config": rig_cfg,
        "overrides": overrides,
    }
    job["job_id"] = job_id(job)
    return job


def canonical_json(obj):
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), allow_nan=False)


def job_id(job):
    """'<rig>-<material>-s<seed>-<12 hex of the content hash>' (job_id itself excluded)."""
    body = {k: v for k, v in job.items() if k != "job_id"}
    digest = hashlib.sha256(canonical_json(body).encode()).hexdigest()[:12]
    return f"{job['rig']}-{job['material']}-s{job['seed']}-{digest}"
