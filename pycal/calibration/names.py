"""Readable names and units of calibrated parameter groups.

A parameter group sets several config keys to one value; tables and plots name it by
its quantity and the partners it applies to, e.g. the keys
interactions.{M2,steel,pvc}.rolling_resistance_coefficient read
"rolling resistance (M2, steel, PVC)".
"""
from ..post.responses import UNIT_LABELS, unit_of_name

QUANTITIES = {
    "density_kg_m3": "particle density",
    "youngs_modulus_pa": "Young's modulus",
    "friction_coefficient": "friction",
    "rolling_resistance_coefficient": "rolling resistance",
    # the same law pulls particles together (cohesion, a material partner) and onto a
    # wall (adhesion, a boundary partner): the partner in brackets says which
    "cohesion.force_fraction": "pull-off weight fraction",
    "cohesion.pressure_fraction": "pull-off pressure fraction",
}
PARTNER_LABELS = {"pvc": "PVC"}


def _split(key):
    """(partner or None, quantity key) of a dotted config key."""
    parts = key.split(".")
    if parts[0] == "interactions" and len(parts) >= 3:
        return parts[1], ".".join(parts[2:])
    return None, ".".join(parts[1:]) if len(parts) > 1 else key


def quantity_name(qkey):
    return QUANTITIES.get(qkey, qkey.split(".")[-1].replace("_", " "))


def group_label(keys):
    """e.g. 'rolling resistance (M2, steel, PVC)'; keys of different quantities are joined by ' + '."""
    by_quantity = {}
    for k in keys:
        partner, q = _split(k)
        by_quantity.setdefault(q, [])
        if partner is not None and partner not in by_quantity[q]:
            by_quantity[q].append(partner)
    parts = []
    for q, partners in by_quantity.items():
        name = quantity_name(q)
        parts.append(f"{name} ({', '.join(PARTNER_LABELS.get(p, p) for p in partners)})" if partners else name)
    return " + ".join(parts)


def unit_of_key(key):
    """The unit suffix of a config key ('kg_m3', 'pa', 'coefficient', 'fraction', ...), or None."""
    return unit_of_name(key.split(".")[-1])


def unit_label(unit):
    """'kg/m3', 'Pa', or '-' for dimensionless."""
    return UNIT_LABELS.get(unit, unit or "-")


def format_params(params):
    """'rolling resistance (M2, steel, PVC) = 0.35': the material keys of a point ({key:
    value}), keys set to one value shown as their group; rig keys left out."""
    import json
    groups = {}
    for k, v in params.items():
        if not k.startswith("rig."):
            groups.setdefault(json.dumps(v), []).append(k)
    return ", ".join(f"{group_label(keys)} = {_short(json.loads(v))}" for v, keys in groups.items()) or "-"


def _short(v):
    return f"{v:.4g}" if isinstance(v, (int, float)) and not isinstance(v, bool) else str(v)


def fmt3(v):
    """3 significant digits, no exponent between 1e-3 and 1e6 (3767 -> '3770', 0.26485 ->
    '0.265', 1e8 -> '1e8'): one rule for every table and plot label."""
    import math
    if v is None or not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
        return "-" if v is None or isinstance(v, float) else str(v)
    if v != 0 and 1e-3 <= abs(v) < 1e6:
        digits = 2 - int(math.floor(math.log10(abs(v))))
        return f"{round(v, digits):.{max(digits, 0)}f}"
    return f"{v:.3g}".replace("e+0", "e").replace("e+", "e").replace("e-0", "e-")
