"""Pile-angle post-processing (pycal/post/aor.py) on synthetic piles of known slope."""
import math

import numpy as np
import pytest

from pycal.post import aor

R = 0.0125
CFG = dict(slice_height_m=0.0125, exclude_bottom_m=0.025, exclude_apex_m=0.0125, half_width_deg=45)


def cone(angle_left, angle_right=None, height=0.1, spacing=0.004, layers=3):
    """Spheres of radius R whose tops lie on a cone (left half x<0 at angle_left,
    right half x>=0 at angle_right), plus lower spheres under the surface."""
    angle_right = angle_left if angle_right is None else angle_right
    pts = []
    extent = height / math.tan(math.radians(min(angle_left, angle_right)))
    xs = np.arange(-extent, extent + spacing, spacing)
    for x in xs:
        for y in xs:
            r = math.hypot(x, y)
            a = angle_left if x < 0 else angle_right
            top = height - r * math.tan(math.radians(a))
            if top < 2 * R:
                continue
            for k in range(layers):   # the highest is on the surface, the others below it
                pts.append((x, y, top - R - k * 0.3 * R, R))
    return np.array(pts)


@pytest.mark.parametrize("angle", [30.0, 40.0])
def test_symmetric_cone_gives_its_angle(angle):
    m = aor.measure_pile(cone(angle), **CFG)
    for side in ("left", "right", "front", "back"):
        assert m["angles"][side] == pytest.approx(angle, abs=1.0), side
    assert m["mean_deg"] == pytest.approx(angle, abs=1.0)
    assert m["pile_height_m"] == pytest.approx(0.1, abs=0.005)


def test_asymmetric_pile_left_and_right_differ():
    # the centre is the mass centre, not the apex: on an asymmetric pile it moves
    # towards the flatter side, which biases both angles by ~1 deg here (35/42) and by
    # 2-5 deg on a strongly asymmetric one (30/45 reads 28/40.5)
    m = aor.measure_pile(cone(35.0, 42.0), **CFG)
    assert m["angles"]["left"] == pytest.approx(35.0, abs=1.5)
    assert m["angles"]["right"] == pytest.approx(42.0, abs=1.5)
    assert m["angles"]["right"] - m["angles"]["left"] > 5.0
    m = aor.measure_pile(cone(45.0, 30.0), **CFG)
    assert m["angles"]["left"] - m["angles"]["right"] > 10.0


def test_flat_layer_has_no_angle():
    """A monolayer has no flank: no sector has an angle, and none is made up (NaN, null
    in result.json, one warning per sector), not 0 degrees."""
    xs = np.arange(-0.15, 0.15, 2 * R)
    pts = [(x, y, R, R) for x in xs for y in xs]
    m = aor.measure_pile(pts, **CFG)
    assert all(math.isnan(a) for a in m["angles"].values())
    assert math.isnan(m["mean_deg"]) and m["sectors_count"] == 0
    keys = aor.result_keys(m)
    assert keys["aor_mean_deg"] is None and keys["aor_left_deg"] is None and keys["aor_sectors_count"] == 0
    assert len(aor.missing_angles(m)) == 4


def test_a_sector_without_an_angle_is_left_out_of_the_mean():
    """A 35 degree ridge: the cone with its front and back flanks cut down to the first
    layer. Left and right read 35, front and back have no angle, and the mean is 35 (the
    old rule, 0 for a missing sector, read 17.5)."""
    pile = cone(35.0)
    ridge = pile[~((np.abs(pile[:, 1]) >= np.abs(pile[:, 0]) - 1e-9) & (pile[:, 2] > 2 * R))]
    m = aor.measure_pile(ridge, **CFG)
    assert math.isnan(m["angles"]["front"]) and math.isnan(m["angles"]["back"])
    assert m["sectors_count"] == 2
    assert m["mean_deg"] == pytest.approx(35.0, abs=1.0)
    assert m["mean_deg"] == pytest.approx((m["angles"]["left"] + m["angles"]["right"]) / 2)
    keys = aor.result_keys(m)
    assert keys["aor_front_deg"] is None and keys["aor_back_deg"] is None and keys["aor_sectors_count"] == 2
    assert keys["aor_mean_deg"] == pytest.approx(m["mean_deg"])
    lines = aor.missing_angles(m)
    assert len(lines) == 2 and lines[0].startswith("warning: aor front: no angle (0 silhouette slice(s)")
    assert "left out of aor_mean_deg" in lines[0]


def test_vertical_column_is_90_degrees_and_one_particle_has_no_angle():
    # a column of stacked rings (the wet pile that stands with vertical faces)
    pts = [(0.05 * math.cos(t), 0.05 * math.sin(t), R + k * 2 * R, R)
           for k in range(5) for t in np.linspace(0, 2 * math.pi, 24, endpoint=False)]
    m = aor.measure_pile(pts, **CFG)
    for side, a in m["angles"].items():
        assert a == pytest.approx(90.0, abs=0.5), side
    # one particle: no fit at all
    m = aor.measure_pile([(0.0, 0.0, R, R)], **CFG)
    assert math.isnan(m["mean_deg"]) and m["sectors_count"] == 0


def test_first_layer_and_apex_are_excluded():
    m = aor.measure_pile(cone(35.0), **CFG)
    used = [p for p in m["fits"]["left"]["points"] if p[2]]
    assert 0 < len(used) < len(m["fits"]["left"]["points"])
    rows = aor.profile_rows(m)
    assert {r[0] for r in rows} == {"left", "right", "front", "back"}


def test_result_keys():
    m = aor.measure_pile(cone(35.0), **CFG)
    keys = aor.result_keys(m, "surcharge")
    assert set(keys) == {"surcharge_left_deg", "surcharge_right_deg", "surcharge_front_deg",
                         "surcharge_back_deg", "surcharge_mean_deg", "surcharge_sectors_count",
                         "surcharge_flank_flags"}
    assert keys["surcharge_sectors_count"] == 4 and aor.missing_angles(m) == []


def test_side_view_draws_the_flanks_at_their_angles(tmp_path):
    """The left and right lines of the side view rise at the cone's 35 degrees (as drawn,
    in data coordinates), and the PNG is the stated 8 x 4 inch figure at 110 dpi."""
    pts = cone(35.0)
    m = aor.measure_pile(pts, **CFG)
    fig = aor.pile_figure(pts, m)
    lines = {l.get_label().split()[0]: l for l in fig.axes[0].lines if l.get_label().startswith(("left", "right"))}
    assert set(lines) == {"left", "right"}
    for side, line in lines.items():
        x, z = line.get_data()
        assert math.degrees(math.atan(abs((z[1] - z[0]) / (x[1] - x[0])))) == pytest.approx(35.0, abs=1.0), side
    path = aor.plot_pile(pts, m, tmp_path / "p.png")
    import matplotlib.image
    assert matplotlib.image.imread(path).shape[:2] == (440, 880)
    assert [p.name for p in tmp_path.iterdir()] == ["p.png"]       # no .part left


def test_particles_rolled_away_on_the_table_do_not_change_the_angle():
    pile = cone(38.0)
    strays = [(0.25, 0.01, R, R), (-0.22, 0.02, R, R), (0.03, 0.24, R, R), (0.0, -0.3, R, R)]
    a = aor.measure_pile(pile, **CFG)["angles"]
    b = aor.measure_pile(np.vstack([pile, strays]), **CFG)["angles"]
    for side in a:
        assert b[side] == pytest.approx(a[side], abs=1.0), side


def _fit(points, z_lo, z_hi):
    """fit_silhouette of [(z, r)] slice points with the slices z_lo..z_hi used."""
    return aor.fit_silhouette(points, z_lo, z_hi)


def test_a_regular_pile_has_no_doubtful_flank():
    m = aor.measure_pile(cone(35.0), **CFG)
    assert aor.flank_flags(m) == {}
    assert aor.result_keys(m)["aor_flank_flags"] == {}


def test_a_steep_fit_through_the_foot_of_a_shallow_silhouette_is_flagged():
    """The report's case: a 30 deg silhouette (r = 0.2 - z / tan 30) whose two used
    slices near the foot stand one above the other (a particle perched on the toe):
    the fit reads 90 deg, the silhouette 30 deg."""
    t = math.tan(math.radians(30.0))
    pts = [(z, 0.2 - z / t) for z in (0.00625, 0.01875, 0.03125, 0.04375, 0.05625, 0.06875)]
    pts[1] = (0.01875, 0.2 - 0.03125 / t)          # the 2nd slice's edge as far out as the 3rd's
    fit = _fit(pts, 0.015, 0.035)                   # only slices 2 and 3 used
    assert fit["n_used"] == 2 and fit["angle_deg"] == pytest.approx(90.0)
    assert aor.silhouette_angle_deg(fit["points"]) == pytest.approx(30.0, abs=3.0)
    why = aor.flank_problem(fit)
    assert why.startswith("fit 90 deg through 2 slices") and "whole silhouette 3" in why


def test_a_two_slice_fit_on_the_silhouette_is_not_flagged_and_a_far_one_with_more_is():
    t = math.tan(math.radians(40.0))
    line = [(z, 0.2 - z / t) for z in (0.00625, 0.01875, 0.03125, 0.04375, 0.05625)]
    assert aor.flank_problem(_fit(line, 0.015, 0.035)) is None            # 2 slices, on the line
    # 3 used slices 30 deg steeper than a 40 deg silhouette of 7 slices: flagged
    steep = math.tan(math.radians(75.0))
    pts = [(z, 0.2 - z / t) for z in (0.00625, 0.01875, 0.03125, 0.04375, 0.05625, 0.06875, 0.08125)]
    pts[2:5] = [(z, pts[2][1] - (z - pts[2][0]) / steep) for z, _ in pts[2:5]]
    fit = _fit(pts, 0.03, 0.06)
    assert fit["n_used"] == 3 and fit["angle_deg"] == pytest.approx(75.0, abs=0.5)
    assert "through 3 slices" in aor.flank_problem(fit)


def test_the_profile_refit_reads_the_run_s_angles_and_the_side_view_marks_a_doubtful_flank(tmp_path):
    pts = cone(35.0)
    m = aor.measure_pile(pts, **CFG)
    aor.write_profile_csv(m, tmp_path / "pile_profile.csv")
    fits = aor.read_profile_fits(tmp_path / "pile_profile.csv")
    for side in ("left", "right", "front", "back"):
        assert fits[side]["angle_deg"] == pytest.approx(m["angles"][side], abs=1e-9)
    # make the right flank doubtful: its fit vertical through two slices
    f = m["fits"]["right"]
    f["angle_deg"], f["n_used"] = 90.0, 2
    fig = aor.pile_figure(pts, m)
    styles = {l.get_label().split()[0]: l.get_linestyle() for l in fig.axes[0].lines
              if l.get_label().startswith(("left", "right"))}
    assert styles == {"left": "-", "right": "--"}
    assert "right 90.0?" in fig.axes[0].get_title()


# ---------- the share of the pile inside the lifted cylinder's footprint ----------

FOOT_R = 0.0725          # the cell's inner radius, m


def grid_body(inside, extent, height, spacing=0.003):
    """Spheres of radius spacing / 2 on a cubic grid, those whose centre satisfies
    inside(rho, z) (m): a solid body of known volume in small equal spheres."""
    r = spacing / 2.0
    xs = np.arange(-extent, extent + 1e-12, spacing)
    zs = np.arange(r, height, spacing)
    x, y, z = np.meshgrid(xs, xs, zs, indexing="ij")
    keep = inside(np.hypot(x, y), z)
    return np.column_stack([x[keep], y[keep], z[keep], np.full(int(keep.sum()), r)])


def test_one_sphere_counts_its_volume_on_the_inner_side_of_the_wall():
    r = 0.0125
    on_wall = [(FOOT_R, 0.0, r, r)]
    assert aor.footprint_fraction(on_wall, FOOT_R) == pytest.approx(0.5)
    # centre r/2 inside the wall: the outer cap has height r/2, volume pi (r/2)^2 (3r - r/2) / 3
    # = 5/32 of the sphere
    half_in = [(0.0, -(FOOT_R - r / 2), r, r)]
    assert aor.footprint_fraction(half_in, FOOT_R) == pytest.approx(1 - 5 / 32)
    assert aor.footprint_fraction([(0.0, 0.0, r, r)], FOOT_R) == 1.0
    assert aor.footprint_fraction([(0.2, 0.0, r, r)], FOOT_R) == 0.0
    # the axis is where the cylinder stood, not the origin
    assert aor.footprint_fraction([(1.0 + FOOT_R, 2.0, r, r)], FOOT_R, axis_xy=(1.0, 2.0)) == pytest.approx(0.5)


def test_a_pile_that_keeps_the_cylinder_s_shape_reads_one():
    body = grid_body(lambda rho, z: rho <= FOOT_R - 0.0015, FOOT_R, 0.095)
    assert aor.footprint_fraction(body, FOOT_R) == pytest.approx(1.0)


@pytest.mark.parametrize("base_radius_m", [0.1, 0.15])
def test_a_cone_reads_the_share_of_its_volume_inside_the_footprint(base_radius_m):
    height = 0.1
    body = grid_body(lambda rho, z: z <= height * (1 - rho / base_radius_m), base_radius_m, height)
    # volume within radius R of a cone (base Rb, height H): 2 pi H (R^2 / 2 - R^3 / (3 Rb)); whole: pi Rb^2 H / 3
    inside = 2 * math.pi * height * (FOOT_R ** 2 / 2 - FOOT_R ** 3 / (3 * base_radius_m))
    whole = math.pi * base_radius_m ** 2 * height / 3
    assert aor.footprint_fraction(body, FOOT_R) == pytest.approx(inside / whole, abs=0.01)


def test_faces_leaning_two_degrees_out_keep_about_95_percent():
    height, lean = 0.1, math.radians(2.0)
    base = FOOT_R + height * math.tan(lean)
    body = grid_body(lambda rho, z: rho <= base - z * math.tan(lean), base, height, spacing=0.002)
    # a frustum with the cylinder's radius on top: pi R^2 H of pi H (R^2 + R Rb + Rb^2) / 3 lies inside
    expected = 3 * FOOT_R ** 2 / (FOOT_R ** 2 + FOOT_R * base + base ** 2)
    assert expected == pytest.approx(0.953, abs=0.001)
    assert aor.footprint_fraction(body, FOOT_R) == pytest.approx(expected, abs=0.005)


def test_the_lab_wet_pile_with_its_front_slumped_to_32_degrees_keeps_89_percent():
    """The cross_binding stage's target (configs/calibrations/zinc_ore.yaml): three quarters of
    the cylinder standing (0.095 m high), the front quarter slumped to a cone at 32 deg about the
    axis that keeps its quarter's volume."""
    height, slope = 0.095, math.tan(math.radians(32.0))
    # per radian of azimuth: the cylinder holds H R^2 / 2, a cone of base b holds slope b^3 / 6
    base = (3 * height * FOOT_R ** 2 / slope) ** (1 / 3)
    front_inside = slope * (base * FOOT_R ** 2 / 2 - FOOT_R ** 3 / 3) / (height * FOOT_R ** 2 / 2)
    expected = 0.75 + 0.25 * front_inside
    assert expected == pytest.approx(0.89, abs=0.002)
    r = 0.0015
    xs = np.arange(-base, base + 1e-12, 2 * r)
    x, y, z = np.meshgrid(xs, xs, np.arange(r, height, 2 * r), indexing="ij")
    rho, front = np.hypot(x, y), (y < -np.abs(x))            # the front quarter: azimuth -135 .. -45 deg
    keep = np.where(front, z <= slope * (base - rho), (rho <= FOOT_R) & (z <= height))
    body = np.column_stack([x[keep], y[keep], z[keep], np.full(int(keep.sum()), r)])
    assert aor.footprint_fraction(body, FOOT_R) == pytest.approx(expected, abs=0.01)
