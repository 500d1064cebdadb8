"""Load and validate the lab data in labresults/ (see labresults/README.md).

Files: samples.yaml, the tables size_distribution.csv, angle_of_repose.csv,
surcharge.csv, boundaries.csv, shapes.csv, shape_shares.csv, and the target curves
curves/<name>.csv. Every numeric column carries its unit in its name (``_pa``,
``_kg_m3``, ``_deg``, ``_percent``...; ``mu_*`` = friction coefficient, no unit) and
every row a ``provenance`` (measured / reconstructed / synthetic: simulated by a twin). Errors name the file relative
to the repo and the column: ``labresults/curves/x.csv: stress_pa: row 3: ...``.
CSV lines starting with ``#`` are comments.
"""
import math
from collections import namedtuple
from pathlib import Path

import numpy as np
import pandas as pd

from . import CONFIG_DIR, LAB_DIR
from .configs import DIMENSIONLESS_SUFFIXES, UNIT_SUFFIXES, _Checker, load_yaml
from .errors import ConfigError

PROVENANCES = ("measured", "reconstructed", "synthetic")   # synthetic: simulated with known parameters (a twin)
OUTCOMES = ("slides", "sticks")   # curves: `sticks` = the cell does not slide up to the max tilt
LAB_UNIT_SUFFIXES = UNIT_SUFFIXES + DIMENSIONLESS_SUFFIXES + ("_exponent", "_t_h", "_kg_m")
DIMENSIONLESS_PREFIXES = ("mu_",)  # friction coefficients
TEXT_COLUMNS = ("class", "sample", "shape", "surface", "material", "method", "outcome",
                "provenance", "note", "description")
BAND_SUFFIXES = ("_low", "_high")

# table name -> (columns that must be present and filled, usual columns that may be blank)
TABLES = {
    "size_distribution": (["class", "min_size_m", "max_size_m", "mass_percent", "passing_percent",
                           "provenance"], ["method"]),
    "angle_of_repose": (["sample", "left_deg", "right_deg", "provenance"],
                        ["front_deg", "top_left_deg", "top_right_deg", "note"]),
    "surcharge": (["sample", "left_deg", "right_deg", "provenance"], ["note"]),
    "boundaries": (["surface", "material", "density_kg_m3", "youngs_modulus_pa", "provenance"], []),
    "shapes": (["shape", "vertical_aspect_ratio", "horizontal_aspect_ratio", "provenance"],
               ["smoothness_ratio", "corners_count", "superquadric_exponent"]),
    "shape_shares": (["class", "provenance"], []),
}

TargetCurve = namedtuple("TargetCurve", "name quantity stress_pa value low high outcome provenance")
TargetCurve.__doc__ = """One target curve: arrays over the load steps (stress in Pa).
value/low/high are in the quantity's unit (NaN where outcome == 'sticks')."""


def _rel(path, lab_dir):
    """Path as the user sees it: relative to the folder holding labresults/."""
    path, root = Path(path).resolve(), Path(lab_dir).resolve().parent
    try:
        return str(path.relative_to(root))
    except ValueError:
        return str(path)


def _has_unit(col):
    base = col
    for s in BAND_SUFFIXES:
        if base.endswith(s):
            base = base[: -len(s)]
    return base.endswith(LAB_UNIT_SUFFIXES) or base.startswith(DIMENSIONLESS_PREFIXES)


# ---------------------------------------------------------------- CSV reading

def _read_csv(path, lab_dir, required):
    """Read a CSV as text, check columns and units, convert numeric columns to float.

    `required` columns must exist and be filled; other columns are allowed (and may
    have blanks) if they are text columns or their name has a unit.
    Returns (DataFrame, fail) where fail(field, reason) raises ConfigError."""
    file = _rel(path, lab_dir)

    def fail(field, reason):
        raise ConfigError(file, field, reason)

    if not Path(path).is_file():
        fail("", "file not found")
    try:
        df = pd.read_csv(path, dtype=str, keep_default_na=False, comment="#", skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        fail("", f"not a valid CSV file: {exc}".replace("\n", " "))
    df.columns = [c.strip() for c in df.columns]
    for col in df.columns:
        if col not in TEXT_COLUMNS and not _has_unit(col):
            fail(col, "column name needs a unit suffix (e.g. _pa, _kg_m3, _m, _deg, _percent, "
                      "_ratio, _fraction, _count; mu_* for friction coefficients)")
    for col in required:
        if col not in df.columns:
            fail(col, f"missing column (columns: {', '.join(df.columns)})")
    if df.empty:
        fail("", "no data rows")
    for col in df.columns:
        df[col] = df[col].str.strip()
        if col in TEXT_COLUMNS:
            continue
        values = []
        for i, text in enumerate(df[col], start=1):
            if text == "":
                values.append(np.nan)
                continue
            try:
                x = float(text)
            except ValueError:
                fail(col, f"row {i}: {text!r} is not a number")
            if not math.isfinite(x):
                fail(col, f"row {i}: {text!r} is not a finite number")
            if x < 0:
                fail(col, f"row {i}: {x:g} must be >= 0")
            if col.endswith("_deg") and x > 90:
                fail(col, f"row {i}: {x:g} must be <= 90")
            if col.endswith("_percent") and x > 100:
                fail(col, f"row {i}: {x:g} must be <= 100")
            values.append(x)
        df[col] = np.array(values, dtype=float)
    for col in required:
        blank = df[col].isna() if df[col].dtype == float else (df[col] == "")
        if blank.any():
            fail(col, f"row {int(np.argmax(blank.to_numpy())) + 1}: blank (a value is required)")
    for col in ("provenance",):
        if col in df.columns:
            for i, p in enumerate(df[col], start=1):
                if p not in PROVENANCES:
                    fail(col, f"row {i}: {p!r} must be one of {', '.join(PROVENANCES)}")
    for col in df.columns:
        if col.endswith(("density_kg_m3", "youngs_modulus_pa")) and (df[col] <= 0).any():
            fail(col, f"row {int(np.argmax((df[col] <= 0).to_numpy())) + 1}: must be > 0")
    return df, fail


# ---------------------------------------------------------------- tables

def load_table(name, lab_dir=LAB_DIR):
    """One validated table labresults/<name>.csv as a DataFrame (names: see TABLES)."""
    if name not in TABLES:
        raise ConfigError(f"labresults/{name}.csv", "", f"unknown table (known: {', '.join(TABLES)})")
    df, fail = _read_csv(Path(lab_dir) / f"{name}.csv", lab_dir, TABLES[name][0])
    check = {"size_distribution": _check_size_distribution,
             "shape_shares": _check_shape_shares}.get(name)
    if check:
        check(df, fail)
    return df


def _check_size_distribution(df, fail):
    """Classes coarse to fine, contiguous; mass % add up to 100; % passing consistent."""
    total = df["mass_percent"].sum()
    if abs(total - 100.0) > 0.5:
        fail("mass_percent", f"adds up to {total:g}, not 100 (+/- 0.5)")
    for i, (lo, hi) in enumerate(zip(df["min_size_m"], df["max_size_m"]), start=1):
        if hi <= lo:
            fail("max_size_m", f"row {i}: {hi:g} must be > min_size_m {lo:g}")
        if i < len(df) and abs(df["max_size_m"].iloc[i] - lo) > 1e-9:
            fail("max_size_m", f"row {i + 1}: {df['max_size_m'].iloc[i]:g} must equal min_size_m "
                               f"{lo:g} of row {i} (classes coarse to fine, no gaps)")
    passing = df["mass_percent"][::-1].cumsum()[::-1]
    for i, (given, summed) in enumerate(zip(df["passing_percent"], passing), start=1):
        if abs(given - summed) > 0.5:
            fail("passing_percent", f"row {i}: {given:g} but the mass % of this and the finer "
                                    f"classes add up to {summed:.1f} (+/- 0.5)")


def _check_shape_shares(df, fail):
    cols = [c for c in df.columns if c.endswith("_percent")]
    if not cols:
        fail("", "needs <shape>_percent columns")
    for i, total in enumerate(df[cols].sum(axis=1), start=1):
        if abs(total - 100.0) > 0.5:
            fail(", ".join(cols), f"row {i}: shares add up to {total:g}, not 100 (+/- 0.5)")


# ---------------------------------------------------------------- curves

def curve_names(lab_dir=LAB_DIR):
    """Names of the target curves (files labresults/curves/<name>.csv)."""
    return sorted(p.stem for p in (Path(lab_dir) / "curves").glob("*.csv"))


def curve_quantities(df):
    """Target columns of a curve table: every column X with X_low and X_high."""
    return [c for c in df.columns if c not in TEXT_COLUMNS and c != "stress_pa"
            and not c.endswith(BAND_SUFFIXES)]


def load_curve(name, lab_dir=LAB_DIR):
    """One validated curve labresults/curves/<name>.csv as a DataFrame.

    Columns: stress_pa (load steps, strictly increasing, > 0), for every target
    quantity X the columns X, X_low, X_high (band: low <= X <= high), optional
    outcome (slides/sticks; X may be blank where the cell sticks) and provenance."""
    path = Path(lab_dir) / "curves" / f"{name}.csv"
    if not path.is_file():
        raise ConfigError(_rel(path, lab_dir), "",
                          f"unknown curve {name!r} (known: {', '.join(curve_names(lab_dir))})")
    df, fail = _read_csv(path, lab_dir, ["stress_pa", "provenance"])
    stress = df["stress_pa"].to_numpy()
    for i in range(len(stress)):
        if stress[i] <= 0:
            fail("stress_pa", f"row {i + 1}: {stress[i]:g} must be > 0")
        if i and stress[i] <= stress[i - 1]:
            fail("stress_pa", f"row {i + 1}: {stress[i]:g} must be > {stress[i - 1]:g} of the row "
                              "before (stress steps strictly increasing)")
    outcome = df["outcome"] if "outcome" in df.columns else pd.Series(["slides"] * len(df))
    for i, o in enumerate(outcome, start=1):
        if o not in OUTCOMES:
            fail("outcome", f"row {i}: {o!r} must be one of {', '.join(OUTCOMES)}")
    quantities = curve_quantities(df)
    if not quantities:
        fail("", "no target column (a column X with X_low and X_high)")
    for col in df.columns:
        for s in BAND_SUFFIXES:
            if col.endswith(s) and col[: -len(s)] not in df.columns:
                fail(col, f"band column without its target column {col[: -len(s)]!r}")
    slides = (outcome == "slides").to_numpy()
    for q in quantities:
        for s in BAND_SUFFIXES:
            if q + s not in df.columns:
                fail(q + s, "missing column (every target column needs _low and _high)")
        for col in (q, q + "_low", q + "_high"):
            blank = df[col].isna().to_numpy() & slides
            if blank.any():
                fail(col, f"row {int(np.argmax(blank)) + 1}: blank (allowed only where outcome is sticks)")
        v, lo, hi = df[q].to_numpy(), df[q + "_low"].to_numpy(), df[q + "_high"].to_numpy()
        for i in np.flatnonzero(lo > v):
            fail(q + "_low", f"row {i + 1}: {lo[i]:g} must be <= {q} {v[i]:g}")
        for i in np.flatnonzero(hi < v):
            fail(q + "_high", f"row {i + 1}: {hi[i]:g} must be >= {q} {v[i]:g}")
    return df


def target_curve(name, quantity=None, lab_dir=LAB_DIR):
    """Target curve `name` (e.g. 'wall_friction_fines_dry') as a TargetCurve of arrays.

    `quantity` picks the column (e.g. 'mu_static', 'bulk_stiffness_pa'); it may be
    left out when the curve has only one. stress_pa in Pa; value/low/high in the
    quantity's unit (friction: coefficient, no unit); outcome per step 'slides'/'sticks'."""
    df = load_curve(name, lab_dir)
    quantities = curve_quantities(df)
    if quantity is None:
        if len(quantities) != 1:
            raise ConfigError(_rel(Path(lab_dir) / "curves" / f"{name}.csv", lab_dir), "quantity",
                              f"choose one of {', '.join(quantities)}")
        quantity = quantities[0]
    if quantity not in quantities:
        raise ConfigError(_rel(Path(lab_dir) / "curves" / f"{name}.csv", lab_dir), quantity,
                          f"no such target column (columns: {', '.join(quantities)})")
    outcome = df["outcome"] if "outcome" in df.columns else ["slides"] * len(df)
    return TargetCurve(name, quantity, df["stress_pa"].to_numpy(), df[quantity].to_numpy(),
                       df[quantity + "_low"].to_numpy(), df[quantity + "_high"].to_numpy(),
                       np.asarray(outcome, dtype=str), np.asarray(df["provenance"], dtype=str))


# ---------------------------------------------------------------- samples.yaml

def load_samples(lab_dir=LAB_DIR):
    """labresults/samples.yaml, validated: material, belt, design and samples sections.

    Units in key names: densities kg/m3, sizes m, flow t/h, speed m/s, masses kg,
    moisture % (dry basis)."""
    path = Path(lab_dir) / "samples.yaml"
    data = load_yaml(path)
    c = _Checker(path)
    c.file = _rel(path, lab_dir)
    c.keys(data, "", ["material", "belt", "design", "samples"])
    m = data["material"]
    c.keys(m, "material", ["particle_density_kg_m3", "mine_bulk_density_kg_m3", "provenance"],
           ["description", "mean_aspect_ratio"])
    c.number(m["particle_density_kg_m3"], "material.particle_density_kg_m3", 0, lo_open=True)
    c.number(m["mine_bulk_density_kg_m3"], "material.mine_bulk_density_kg_m3", 0, lo_open=True)
    if "mean_aspect_ratio" in m:
        c.number(m["mean_aspect_ratio"], "material.mean_aspect_ratio", 1.0)
    c.string(m["provenance"], "material.provenance", PROVENANCES)
    b = data["belt"]
    c.keys(b, "belt", ["flow_t_h", "speed_m_s", "provenance"],
           ["photographed_length_m", "photographed_mass_kg", "mass_per_metre_kg_m"])
    for k in b:
        if k != "provenance":
            c.number(b[k], f"belt.{k}", 0, lo_open=True)
    c.string(b["provenance"], "belt.provenance", PROVENANCES)
    d = data["design"]
    c.keys(d, "design", ["drop_height_m", "provenance"])
    c.number(d["drop_height_m"], "design.drop_height_m", 0, lo_open=True)
    c.string(d["provenance"], "design.provenance", PROVENANCES + ("assumption",))
    samples = data["samples"]
    if not isinstance(samples, dict) or not samples:
        c.fail("samples", "must be a non-empty mapping key -> sample")
    known_curves = set(curve_names(lab_dir))
    for key, s in samples.items():
        k = f"samples.{key}"
        c.keys(s, k, ["description", "state", "min_size_m", "max_size_m", "bulk_density_kg_m3",
                      "curves", "provenance"], ["moisture_percent_dry_basis"])
        c.string(s["state"], f"{k}.state", ["dry", "wet"])
        lo = c.number(s["min_size_m"], f"{k}.min_size_m", 0)
        hi = c.number(s["max_size_m"], f"{k}.max_size_m", 0, lo_open=True)
        if hi <= lo:
            c.fail(f"{k}.max_size_m", f"{hi} must be > min_size_m {lo}")
        c.number(s["bulk_density_kg_m3"], f"{k}.bulk_density_kg_m3", 0, lo_open=True)
        if s.get("moisture_percent_dry_basis") is not None:
            c.number(s["moisture_percent_dry_basis"], f"{k}.moisture_percent_dry_basis", 0, 100)
        if not isinstance(s["curves"], list):
            c.fail(f"{k}.curves", "must be a list of curve names")
        for name in s["curves"]:
            if name not in known_curves:
                c.fail(f"{k}.curves", f"{name!r} has no file curves/{name}.csv")
        c.string(s["provenance"], f"{k}.provenance", PROVENANCES)
    return data


def sample(key, lab_dir=LAB_DIR):
    """One sample of samples.yaml as a dict, with particle_density_kg_m3,
    solid_fraction (bulk / particle density) and its rows of angle_of_repose.csv
    and surcharge.csv (angles in deg) as dicts under 'angle_of_repose', 'surcharge'."""
    data = load_samples(lab_dir)
    if key not in data["samples"]:
        raise ConfigError(_rel(Path(lab_dir) / "samples.yaml", lab_dir), f"samples.{key}",
                          f"unknown sample (known: {', '.join(data['samples'])})")
    out = dict(data["samples"][key])
    rho_p = float(data["material"]["particle_density_kg_m3"])
    out["particle_density_kg_m3"] = rho_p
    out["solid_fraction"] = out["bulk_density_kg_m3"] / rho_p
    for table in ("angle_of_repose", "surcharge"):
        df = load_table(table, lab_dir)
        rows = df[df["sample"] == key]
        out[table] = None if rows.empty else {
            c: (None if isinstance(v, float) and math.isnan(v) else v)
            for c, v in rows.iloc[0].items()}
    return out


def aor_target_deg(key, test="angle_of_repose", lab_dir=LAB_DIR):
    """Mean of the left and right angle (deg) of sample `key` in `test`
    ('angle_of_repose' or 'surcharge'): the target of the AoR/surcharge rigs."""
    if test not in ("angle_of_repose", "surcharge"):
        raise ConfigError(_rel(Path(lab_dir) / f"{test}.csv", lab_dir), "test",
                          f"{test!r} must be angle_of_repose or surcharge")
    row = sample(key, lab_dir)[test]
    if row is None:
        raise ConfigError(_rel(Path(lab_dir) / f"{test}.csv", lab_dir), "sample",
                          f"no row for sample {key!r}")
    return (row["left_deg"] + row["right_deg"]) / 2.0


# ---------------------------------------------------------------- everything

def _check_sample_rows(table, df, samples, lab_dir):
    file = _rel(Path(lab_dir) / f"{table}.csv", lab_dir)
    seen = set()
    for i, key in enumerate(df["sample"], start=1):
        if key not in samples:
            raise ConfigError(file, "sample", f"row {i}: {key!r} is not a sample of samples.yaml "
                                              f"(known: {', '.join(samples)})")
        if key in seen:
            raise ConfigError(file, "sample", f"row {i}: {key!r} appears twice")
        seen.add(key)


def _check_material_refs(samples, config_dir, lab_dir):
    """Every configs/materials/*.yaml and configs/material_sets/*.yaml `lab_sample:` must be a
    key of samples.yaml."""
    for path in sorted((Path(config_dir) / "materials").glob("*.yaml")) + \
            sorted((Path(config_dir) / "material_sets").glob("*.yaml")):
        ref = load_yaml(path).get("lab_sample")
        if ref is not None and ref not in samples:
            raise ConfigError(_rel(path, config_dir), "lab_sample",
                              f"{ref!r} is not a sample of {_rel(Path(lab_dir) / 'samples.yaml', lab_dir)} "
                              f"(known: {', '.join(samples)})")


def load_all(lab_dir=LAB_DIR, config_dir=CONFIG_DIR):
    """Load and validate every lab-data file; raise ConfigError on the first problem.

    Returns {'samples': dict, 'tables': {name: DataFrame}, 'curves': {name: DataFrame}}.
    Also checks that the samples named in the tables and in the material configs'
    `lab_sample:` exist, and that shape_shares uses the classes and shapes defined."""
    lab_dir = Path(lab_dir)
    samples = load_samples(lab_dir)
    tables = {name: load_table(name, lab_dir) for name in TABLES}
    for table in ("angle_of_repose", "surcharge"):
        _check_sample_rows(table, tables[table], samples["samples"], lab_dir)
    shares = tables["shape_shares"]
    file = _rel(lab_dir / "shape_shares.csv", lab_dir)
    for i, cls in enumerate(shares["class"], start=1):
        if cls not in set(tables["size_distribution"]["class"]):
            raise ConfigError(file, "class", f"row {i}: {cls!r} is not a class of size_distribution.csv")
    shapes = set(tables["shapes"]["shape"])
    for col in shares.columns:
        if col.endswith("_percent") and col[: -len("_percent")] not in shapes:
            raise ConfigError(file, col, f"{col[: -len('_percent')]!r} is not a shape of shapes.csv")
    curves = {name: load_curve(name, lab_dir) for name in curve_names(lab_dir)}
    if config_dir is not None and Path(config_dir).is_dir():
        _check_material_refs(samples["samples"], config_dir, lab_dir)
    return {"samples": samples, "tables": tables, "curves": curves}
