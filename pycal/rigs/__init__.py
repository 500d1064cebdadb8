"""The rigs pycal knows: one descriptor per rig (pycal/rigs/<rig>.py, a module-level
DESCRIPTOR), registered by its module's name. Adding a rig = this descriptor, its YADE
script (yade_scripts/<rig>.py), its config (configs/rigs/<rig>.yaml) and a physics test.

`check_config` checks a rig config against its descriptor and pycal/rigs/fields.py:
every key present, none unknown (the nearest known name is suggested), each value of
its type and range; a ConfigError names the file and the key.
"""
import difflib
import importlib
import math
import pkgutil
from pathlib import Path

from ..errors import ConfigError
from .descriptor import SHARED_RESULT_KEYS, RigDescriptor  # noqa: F401
from .fields import FIELDS

SECTIONS = ("geometry", "procedure", "measure")
_REGISTRY = {}


def _load():
    if not _REGISTRY:
        for info in pkgutil.iter_modules([str(Path(__file__).parent)]):
            if info.name.startswith("_") or info.name in ("descriptor", "fields", "scaling"):
                continue
            module = importlib.import_module(f"{__name__}.{info.name}")
            desc = module.DESCRIPTOR
            assert desc.name == info.name, f"pycal/rigs/{info.name}.py describes {desc.name!r}"
            _REGISTRY[desc.name] = desc
    return _REGISTRY


def names():
    return sorted(_load())


def get(name, where="rig"):
    """The descriptor of rig `name`; a ConfigError naming `where` when there is none."""
    reg = _load()
    if name not in reg:
        raise ConfigError(where, str(name), f"no rig descriptor pycal/rigs/{name}.py (rigs: {', '.join(sorted(reg))})")
    return reg[name]


def nearest(name, known):
    """' (did you mean X?)' for the closest known name, or ''."""
    close = difflib.get_close_matches(str(name), list(known), n=1, cutoff=0.6)
    return f" (did you mean {close[0]}?)" if close else ""


def check_value(key, value, boundaries=()):
    """None if `value` fits the field `key` (pycal/rigs/fields.py), else the reason."""
    f = FIELDS[key]
    if f.kind == "bool":
        return None if isinstance(value, bool) else f"{value!r} must be true or false"
    if f.kind == "choice":
        return None if value in f.choices else f"{value!r} must be one of {', '.join(f.choices)}"
    if f.kind == "boundary":
        return None if value in boundaries else f"unknown boundary {value!r} (known: {', '.join(boundaries)})"
    if f.kind == "stress_list":
        if not isinstance(value, list) or not value:
            return f"{value!r} must be a non-empty list of stresses in Pa"
        for v in value:
            why = _number_reason(v, 0.0, None, True, False, False, "stresses > 0")
            if why:
                return why
        return None
    return _number_reason(value, f.lo, f.hi, f.lo_open, f.hi_open, f.kind == "integer", f.reason)


def _number_reason(v, lo, hi, lo_open, hi_open, integer, reason):
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return f"{v!r} must be a number"
    if not math.isfinite(v):
        return f"{v!r} must be a finite number"
    if integer and v != int(v):
        return f"{v!r} must be a whole number"
    bad_lo = lo is not None and (v <= lo if lo_open else v < lo)
    bad_hi = hi is not None and (v >= hi if hi_open else v > hi)
    if bad_lo or bad_hi:
        lo_s = "" if lo is None else f"{'>' if lo_open else '>='} {lo:g}"
        hi_s = "" if hi is None else f"{'<' if hi_open else '<='} {hi:g}"
        rng = " and ".join(s for s in (lo_s, hi_s) if s)
        return f"{v!r} must be {rng}" + (f" ({reason})" if reason else "")
    return None


def check_config(data, file, boundaries, numerics_keys):
    """Check one rig config mapping (configs/rigs/<rig>.yaml) against its descriptor."""
    desc = get(data.get("name"), f"{file}: name")
    if data.get("script") != desc.script:
        raise ConfigError(file, "script", f"{data.get('script')!r} must be {desc.script!r} (pycal/rigs/{desc.name}.py)")
    for section in SECTIONS:
        known = desc.keys(section)
        got = data.get(section, {})
        if section == "measure" and not known and not got:
            continue
        if not isinstance(got, dict):
            raise ConfigError(file, section, "must be a mapping")
        for k in got:
            if k not in known:
                raise ConfigError(file, f"{section}.{k}", f"unknown key{nearest(k, known)} (known: {', '.join(known)})")
        for k in known:
            if k not in got and f"{section}.{k}" not in desc.optional and (section, k) != ("geometry", "scale"):
                raise ConfigError(file, f"{section}.{k}", "missing")
        for k, v in got.items():
            why = check_value(k, v, boundaries)
            if why:
                raise ConfigError(file, f"{section}.{k}", why)
    num = data.get("numerics", {})
    if not isinstance(num, dict):
        raise ConfigError(file, "numerics", "must be a mapping")
    for k, v in num.items():
        if k not in numerics_keys:
            raise ConfigError(file, f"numerics.{k}", f"unknown key{nearest(k, numerics_keys)} "
                              f"(configs/numerics.yaml: {', '.join(numerics_keys)})")
        why = check_value(k, v) if k in FIELDS else None
        if why:
            raise ConfigError(file, f"numerics.{k}", why)
    return desc


def check_numerics(data, file):
    """configs/numerics.yaml: every key known (pycal/rigs/fields.py) and in range."""
    for k, v in data.items():
        if k not in FIELDS:
            raise ConfigError(file, k, f"unknown key{nearest(k, FIELDS)}")
        why = check_value(k, v)
        if why:
            raise ConfigError(file, k, why)
