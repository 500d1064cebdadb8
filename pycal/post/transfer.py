"""Measurements of the transfer rig from its time record (pure Python, no YADE): impact
stress on the footprint, throughput in and out, holdup, the plugging verdict; the side-view
frames and the record plot (docs/rigs.md, transfer).

Record rows (RECORD_COLUMNS, one per record interval): masses at the row's time and the
plate's normal forces averaged over the interval before it.
"""
import math

import numpy as np

from .aor_mixed import MATERIAL_COLOURS

RECORD_COLUMNS = ["time_s", "fed_mass_kg", "in_flight_mass_kg", "on_plate_mass_kg", "run_off_mass_kg",
                  "spilled_upstream_mass_kg", "footprint_normal_force_n", "plate_normal_force_n", "bodies_count"]
PROFILE_COLUMNS = ["s_from_plate_top_m", "normal_stress_pa", "in_footprint"]


def _col(records, name):
    return np.array([r[RECORD_COLUMNS.index(name)] for r in records], dtype=float)


def window_rows(records, t0, t1):
    """Indices of the rows whose interval lies in [t0, t1] (s): the row's time minus one record
    interval >= t0 and its time <= t1."""
    t = _col(records, "time_s")
    dt = np.diff(t, prepend=0.0)
    return np.nonzero((t - dt >= t0 - 1e-9) & (t <= t1 + 1e-9))[0]


def mass_at(records, t):
    """The record row at the first time >= t (s), as a dict."""
    for r in records:
        if r[0] >= t - 1e-9:
            return dict(zip(RECORD_COLUMNS, r))
    return dict(zip(RECORD_COLUMNS, records[-1]))


def rate(records, name, t0, t1):
    """Change of a cumulative mass column between the rows at t0 and t1, per second (kg/s)."""
    a, b = mass_at(records, t0), mass_at(records, t1)
    return (b[name] - a[name]) / (b["time_s"] - a["time_s"])


def summarise(records, geo, measure, feed_time_s, holdup_wait_s):
    """Result keys of the steady window [measure.steady_from_s, feed stop] and of the holdup.

    impact_stress_pa = mean footprint normal force over the window / footprint area;
    throughput_in/out = fed / run-off mass change over the window per second;
    holdup_growth_kg_s = least-squares slope of the on-plate mass over the window, and
    on_plate_mass_mean_kg its mean;
    plugged = throughput_out < plug_outflow_ratio x throughput_in."""
    t0, t1 = measure["steady_from_s"], feed_time_s
    rows = window_rows(records, t0, t1)
    if len(rows) < 2:
        raise ValueError(f"steady window {t0} - {t1} s holds {len(rows)} record rows")
    foot = _col(records, "footprint_normal_force_n")[rows]
    plate = _col(records, "plate_normal_force_n")[rows]
    t = _col(records, "time_s")[rows]
    on_plate = _col(records, "on_plate_mass_kg")[rows]
    growth = float(np.polyfit(t, on_plate, 1)[0])
    q_in = rate(records, "fed_mass_kg", t0, t1)
    q_out = rate(records, "run_off_mass_kg", t0, t1)
    stress = float(np.mean(foot)) / geo["footprint_area_m2"]
    design = geo["design_impact_stress_pa"]
    end = mass_at(records, feed_time_s + holdup_wait_s)
    stop = mass_at(records, feed_time_s)
    return {
        "impact_stress_pa": stress,
        "design_impact_stress_pa": design,
        "momentum_flux_stress_pa": geo["momentum_flux_stress_pa"],
        "impact_stress_over_design_ratio": stress / design,
        "plate_normal_force_n": float(np.mean(plate)),
        "throughput_in_kg_s": q_in,
        "throughput_out_kg_s": q_out,
        "outflow_ratio": q_out / q_in,
        "holdup_growth_kg_s": growth,
        "on_plate_mass_mean_kg": float(np.mean(on_plate)),
        "plugged": bool(q_out < measure["plug_outflow_ratio"] * q_in),
        "holdup_mass_kg": end["on_plate_mass_kg"],
        "holdup_time_s": end["time_s"] - feed_time_s,
        "fed_mass_kg": end["fed_mass_kg"],
        "run_off_mass_kg": end["run_off_mass_kg"],
        "spilled_upstream_mass_kg": end["spilled_upstream_mass_kg"],
        "in_flight_mass_kg": end["in_flight_mass_kg"],
        "fed_mass_at_feed_stop_kg": stop["fed_mass_kg"],
        "on_plate_mass_at_feed_stop_kg": stop["on_plate_mass_kg"],
        "run_off_mass_at_feed_stop_kg": stop["run_off_mass_kg"],
        "spilled_upstream_mass_at_feed_stop_kg": stop["spilled_upstream_mass_kg"],
        "in_flight_mass_at_feed_stop_kg": stop["in_flight_mass_kg"],
        "steady_window_s": [t0, t1],
    }


def stress_profile_rows(edges, force_sums, samples, width):
    """[(bin centre s m, mean normal stress Pa, in footprint)] of the plate: force sums per bin
    over `samples` samples / (bin length x slice width)."""
    out = []
    for k in range(len(edges) - 1):
        length = edges[k + 1] - edges[k]
        stress = force_sums[k][0] / max(samples, 1) / (length * width)
        out.append((0.5 * (edges[k] + edges[k + 1]), stress, force_sums[k][1]))
    return out


def frame_limits(geo):
    """(x range, z range) of the side-view frames, in m relative to the plate's top end."""
    top, t, n = geo["plate_top_m"], geo["plate_tangent"], geo["plate_normal"]
    L = geo["plate_length_m"]
    wx, wz = geo["injection_window_centre_m"]
    xs = [0.0, L * t[0], wx - top[0] - geo["stream_length_m"], wx - top[0] + geo["stream_length_m"]]
    zs = [0.0, L * t[1], wz - top[1] + 0.08]
    return (min(xs) - 0.08, max(xs) + 0.08), (min(zs) - 0.08, max(zs) + 0.05)


def draw_frame(path, rows, geo, time_s, title, limits):
    """Side view (x-z, seen from -y) of every particle sphere at one time, coloured by
    material (lump members dark grey with a white edge), the plate, the injection window and
    the footprint. rows: (x, z, radius, material, clump id or -1) in world coordinates (m)."""
    from matplotlib.collections import EllipseCollection
    from ..plotting import new_figure, save_png
    top, t = geo["plate_top_m"], geo["plate_tangent"]
    fig, ax = new_figure(figsize=(7.5, 5.0))
    if rows:
        xy = np.array([[r[0] - top[0], r[1] - top[1]] for r in rows])
        d = np.array([2.0 * r[2] for r in rows])
        colours = [MATERIAL_COLOURS.get(r[3], "0.7") for r in rows]
        edges = ["w" if int(r[4]) >= 0 else "k" for r in rows]
        ax.add_collection(EllipseCollection(d, d, np.zeros(len(d)), units="xy", offsets=xy,
                                            offset_transform=ax.transData, facecolors=colours,
                                            edgecolors=edges, linewidths=0.3, alpha=0.9))
    L = geo["plate_length_m"]
    ax.plot([0.0, L * t[0]], [0.0, L * t[1]], "-", color="k", lw=2.5, label="steel plate")
    s0, s1 = geo["footprint_start_m"], geo["footprint_end_m"]
    ax.plot([s0 * t[0], s1 * t[0]], [s0 * t[1], s1 * t[1]], "-", color="tab:red", lw=4, label="footprint")
    wx, wz = geo["injection_window_centre_m"]
    half = 0.5 * geo["stream_length_m"]
    ax.plot([wx - top[0] - half, wx - top[0] + half], [wz - top[1]] * 2, "--", color="tab:green", lw=1.5,
            label="injection window")
    for mat, col in MATERIAL_COLOURS.items():
        if any(r[3] == mat for r in rows):
            ax.plot([], [], "o", color=col, label=mat)
    ax.set_xlim(*limits[0])
    ax.set_ylim(*limits[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x from the plate's top end (m)")
    ax.set_ylabel("z from the plate's top end (m)")
    ax.set_title(f"{title}\nt = {time_s:.3f} s", fontsize=9)
    ax.legend(loc="upper right", fontsize=7)
    fig.tight_layout()
    return save_png(fig, path)


def plot_record(path, records, geo, result, title):
    """Masses on the plate, in flight, run off and fed vs time, and the footprint's normal
    stress vs time against the design value and the momentum flux."""
    from ..plotting import new_figure, save_png
    fig, (a1, a2) = new_figure(2, 1, figsize=(7.0, 6.0))
    t = _col(records, "time_s")
    for name, style in (("fed_mass_kg", "k-"), ("on_plate_mass_kg", "b-"), ("in_flight_mass_kg", "g-"),
                        ("run_off_mass_kg", "r-"), ("spilled_upstream_mass_kg", "m:")):
        a1.plot(t, _col(records, name), style, label=name.replace("_kg", " (kg)"))
    t0, t1 = result["steady_window_s"]
    for ax in (a1, a2):
        ax.axvspan(t0, t1, color="0.9")
    a1.set_ylabel("mass (kg)")
    a1.legend(fontsize=7)
    a1.set_title(title, fontsize=9)
    a2.plot(t, _col(records, "footprint_normal_force_n") / geo["footprint_area_m2"] / 1000.0, "b-", lw=0.8,
            label="footprint normal stress")
    a2.axhline(result["impact_stress_pa"] / 1000.0, color="b", ls="--",
               label=f"steady mean {result['impact_stress_pa'] / 1000:.1f} kPa")
    a2.axhline(geo["design_impact_stress_pa"] / 1000.0, color="r", ls="-",
               label=f"design rho0 v0 vz {geo['design_impact_stress_pa'] / 1000:.1f} kPa")
    a2.axhline(geo["momentum_flux_stress_pa"] / 1000.0, color="g", ls=":",
               label=f"momentum flux at this angle {geo['momentum_flux_stress_pa'] / 1000:.1f} kPa")
    a2.set_xlabel("time (s)")
    a2.set_ylabel("stress (kPa)")
    a2.legend(fontsize=7)
    fig.tight_layout()
    return save_png(fig, path)


def finite_or_none(value):
    """A float for result.json, None for NaN/inf (JSON has neither)."""
    return value if value is not None and math.isfinite(value) else None
