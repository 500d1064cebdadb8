"""Pile angles of the mixed-set AoR rig (pure Python, no YADE): pycal.post.aor's
silhouette method on every particle sphere (the member spheres of the M1 clumps count
as particles), plus the angle of the upper part of the pile (the lab's dihedral top,
57 / 45 degrees dry).

Upper-part angle: the same per-sector silhouette fit (pycal/post/aor.py) on slices of
upper_silhouette_slice_height_m between upper_fit_from_height_fraction x pile height
and upper_exclude_apex_m below the highest particle top. A dihedral pile (steep top,
shallow flanks) reads a larger upper angle than whole-slope angle; a straight cone
about the same. The upper half of a ~9 cm pile of 25 mm spheres holds 1 - 2 spheres
per sector, so the upper angle is much noisier than the whole-slope one. The rule of
pycal.post.aor holds for both: a sector with fewer than 2 slices has no angle (null in
its key, left out of the mean; aor_sectors_count and aor_upper_sectors_count say how
many sectors have one).

Input rows: (x, y, z, radius, material, clump id or -1), m.
"""
import numpy as np

from . import aor

MATERIAL_COLOURS = {"M1": "0.25", "M2": "tab:blue", "M3-dry": "tab:orange", "M3-wet": "tab:brown"}


def positions(rows):
    """(x, y, z, r) array of the rows."""
    return np.array([[float(r[0]), float(r[1]), float(r[2]), float(r[3])] for r in rows])


def measure(rows, measure_cfg, table_z_m=0.0):
    """(whole-slope measure_pile result, upper-part measure_pile result)."""
    pos = positions(rows)
    whole = aor.measure_from_config(pos, measure_cfg, table_z_m)
    height = float(np.max(pos[:, 2] + pos[:, 3])) - table_z_m
    upper = aor.measure_pile(pos, measure_cfg["upper_silhouette_slice_height_m"],
                             measure_cfg["upper_fit_from_height_fraction"] * height,
                             measure_cfg["upper_exclude_apex_m"], measure_cfg["sector_half_width_deg"], table_z_m)
    return whole, upper


def result_keys(whole, upper, prefix="aor"):
    """{aor_left_deg, ..., aor_mean_deg, aor_sectors_count, aor_upper_left_deg, ...,
    aor_upper_mean_deg, aor_upper_sectors_count, the flank flags of both}: pycal.post.aor.result_keys
    of both."""
    return {**aor.result_keys(whole, prefix), **aor.result_keys(upper, f"{prefix}_upper")}


def missing_angles(whole, upper, prefix="aor"):
    """Warning lines of the sectors without an angle, whole slope and upper part."""
    return aor.missing_angles(whole, prefix) + aor.missing_angles(upper, f"{prefix}_upper")


def plot(rows, whole, upper, path, title=None):
    """Side view (x-z) of every particle sphere coloured by material (M1 clump members
    dark grey), the whole-slope fits (solid) and the upper-part fits (dashed) of the
    left and right sectors."""
    from matplotlib.patches import Circle
    from ..plotting import new_figure, save_png

    cx = whole["centre"][0]
    fig, ax = new_figure(figsize=(8, 4.2))
    # seen from the front (-y): the back (large y) is drawn first, the front on top
    for x, _, z, r, mat, cid in sorted(rows, key=lambda q: -float(q[1])):
        lump = int(cid) >= 0
        ax.add_patch(Circle((float(x), float(z)), float(r), facecolor=MATERIAL_COLOURS.get(mat, "0.7"),
                            edgecolor="w" if lump else "k", lw=0.8 if lump else 0.3, alpha=0.9))
    for res, style, tag in ((whole, "-", ""), (upper, "--", "upper ")):
        for name, sign, colour in (("left", -1.0, "tab:green"), ("right", 1.0, "tab:red")):
            f = res["fits"][name]
            if f.get("line"):
                (r0, z0), (r1, z1) = f["line"]
                ax.plot([cx + sign * r0, cx + sign * r1], [z0, z1], style, color=colour, lw=2,
                        label=f"{tag}{name} {f['angle_deg']:.1f} deg")
            if not tag:
                pts = [(rr, zz) for rr, zz, u in f["points"]]
                ax.plot([cx + sign * q[0] for q in pts], [q[1] for q in pts], "o", ms=3, color=colour, mfc="none")
    for mat, col in MATERIAL_COLOURS.items():
        if any(row[4] == mat for row in rows):
            ax.plot([], [], "o", color=col, label=mat)
    a = positions(rows)
    ang = ", ".join(f"{k} {whole['angles'][k]:.1f}" for k, _ in aor.SECTORS)
    up = ", ".join(f"{k} {upper['angles'][k]:.1f}" for k, _ in aor.SECTORS)
    ax.set_title((title + "\n" if title else "") + f"angles (deg): {ang}\nupper half: {up}", fontsize=8)
    ax.set_xlim(min(a[:, 0].min(), cx) - 0.03, max(a[:, 0].max(), cx) + 0.03)
    ax.set_ylim(-0.005, max((a[:, 2] + a[:, 3]).max(), 0.02) + 0.02)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.legend(loc="upper right", fontsize=7, ncol=2)
    fig.tight_layout()
    return save_png(fig, path)
