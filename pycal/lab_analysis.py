"""Lab analysis: moisture, solid fractions, belt load, rolling-resistance estimate and
the impact stress a chute imposes (docs/lab-tests.md sections 3, 7 and 9). SI units.

CLI: `pycal impact ...` (one design case) and `pycal analyse --out DIR` (table of
derived quantities, impact stress vs drop height as CSV and PNG).
"""
import math
from pathlib import Path

import numpy as np
import pandas as pd

from . import labdata
from .errors import ConfigError
from .files import atomic_path
from .impact_formula import G_M_S2, impact_stress, min_drop_height_m  # noqa: F401 (pycal impact)



def moisture_percent_dry_basis(wet_mass_kg, dry_mass_kg):
    """Moisture in % of the dry mass: (wet - dry) x 100 / dry (any mass unit)."""
    if not dry_mass_kg > 0:
        raise ValueError(f"dry mass {dry_mass_kg} must be > 0")
    return (wet_mass_kg - dry_mass_kg) * 100.0 / dry_mass_kg


def dry_bulk_density(wet_bulk_density_kg_m3, moisture_percent):
    """Bulk density of the dry solids (kg/m3) in a wet bulk of given moisture (% dry basis)."""
    return wet_bulk_density_kg_m3 / (1.0 + moisture_percent / 100.0)


def solid_fraction(bulk_density_kg_m3, particle_density_kg_m3):
    """Volume fraction of solids, bulk density / particle density (no unit)."""
    return bulk_density_kg_m3 / particle_density_kg_m3


def t_h_to_kg_s(flow_t_h):
    """Mass flow t/h -> kg/s."""
    return flow_t_h * 1000.0 / 3600.0


def belt_load_kg_m(flow_t_h, speed_m_s):
    """Mass on one metre of belt (kg/m) = mass flow / belt speed."""
    return t_h_to_kg_s(flow_t_h) / speed_m_s


def rolling_resistance_from_aspect_ratio(aspect_ratio):
    """Rolling-resistance coefficient for a sphere standing in for a particle of this
    aspect ratio (long / short axis, >= 1): mu_r = (AR - 1) / 2.

    Assumption: a straight line through the two points the case study quotes from
    Wensrich & Katterfeld, Powder Technology 217 (2012) 409-417: AR 1.0 -> 0 (a
    sphere needs none) and AR 1.7 -> 0.35; not the paper's own fit, so use it only
    as the start value of the calibration (AR 1.0 - 2.0)."""
    if not aspect_ratio >= 1.0:
        raise ValueError(f"aspect ratio {aspect_ratio} must be >= 1 (long / short axis)")
    return 0.5 * (aspect_ratio - 1.0)


def impact_vs_drop_height(heights_m, belt_speed_m_s, mass_flow_kg_s, bulk_density_kg_m3):
    """impact_stress() for each drop height (m) from min_drop_height_m on (lower heights
    are left out: the rule does not apply there), as a DataFrame with drop_height_m first."""
    h_min = min_drop_height_m(belt_speed_m_s)
    rows = [{"drop_height_m": h, **impact_stress(h, belt_speed_m_s, mass_flow_kg_s, bulk_density_kg_m3)}
            for h in heights_m if h >= h_min]
    return pd.DataFrame(rows)


def derived_quantities(lab=None):
    """Every derived quantity of the shipped lab data as a DataFrame (name, value, unit, source).

    `lab` is labdata.load_all() output (loaded when None)."""
    lab = lab or labdata.load_all()
    s = lab["samples"]
    rho_p = float(s["material"]["particle_density_kg_m3"])
    rows = []

    def add(name, value, unit, source):
        rows.append({"name": name, "value": float(value), "unit": unit, "source": source})

    yaml_src = "labresults/samples.yaml"
    for key, smp in s["samples"].items():
        add(f"solid_fraction_{key}", solid_fraction(smp["bulk_density_kg_m3"], rho_p), "-",
            f"{yaml_src}: bulk / particle density")
        w = smp.get("moisture_percent_dry_basis")
        if w is not None:
            add(f"moisture_percent_dry_basis_{key}", w, "%", f"{yaml_src} (measured)")
            add(f"moisture_percent_wet_basis_{key}", w * 100.0 / (100.0 + w), "%",
                "water / wet mass = w / (100 + w)")
            dry = dry_bulk_density(smp["bulk_density_kg_m3"], w)
            add(f"dry_solids_bulk_density_{key}", dry, "kg/m3", "wet bulk density / (1 + w/100)")
            add(f"dry_solids_solid_fraction_{key}", solid_fraction(dry, rho_p), "-",
                "dry solids bulk density / particle density")
    add("solid_fraction_mine_bulk", solid_fraction(s["material"]["mine_bulk_density_kg_m3"], rho_p),
        "-", f"{yaml_src}: mine bulk / particle density")

    sd = lab["tables"]["size_distribution"]
    for label, lo, hi in (("plus_25mm", 0.025, None), ("minus_25_plus_6mm", 0.006, 0.025),
                          ("minus_6mm", None, 0.006)):
        sel = np.ones(len(sd), dtype=bool)
        if lo is not None:
            sel &= sd["min_size_m"].to_numpy() >= lo - 1e-12
        if hi is not None:
            sel &= sd["max_size_m"].to_numpy() <= hi + 1e-12
        add(f"mass_percent_{label}", sd["mass_percent"][sel].sum(), "%",
            "labresults/size_distribution.csv (M1 / M2 / M3 share)")

    for table in ("angle_of_repose", "surcharge"):
        df = lab["tables"][table]
        for _, row in df.iterrows():
            add(f"{table}_mean_deg_{row['sample']}", (row["left_deg"] + row["right_deg"]) / 2, "deg",
                f"labresults/{table}.csv: (left + right) / 2")

    belt = s["belt"]
    load = belt_load_kg_m(belt["flow_t_h"], belt["speed_m_s"])
    add("belt_load_kg_m", load, "kg/m", f"{yaml_src}: flow / speed")
    if "mass_per_metre_kg_m" in belt:
        add("belt_load_study_kg_m", belt["mass_per_metre_kg_m"], "kg/m", f"{yaml_src} (study)")
        add("belt_load_difference_percent", (load / belt["mass_per_metre_kg_m"] - 1) * 100, "%",
            "belt_load / study value - 1")
        if "photographed_mass_kg" in belt:
            add("photographed_share_percent", belt["photographed_mass_kg"] * 100 / belt["mass_per_metre_kg_m"],
                "%", "photographed mass / mass per metre")
    ar = s["material"].get("mean_aspect_ratio")
    if ar is not None:
        add("rolling_resistance_estimate", rolling_resistance_from_aspect_ratio(ar), "-",
            "(AR - 1) / 2 at the mean aspect ratio (Wensrich & Katterfeld 2012 anchors)")

    h = s["design"]["drop_height_m"]
    add("design_drop_height_m", h, "m", f"{yaml_src} ({s['design']['provenance']})")
    imp = impact_stress(h, belt["speed_m_s"], t_h_to_kg_s(belt["flow_t_h"]),
                        s["material"]["mine_bulk_density_kg_m3"])
    units = {"_m_s": "m/s", "_kg_m3": "kg/m3", "_m2": "m2", "_pa": "Pa"}
    for k, v in imp.items():
        add(k, v, next(u for suf, u in units.items() if k.endswith(suf)),
            "P = rho0 v0 vz (docs/method.md), design drop height, belt data, mine bulk density")
    steps = [c["stress_pa"].max() for c in lab["curves"].values()]
    if steps:
        add("highest_lab_load_step_pa", max(steps), "Pa", "labresults/curves/*.csv")
        add("impact_stress_over_highest_load_step", imp["impact_stress_pa"] / max(steps), "-",
            "< 1: the rigs' load steps cover the chute")
    return pd.DataFrame(rows, columns=["name", "value", "unit", "source"])


# ---------------------------------------------------------------- CLI

def _check_positive(args, fields):
    for flag, attr in fields:
        value = getattr(args, attr)
        if value is None or not (math.isfinite(value) and value > 0):
            raise ConfigError(flag, attr, f"{value} must be > 0")


def cli_impact(args):
    """`pycal impact`: print the impact numbers for one chute (units on every line)."""
    _check_positive(args, [("--drop-height-m", "drop_height_m"), ("--belt-speed-m-s", "belt_speed_m_s"),
                           ("--flow-t-h", "flow_t_h"), ("--bulk-density-kg-m3", "bulk_density_kg_m3")])
    h_min = min_drop_height_m(args.belt_speed_m_s)
    if args.drop_height_m < h_min:
        raise ConfigError("--drop-height-m", "drop_height_m",
                          f"{args.drop_height_m:g} m is below v0^2 / (2 g) = {h_min:.3g} m for a belt speed of "
                          f"{args.belt_speed_m_s:g} m/s: the stream has not thinned yet, the impact-stress rule "
                          "(rho_b = rho0 v0 / vz) does not apply")
    r = impact_stress(args.drop_height_m, args.belt_speed_m_s, t_h_to_kg_s(args.flow_t_h),
                      args.bulk_density_kg_m3)
    print(f"impact velocity (vertical): {r['impact_velocity_vertical_m_s']:.2f} m/s")
    print(f"impact speed (belt and vertical, not used): {r['impact_speed_m_s']:.2f} m/s")
    print(f"stream bulk density (rho0 v0 / vz): {r['stream_bulk_density_kg_m3']:.1f} kg/m3")
    print(f"stream cross-section: {r['stream_area_m2']:.4f} m2")
    print(f"impact stress (rho_b vz^2): {r['impact_stress_pa'] / 1000:.2f} kPa")
    return r


def plot_impact(curve, design_h_m, design_p_pa, highest_step_pa, path, label="impact stress"):
    """PNG of impact stress (kPa) vs drop height (m), marking the design drop height
    (m) and its stress (Pa) and, if given, the highest lab load step (Pa)."""
    from .plotting import new_figure, save_png
    fig, ax = new_figure(figsize=(6.4, 4.4))
    ax.plot(curve["drop_height_m"], curve["impact_stress_pa"] / 1000, "-", color="C0", label=label)
    ax.axvline(design_h_m, color="C3", ls="--", lw=1)
    ax.plot([design_h_m], [design_p_pa / 1000], "o", color="C3",
            label=f"design: {design_h_m:g} m -> {design_p_pa / 1000:.1f} kPa")
    if highest_step_pa:
        ax.axhline(highest_step_pa / 1000, color="0.4", ls=":", lw=1,
                   label=f"highest lab load step {highest_step_pa / 1000:g} kPa")
    ax.set_xlabel("drop height (m)")
    ax.set_ylabel("impact stress (kPa)")
    ax.set_title("Impact stress at the receiving point: P = rho_b vz^2, rho_b = rho0 v0 / vz", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left")
    fig.tight_layout()
    save_png(fig, path, dpi=120)


def cli_analyse(args):
    """`pycal analyse --out DIR`: write derived_quantities.csv, impact_vs_drop_height.csv
    and impact_vs_drop_height.png to DIR and print the table."""
    lab = labdata.load_all()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    table = derived_quantities(lab)
    with atomic_path(out / "derived_quantities.csv") as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")

    s = lab["samples"]
    belt, rho0, h = s["belt"], s["material"]["mine_bulk_density_kg_m3"], s["design"]["drop_height_m"]
    heights = np.round(np.arange(0.5, 15.0 + 1e-9, 0.5), 6)
    curve = impact_vs_drop_height(heights, belt["speed_m_s"], t_h_to_kg_s(belt["flow_t_h"]), rho0)
    curve = curve.drop(columns="stream_area_m2")
    with atomic_path(out / "impact_vs_drop_height.csv") as tmp:
        curve.to_csv(tmp, index=False, float_format="%.6g")
    design = impact_stress(h, belt["speed_m_s"], t_h_to_kg_s(belt["flow_t_h"]), rho0)
    highest = max((c["stress_pa"].max() for c in lab["curves"].values()), default=None)
    label = (f"impact stress ({belt['flow_t_h']:g} t/h, {belt['speed_m_s']:g} m/s, "
             f"{rho0:g} kg/m3)")
    plot_impact(curve, h, design["impact_stress_pa"], highest, out / "impact_vs_drop_height.png", label)

    with pd.option_context("display.max_colwidth", 70, "display.width", 200):
        print(table.to_string(index=False, formatters={"value": "{:.6g}".format}))
    for name in ("derived_quantities.csv", "impact_vs_drop_height.csv", "impact_vs_drop_height.png"):
        print(f"wrote {out / name}")
    return table
