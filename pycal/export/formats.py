"""The export formats of a calibrated material or material set (`pycal export`): yaml
(ours, with intervals and provenance), liggghts (an input fragment for LIGGGHTS-PUBLIC),
rocky and edem (tables of the values each code's GUI asks for, each conversion named).

A material set (configs/material_sets/, e.g. mixed-wet) is exported with every
component's calibrated values and the set's cross pairs, as the study's validation runs
use them. Sphere components are written in full; a clump component's contact values are
written, its multisphere templates are not (one line says so and where its shapes are);
a cohesion model another code does not have is one "not representable" line.
"""
import shutil
from dataclasses import dataclass, field
from pathlib import Path

from .. import CONFIG_DIR
from ..configs import load_boundaries, load_numerics, load_yaml, material_set_names, validate_material
from ..errors import ConfigError
from ..files import write_csv, write_text
from . import conversions as cv

FORMATS = ("yaml", "liggghts", "rocky", "edem")


@dataclass
class Exported:
    """What is exported: one material (components = {name: config}) or a material set."""
    name: str
    components: dict                                 # {component: material config with calibrated values}
    mass_fractions: dict                             # {component: mass fraction}; {name: 1.0} for a material
    records: dict = field(default_factory=dict)      # {component: its calibration record}
    material_set: dict = None                        # the resolved set (None for one material)

    def pair(self, a, b):
        """The interaction values of the pair (a, b), or None (two boundaries never touch)."""
        for x, y in ((a, b), (b, a)):
            if x in self.components and y in self.components[x]["interactions"]:
                return self.components[x]["interactions"][y]
        return None

    def radius(self, name):
        """Sphere radius (m) of a component; None for a clump component or a boundary."""
        p = self.components[name]["particles"] if name in self.components else None
        return 0.5 * p["diameter_m"] if p and p["shape"] == "sphere" else None

    def spheres(self):
        return [c for c in self.components if self.radius(c) is not None]


def _record(folder, material):
    path = folder / f"{material}.calibration.yaml"
    return load_yaml(path) if path.is_file() else None


def load_calibrated(study_dir, name):
    """The Exported material or material set `name` of the study in study_dir."""
    folder = Path(study_dir) / "calibrated"
    if name in material_set_names():
        from ..calibration.calibrated import load_study_overrides, overrides_for_material
        from ..jobs import resolve_set_materials
        materials, mset = resolve_set_materials(name, overrides_for_material(load_study_overrides(study_dir), name))
        records = {m: r for m in materials if (r := _record(folder, m)) is not None}
        return Exported(name, materials, {m: c["mass_fraction"] for m, c in mset["components"].items()},
                        records, mset)
    path = folder / f"{name}.yaml"
    if not path.is_file():
        known = sorted(p.stem for p in folder.glob("*.yaml") if not p.stem.endswith(".calibration"))
        raise ConfigError("--material", name, f"no calibrated/{name}.yaml in {study_dir} (calibrated: "
                          f"{', '.join(known) or 'none'}; material sets: {', '.join(material_set_names())})")
    mat = load_yaml(path)
    validate_material(mat, path, set(load_boundaries()) | set(mat.get("interactions", {})))
    record = _record(folder, name)
    return Exported(name, {name: mat}, {name: 1.0}, {name: record} if record else {})


def _spheres_only(ex, fmt):
    if not ex.spheres():
        shape = next(iter(ex.components.values()))["particles"]["shape"]
        raise ConfigError("--material", ex.name, f"a {shape} material: "
                          f"the {fmt} export writes sphere materials (a set may hold clumps)")


def _types(ex):
    """[(name, E Pa, nu)] of every component and every boundary one of them has a pair with."""
    b = load_boundaries()
    out = [(m, c["contact"]["youngs_modulus_pa"], c["contact"]["poisson_ratio"]) for m, c in ex.components.items()]
    walls = [n for n in b if any(n in c["interactions"] for c in ex.components.values())]
    return out + [(n, b[n]["youngs_modulus_pa"], b[n]["poisson_ratio"]) for n in walls]


def _pairs(ex):
    """[(a, b, values)] of every pair once: component-component, then component-boundary."""
    out, seen, walls = [], set(), load_boundaries()
    for a, c in ex.components.items():
        for b, props in c["interactions"].items():
            if b in ex.components or b in walls:
                if frozenset((a, b)) not in seen:
                    seen.add(frozenset((a, b)))
                    out.append((a, b, props))
    return out


def _clump_lines(ex):
    return [f"{m}: a clump material (size classes and shapes in its configs/materials/{m}.yaml, "
            f"{100 * ex.mass_fractions[m]:.3g} % of the mass): its multisphere templates are not written"
            for m in ex.components if ex.radius(m) is None]


def cohesion_lines(ex, code):
    """What each pair's cohesion becomes in `code`: [(pair, text)]. Our constant pull-off
    is a fraction of the weight of the lighter sphere of the pair."""
    out = []
    for a, b, props in _pairs(ex):
        c = props["cohesion"]
        model = c["model"]
        if model == "none":
            continue
        pair = f"{a}-{b}"
        if model == "force_fraction":
            spheres = [m for m in (a, b) if ex.radius(m) is not None]
            f = c["force_fraction"]
            if spheres:
                force = min(cv.pull_off_force_n(f, ex.radius(m), ex.components[m]["particles"]["density_kg_m3"])
                            for m in spheres)
                what = f"{force:.3g} N"
            else:
                what = "a force"
            text = {"rocky": f"adhesive model Constant, force fraction {f:g} of the lighter particle's weight "
                             f"({what}): the same model",
                    "liggghts": f"not representable: a constant pull-off of {what} ({f:g} x the lighter particle's "
                                "weight); cohesion sjkr gives k x contact area, which grows with the overlap",
                    "edem": f"not representable: a constant pull-off of {what} ({f:g} x the lighter particle's "
                            "weight); JKR grows with the contact radius"}[code]
        else:
            values = ", ".join(f"{k} {v}" for k, v in c.items() if k != "model")
            text = f"not representable: our {model} cohesion ({values})"
        out.append((pair, text))
    return out


def write_yaml(study_dir, ex, out):
    """Our own format: the calibrated material configs, their calibration records and,
    for a set, the set with its resolved cross pairs."""
    out.mkdir(parents=True, exist_ok=True)
    src = Path(study_dir) / "calibrated"
    if ex.material_set is None:
        files = [shutil.copyfile(src / f"{ex.name}.yaml", out / f"{ex.name}.yaml")]
        if ex.records:
            files.append(shutil.copyfile(src / f"{ex.name}.calibration.yaml", out / f"{ex.name}.calibration.yaml"))
        return [Path(f) for f in files]
    import yaml
    doc = {"material_set": ex.name, "study": str(study_dir), "set": ex.material_set,
           "components": ex.components, "calibration_records": ex.records}
    return [write_text(out / f"{ex.name}.set.yaml", "# a material set as the study's validation runs use it: "
                       "components with their calibrated values, the set's cross pairs resolved\n"
                       + yaml.safe_dump(doc, sort_keys=False))]


def _provenance(ex):
    r = next(iter(ex.records.values()), None) or {}
    return r.get("study", "?"), r.get("git_commit", "?")


def write_liggghts(study_dir, ex, out):
    """in.<name>.liggghts: atom style, Hertz with tangential history and epsd2 rolling
    friction, property/global tables for every type pair, time step, sphere templates (and
    their mass fractions for a set)."""
    _spheres_only(ex, "liggghts")
    types = _types(ex)
    n = len(types)
    names = [t[0] for t in types]

    def table(key, value_of):
        vals = [f"{value_of(a, b):.6g}" for a in names for b in names]
        return f"fix m_{key} all property/global {key} peratomtypepair {n} " + " ".join(vals)

    def pair_value(field_name, wall_wall):
        def f(a, b):
            p = ex.pair(a, b)
            return wall_wall if p is None else p[field_name]
        return f

    def rolling(a, b):
        p = ex.pair(a, b)
        if p is None:
            return 0.0
        ra, rb = ex.radius(a), ex.radius(b)
        if ra is None or rb is None:   # a wall or a clump: the coefficient as on a wall (the sphere's own radius)
            return cv.liggghts_rolling_coefficient(p["rolling_resistance_coefficient"], ra or rb)
        return cv.liggghts_rolling_coefficient(p["rolling_resistance_coefficient"], ra, rb)

    num = load_numerics(CONFIG_DIR)
    dt = min(cv.hertz_timestep_s(ex.radius(m), ex.components[m]["contact"]["youngs_modulus_pa"],
                                 ex.components[m]["particles"]["density_kg_m3"], num["timestep_safety_factor"])
             for m in ex.spheres())
    study, commit = _provenance(ex)
    lines = [f"# {ex.name} calibrated by pycal (study {study}, commit {commit}); SI units",
             "# use: define the simulation box as 'region domain block ... units box', then 'include' this file;",
             "# your walls (fix mesh/surface ... type N) take the wall's atom type below",
             "# atom types: " + ", ".join(f"{k + 1} = {t}" for k, t in enumerate(names)),
             "atom_style granular", "atom_modify map array", "boundary f f f", "newton off",
             "communicate single vel yes", "units si", f"create_box {n} domain",
             "hard_particles yes   # the steel and PVC walls are stiffer than LIGGGHTS' 1e9 Pa check",
             f"fix m_E all property/global youngsModulus peratomtype {' '.join(f'{t[1]:.6g}' for t in types)}",
             f"fix m_nu all property/global poissonsRatio peratomtype {' '.join(f'{t[2]:.6g}' for t in types)}",
             table("coefficientRestitution", pair_value("restitution_coefficient", 0.5)),
             table("coefficientFriction", pair_value("friction_coefficient", 0.0)),
             "# rolling: ours caps the moment at mu_r x min(R1, R2) x |Fn|, epsd2 at rmu x R1 R2 / (R1 + R2) x |Fn|:",
             "# rmu = 2 mu_r between equal spheres, mu_r on a wall (pycal/export/conversions.py)",
             table("coefficientRollingFriction", rolling),
             "pair_style gran model hertz tangential history rolling_friction epsd2",
             "pair_coeff * *",
             f"timestep {dt:.4g}   # {num['timestep_safety_factor']:g} x R sqrt(rho / E) of the smallest sphere, "
             "as our rigs"]
    seeds = iter((15485863, 15485867, 32452843, 32452867, 49979687))
    templates = []
    for m in ex.spheres():
        k = names.index(m) + 1
        templates.append(f"pts{k}")
        lines.append(f"fix pts{k} all particletemplate/sphere {next(seeds)} atom_type {k} density constant "
                     f"{ex.components[m]['particles']['density_kg_m3']:.6g} radius constant {ex.radius(m):.6g}")
    total = sum(ex.mass_fractions[m] for m in ex.spheres())
    pairs = " ".join(f"{t} {ex.mass_fractions[m] / total:.6g}" for t, m in zip(templates, ex.spheres()))
    if ex.material_set is not None:
        lines.append("# mass fractions of the sphere components (a clump component's share left out, renormalised)")
    lines.append(f"fix pdd all particledistribution/discrete 86028121 {len(templates)} {pairs}   "
                 "# for fix insert/pack or insert/stream: distributiontemplate pdd")
    lines += [f"# {text}" for text in _clump_lines(ex)]
    lines += [f"# cohesion {pair}: {text}" for pair, text in cohesion_lines(ex, "liggghts")]
    out.mkdir(parents=True, exist_ok=True)
    return [write_text(out / f"in.{ex.name}.liggghts", "\n".join(lines) + "\n")]


def _table_rows(ex, code):
    rows = []
    for m, mat in ex.components.items():
        e, nu = mat["contact"]["youngs_modulus_pa"], mat["contact"]["poisson_ratio"]
        p = mat["particles"]
        rows.append((m, "density", f"{p['density_kg_m3']:.6g}", "kg/m3", "same"))
        if ex.material_set is not None:
            rows.append((m, "mass fraction of the sample", f"{ex.mass_fractions[m]:.6g}", "-", "same"))
        if ex.radius(m) is not None:
            rows.append((m, "diameter", f"{p['diameter_m']:.6g}", "m", "same"))
        else:
            rows.append((m, "shape", "clump", "", f"build the size classes and shapes of configs/materials/{m}.yaml "
                                                  "in the code's particle editor"))
        if code == "edem":
            rows += [(m, "shear modulus", f"{cv.shear_modulus_pa(e, nu):.6g}", "Pa", "G = E / (2 (1 + nu))"),
                     (m, "Poisson's ratio", f"{nu:.6g}", "-", "same")]
        else:
            rows += [(m, "Young's modulus (Hertzian)", f"{e:.6g}", "Pa", "same"),
                     (m, "Poisson's ratio", f"{nu:.6g}", "-", "same")]
    rolling = ("same (elastic-plastic, moment capped at mu_r R |Fn|, R the particle's radius: Rocky's type C)"
               if code == "rocky" else
               "same coefficient, but EDEM's rolling friction is a constant directional torque (no spring): "
               "check a pile")
    for a, b, p in _pairs(ex):
        pair = f"{a}-{b}"
        rows += [(pair, "coefficient of restitution", f"{p['restitution_coefficient']:.6g}", "-", "same"),
                 (pair, "static friction", f"{p['friction_coefficient']:.6g}", "-", "same"),
                 (pair, "rolling resistance", f"{p['rolling_resistance_coefficient']:.6g}", "-", rolling)]
    rows += [(pair, "cohesion", "", "", text) for pair, text in cohesion_lines(ex, code)]
    for m in ex.spheres():
        c = ex.components[m]["contact"]
        t = cv.rayleigh_time_s(ex.radius(m), c["youngs_modulus_pa"], c["poisson_ratio"],
                               ex.components[m]["particles"]["density_kg_m3"])
        rows.append((m, "Rayleigh time", f"{t:.4g}", "s",
                     "pi R sqrt(rho / G) / (0.1631 nu + 0.8766); choose the code's fraction of the smallest"))
    return rows


def write_table(study_dir, ex, out, code):
    _spheres_only(ex, code)
    out.mkdir(parents=True, exist_ok=True)
    return [write_csv(out / f"{ex.name}.{code}.csv", ["what", "input", "value", "unit", "conversion"],
                      [list(r) for r in _table_rows(ex, code)])]


def export(study_dir, name, fmt, out):
    """Write the material or material set `name` of the study in `fmt` into folder `out`;
    returns the files."""
    if fmt not in FORMATS:
        raise ConfigError("--format", fmt, f"must be one of {', '.join(FORMATS)}")
    ex = load_calibrated(study_dir, name)
    out = Path(out)
    if fmt == "yaml":
        return write_yaml(study_dir, ex, out)
    if fmt == "liggghts":
        return write_liggghts(study_dir, ex, out)
    return write_table(study_dir, ex, out, fmt)
