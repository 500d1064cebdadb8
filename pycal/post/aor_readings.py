"""Candidate readings of a pile's angle, to choose the one that measures the pile rather
than the sector grid (pure Python; bench/aor_reading.py compares them on many seeds).

All take the pile's particles [(x, y, z, r)] (m) and the rig's `measure:` settings, and
keep the flank-slope meaning of the lab's gauge (the angle of the flank from the
horizontal, between the first layer and the rounded top):

- sector_mean: the rig's reading (pycal.post.aor.measure_pile): four 90-degree sectors
  about the x and y axes, the mean of their silhouette fits;
- rotated_sector_mean: the same fit averaged over `frames` orientations of the sector
  frame (0, 90 / frames, ... deg): the pile, not where the frame happens to cut it;
- sector_median: `sectors` narrower sectors (half width 180 / sectors deg), the median of
  their silhouette fits (a sector without a fit is left out);
- cone: the exposed particles (no other particle above a particle's top within a
  particle diameter horizontally) between the first layer and the rounded top, their
  tops fitted as z = h - tan(angle) x r (r: horizontal distance from the pile centre).
Each returns the angle in degrees (NaN when the pile gives none).
"""
import math

import numpy as np

from .aor import as_array, fit_silhouette, measure_pile, pile_centre, sector_silhouette


def sector_mean(positions, m):
    return measure_pile(positions, m["silhouette_slice_height_m"], m["exclude_bottom_m"], m["exclude_apex_m"],
                        m["sector_half_width_deg"])["mean_deg"]


def _sector_angles(a, centre, axes_deg, half_width_deg, m):
    top = float(np.max(a[:, 2] + a[:, 3]))
    out = []
    for axis in axes_deg:
        sil = sector_silhouette(a, centre, axis, half_width_deg, m["silhouette_slice_height_m"])
        out.append(fit_silhouette(sil, m["exclude_bottom_m"], top - m["exclude_apex_m"])["angle_deg"])
    return out


def rotated_sector_mean(positions, m, frames=8):
    a = as_array(positions)
    centre = pile_centre(a)
    means = []
    for k in range(frames):
        off = k * 90.0 / frames
        angles = [v for v in _sector_angles(a, centre, [off + 90.0 * j for j in range(4)],
                                            m["sector_half_width_deg"], m) if not math.isnan(v)]
        if angles:
            means.append(sum(angles) / len(angles))
    return float(np.mean(means)) if means else math.nan


def sector_median(positions, m, sectors=12):
    a = as_array(positions)
    centre = pile_centre(a)
    angles = [v for v in _sector_angles(a, centre, [360.0 * j / sectors for j in range(sectors)],
                                        180.0 / sectors, m) if not math.isnan(v)]
    return float(np.median(angles)) if angles else math.nan


def exposed(a):
    """Mask of the particles with no other particle's centre higher within a particle
    diameter horizontally (the pile's surface seen from above)."""
    d = 2.0 * float(np.max(a[:, 3]))
    dx = a[:, 0][:, None] - a[:, 0][None, :]
    dy = a[:, 1][:, None] - a[:, 1][None, :]
    near = np.hypot(dx, dy) < d
    higher = a[:, 2][None, :] > a[:, 2][:, None]
    return ~np.any(near & higher, axis=1)


def cone(positions, m):
    a = as_array(positions)
    centre = pile_centre(a)
    tops = a[:, 2] + a[:, 3]
    h = float(np.max(tops))
    sel = exposed(a) & (a[:, 2] >= m["exclude_bottom_m"]) & (tops <= h - m["exclude_apex_m"])
    if np.count_nonzero(sel) < 3:
        return math.nan
    r = np.hypot(a[sel, 0] - centre[0], a[sel, 1] - centre[1])
    slope, _ = np.polyfit(r, tops[sel], 1)
    return math.degrees(math.atan(-slope)) if slope < 0 else 90.0


READINGS = {"sector_mean": sector_mean, "rotated_sector_mean": rotated_sector_mean,
            "sector_median": sector_median, "cone": cone}
