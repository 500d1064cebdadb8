"""The export formats of a calibrated material (`pycal export`): yaml (ours, with
intervals and provenance), liggghts (an input fragment for LIGGGHTS-PUBLIC), rocky and
edem (tables of the values each code's GUI asks for, each conversion named).

Only sphere materials are exported (a clump material's multisphere template is not
written); a cohesion model another code does not have is one "not representable" line.
"""
import shutil
from pathlib import Path

from .. import CONFIG_DIR
from ..configs import load_boundaries, load_numerics, load_yaml, validate_material
from ..errors import ConfigError
from ..files import write_csv, write_text
from . import conversions as cv

FORMATS = ("yaml", "liggghts", "rocky", "edem")


def load_calibrated(study_dir, material):
    """(material config with the calibrated values, its calibration record or None)."""
    folder = Path(study_dir) / "calibrated"
    path = folder / f"{material}.yaml"
    if not path.is_file():
        known = sorted(p.stem for p in folder.glob("*.yaml") if not p.stem.endswith(".calibration"))
        raise ConfigError("--material", material, f"no calibrated/{material}.yaml in {study_dir} "
                          f"(calibrated: {', '.join(known) or 'none'})")
    mat = load_yaml(path)
    partners = set(load_boundaries()) | set(mat.get("interactions", {}))
    validate_material(mat, path, partners)
    record = folder / f"{material}.calibration.yaml"
    return mat, (load_yaml(record) if record.is_file() else None)


def _sphere(mat, fmt):
    p = mat["particles"]
    if p["shape"] != "sphere":
        raise ConfigError("--material", mat["name"], f"a {p['shape']} material: the {fmt} export writes spheres only")
    return 0.5 * p["diameter_m"], p["density_kg_m3"]


def _types(mat):
    """[(name, E Pa, nu)] of the material and every boundary it has a pair with."""
    b = load_boundaries()
    out = [(mat["name"], mat["contact"]["youngs_modulus_pa"], mat["contact"]["poisson_ratio"])]
    out += [(n, b[n]["youngs_modulus_pa"], b[n]["poisson_ratio"]) for n in mat["interactions"] if n in b]
    return out


def _pair(mat, a, b):
    """The interaction values of the pair (a, b); boundary-boundary pairs never touch."""
    name = mat["name"]
    other = b if a == name else a if b == name else None
    return mat["interactions"][other] if other is not None else None


def cohesion_lines(mat, code):
    """What each pair's cohesion becomes in `code`: [(pair, text)]."""
    radius, density = _sphere(mat, code)
    out = []
    for partner, props in mat["interactions"].items():
        c = props["cohesion"]
        model = c["model"]
        if model == "none":
            continue
        pair = f"{mat['name']}-{partner}"
        if model == "force_fraction":
            f = c["force_fraction"]
            force = cv.pull_off_force_n(f, radius, density)
            text = {"rocky": f"adhesive model Constant, force fraction {f:g} of the particle's weight "
                             f"({force:.3g} N on a {2 * radius:g} m particle): the same model",
                    "liggghts": f"not representable: a constant pull-off of {force:.3g} N ({f:g} x the particle's "
                                "weight); cohesion sjkr gives k x contact area, which grows with the overlap",
                    "edem": f"not representable: a constant pull-off of {force:.3g} N ({f:g} x the particle's "
                            "weight); JKR grows with the contact radius"}[code]
        else:
            values = ", ".join(f"{k} {v}" for k, v in c.items() if k != "model")
            text = f"not representable: our {model} cohesion ({values})"
        out.append((pair, text))
    return out


def write_yaml(study_dir, mat, record, out):
    """Our own format: the calibrated material config and its calibration record."""
    out.mkdir(parents=True, exist_ok=True)
    src = Path(study_dir) / "calibrated"
    files = [shutil.copyfile(src / f"{mat['name']}.yaml", out / f"{mat['name']}.yaml")]
    if record is not None:
        files.append(shutil.copyfile(src / f"{mat['name']}.calibration.yaml", out / f"{mat['name']}.calibration.yaml"))
    return [Path(f) for f in files]


def write_liggghts(study_dir, mat, record, out):
    """in.<material>.liggghts: atom style, Hertz with tangential history and epsd2 rolling
    friction, property/global tables for every type pair, time step, particle template."""
    radius, density = _sphere(mat, "liggghts")
    types = _types(mat)
    n = len(types)
    names = [t[0] for t in types]

    def table(key, value_of):
        vals = []
        for a in names:
            for b in names:
                v = value_of(a, b)
                vals.append(f"{v:.6g}")
        return f"fix m_{key} all property/global {key} peratomtypepair {n} " + " ".join(vals)

    def pair_value(field, wall_wall):
        def f(a, b):
            p = _pair(mat, a, b)
            return wall_wall if p is None else p[field]
        return f

    def rolling(a, b):
        p = _pair(mat, a, b)
        if p is None:
            return 0.0
        on_wall = a != mat["name"] or b != mat["name"]
        return cv.liggghts_rolling_coefficient(p["rolling_resistance_coefficient"], radius,
                                               None if on_wall else radius)

    num = load_numerics(CONFIG_DIR)
    dt = cv.hertz_timestep_s(radius, mat["contact"]["youngs_modulus_pa"], density, num["timestep_safety_factor"])
    src = (record or {}).get("study", "?"), (record or {}).get("git_commit", "?")
    lines = [f"# {mat['name']} calibrated by pycal (study {src[0]}, commit {src[1]}); SI units",
             "# atom types: " + ", ".join(f"{k + 1} = {t}" for k, t in enumerate(names)),
             "atom_style granular", "atom_modify map array", "communicate single vel yes", "units si",
             f"fix m_E all property/global youngsModulus peratomtype {' '.join(f'{t[1]:.6g}' for t in types)}",
             f"fix m_nu all property/global poissonsRatio peratomtype {' '.join(f'{t[2]:.6g}' for t in types)}",
             table("coefficientRestitution", pair_value("restitution_coefficient", 0.5)),
             table("coefficientFriction", pair_value("friction_coefficient", 0.0)),
             "# rolling: ours caps the moment at mu_r x min(R1, R2) x |Fn|, epsd2 at rmu x R1 R2 / (R1 + R2) x |Fn|:",
             "# rmu = 2 mu_r between equal spheres, mu_r on a wall (pycal/export/conversions.py)",
             table("coefficientRollingFriction", rolling),
             "pair_style gran model hertz tangential history rolling_friction epsd2",
             "pair_coeff * *",
             f"timestep {dt:.4g}   # {num['timestep_safety_factor']:g} x R sqrt(rho / E), as our rigs",
             f"fix pts all particletemplate/sphere 15485863 atom_type 1 density constant {density:.6g} "
             f"radius constant {radius:.6g}"]
    lines += [f"# cohesion {pair}: {text}" for pair, text in cohesion_lines(mat, "liggghts")]
    out.mkdir(parents=True, exist_ok=True)
    return [write_text(out / f"in.{mat['name']}.liggghts", "\n".join(lines) + "\n")]


def _table_rows(mat, code):
    radius, density = _sphere(mat, code)
    e, nu = mat["contact"]["youngs_modulus_pa"], mat["contact"]["poisson_ratio"]
    rows = [("particle", "density", f"{density:.6g}", "kg/m3", "same"),
            ("particle", "diameter", f"{2 * radius:.6g}", "m", "same")]
    if code == "edem":
        rows += [("particle", "shear modulus", f"{cv.shear_modulus_pa(e, nu):.6g}", "Pa", "G = E / (2 (1 + nu))"),
                 ("particle", "Poisson's ratio", f"{nu:.6g}", "-", "same")]
    else:
        rows += [("particle", "Young's modulus (Hertzian)", f"{e:.6g}", "Pa", "same"),
                 ("particle", "Poisson's ratio", f"{nu:.6g}", "-", "same")]
    for partner, p in mat["interactions"].items():
        pair = f"{mat['name']}-{partner}"
        rolling = ("same (elastic-plastic, moment capped at mu_r R |Fn|, R the particle's radius: Rocky's type C)"
                   if code == "rocky" else
                   "same coefficient, but EDEM's rolling friction is a constant directional torque (no spring): "
                   "check a pile")
        rows += [(pair, "coefficient of restitution", f"{p['restitution_coefficient']:.6g}", "-", "same"),
                 (pair, "static friction", f"{p['friction_coefficient']:.6g}", "-", "same"),
                 (pair, "rolling resistance", f"{p['rolling_resistance_coefficient']:.6g}", "-", rolling)]
    rows += [(pair, "cohesion", "", "", text) for pair, text in cohesion_lines(mat, code)]
    rows.append(("time step", "Rayleigh time", f"{cv.rayleigh_time_s(radius, e, nu, density):.4g}", "s",
                 "pi R sqrt(rho / G) / (0.1631 nu + 0.8766); choose the code's fraction of it"))
    return rows


def write_table(study_dir, mat, record, out, code):
    out.mkdir(parents=True, exist_ok=True)
    return [write_csv(out / f"{mat['name']}.{code}.csv", ["what", "input", "value", "unit", "conversion"],
                      [list(r) for r in _table_rows(mat, code)])]


def export(study_dir, material, fmt, out):
    """Write `material` of the study in `fmt` into folder `out`; returns the files."""
    if fmt not in FORMATS:
        raise ConfigError("--format", fmt, f"must be one of {', '.join(FORMATS)}")
    mat, record = load_calibrated(study_dir, material)
    out = Path(out)
    if fmt == "yaml":
        return write_yaml(study_dir, mat, record, out)
    if fmt == "liggghts":
        return write_liggghts(study_dir, mat, record, out)
    return write_table(study_dir, mat, record, out, fmt)
