"""Building blocks shared by several rigs (runs inside YADE).

The phases (fill_cell, lift_cylinder, settle_pile, vibrate_table, cylinder_lift_pile) are
generators (demlib.phases): `yield from` them in a rig procedure, or drive() them in a
lone scene.
"""
from yade import O

from .jobio import write_csv
from .phases import steps_of


def table_half_width(geometry):
    """Half width (m) of the square table under the cell: table_radius_m, else the cell's
    inner diameter (the rig's box reaches that far from the axis)."""
    return geometry.get("table_radius_m", geometry["cell_inner_diameter_m"])


def fill_cell(scene):
    """Phase: table + PVC cylinder; pour, settle, strike level at the rim, settle again.
    Returns {'cylinder_ids', 'table_ids', 'settle_time_s', 'steps', 'timestep_s'}."""
    g, p = scene.rig["geometry"], scene.rig["procedure"]
    d, h = g["cell_inner_diameter_m"], g["cell_height_m"]
    table_half = table_half_width(g)
    table = scene.add_table(table_half, g["table_material"])
    column = p["pour_height_factor"] * h
    cyl = scene.add_cylinder(d, column + 2 * scene.radius, g["cell_facet_segments_count"], g["cell_material"])
    scene.set_domain((-table_half, -table_half, -0.05), (table_half, table_half, column + 0.1))
    scene.pour_cloud(d, 0.0, column, p["pour_porosity_ratio"])
    dt = yield scene.timestep()
    t1 = yield from scene.settle("pour")
    above = [b.id for b in scene.live_spheres() if b.state.pos[2] - scene.origin[2] > p["strike_level_height_m"]]
    scene.remove_spheres(above)
    t2 = yield from scene.settle("strike")
    return {"cylinder_ids": cyl, "table_ids": table, "settle_time_s": t1 + t2,
            "steps": O.iter, "timestep_s": dt}


def write_positions(scene, out_dir, name):
    rows = scene.particle_positions()
    return write_csv(out_dir, name, ["x_m", "y_m", "z_m", "radius_m"], rows)


# ---------- cylinder lift, pile measurement, table vibration (rigs aor, surcharge) ----------

def highest_top(scene):
    """Highest particle top z + r (m, world)."""
    return max(b.state.pos[2] + b.shape.radius for b in scene.live_spheres())


def set_velocity(ids, vel):
    """Kinematic motion: NewtonIntegrator moves a non-dynamic body by its state.vel."""
    from yade import Vector3
    v = Vector3(*vel)
    for i in ids:
        O.bodies[i].state.vel = v


def remove_fallen(scene, below_z):
    """Erase particles that left the table: centre below below_z (m), or beyond the
    table's edge (half width of rig geometry, table_half_width) by more than a radius.
    They are no longer part of the pile; one squeezed out of a loaded pile can leave
    the edge at several m/s and would reach the domain guard before it drops below
    below_z. Returns how many were removed."""
    edge = table_half_width(scene.rig["geometry"]) + scene.radius
    ox, oy = scene.origin[0], scene.origin[1]
    gone = [b.id for b in scene.live_spheres()
            if b.state.pos[2] < below_z
            or max(abs(b.state.pos[0] - ox), abs(b.state.pos[1] - oy)) > edge]
    if gone:
        scene.remove_spheres(gone)
    return len(gone)


def lift_cylinder(scene, cyl_ids, speed, clearance, bottom_z=0.0, table_z=0.0):
    """Phase: lift the cylinder facets at `speed` (m/s) in chunks of the rest-check interval
    (particles that fell off the table erased, then the guards checked, each chunk) until the cylinder's bottom edge is `clearance` (m)
    above the highest particle top; then stop the facets (velocity zeroed: kinematic
    bodies keep their velocity) and erase them. Returns {'lift_time_s', 'lift_height_m',
    'n_fallen'}."""
    if speed <= 0:
        from .jobio import RigFailure
        raise RigFailure(f"lift speed {speed} m/s must be > 0")
    ref = cyl_ids[0]
    z_ref0 = O.bodies[ref].state.pos[2]
    t0 = O.time
    limit = (highest_top(scene) + clearance - bottom_z) / speed * 1.5 + 1.0
    interval = scene.num["rest_check_interval_s"]
    fallen = 0
    set_velocity(cyl_ids, (0, 0, speed))
    steps = steps_of(interval, O.dt)
    while True:
        yield steps
        fallen += remove_fallen(scene, table_z - 2.0 * scene.radius)
        scene.check()
        if not scene.live_spheres():
            from .jobio import RigFailure
            raise RigFailure("lift: every particle fell off the table")
        lifted = O.bodies[ref].state.pos[2] - z_ref0
        if bottom_z + lifted >= highest_top(scene) + clearance:
            break
        if O.time - t0 > limit:
            from .jobio import RigFailure
            raise RigFailure(f"lift: cylinder not clear of the pile after {O.time - t0:.2f} s")
    set_velocity(cyl_ids, (0, 0, 0))
    for i in cyl_ids:
        O.bodies.erase(i)
    return {"lift_time_s": O.time - t0, "lift_height_m": lifted, "n_fallen": fallen}


def settle_pile(scene, what, table_z=0.0):
    """Phase: Scene.settle's loop (same rest criterion, guards and time limit), but particles
    that rolled off the table are erased at every check before the guards see them
    (a frictionless sphere slides for ever: Cundall damping does not act on a zero net
    force). Returns (settle time s, number erased)."""
    from .jobio import RigFailure
    t0 = O.time
    chunk = steps_of(scene.num["rest_check_interval_s"], O.dt)
    fallen = 0
    while True:
        yield chunk
        fallen += remove_fallen(scene, table_z - 2.0 * scene.radius)
        if not scene.live_spheres():
            raise RigFailure(f"{what}: every particle fell off the table")
        scene.check()
        if scene.is_at_rest():
            return O.time - t0, fallen
        if O.time - t0 > scene.num["max_settle_time_s"]:
            raise RigFailure(f"{what}: no rest after {scene.num['max_settle_time_s']} s of simulated time "
                             f"(kinetic energy ratio {scene.kinetic_energy_ratio():.3g}, "
                             f"unbalanced force ratio {scene.unbalanced_force_ratio():.3g})")


def vibrate_table(scene, table_ids, frequency, amp_x, amp_z, duration, updates_per_period=20):
    """Phase: kinematic elliptical vibration of the table facets (no dynamics of the table):
    displacement x = amp_x sin(w t), z = amp_z (1 - cos(w t)) (90 degree phase, starts
    at rest position), w = 2 pi frequency, for `duration` s. Velocity is set
    `updates_per_period` times per period so that each chunk ends exactly on the
    prescribed position (no drift); guards are checked every rest-check interval.
    The table is stopped and put back at its home position at the end.
    Returns {'vibration_time_s', 'n_fallen'}."""
    import math
    from yade import Vector3
    w = 2.0 * math.pi * frequency
    home = {i: Vector3(O.bodies[i].state.pos) for i in table_ids}
    n = steps_of(1.0 / (frequency * updates_per_period), O.dt)
    total = int(math.ceil(duration / O.dt))
    check = steps_of(scene.num["rest_check_interval_s"], O.dt)
    t0, done, next_check, fallen = O.time, 0, check, 0
    while done < total:
        k = min(n, total - done)
        t_end = (done + k) * O.dt
        off = Vector3(amp_x * math.sin(w * t_end), 0.0, amp_z * (1.0 - math.cos(w * t_end)))
        for i in table_ids:
            s = O.bodies[i].state
            s.vel = (home[i] + off - s.pos) / (k * O.dt)
        yield k
        done += k
        if done >= next_check:
            fallen += remove_fallen(scene, -2.0 * scene.radius)
            scene.check()
            next_check += check
    for i in table_ids:
        O.bodies[i].state.vel = Vector3(0, 0, 0)
        O.bodies[i].state.pos = home[i]
    return {"vibration_time_s": O.time - t0, "n_fallen": fallen}


def measure_pile(scene, out_dir, prefix="aor", files="pile", title=None):
    """Measure the pile (pycal.post.aor; the repo root is on PYTHONPATH),
    write <files>_particles.csv, <files>_profile.csv and <files>_side.png; print one
    warning line per sector without an angle (null in result.json, left out of the mean).
    Returns (result keys {prefix_left_deg, ...}, full measurement dict)."""
    import os
    from pycal.post import aor as aor_post
    positions = scene.particle_positions()
    write_csv(out_dir, f"{files}_particles.csv", ["x_m", "y_m", "z_m", "radius_m"], positions)
    m = aor_post.measure_from_config(positions, scene.rig["measure"])
    write_csv(out_dir, f"{files}_profile.csv", aor_post.PROFILE_COLUMNS, aor_post.profile_rows(m))
    aor_post.plot_pile(positions, m, os.path.join(out_dir, f"{files}_side.png"), title=title)
    for line in aor_post.missing_angles(m, prefix):
        print(line, flush=True)
    return aor_post.result_keys(m, prefix), m


def cylinder_lift_pile(scene, fill=fill_cell):
    """Phase: the cylinder-lift pile of the AoR rigs: fill(scene) (default fill_cell: pour,
    settle, strike), lift the cylinder at procedure.lift_speed_m_s until it is
    lift_clearance_m above the highest particle top, erase it, settle the pile.
    Returns (the timing and count entries of result.json, the fill's dict)."""
    p = scene.rig["procedure"]
    cell = yield from fill(scene)
    lift = yield from lift_cylinder(scene, cell["cylinder_ids"], p["lift_speed_m_s"], p["lift_clearance_m"],
                                    bottom_z=scene.origin[2], table_z=scene.origin[2])
    t_settle, n_fallen = yield from settle_pile(scene, "pile settle", table_z=scene.origin[2])
    return {
        "lift_time_s": lift["lift_time_s"],
        "lift_height_m": lift["lift_height_m"],
        "settle_time_s": t_settle,
        "fill_settle_time_s": cell["settle_time_s"],
        "n_fallen_off": lift["n_fallen"] + n_fallen,
        "steps": O.iter,
        "timestep_s": cell["timestep_s"],
    }, cell
