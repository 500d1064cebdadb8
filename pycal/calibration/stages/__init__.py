"""The stage kinds a study config names (`stage: <kind>`): one module per kind family in this
package (one_parameter.py, joint.py, inherit.py), each with a module-level KINDS tuple of
StageKind (kind.py) and its ORDER among the modules, registered by name. Adding a kind = a
module here with its config check (`normalise`), its runner and its defaults; nothing else
names kinds (checks.py holds the checks the kinds share)."""
import importlib
import pkgutil
from pathlib import Path

from .kind import StageKind  # noqa: F401 (the registry's entries)

_REGISTRY = {}
NOT_KINDS = ("checks", "kind")


def module_names():
    """The kind modules of this package (what the registry imports)."""
    return sorted(i.name for i in pkgutil.iter_modules([str(Path(__file__).parent)])
                  if not i.name.startswith("_") and i.name not in NOT_KINDS)


def _load():
    if not _REGISTRY:
        modules = [importlib.import_module(f"{__name__}.{name}") for name in module_names()]
        for module in sorted(modules, key=lambda m: m.ORDER):     # the order a reader meets the kinds
            for kind in module.KINDS:
                assert kind.name not in _REGISTRY, f"stage kind {kind.name} registered twice"
                _REGISTRY[kind.name] = kind
    return _REGISTRY


def names():
    """Every kind's name, in the order a reader meets them (each module's ORDER)."""
    return list(_load())


def get(name):
    """The StageKind called `name` (KeyError naming the known ones if none)."""
    reg = _load()
    if name not in reg:
        raise KeyError(f"no stage kind {name!r} (known: {', '.join(sorted(reg))})")
    return reg[name]


def calibrates(name):
    """True when a stage of this kind calibrates (runs and has a verdict); False for a copy."""
    return get(name).calibrates
