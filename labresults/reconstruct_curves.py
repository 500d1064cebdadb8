"""Write the reconstructed target curves of docs/lab-tests.md section 8 to curves/*.csv.

The case study shows these curves only as plots without numbers; each rule below
turns what its text says into a target and a band (README.md has the table).
Run:  /usr/bin/python3 labresults/reconstruct_curves.py
It overwrites only the files it makes: do not run it over measured curves you
dropped in (or remove their names from CURVES first).
"""
import math
from pathlib import Path

STEPS_PA = [3000, 6000, 12000, 24000, 40000, 60000, 90000]   # the rigs' load steps (top: above the design impact stress, 88.6 kPa)
PARTICLE_DENSITY = 2750.0                                     # kg/m3
BULK_DENSITY = {"fines_dry": 1601.0, "fines_wet": 1146.0, "gravel_dry": 1603.0}  # kg/m3
DRY_RAMP_SLOPE = 0.1 / (60000 - 3000)   # 1/Pa: dry fines wall friction, 3 kPa -> plateau


def ramp(s, start, end, s0, s1):
    """start at s0, linear to end at s1, constant beyond."""
    return start + (end - start) * min(max((s - s0) / (s1 - s0), 0.0), 1.0)


def band(d):
    return lambda v, s: (v - d, v + d)


def wall_plateau(start, plateau, s1):
    return {"value": lambda s: ramp(s, start, plateau, 3000, s1), "band": band(0.05), "fmt": 3}


def linear_mu(intercept, slope, slope_low, slope_high, d):
    """intercept + slope x stress; band: intercept -/+ d with the low/high slopes."""
    return {"value": lambda s: intercept + slope * s,
            "band": lambda v, s: (intercept - d + slope_low * s, intercept + d + slope_high * s),
            "fmt": 3}


def stiffness(c):
    """bulk stiffness proportional to stress; band /3 .. x3, kept inside 1e5 .. 1e7 Pa."""
    return {"value": lambda s: c * s,
            "band": lambda v, s: (max(v / 3, 1e5), min(v * 3, 1e7)), "fmt": "sig"}


def solid_fraction(sample):
    phi0 = BULK_DENSITY[sample] / PARTICLE_DENSITY
    return {"value": lambda s: 0.65 - (0.65 - phi0) * math.exp(-s / 20000.0),
            "band": band(0.03), "fmt": 3}


def ucs_density(sample, scale_pa):
    rho0 = BULK_DENSITY[sample]
    return {"value": lambda s: PARTICLE_DENSITY - (PARTICLE_DENSITY - rho0) * math.exp(-s / scale_pa),
            "band": lambda v, s: (v - 100, min(v + 100, PARTICLE_DENSITY)), "fmt": 0}


EXPANSION = {"value": lambda s: 6e6 * (1 - math.exp(-s / 5000.0)),
             "band": lambda v, s: (v - 2e6, v + 2e6), "fmt": "sig"}

WALL_WET = 2 * DRY_RAMP_SLOPE     # 3.5e-6 1/Pa
INTERNAL_DRY = 2.0e-6             # 1/Pa
INTERNAL_WET = 5.0e-6             # 1/Pa
STICKS = {"value": None}

# name -> (rule text, {column: spec}, outcome(stress) or None)
CURVES = {
    "wall_friction_fines_dry": (
        "0.40 at 3 kPa rising linearly to a plateau of 0.50 (static) / 0.50 -> 0.60 (dynamic) "
        "at 60 kPa; band +/-0.05",
        {"mu_static": wall_plateau(0.40, 0.50, 60000), "mu_dynamic": wall_plateau(0.50, 0.60, 60000)},
        None),
    "wall_friction_gravel_dry": (
        "0.40 at 3 kPa rising linearly to a plateau of 0.50 at 30 kPa, static and dynamic; band +/-0.05",
        {"mu_static": wall_plateau(0.40, 0.50, 30000), "mu_dynamic": wall_plateau(0.40, 0.50, 30000)},
        None),
    "wall_friction_fines_wet": (
        "dry intercepts (0.40 static, 0.50 dynamic) + 3.5e-6/Pa x stress (twice the dry ramp slope); "
        "band: intercept -/+0.05, slope 1.75e-6 .. 5.25e-6/Pa",
        {"mu_static": linear_mu(0.40, WALL_WET, WALL_WET / 2, 1.5 * WALL_WET, 0.05),
         "mu_dynamic": linear_mu(0.50, WALL_WET, WALL_WET / 2, 1.5 * WALL_WET, 0.05)},
        None),
    "internal_friction_fines_dry": (
        "0.50 + 2.0e-6/Pa x stress; band: intercept 0.40 .. 0.60, slope 0 .. 4.0e-6/Pa",
        {"mu_static": linear_mu(0.50, INTERNAL_DRY, 0.0, 2 * INTERNAL_DRY, 0.1)},
        None),
    "internal_friction_fines_wet": (
        "static = dynamic = 0.50 + 5.0e-6/Pa x stress up to 40 kPa; band: intercept 0.40 .. 0.60, "
        "slope 2.5e-6 .. 1.0e-5/Pa; from 60 kPa (above 55 kPa) the cell sticks up to 90 deg tilt",
        {"mu_static": linear_mu(0.50, INTERNAL_WET, INTERNAL_WET / 2, 2 * INTERNAL_WET, 0.1),
         "mu_dynamic": linear_mu(0.50, INTERNAL_WET, INTERNAL_WET / 2, 2 * INTERNAL_WET, 0.1)},
        lambda s: "sticks" if s > 55000 else "slides"),
    "internal_friction_gravel_dry": (
        "not measurable: the particles interlock and the mobile cell did not move; target: sticks",
        {"mu_static": STICKS},
        lambda s: "sticks"),
}
for _s in ("fines_dry", "fines_wet", "gravel_dry"):
    CURVES[f"ccs_{_s}"] = (
        "bulk stiffness = 40 x stress (band /3 .. x3 within 1e5 .. 1e7 Pa); solid fraction = "
        "0.65 - (0.65 - bulk/particle density) exp(-stress/20 kPa), band +/-0.03",
        {"bulk_stiffness_pa": stiffness(40.0), "solid_fraction": solid_fraction(_s)}, None)
_UCS = {"fines_dry": (60.0, 150000.0), "fines_wet": (100.0, 40000.0), "gravel_dry": (40.0, 150000.0)}
for _s, (_c, _scale) in _UCS.items():
    CURVES[f"ucs_{_s}"] = (
        f"bulk stiffness = {_c:.0f} x stress (band /3 .. x3 within 1e5 .. 1e7 Pa); bulk density = "
        f"2750 - (2750 - {BULK_DENSITY[_s]:.0f}) exp(-stress/{_scale / 1000:.0f} kPa), band +/-100 kg/m3 "
        "(high <= 2750)",
        {"bulk_stiffness_pa": stiffness(_c), "bulk_density_kg_m3": ucs_density(_s, _scale)}, None)
for _s in ("fines_dry", "gravel_dry"):
    CURVES[f"ccs_expansion_{_s}"] = (
        "particle stiffness = 6e6 (1 - exp(-stress/5 kPa)) Pa, band +/-2e6 Pa "
        "(stress = the step the unloading passes through)",
        {"particle_stiffness_pa": EXPANSION}, None)


def _fmt(x, fmt):
    if x is None:
        return ""
    if fmt == "sig":                      # 4 significant digits, written in full
        return f"{float(f'{x:.4g}'):.0f}"
    return f"{x:.{fmt}f}"


def write_curve(path, rule, columns, outcome):
    header = ["stress_pa"]
    for q in columns:
        header += [q, f"{q}_low", f"{q}_high"]
    header += (["outcome"] if outcome else []) + ["provenance"]
    lines = [f"# reconstructed from the text of docs/lab-tests.md section 8: {rule}", ",".join(header)]
    for s in STEPS_PA:
        row = [str(s)]
        out = outcome(s) if outcome else "slides"
        for spec in columns.values():
            if out == "sticks" or spec["value"] is None:
                row += ["", "", ""]
            else:
                v = spec["value"](s)
                lo, hi = spec["band"](v, s)
                row += [_fmt(v, spec["fmt"]), _fmt(lo, spec["fmt"]), _fmt(hi, spec["fmt"])]
        row += ([out] if outcome else []) + ["reconstructed"]
        lines.append(",".join(row))
    path.write_text("\n".join(lines) + "\n")


def main():
    out = Path(__file__).resolve().parent / "curves"
    out.mkdir(exist_ok=True)
    for name, (rule, columns, outcome) in CURVES.items():
        write_curve(out / f"{name}.csv", rule, columns, outcome)
    print(f"wrote {len(CURVES)} curves to {out}")


if __name__ == "__main__":
    main()
