"""A rig at a geometric scale: `geometry.scale` s (default 1, the lab's size).

Every length of the rig itself is multiplied by s (cells, cylinder, tables, plates,
gaps, the strike level, the pour column that follows the cell height, the clearances);
the particles keep their size, so a rig at s = 2 holds ~8x the grains of the lab's.
The lab's stresses are kept: consolidation and load steps stay in Pa, and the masses
whose weight loads an area (lid, cell ring) are multiplied by s^2. Speeds and rates are
kept (lift in m/s, tilt in deg/s, the vibrator's frequency and amplitudes, the servo's
limits): each is a rate at which the rig moves against grains that are the same at
every scale. Readings tied to a grain or to the lab's reading rule are kept too (pile
slices and exclusions of a particle's size, the 1 mm slide onset, the 10 mm travel).
Which key does what is stated once, in pycal/rigs/fields.py (Field.scales);
docs/rigs.md "Geometric scale" gives the reasons.

The resolved job holds the lengths as built (already multiplied) and records
geometry.scale; at s = 1 the key is left out of the job, so a job at the lab's size is
the job it always was (same job id).
"""
import copy

from ..errors import ConfigError
from .fields import FIELDS

SCALE_KEY = "scale"
SECTIONS = ("geometry", "procedure", "measure")


def scale_of(rig_cfg):
    """The rig config's geometric scale (1 when geometry.scale is left out)."""
    return float(rig_cfg.get("geometry", {}).get(SCALE_KEY, 1.0))


def scaled_keys(rig_cfg):
    """{'section.key': rule} of the keys of `rig_cfg` that geometry.scale changes
    ('length': x s, 'area': x s^2)."""
    out = {}
    for section in SECTIONS:
        for key in rig_cfg.get(section, {}) or {}:
            rule = FIELDS[key].scales if key in FIELDS else ""
            if rule:
                out[f"{section}.{key}"] = rule
    return out


def apply_scale(rig, rig_cfg, file, field):
    """The rig config as built at its geometry.scale (a new dict): lengths x s, load
    masses x s^2 (to 12 significant digits: 0.2175, not 0.21749999999999997),
    geometry.scale kept when s != 1 and left out when s == 1. A ConfigError naming
    `file` and `field` (the config's geometry.scale or '--set' and the override) when
    the rig cannot be scaled (its descriptor's scale_refused)."""
    from . import get
    out = copy.deepcopy(rig_cfg)
    s = scale_of(rig_cfg)
    out["geometry"].pop(SCALE_KEY, None)
    if s == 1.0:
        return out
    refused = get(rig).scale_refused
    if refused:
        raise ConfigError(file, field, f"rig {rig} cannot be scaled: {refused}")
    factor = {"length": s, "area": s * s}
    for dotted, rule in scaled_keys(rig_cfg).items():
        section, key = dotted.split(".", 1)
        out[section][key] = float(f"{out[section][key] * factor[rule]:.12g}")
    out["geometry"][SCALE_KEY] = s
    return out

