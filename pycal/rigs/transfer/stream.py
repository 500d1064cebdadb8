"""The falling stream of a belt transfer and where it meets an inclined plate (pure Python,
SI units): the geometry of the `transfer` rig (docs/rigs.md), computed from its job alone.

World frame of the rig: x horizontal in the belt's direction of travel, y across the
stream (the rig's periodic slice), z up. The stream leaves the belt horizontally at the
belt speed v0 (m/s) with the belt's bulk density rho0 (kg/m3) and mass flow Q (kg/s) and
falls freely (no air drag): after a fall h it moves at (v0, 0, -sqrt(2 g h)), and it keeps
its horizontal cross-section A = Q / (rho0 v0), so its bulk density is rho0 v0 / vz
(docs/lab-tests.md section 9). The stream is `stream_width_m` B wide across the belt (an
assumption: the case study gives no belt width); across a horizontal plane it is
Lf = A / B long in x. The rig simulates a slice of width W of it: mass flow Q W / B.

The plate is flat, inclined at alpha from the horizontal and descends along +x: top end T,
downhill unit vector t = (cos a, 0, -sin a), outward normal n = (sin a, 0, cos a); s = (p - T).t
is the distance along the plate from its top end, (p - T).n the height above it.

The design drop height H is the fall of the stream's centre line from the belt to its first
contact with the plate: the centre of a sphere of the contact radius R one radius above the
impact point (T + s_c t + R n). The stream is injected through a horizontal window
`injection_height_m` h_i above that point, with the velocity it has there,
(v0, 0, -sqrt(2 g (H - h_i))), and the density rho0 v0 / vz it has there.

Footprint: where the stream's outermost centre trajectories (the injection window's edges,
free flight) come within R of the plate, projected onto the plate ([s_a, s_b]).

Two reference stresses (neither depends on the DEM):
- design_impact_stress_pa: the method's formula, P = rho0 v0 vz (only the vertical velocity,
  the stream meeting a horizontal surface; pycal.impact_formula.impact_stress);
- momentum_flux_stress_pa: the stream's normal momentum flux over its footprint on this
  plate, rho_b u_n^2 with u_n = vz cos a - v0 sin a the velocity component normal to the plate
  (= the design value for a = 0), i.e. the design formula rho_b v^2 sin^2(theta) with the
  stream's full speed and its real angle theta to this plate.
"""
import math

from ...errors import ConfigError
from ...impact_formula import impact_stress, min_drop_height_m
from ...lump_geometry import bounding_radius, particle_radii, shape_members

RIG_FILE = "configs/rigs/transfer.yaml"
CELL_MARGIN_M = 3.0          # periodic cell size in x and z: the rig's extent plus this (no image ever meets)
PLATE_TOP_X_M = 1.0          # world position of the plate's top end: x = 1 m, z = 1 m + 2 L sin a (the plate's
PLATE_APEX_Z_M = 1.0         # facet reaches on to s = 2 L, beyond its lower end: every coordinate of the rig > 0)
PLATE_HALF_WIDTH_M = 10.0    # the plate's facet spans y = -10 ... 10 m at its top end (see yade_scripts/transfer.py)
MAX_INJECTION_SOLID_FRACTION = 0.45   # random sequential placement of the stream's layers stalls near 0.38 - 0.5
MAX_INCLINATION_DEG = 75.0


def _num(value):
    return "none" if value is None else f"{value:.3g}"


def _fail(key, reason):
    raise ConfigError(RIG_FILE, key, reason)


def design_case(job):
    """(H m, v0 m/s, Q kg/s, rho0 kg/m3, g m/s2) of a transfer job."""
    p = job["rig_config"]["procedure"]
    return (p["design_drop_height_m"], p["design_belt_speed_m_s"], p["design_mass_flow_kg_s"],
            p["design_belt_bulk_density_kg_m3"], job["rig_config"]["numerics"]["gravity_m_s2"])


def plate_frame(job):
    """(T = (x, z) of the plate's top end, t = (tx, tz), n = (nx, nz), alpha rad, length m)."""
    g = job["rig_config"]["geometry"]
    a = math.radians(g["plate_inclination_deg"])
    length = g["plate_length_m"]
    top = (PLATE_TOP_X_M, PLATE_APEX_Z_M + 2.0 * length * math.sin(a))
    return top, (math.cos(a), -math.sin(a)), (math.sin(a), math.cos(a)), a, length


def to_plate(top, t, n, x, z):
    """(s, height above the plate) of a world point (x, z) (m)."""
    dx, dz = x - top[0], z - top[1]
    return dx * t[0] + dz * t[1], dx * n[0] + dz * n[1]


def contact_radius_m(job):
    """R (m): the radius of the job's sphere materials (the smallest, if they differ); a job of
    lumps only: the smallest lump member (pycal.lump_geometry.particle_radii)."""
    spheres = [0.5 * m["particles"]["diameter_m"] for m in job["materials"].values()
               if m["particles"]["shape"] == "sphere"]
    return min(spheres) if spheres else min(particle_radii(job).values())


def largest_bounding_radius_m(job):
    """Radius (m) of the largest particle's bounding sphere: a sphere's radius, a lump's
    bounding sphere at its class's largest size (pycal/lump_geometry.py)."""
    comps = job.get("material_set", {}).get("components", {})
    out = 0.0
    for name, mat in job["materials"].items():
        p = mat["particles"]
        if p["shape"] == "sphere":
            out = max(out, 0.5 * p["diameter_m"])
            continue
        chosen = comps.get(name, {}).get("size_classes")
        for sc in p["size_classes"]:
            if chosen is not None and sc["name"] not in chosen:
                continue
            for shape, pct in sc["shape_percent"].items():
                if pct > 0:
                    out = max(out, bounding_radius(*shape_members(p["shapes"][shape], sc["max_size_m"])))
    return out


def lightest_particle_density(job):
    """The smallest particle density (kg/m3) of the job's materials."""
    return min(m["particles"]["density_kg_m3"] for m in job["materials"].values())


def _hit_time(x0, z0, vx, vz0, g, top, n, offset):
    """First time (s) > 0 at which the free-flight point from (x0, z0) with velocity (vx, -vz0)
    comes within `offset` of the plate's plane (height above it = offset); None if never."""
    # height(t) = (x0 + vx t - Tx) nx + (z0 - vz0 t - g t^2 / 2 - Tz) nz
    a = -0.5 * g * n[1]
    b = vx * n[0] - vz0 * n[1]
    c = (x0 - top[0]) * n[0] + (z0 - top[1]) * n[1] - offset
    if c <= 0:
        return 0.0
    disc = b * b - 4 * a * c
    if disc < 0:
        return None
    roots = [(-b - math.sqrt(disc)) / (2 * a), (-b + math.sqrt(disc)) / (2 * a)] if a != 0 else [-c / b]
    pos = [r for r in roots if r > 0]
    return min(pos) if pos else None


def geometry(job):
    """Everything the rig and its post-processing need about the stream and the plate, from
    the job (no YADE). Keys (SI units): see the module doc; coordinates are world (x, z)."""
    H, v0, Q, rho0, g = design_case(job)
    geo, proc = job["rig_config"]["geometry"], job["rig_config"]["procedure"]
    top, t, n, alpha, length = plate_frame(job)
    R = contact_radius_m(job)
    s_c, h_i = geo["impact_point_from_plate_top_m"], proc["injection_height_m"]
    W, B = geo["slice_width_m"], geo["stream_width_m"]
    vz = math.sqrt(2.0 * g * H)
    vz_i = math.sqrt(max(vz * vz - 2.0 * g * h_i, 0.0))
    # centre of the first contact at the impact point, and the stream's centre line above it
    cx = top[0] + s_c * t[0] + R * n[0]
    cz = top[1] + s_c * t[1] + R * n[1]
    flight = (vz - vz_i) / g
    area = Q / (rho0 * v0)                  # horizontal cross-section of the whole stream (m2)
    lf = area / B                           # its length in x (m)
    window_x = cx - v0 * flight             # centre of the injection window (m)
    window_z = cz + h_i
    ends = []
    for u in (-0.5 * lf, 0.5 * lf):
        tt = _hit_time(window_x + u, window_z, v0, vz_i, g, top, n, R)
        if tt is None:
            ends.append(None)
            continue
        x = window_x + u + v0 * tt
        z = window_z - vz_i * tt - 0.5 * g * tt * tt
        ends.append(to_plate(top, t, n, x - R * n[0], z - R * n[1])[0])
    u_n = vz * math.cos(alpha) - v0 * math.sin(alpha)
    rho_b = rho0 * v0 / vz
    flow = Q * W / B
    out = {
        "plate_top_m": top, "plate_tangent": t, "plate_normal": n, "plate_inclination_rad": alpha,
        "plate_length_m": length, "contact_radius_m": R,
        "impact_point_centre_m": (cx, cz),
        "vertical_speed_at_plate_m_s": vz, "speed_at_plate_m_s": math.hypot(v0, vz),
        "vertical_speed_at_injection_m_s": vz_i, "speed_at_injection_m_s": math.hypot(v0, vz_i),
        "belt_speed_m_s": v0, "gravity_m_s2": g, "drop_height_m": H,
        "stream_area_m2": area, "stream_length_m": lf,
        "stream_bulk_density_at_plate_kg_m3": rho_b,
        "stream_bulk_density_at_injection_kg_m3": rho0 * v0 / vz_i if vz_i > 0 else math.inf,
        "injection_window_centre_m": (window_x, window_z), "flight_time_s": flight,
        "slice_width_m": W, "slice_mass_flow_kg_s": flow,
        "footprint_start_m": min(e for e in ends if e is not None) if None not in ends else None,
        "footprint_end_m": max(e for e in ends if e is not None) if None not in ends else None,
        "normal_speed_at_plate_m_s": u_n,
        "design_impact_stress_pa": impact_stress(H, v0, Q, rho0, g)["impact_stress_pa"]
        if H >= min_drop_height_m(v0, g) else None,
        "momentum_flux_stress_pa": rho_b * u_n * u_n if u_n > 0 else 0.0,
    }
    if out["footprint_start_m"] is not None:
        out["footprint_length_m"] = out["footprint_end_m"] - out["footprint_start_m"]
        out["footprint_area_m2"] = out["footprint_length_m"] * W
    return out


def layer_times(job):
    """(number of injected layers N, layer interval s): the feed time split into N equal
    intervals, each layer at most procedure.injection_layer_thickness_m thick
    (thickness = vertical injection speed x interval)."""
    proc = job["rig_config"]["procedure"]
    vz_i = geometry(job)["vertical_speed_at_injection_m_s"]
    n = max(1, math.ceil(proc["feed_time_s"] * vz_i / proc["injection_layer_thickness_m"] - 1e-9))
    return n, proc["feed_time_s"] / n


def check_job(job):
    """Refuse a transfer job whose geometry cannot work (ConfigError naming the rig-config key:
    exit 2, nothing written). Checked: the design case is one the impact rule covers, the
    plate, the injection window above the plate, the stream meeting the plate within its
    length, the slice wider than two of the largest particles, placeable stream density, and
    the measurement window inside the feed. Each key's own type and range is checked before
    (pycal/rigs/fields.py, the rig's descriptor)."""
    H, v0, Q, rho0, g = design_case(job)
    geo, proc, meas = (job["rig_config"][k] for k in ("geometry", "procedure", "measure"))
    if H < min_drop_height_m(v0, g):
        _fail("procedure.design_drop_height_m", f"{H:g} is below v0^2 / (2 g) = {min_drop_height_m(v0, g):.3g} m: "
              "the stream would be denser than on the belt and the impact-stress rule does not apply")
    alpha = geo["plate_inclination_deg"]
    if not 0.0 <= alpha <= MAX_INCLINATION_DEG:
        _fail("geometry.plate_inclination_deg", f"{alpha} must be within 0 - {MAX_INCLINATION_DEG:g} deg "
              "(the plate descends along the belt's direction of travel)")
    if not 0.0 < geo["impact_point_from_plate_top_m"] < geo["plate_length_m"]:
        _fail("geometry.impact_point_from_plate_top_m", f"{geo['impact_point_from_plate_top_m']} must lie on the "
              f"plate (0 - {geo['plate_length_m']} m)")
    if proc["injection_height_m"] >= H:
        _fail("procedure.injection_height_m", f"{proc['injection_height_m']} must be below the drop height {H:g} m")
    if not 0.0 <= meas["steady_from_s"] < proc["feed_time_s"]:
        _fail("measure.steady_from_s", f"{meas['steady_from_s']} must be >= 0 and before the feed stops "
              f"({proc['feed_time_s']} s)")
    b = largest_bounding_radius_m(job)
    if geo["slice_width_m"] <= 2.0 * b:
        _fail("geometry.slice_width_m", f"{geo['slice_width_m']} must be wider than the largest particle "
              f"(bounding diameter {2 * b:.4g} m): it would overlap its own periodic image")
    geo_out = geometry(job)
    if geo_out["footprint_start_m"] is None or not (0.0 < geo_out["footprint_start_m"]
                                                    and geo_out["footprint_end_m"] < geo["plate_length_m"]):
        _fail("geometry.impact_point_from_plate_top_m", "the stream does not meet the plate within its length "
              f"(footprint {_num(geo_out['footprint_start_m'])} - {_num(geo_out['footprint_end_m'])} m from the top end, "
              f"plate {geo['plate_length_m']} m): move the impact point or lengthen the plate")
    top, t, n = geo_out["plate_top_m"], geo_out["plate_tangent"], geo_out["plate_normal"]
    wx, wz = geo_out["injection_window_centre_m"]
    lowest = min(to_plate(top, t, n, wx + u, wz)[1] for u in (-0.5 * geo_out["stream_length_m"],
                                                             0.5 * geo_out["stream_length_m"]))
    if lowest < 2.0 * b:
        _fail("procedure.injection_height_m", f"{proc['injection_height_m']} m puts the injection window "
              f"{lowest:.3g} m above the plate, less than one largest particle ({2 * b:.3g} m): inject higher")
    fraction = geo_out["stream_bulk_density_at_injection_kg_m3"] / lightest_particle_density(job)
    if fraction > MAX_INJECTION_SOLID_FRACTION:
        _fail("procedure.injection_height_m", f"the stream's solid fraction at the injection window would be "
              f"{fraction:.2f} (> {MAX_INJECTION_SOLID_FRACTION}): its particles cannot be placed at random; "
              "inject lower (the stream thins as it falls)")
    return geo_out
