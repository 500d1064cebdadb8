"""Load and validate configs/ (materials, boundaries, rigs, numerics).

Every error names the file, the dotted key and the reason, e.g.
``configs/materials/M2.yaml: particles.density_kg_m3: -5 must be > 0``.
Unknown keys are errors, never silently ignored.
"""
import copy
import math
import re
from pathlib import Path

import yaml

from . import CONFIG_DIR, plausible
from .contact_rules import COHESION_MODELS, CONTACT_MODELS
from .errors import ConfigError

# Suffixes that say a rig/numerics key's unit (SI) or that it is dimensionless.
UNIT_SUFFIXES = ("_m", "_m_s", "_m_s2", "_s", "_pa", "_n", "_kg", "_kg_m3", "_deg", "_deg_s",
                 "_hz", "_j", "_rad", "_rad_s")
DIMENSIONLESS_SUFFIXES = ("_ratio", "_fraction", "_factor", "_coefficient", "_count", "_percent")
DIMENSIONLESS_NAMES = ("scale",)      # whole key names that are a pure ratio (a rig's geometry.scale)


def _rel(path):
    """Path as the user sees it (relative to the repo root when inside it)."""
    path = Path(path).resolve()
    try:
        return str(path.relative_to(CONFIG_DIR.parent))
    except ValueError:
        return str(path)


class YamlLoader(yaml.SafeLoader):
    """SafeLoader that also reads 2.38e11 and 1e-3 as floats (YAML 1.1 wants 2.38e+11)."""


YamlLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"""^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+]?[0-9]+)?
                   |[-+]?[0-9][0-9_]*[eE][-+]?[0-9]+
                   |\.[0-9_]+(?:[eE][-+]?[0-9]+)?
                   |[-+]?\.(?:inf|Inf|INF)
                   |\.(?:nan|NaN|NAN))$""", re.X),
    list("-+0123456789."))


def parse_yaml_text(text):
    return yaml.load(text, Loader=YamlLoader)


def load_yaml(path):
    """Read a YAML mapping; a syntax error or a non-mapping names the file."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(_rel(path), "", "file not found")
    try:
        data = parse_yaml_text(path.read_text())
    except yaml.YAMLError as exc:
        raise ConfigError(_rel(path), "", f"not valid YAML: {exc}".replace("\n", " ")) from None
    if not isinstance(data, dict):
        raise ConfigError(_rel(path), "", "must be a YAML mapping")
    return data


class _Checker:
    """Small helper to check fields of one file with dotted-key messages."""

    def __init__(self, file):
        self.file = _rel(file)

    def fail(self, key, reason):
        raise ConfigError(self.file, key, reason)

    def keys(self, data, key, required, optional=()):
        if not isinstance(data, dict):
            self.fail(key, "must be a mapping")
        for k in required:
            if k not in data:
                self.fail(f"{key}.{k}" if key else k, "missing")
        allowed = set(required) | set(optional)
        for k in data:
            if k not in allowed:
                self.fail(f"{key}.{k}" if key else k,
                          f"unknown key (allowed: {', '.join(sorted(allowed))})")

    def number(self, value, key, lo=None, hi=None, lo_open=False):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(key, f"{value!r} must be a number")
        if not math.isfinite(value):
            self.fail(key, f"{value!r} must be a finite number")
        if lo is not None and (value <= lo if lo_open else value < lo):
            self.fail(key, f"{value} must be {'>' if lo_open else '>='} {lo}")
        if hi is not None and value > hi:
            self.fail(key, f"{value} must be <= {hi}")
        return float(value)

    def plausible(self, value, key, lo=None, hi=None, lo_open=False):
        """number() and then the plausible range of the key (pycal/plausible.py)."""
        self.number(value, key, lo, hi, lo_open)
        why = plausible.check(key, value)
        if why:
            self.fail(key, why)
        return float(value)

    def string(self, value, key, choices=None):
        if not isinstance(value, str) or not value:
            self.fail(key, f"{value!r} must be a non-empty string")
        if choices is not None and value not in choices:
            self.fail(key, f"{value!r} must be one of {', '.join(choices)}")
        return value


def material_names(config_dir=CONFIG_DIR):
    return sorted(p.stem for p in (Path(config_dir) / "materials").glob("*.yaml"))


def load_boundaries(config_dir=CONFIG_DIR):
    """Boundary surfaces (steel, PVC...) with density, Young's modulus, Poisson ratio."""
    path = Path(config_dir) / "boundaries.yaml"
    data = load_yaml(path)
    c = _Checker(path)
    for name, b in data.items():
        c.keys(b, name, ["density_kg_m3", "youngs_modulus_pa", "poisson_ratio"],
               ["description", "provenance"])
        c.plausible(b["density_kg_m3"], f"{name}.density_kg_m3", 0, lo_open=True)
        c.plausible(b["youngs_modulus_pa"], f"{name}.youngs_modulus_pa", 0, lo_open=True)
        c.plausible(b["poisson_ratio"], f"{name}.poisson_ratio", -1, 0.5)
    return data


def validate_material(data, path, partners):
    """Check one material mapping; `partners` = every valid interaction partner name."""
    c = _Checker(path)
    c.keys(data, "", ["name", "particles", "contact", "interactions"],
           ["description", "lab_sample", "moisture_percent_dry_basis", "provenance"])
    if data["name"] != Path(path).stem and Path(path).suffix == ".yaml":
        c.fail("name", f"{data['name']!r} must equal the file name {Path(path).stem!r}")
    if "moisture_percent_dry_basis" in data:
        c.number(data["moisture_percent_dry_basis"], "moisture_percent_dry_basis", 0, 100)
    p = data["particles"]
    c.keys(p, "particles", ["shape", "density_kg_m3"], ["diameter_m", "size_classes", "shapes"])
    shape = c.string(p["shape"], "particles.shape", ["sphere", "clump"])
    c.plausible(p["density_kg_m3"], "particles.density_kg_m3", 0, lo_open=True)
    if shape == "sphere":
        if "diameter_m" not in p:
            c.fail("particles.diameter_m", "missing (required for shape: sphere)")
        c.plausible(p["diameter_m"], "particles.diameter_m", 0, lo_open=True)
    else:
        _validate_clump_particles(c, p)
    k = data["contact"]
    c.keys(k, "contact", ["youngs_modulus_pa", "poisson_ratio"])
    c.plausible(k["youngs_modulus_pa"], "contact.youngs_modulus_pa", 0, lo_open=True)
    c.plausible(k["poisson_ratio"], "contact.poisson_ratio", -1, 0.5)
    inter = data["interactions"]
    if not isinstance(inter, dict):
        c.fail("interactions", "must be a mapping partner -> properties")
    for needed in [data["name"]] + [b for b in partners if b in load_boundaries_cached()]:
        if needed not in inter:
            c.fail(f"interactions.{needed}", "missing (every material needs itself and every boundary)")
    for partner, props in inter.items():
        key = f"interactions.{partner}"
        if partner not in partners:
            c.fail(key, f"unknown partner (materials and boundaries: {', '.join(sorted(partners))})")
        _check_pair_props(c, props, key)
    return data


def _validate_clump_particles(c, p):
    for k in ("size_classes", "shapes"):
        if k not in p:
            c.fail(f"particles.{k}", "missing (required for shape: clump)")
    shapes = p["shapes"]
    if not isinstance(shapes, dict) or not shapes:
        c.fail("particles.shapes", "must be a non-empty mapping")
    for name, s in shapes.items():
        c.keys(s, f"particles.shapes.{name}", ["vertical_aspect_ratio", "horizontal_aspect_ratio"],
               ["smoothness", "corners_count", "superquadric_degree"])
        for r in ("vertical_aspect_ratio", "horizontal_aspect_ratio"):
            c.number(s[r], f"particles.shapes.{name}.{r}", 0, lo_open=True)
    total = 0.0
    for i, sc in enumerate(p["size_classes"]):
        key = f"particles.size_classes[{i}]"
        c.keys(sc, key, ["name", "min_size_m", "max_size_m", "mass_percent", "shape_percent"])
        lo = c.plausible(sc["min_size_m"], f"{key}.min_size_m", 0, lo_open=True)
        hi = c.plausible(sc["max_size_m"], f"{key}.max_size_m", 0, lo_open=True)
        if hi <= lo:
            c.fail(f"{key}.max_size_m", f"{hi} must be > min_size_m {lo}")
        total += c.number(sc["mass_percent"], f"{key}.mass_percent", 0, 100)
        share = sc["shape_percent"]
        for sname, v in share.items():
            if sname not in shapes:
                c.fail(f"{key}.shape_percent.{sname}", "unknown shape (see particles.shapes)")
            c.number(v, f"{key}.shape_percent.{sname}", 0, 100)
        if abs(sum(share.values()) - 100.0) > 0.01:
            c.fail(f"{key}.shape_percent", f"shares add up to {sum(share.values())}, not 100")


_BOUNDARIES = {}


def load_boundaries_cached(config_dir=CONFIG_DIR):
    key = str(config_dir)
    if key not in _BOUNDARIES:
        _BOUNDARIES[key] = load_boundaries(config_dir)
    return _BOUNDARIES[key]


def _config_file(config_dir, folder, name, kind):
    """configs/<folder>/<name>.yaml and the names known there; an unknown name is a
    ConfigError listing the known ones."""
    names = sorted(p.stem for p in (Path(config_dir) / folder).glob("*.yaml"))
    path = Path(config_dir) / folder / f"{name}.yaml"
    if name not in names:
        raise ConfigError(_rel(path), "", f"unknown {kind} {name!r} (known: {', '.join(names)})")
    return path, names


def load_material(name, config_dir=CONFIG_DIR):
    """One validated material config by name (file configs/materials/<name>.yaml)."""
    path, names = _config_file(config_dir, "materials", name, "material")
    partners = set(names) | set(load_boundaries_cached(config_dir))
    return validate_material(load_yaml(path), path, partners)


def check_rig_keys(data, c, key=""):
    """Every numeric leaf key of a rig/numerics config must carry an SI unit suffix
    (e.g. _m, _pa, _s, _deg_s) or a dimensionless one (e.g. _ratio, _count)."""
    if isinstance(data, dict):
        for k, v in data.items():
            sub = f"{key}.{k}" if key else str(k)
            is_num = (isinstance(v, (int, float)) and not isinstance(v, bool)) or (
                isinstance(v, list) and v and all(isinstance(x, (int, float)) for x in v))
            if is_num:
                if not str(k).endswith(UNIT_SUFFIXES + DIMENSIONLESS_SUFFIXES) and k not in DIMENSIONLESS_NAMES:
                    c.fail(sub, "numeric key needs a unit suffix (SI: "
                           + ", ".join(UNIT_SUFFIXES) + "; or dimensionless: "
                           + ", ".join(DIMENSIONLESS_SUFFIXES) + ")")
                values = v if isinstance(v, list) else [v]
                if any(x != x for x in values):
                    c.fail(sub, "NaN is not a value")
                if str(k).endswith(("_pa",)) and isinstance(v, list):
                    if any(x <= 0 for x in v):
                        c.fail(sub, "stresses must be > 0")
            elif isinstance(v, dict):
                check_rig_keys(v, c, sub)


# Numerics keys whose value is a name: key -> allowed values
NUMERICS_CHOICES = {
    "contact_model": tuple(CONTACT_MODELS),
    # rest check: kinetic energy of translation and rotation, or of translation only (a particle
    # may spin in place on its elastic twisting spring with the bulk at rest: hertz_mindlin without
    # global damping; a particle pinched between coincident facet vertices of the internal-friction
    # rig's rims spun at 10 rad/s at 86 kPa under the first law)
    "rest_kinetic_energy": ("total", "translational"),
}


def load_numerics(config_dir=CONFIG_DIR):
    from . import rigs
    path = Path(config_dir) / "numerics.yaml"
    data = load_yaml(path)
    c = _Checker(path)
    check_rig_keys(data, c)
    for k in NUMERICS_CHOICES:
        if k not in data:
            c.fail(k, f"missing (one of {', '.join(NUMERICS_CHOICES[k])})")
    rigs.check_numerics(data, _rel(path))
    return data


def rig_names(config_dir=CONFIG_DIR):
    return sorted(p.stem for p in (Path(config_dir) / "rigs").glob("*.yaml"))


def load_rig(name, config_dir=CONFIG_DIR):
    """One validated rig config by name, with the shared numerics merged in: checked
    against the rig's descriptor (pycal/rigs/<name>.py: every key, its type and range)."""
    from . import rigs
    path, _ = _config_file(config_dir, "rigs", name, "rig")
    data = load_yaml(path)
    c = _Checker(path)
    c.keys(data, "", ["name", "script", "geometry", "procedure"], ["description", "measure", "assumptions", "numerics"])
    if data["name"] != name:
        c.fail("name", f"{data['name']!r} must equal the file name {name!r}")
    check_rig_keys(data, c)
    numerics = load_numerics(config_dir)
    rigs.check_config(data, _rel(path), tuple(load_boundaries_cached(config_dir)), tuple(numerics))
    merged = copy.deepcopy(data)
    merged["numerics"] = {**numerics, **data.get("numerics", {})}
    return merged


# ---------------------------------------------------------------- material sets
# configs/material_sets/<name>.yaml: several materials in one sample (e.g. the -50 mm
# sample = M1 lumps + M2 gravel + M3 fines) with their mass shares and the properties
# of every pair of two different components (cross_interactions). In a job of a set,
# those pair values replace the components' own entries for each other on both sides,
# so both materials of a pair agree (YADE needs one value per pair).

SET_DIR = "material_sets"


def material_set_names(config_dir=CONFIG_DIR):
    return sorted(p.stem for p in (Path(config_dir) / SET_DIR).glob("*.yaml"))


def _check_pair_props(c, props, key):
    """friction, restitution, rolling resistance and cohesion of one pair (as under `interactions:`).
    Whether the scene's contact law can realise them is checked per job (pycal.contact_rules)."""
    c.keys(props, key, ["friction_coefficient", "restitution_coefficient", "rolling_resistance_coefficient",
                        "cohesion"])
    c.plausible(props["friction_coefficient"], f"{key}.friction_coefficient", 0)
    c.plausible(props["restitution_coefficient"], f"{key}.restitution_coefficient", 0.05, 1.0)
    c.plausible(props["rolling_resistance_coefficient"], f"{key}.rolling_resistance_coefficient", 0)
    coh = props["cohesion"]
    if not isinstance(coh, dict) or "model" not in coh:
        c.fail(f"{key}.cohesion", "must be a mapping with a 'model' key")
    model = c.string(coh["model"], f"{key}.cohesion.model", list(COHESION_MODELS))
    params = COHESION_MODELS[model]["params"]
    c.keys(coh, f"{key}.cohesion", ["model"] + list(params))
    for pname, (lo, hi) in params.items():
        c.plausible(coh[pname], f"{key}.cohesion.{pname}", lo, hi)


def _take_from_components(c, data, materials):
    """Apply the set's `from_components` rules in place: each {to: cross_interactions.A.B.<key>,
    from: <component>, key: <key of that component's config>} copies the component's value
    (with any override or calibrated value it has) into the cross pair, e.g. the wet fines'
    fines-wall adhesion into the fines-gravel pair. One rule per value: a calibrated
    component value reaches the set without being written twice."""
    rules = data.get("from_components", [])
    if not isinstance(rules, list):
        c.fail("from_components", "must be a list of {to, from, key}")
    comps = data["components"]
    for i, rule in enumerate(rules):
        k = f"from_components[{i}]"
        c.keys(rule, k, ["to", "from", "key"])
        if rule["from"] not in comps:
            c.fail(f"{k}.from", f"{rule['from']!r} is not a component ({', '.join(comps)})")
        to = str(rule["to"]).split(".")
        if len(to) < 4 or to[0] != "cross_interactions" or to[1] not in comps or to[2] not in comps:
            c.fail(f"{k}.to", f"{rule['to']!r} must be cross_interactions.<A>.<B>.<property> of two components")
        if component_value(materials, rule) is None:
            c.fail(f"{k}.key", f"{rule['key']!r}: no such key in configs/materials/{rule['from']}.yaml")
        if not isinstance(data["cross_interactions"].get(to[1], {}).get(to[2]), dict):
            c.fail(f"{k}.to", f"cross_interactions.{to[1]}.{to[2]} is not in the set (write the pair as A: {{B: ...}})")
        put_component_value(data, rule, materials)


def component_value(materials, rule):
    """The value a from_components rule takes: `key` of material `from` in `materials`
    ({name: config}), or None when there is no such key."""
    node = materials.get(rule.get("from"))
    for part in str(rule.get("key", "")).split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def put_component_value(data, rule, materials):
    """Write a copy of the rule's component value at its `to` path (cross_interactions.A.B.
    <key>) of the set `data`, creating the last levels below the pair. The value must exist."""
    to = str(rule["to"]).split(".")
    node = data["cross_interactions"][to[1]][to[2]]
    for part in to[3:-1]:
        node = node.setdefault(part, {})
    node[to[-1]] = copy.deepcopy(component_value(materials, rule))


def validate_material_set(data, path, materials):
    """Check one material set mapping. `materials`: {name: validated material config} of
    every known material. Returns the set with `mass_fraction` added to each component
    (mass_percent / sum of the components' mass_percent)."""
    c = _Checker(path)
    c.keys(data, "", ["name", "components", "cross_interactions"],
           ["description", "lab_sample", "provenance", "assumptions", "from_components"])
    data = copy.deepcopy(data)
    if Path(path).suffix == ".yaml" and data["name"] != Path(path).stem:
        c.fail("name", f"{data['name']!r} must equal the file name {Path(path).stem!r}")
    if data["name"] in materials:
        c.fail("name", f"{data['name']!r} is also a material name (configs/materials/)")
    comps = data["components"]
    if not isinstance(comps, dict) or len(comps) < 2:
        c.fail("components", "must map at least two material names to their share")
    total = 0.0
    for name, comp in comps.items():
        key = f"components.{name}"
        if name not in materials:
            c.fail(key, f"unknown material (known: {', '.join(sorted(materials))})")
        mat = materials[name]
        c.keys(comp, key, ["mass_percent"], ["size_classes"])
        pct = c.number(comp["mass_percent"], f"{key}.mass_percent", 0, 100, lo_open=True)
        total += pct
        if "size_classes" in comp:
            if mat["particles"]["shape"] != "clump":
                c.fail(f"{key}.size_classes", f"only for clump materials ({name} is made of spheres)")
            classes = {sc["name"]: sc for sc in mat["particles"]["size_classes"]}
            chosen = comp["size_classes"]
            if not isinstance(chosen, list) or not chosen:
                c.fail(f"{key}.size_classes", "must be a non-empty list of size class names")
            for cl in chosen:
                if cl not in classes:
                    c.fail(f"{key}.size_classes", f"unknown class {cl!r} of {name} (known: {', '.join(classes)})")
            if len(set(chosen)) != len(chosen):
                c.fail(f"{key}.size_classes", "a class is listed twice")
            class_total = sum(classes[cl]["mass_percent"] for cl in chosen)
            if abs(class_total - pct) > 0.01:
                c.fail(f"{key}.mass_percent", f"{pct} differs from the sum of its size classes' "
                                              f"mass_percent in configs/materials/{name}.yaml ({class_total:g})")
    if total > 100.0 + 1e-9:
        c.fail("components", f"mass_percent adds up to {total:g} > 100")
    cross = data["cross_interactions"]
    if not isinstance(cross, dict):
        c.fail("cross_interactions", "must map each pair of different components once: A: {B: {...}}")
    seen = set()
    for a, partners in cross.items():
        if a not in comps:
            c.fail(f"cross_interactions.{a}", f"not a component ({', '.join(comps)})")
        if not isinstance(partners, dict):
            c.fail(f"cross_interactions.{a}", "must be a mapping partner -> properties")
        for b in partners:
            key = f"cross_interactions.{a}.{b}"
            if b not in comps:
                c.fail(key, f"not a component ({', '.join(comps)})")
            if b == a:
                c.fail(key, "a material with itself is set in its own config (configs/materials/)")
            pair = frozenset((a, b))
            if pair in seen:
                c.fail(key, f"the pair {a} - {b} is listed twice")
            seen.add(pair)
    names = list(comps)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            if frozenset((a, b)) not in seen:
                c.fail(f"cross_interactions.{a}.{b}", "missing (every pair of two components, once)")
    _take_from_components(c, data, materials)
    for a, partners in cross.items():
        for b, props in partners.items():
            _check_pair_props(c, props, f"cross_interactions.{a}.{b}")
    out = copy.deepcopy(data)
    for name, comp in out["components"].items():
        comp["mass_fraction"] = comp["mass_percent"] / total
    return out


def load_material_set(name, config_dir=CONFIG_DIR, materials=None):
    """One validated material set by name (configs/material_sets/<name>.yaml), with
    each component's mass_fraction. `materials` (optional): the component configs to
    validate against (default: the shipped ones)."""
    path, _ = _config_file(config_dir, SET_DIR, name, "material set")
    if materials is None:
        materials = {m: load_material(m, config_dir) for m in material_names(config_dir)}
    return validate_material_set(load_yaml(path), path, materials)
