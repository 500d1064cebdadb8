"""Pile angles of the cylinder-lift angle of repose and surcharge rigs (pure Python).

Imported by the rig scripts inside YADE and by the tests: numpy, matplotlib (only in
plot_pile, through pycal.plotting) and the standard library only, never yade.

Input: particle positions [(x, y, z, r), ...] in m, the table top at z = table_z_m (0).

Method - the pile's silhouette, as a gauge laid on the flank sees it
(configs/rigs/aor.yaml `measure:`):
1. Pile centre = mass centre of the particles in x, y (weights r^3: equal density).
2. Four sectors around the centre, each +- sector_half_width_deg about an axis:
   right = +x, back = +y, left = -x, front = -y (azimuth of the particle centre).
3. In each sector the pile is cut into horizontal slices of silhouette_slice_height_m
   (by particle centre height). Per slice the silhouette point is the outermost particle
   edge: horizontal distance of the centre from the pile centre + radius.
4. Slices below exclude_bottom_m (the first layer: the toe and the particles that
   rolled away on the table) and within exclude_apex_m of the pile top (the rounded
   top) are left out.
5. Least-squares line r_edge = a + b z through the used points (r as a function of
   height, so that a vertical flank, b = 0, is well posed); angle = atan(-1 / b) for
   b < 0 and 90 degrees for b >= 0 (a vertical or overhanging flank). Fewer than 2
   used slices: no angle (NaN in Python, null in result.json; n_used says why).
   The mean angle is the mean over the sectors that have an angle (NaN if none);
   `sectors_count` says how many: a sector without an angle is reported, never
   counted as 0 degrees.
6. pile_height_m = highest particle top - table_z_m; pile_radius_m = largest horizontal
   distance of a particle edge from the pile centre.
   footprint_fraction (the mixed-set rig's pile_footprint_fraction): the share of the
   particle volume inside the lifted cylinder's footprint (a standing pile ~1, a cone
   less); it tells a pile that keeps its faces from one that slumps where the bumpy
   silhouette of a standing face of 25 mm spheres reads anything from 60 to 90 deg.
7. A flank fit is flagged (`flank_flags`; the report and the side view mark it, the
   angle is kept) when it differs from the sector's whole silhouette (Theil-Sen slope
   through every slice, toe and apex included: robust to one stray point) by more than
   FLANK_MAX_DIFF_DEG, or by more than FLANK_MAX_DIFF_FEW_DEG when it rests on fewer than
   FLANK_MIN_POINTS slices (a line through 2 slices takes any angle). Measured on 420
   sectors of 114 local M2 / M3-dry piles: the median difference is 6 deg, 10 % exceed
   20 deg (e.g. a 90 deg fit through the foot of a 24 deg silhouette); 103 fits rest on
   2 slices; the rule flags 46 (11 %).

Why not the highest particle top in radial bins (the first version): with ~70 spheres
of 25 mm a bin often holds only a particle hidden under its neighbours or a stray one
on the table, the fit mixed the plateau with strays, and the angle fell when the
rolling resistance rose (M2, 3 seeds: 23.7 +- 11 deg at eta 0.35, 17.1 +- 4.9 at 0.71).
The silhouette on the same piles: 57.3 +- 7.2 and 66.6 +- 5.8, rising with eta.

Known limits: the centre is the mass centre, not the apex, so on an asymmetric pile
it moves towards the flatter side; a pile of ~4 layers of 25 mm spheres gives only
~4-6 silhouette points per sector: angles are noisy, repeat seeds.
"""
import math

import numpy as np

from ..files import write_csv

SECTORS = (("left", 180.0), ("right", 0.0), ("front", -90.0), ("back", 90.0))
FLANK_MIN_POINTS = 3            # method step 7: fewer slices, the tighter limit
FLANK_MAX_DIFF_DEG = 25.0       # fit against the whole silhouette's slope
FLANK_MAX_DIFF_FEW_DEG = 12.0   # the same for a fit through fewer than FLANK_MIN_POINTS slices


def as_array(positions):
    a = np.asarray(positions, dtype=float)
    if a.ndim != 2 or a.shape[1] != 4:
        raise ValueError("positions must be rows of (x, y, z, radius)")
    return a


def pile_centre(positions):
    """Mass centre (x, y) of the particles (weights r^3)."""
    a = as_array(positions)
    w = a[:, 3] ** 3
    return float(np.sum(a[:, 0] * w) / np.sum(w)), float(np.sum(a[:, 1] * w) / np.sum(w))


def _in_sector(phi_deg, axis_deg, half_width_deg):
    d = (phi_deg - axis_deg + 180.0) % 360.0 - 180.0
    return np.abs(d) <= half_width_deg + 1e-9


def sector_silhouette(positions, centre, axis_deg, half_width_deg, slice_height_m):
    """[(z_mid_m, r_edge_m)] of the non-empty height slices of one sector."""
    a = as_array(positions)
    dx, dy = a[:, 0] - centre[0], a[:, 1] - centre[1]
    sel = _in_sector(np.degrees(np.arctan2(dy, dx)), axis_deg, half_width_deg)
    if not np.any(sel):
        return []
    edge = (np.hypot(dx, dy) + a[:, 3])[sel]
    z = a[sel, 2]
    k = np.floor(z / slice_height_m).astype(int)
    return [((i + 0.5) * slice_height_m, float(edge[k == i].max())) for i in sorted(set(k.tolist()))]


def fit_silhouette(points, z_lo_m, z_hi_m):
    """Fit r_edge = a + b z through the points with z_lo_m <= z <= z_hi_m. Returns dict:
    angle_deg, n_used, points [(r, z, used)], line [(r0, z0), (r1, z1)] or None."""
    pts = [(r, z, z_lo_m <= z <= z_hi_m) for z, r in points]
    used = [(r, z) for r, z, u in pts if u]
    fit = {"angle_deg": math.nan, "n_used": len(used), "points": pts, "line": None}
    if len(used) < 2:
        return fit
    rs, zs = np.array([p[0] for p in used]), np.array([p[1] for p in used])
    b, a0 = np.polyfit(zs, rs, 1)
    fit["angle_deg"] = _angle_of_slope(b)
    z0, z1 = float(zs.min()), float(zs.max())
    fit["line"] = [(float(a0 + b * z0), z0), (float(a0 + b * z1), z1)]
    return fit


def _angle_of_slope(b):
    """Flank angle (deg) of r_edge = a + b z: atan(-1 / b), 90 for b >= 0."""
    return math.degrees(math.atan(-1.0 / b)) if b < 0 else 90.0


def silhouette_angle_deg(points):
    """Angle (deg) of a sector's whole silhouette: the Theil-Sen slope (median of the
    pairwise slopes dr/dz) through every slice point [(r, z, used)], toe and apex
    included; NaN with fewer than 2 points at different heights."""
    pts = [(r, z) for r, z, _ in points]
    slopes = [(r2 - r1) / (z2 - z1) for i, (r1, z1) in enumerate(pts) for r2, z2 in pts[i + 1:] if z2 != z1]
    return _angle_of_slope(float(np.median(slopes))) if slopes else math.nan


def flank_problem(fit):
    """Why a sector's flank fit is implausible (method step 7), or None (also for a
    sector without an angle: missing_angles reports those)."""
    if math.isnan(fit["angle_deg"]):
        return None
    whole = silhouette_angle_deg(fit["points"])
    if math.isnan(whole):
        return None
    few = fit["n_used"] < FLANK_MIN_POINTS
    if abs(fit["angle_deg"] - whole) <= (FLANK_MAX_DIFF_FEW_DEG if few else FLANK_MAX_DIFF_DEG):
        return None
    return (f"fit {fit['angle_deg']:.0f} deg through {fit['n_used']} slices, "
            f"whole silhouette {whole:.0f} deg")


def flank_flags(m):
    """{sector: reason} of the flagged flank fits of a measure_pile result."""
    out = {}
    for name, _ in SECTORS:
        why = flank_problem(m["fits"][name]) if name in m["fits"] else None
        if why:
            out[name] = why
    return out


def measure_pile(positions, slice_height_m, exclude_bottom_m, exclude_apex_m, half_width_deg,
                 table_z_m=0.0):
    """Angles of the four sectors and the pile size. Returns dict with
    'angles' {sector: deg, NaN = no angle}, 'mean_deg' (over the sectors with an angle,
    NaN if none), 'sectors_count' (sectors with an angle), 'fits' {sector:
    fit_silhouette dict}, 'centre', 'n_particles', 'pile_height_m', 'pile_radius_m'."""
    a = as_array(positions)
    if len(a) == 0:
        raise ValueError("no particles to measure")
    centre = pile_centre(a)
    top = float(np.max(a[:, 2] + a[:, 3]))
    fits = {}
    for name, axis in SECTORS:
        sil = sector_silhouette(a, centre, axis, half_width_deg, slice_height_m)
        fits[name] = fit_silhouette(sil, table_z_m + exclude_bottom_m, top - exclude_apex_m)
    angles = {k: f["angle_deg"] for k, f in fits.items()}
    measured = [v for v in angles.values() if not math.isnan(v)]
    rh = np.hypot(a[:, 0] - centre[0], a[:, 1] - centre[1]) + a[:, 3]
    return {
        "angles": angles,
        "mean_deg": float(sum(measured) / len(measured)) if measured else math.nan,
        "sectors_count": len(measured),
        "fits": fits,
        "centre": centre,
        "n_particles": int(len(a)),
        "pile_height_m": top - table_z_m,
        "pile_radius_m": float(np.max(rh)),
    }


def footprint_fraction(positions, footprint_radius_m, axis_xy=(0.0, 0.0)):
    """Share (0 - 1) of the pile's particle volume inside the vertical cylinder of radius
    footprint_radius_m (m) about axis_xy (m): what the pile keeps of the lifted cylinder's
    footprint. Each sphere counts with the part of its volume on the inner side of the
    cylinder's wall, the wall taken as a plane at the sphere's scale: with
    h = (footprint_radius_m - distance of its centre from the axis) / radius clipped to
    [-1, 1], the inner part is 1/2 + 3h/4 - h^3/4 of the sphere (a spherical cap). A pile
    that keeps the cylinder's shape reads ~1; a cone spread on the table less."""
    a = as_array(positions)
    if len(a) == 0:
        raise ValueError("no particles to measure")
    rho = np.hypot(a[:, 0] - axis_xy[0], a[:, 1] - axis_xy[1])
    h = np.clip((footprint_radius_m - rho) / a[:, 3], -1.0, 1.0)
    inside = 0.5 + 0.75 * h - 0.25 * h ** 3
    volume = a[:, 3] ** 3
    return float(np.sum(volume * inside) / np.sum(volume))


def measure_from_config(positions, measure_cfg, table_z_m=0.0):
    """measure_pile with the rig config's `measure:` section."""
    return measure_pile(positions, measure_cfg["silhouette_slice_height_m"], measure_cfg["exclude_bottom_m"],
                        measure_cfg["exclude_apex_m"], measure_cfg["sector_half_width_deg"], table_z_m)


def _json_angle(v):
    """An angle for result.json: None (null) where there is none (JSON has no NaN)."""
    return None if math.isnan(v) else float(v)


def result_keys(m, prefix="aor"):
    """{prefix_left_deg, ..., prefix_mean_deg, prefix_sectors_count, prefix_flank_flags}
    of a measure_pile result; a sector without an angle is None (null), and so is the
    mean if no sector has one; flank_flags: {sector: reason} of the implausible fits
    (kept in the mean: the flag is for the reader)."""
    out = {f"{prefix}_{k}_deg": _json_angle(v) for k, v in m["angles"].items()}
    out[f"{prefix}_mean_deg"] = _json_angle(m["mean_deg"])
    out[f"{prefix}_sectors_count"] = m["sectors_count"]
    out[f"{prefix}_flank_flags"] = flank_flags(m)
    return out


def missing_angles(m, prefix="aor"):
    """One warning line per sector without an angle (empty list if every sector has one)."""
    return [f"warning: {prefix} {k}: no angle ({m['fits'][k]['n_used']} silhouette slice(s) between the "
            f"first layer and the top, 2 needed): left out of {prefix}_mean_deg"
            for k, _ in SECTORS if math.isnan(m["angles"][k])]


def profile_rows(m):
    """Rows (sector, r_edge_m, z_m, used_in_fit) for pile_profile.csv."""
    rows = []
    for name, _ in SECTORS:
        for r, z, u in m["fits"][name]["points"]:
            rows.append((name, r, z, int(bool(u))))
    return rows


PROFILE_COLUMNS = ["sector", "r_edge_m", "z_m", "used_in_fit"]


def write_profile_csv(m, path):
    """pile_profile.csv: the silhouette points of every sector (atomic)."""
    return write_csv(path, PROFILE_COLUMNS, profile_rows(m))


def read_profile_fits(path):
    """pile_profile.csv -> {sector: fit_silhouette dict} refitted through the points the
    run used (the same fit: for runs whose result.json has no flank flags)."""
    import csv
    with open(path) as f:
        rows = list(csv.DictReader(f))
    fits = {}
    for name, _ in SECTORS:
        pts = [(float(r["z_m"]), float(r["r_edge_m"]), r["used_in_fit"] == "1") for r in rows if r["sector"] == name]
        used_z = [z for z, _, u in pts if u]
        lo, hi = (min(used_z), max(used_z)) if used_z else (math.inf, -math.inf)
        fits[name] = fit_silhouette([(z, r) for z, r, _ in pts], lo, hi)
    return fits


def read_positions_csv(path):
    """pile_particles.csv -> array of (x, y, z, r)."""
    import csv
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return np.array([[float(r["x_m"]), float(r["y_m"]), float(r["z_m"]), float(r["radius_m"])] for r in rows])


def pile_figure(positions, fits, title=None, centre=None):
    """Side view (x-z plane) of the particles as circles, with the fitted left and right
    lines (labelled '<side> <angle> deg') and the angles in the title. fits:
    measure_pile(...)['fits'] (or the whole measure_pile result). Returns the Figure."""
    from matplotlib.patches import Circle
    from ..plotting import new_figure

    if "fits" in fits:
        centre = centre or fits.get("centre")
        fits = fits["fits"]
    a = as_array(positions)
    if centre is None:
        centre = pile_centre(a)
    cx = centre[0]
    fig, ax = new_figure(figsize=(8, 4))
    for x, _, z, r in a:
        ax.add_patch(Circle((x, z), r, facecolor="0.75", edgecolor="0.3", lw=0.5))
    flags = flank_flags({"fits": fits})
    for name, sign, colour in (("left", -1.0, "tab:blue"), ("right", 1.0, "tab:red")):
        f = fits.get(name)
        if f and f.get("line"):
            (r0, z0), (r1, z1) = f["line"]
            flag = f" - doubtful: silhouette {silhouette_angle_deg(f['points']):.0f} deg" if name in flags else ""
            ax.plot([cx + sign * r0, cx + sign * r1], [z0, z1], color=colour, lw=2,
                    ls="--" if flag else "-", label=f"{name} {f['angle_deg']:.1f} deg{flag}")
            pts = [(rr, zz) for rr, zz, u in f["points"]]
            ax.plot([cx + sign * p[0] for p in pts], [p[1] for p in pts], "o", ms=3, color=colour, mfc="none")
    ang = ", ".join(f"{k} {fits[k]['angle_deg']:.1f}{'?' if k in flags else ''}" for k, _ in SECTORS if k in fits)
    ax.set_title((title + ": " if title else "") + f"angles (deg): {ang}", fontsize=9)
    xs = a[:, 0]
    ax.set_xlim(min(xs.min(), cx) - 0.03, max(xs.max(), cx) + 0.03)
    ax.set_ylim(-0.005, max((a[:, 2] + a[:, 3]).max(), 0.02) + 0.02)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    return fig


def plot_pile(positions, fits, path, title=None, centre=None):
    """pile_figure() written as a PNG (atomic). Returns path."""
    from ..plotting import save_png
    return save_png(pile_figure(positions, fits, title, centre), path)
