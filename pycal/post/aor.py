"""Pile angles of the cylinder-lift angle of repose and surcharge rigs (pure Python).

Imported by the rig scripts inside YADE and by the tests: numpy, matplotlib (only in
plot_pile, Agg backend) and the standard library only, never yade.

Input: particle positions [(x, y, z, r), ...] in m, the table top at z = table_z_m (0).

Method (configs/rigs/aor.yaml `measure:`):
1. Pile centre = mass centre of the particles in x, y (weights r^3: equal density).
2. Four sectors around the centre, each +- sector_half_width_deg about an axis:
   right = +x, back = +y, left = -x, front = -y (azimuth of the particle centre). With
   45 degrees a particle exactly on a diagonal belongs to both neighbouring sectors.
3. In each sector: horizontal distance r of each particle centre from the pile centre;
   R = the farthest r in that sector; profile_bins_count equal bins over [0, R]
   (a particle at r = R goes into the last bin). Per non-empty bin the profile point
   is the highest particle top z + radius, at that particle's own r.
4. A bin is used in the fit when its centre (i + 0.5) / N lies within
   [fit_exclude_apex_fraction, 1 - fit_exclude_toe_fraction]; apex and toe bins are
   dropped (the rounded top and the rolled-out toe are not part of the slope).
5. Least-squares straight line z_top = a + b r through the used points;
   angle = atan(-b) in degrees when b < 0. Rule: the angle is 0 when fewer than 2
   bins are used or the slope is >= 0 (a flat or inverted profile has no repose angle).
6. pile_height_m = highest particle top - table_z_m; pile_radius_m = largest
   horizontal distance of a particle centre from the pile centre plus its radius.

Known limits: the centre is the mass centre, not the apex, so on an asymmetric pile
it moves towards the flatter side and biases the angles (synthetic 35/42 deg cone
reads ~34/41.5, a 30/45 deg one ~28/40.5: the near-centre bins of the steep side then
see the other side's crest). One particle that rolled far away stretches its sector's bins (R is the
farthest particle), so few bins then cover the real slope; with 25 mm spheres and a
~70-particle pile each bin holds only a few particles: angles are noisy, repeat seeds.
"""
import csv
import math

import numpy as np

SECTORS = (("left", 180.0), ("right", 0.0), ("front", -90.0), ("back", 90.0))


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


def sector_profile(positions, centre, axis_deg, bins_count, half_width_deg):
    """[(bin index, r_m, z_top_m)] of the non-empty bins of one sector (see module doc)."""
    a = as_array(positions)
    dx, dy = a[:, 0] - centre[0], a[:, 1] - centre[1]
    phi = np.degrees(np.arctan2(dy, dx))
    sel = _in_sector(phi, axis_deg, half_width_deg)
    if not np.any(sel):
        return []
    r = np.hypot(dx, dy)[sel]
    top = (a[:, 2] + a[:, 3])[sel]
    r_max = float(np.max(r))
    if r_max <= 0.0:
        return [(0, 0.0, float(np.max(top)))]
    idx = np.minimum((r / r_max * bins_count).astype(int), bins_count - 1)
    out = []
    for i in range(bins_count):
        m = idx == i
        if np.any(m):
            k = int(np.argmax(np.where(m, top, -np.inf)))
            out.append((i, float(r[k]), float(top[k])))
    return out


def fit_profile(profile, bins_count, apex_fraction, toe_fraction):
    """Straight-line fit of a sector profile. Returns dict: angle_deg, slope, intercept_m,
    r_min_m, r_max_m (range of the used points), n_used, points [(r, z_top, used)]."""
    points, used = [], []
    for i, r, z in profile:
        c = (i + 0.5) / bins_count
        u = apex_fraction - 1e-12 <= c <= 1.0 - toe_fraction + 1e-12
        points.append((r, z, u))
        if u:
            used.append((r, z))
    fit = {"angle_deg": 0.0, "slope": None, "intercept_m": None, "r_min_m": None, "r_max_m": None,
           "n_used": len(used), "points": points}
    rs = np.array([p[0] for p in used])
    if len(used) < 2 or np.ptp(rs) <= 0.0:
        return fit
    zs = np.array([p[1] for p in used])
    slope, intercept = np.polyfit(rs, zs, 1)
    fit.update(slope=float(slope), intercept_m=float(intercept), r_min_m=float(rs.min()), r_max_m=float(rs.max()))
    if slope < 0:
        fit["angle_deg"] = math.degrees(math.atan(-slope))
    return fit


def measure_pile(positions, bins_count, apex_fraction, toe_fraction, half_width_deg, table_z_m=0.0):
    """Angles of the four sectors and the pile size. Returns dict with
    'angles' {sector: deg}, 'mean_deg', 'fits' {sector: fit_profile dict}, 'centre',
    'n_particles', 'pile_height_m', 'pile_radius_m'."""
    a = as_array(positions)
    if len(a) == 0:
        raise ValueError("no particles to measure")
    centre = pile_centre(a)
    fits = {}
    for name, axis in SECTORS:
        prof = sector_profile(a, centre, axis, bins_count, half_width_deg)
        fits[name] = fit_profile(prof, bins_count, apex_fraction, toe_fraction)
    angles = {k: f["angle_deg"] for k, f in fits.items()}
    rh = np.hypot(a[:, 0] - centre[0], a[:, 1] - centre[1]) + a[:, 3]
    return {
        "angles": angles,
        "mean_deg": float(sum(angles.values()) / len(angles)),
        "fits": fits,
        "centre": centre,
        "n_particles": int(len(a)),
        "pile_height_m": float(np.max(a[:, 2] + a[:, 3]) - table_z_m),
        "pile_radius_m": float(np.max(rh)),
    }


def measure_from_config(positions, measure_cfg, table_z_m=0.0):
    """measure_pile with the rig config's `measure:` section."""
    return measure_pile(positions, measure_cfg["profile_bins_count"], measure_cfg["fit_exclude_apex_fraction"],
                        measure_cfg["fit_exclude_toe_fraction"], measure_cfg["sector_half_width_deg"], table_z_m)


def result_keys(m, prefix="aor"):
    """{prefix_left_deg, ..., prefix_mean_deg} of a measure_pile result."""
    out = {f"{prefix}_{k}_deg": float(v) for k, v in m["angles"].items()}
    out[f"{prefix}_mean_deg"] = m["mean_deg"]
    return out


def profile_rows(m):
    """Rows (sector, r_m, z_top_m, used_in_fit) for pile_profile.csv."""
    rows = []
    for name, _ in SECTORS:
        for r, z, u in m["fits"][name]["points"]:
            rows.append((name, r, z, int(bool(u))))
    return rows


def write_profile_csv(m, path):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["sector", "r_m", "z_top_m", "used_in_fit"])
        w.writerows(profile_rows(m))


def read_positions_csv(path):
    """pile_particles.csv -> array of (x, y, z, r)."""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return np.array([[float(r["x_m"]), float(r["y_m"]), float(r["z_m"]), float(r["radius_m"])] for r in rows])


def plot_pile(positions, fits, path, title=None, centre=None):
    """Side view (x-z plane) of the particles as circles, with the fitted left and right
    lines and the angles in the title. fits: measure_pile(...)['fits'] (or the whole
    measure_pile result)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle

    if "fits" in fits:
        centre = centre or fits.get("centre")
        fits = fits["fits"]
    a = as_array(positions)
    if centre is None:
        centre = pile_centre(a)
    cx = centre[0]
    fig, ax = plt.subplots(figsize=(8, 4))
    for x, _, z, r in a:
        ax.add_patch(Circle((x, z), r, facecolor="0.75", edgecolor="0.3", lw=0.5))
    for name, sign, colour in (("left", -1.0, "tab:blue"), ("right", 1.0, "tab:red")):
        f = fits.get(name)
        if f and f["slope"] is not None:
            r = np.array([f["r_min_m"], f["r_max_m"]])
            ax.plot(cx + sign * r, f["intercept_m"] + f["slope"] * r, color=colour, lw=2,
                    label=f"{name} {f['angle_deg']:.1f} deg")
            pts = [(rr, zz) for rr, zz, u in f["points"]]
            ax.plot([cx + sign * p[0] for p in pts], [p[1] for p in pts], "o", ms=3, color=colour, mfc="none")
    ang = ", ".join(f"{k} {fits[k]['angle_deg']:.1f}" for k, _ in SECTORS if k in fits)
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
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
