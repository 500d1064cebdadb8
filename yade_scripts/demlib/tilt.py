"""Tilt-table building blocks of the friction rigs (runs inside YADE).

The table is tilted by rotating the gravity vector about the scene's y axis: the
bearing plate stays in the plane z = 0 and "down the slope" is +x, so the sliding
displacement is simply the x displacement of the rigid cell.

Pieces:
- add_bearing_plate: a long steel plate (two facets) for the cell to slide on;
- add_rigid_cell: PVC facets clumped into one rigid body with the configured mass and
  thin-walled-tube inertia;
- Lid: the steel lid (loading.add_plate facets): servo plate while loading, free dead
  weight once unloaded; join()/split() make cell + lid one rigid body for the tilt and
  separate them again for the next load;
- pour_and_strike: loose pour through the cell(s) and a temporary funnel, strike level;
- consolidate: load the lid to a stress, record the spring curve, unload to dead weight;
- tilt_test: tilt at a constant rate until the cell has slid the onset distance (static
  friction), hold that angle and time the travel (dynamic friction), stop, tilt back.

Every number comes from the job (rig_config.geometry / procedure / numerics).
"""
import math
import os

from yade import O, utils, geom
from yade import Vector3

from .jobio import RigFailure


DAMPING_MODES = ("damped", "undamped", "undamped_when_sliding")
from pycal.post.friction import DYNAMIC_MAX_ANGLE_DEG  # pure Python: one rule for rig and post


# ------------------------------------------------------------------ geometry
def add_bearing_plate(scene, x_min, x_max, half_width, material, z=0.0):
    """Rectangular plate [x_min, x_max] x [-half_width, half_width] in the plane z (two
    facets, fixed). Returns the facet ids."""
    mat = scene.contact.mat_id[material]
    a, b = Vector3(x_min, -half_width, z), Vector3(x_max, -half_width, z)
    c, d = Vector3(x_max, half_width, z), Vector3(x_min, half_width, z)
    facets = [utils.facet((a, b, c), material=mat, fixed=True),
              utils.facet((a, c, d), material=mat, fixed=True)]
    return O.bodies.append(facets)


class RigidBody:
    """A clump of facets moving as one body, with its configured mass and
    inertia. Positions are read from a reference member (clump centres move
    when members join or leave)."""

    def __init__(self, clump_id, member_ids, mass, inertia, bottom_z):
        self.id = clump_id
        self.members = list(member_ids)
        self.mass = mass
        self.inertia = inertia
        self.ref = self.members[0]
        self.ref_to_bottom = bottom_z - O.bodies[self.ref].state.pos[2]

    @property
    def body(self):
        return O.bodies[self.id]

    @property
    def pos(self):
        """Position of the reference member (moves with the body)."""
        return O.bodies[self.ref].state.pos

    def bottom_z(self):
        return O.bodies[self.ref].state.pos[2] + self.ref_to_bottom

    def hold(self, hold=True):
        """Fix it in place (all six DOFs) or release its translations (rotations stay
        blocked: the cell and lid are guided, they do not tip)."""
        st = O.bodies[self.id].state
        st.vel = Vector3(0, 0, 0)
        st.angVel = Vector3(0, 0, 0)
        st.blockedDOFs = "xyzXYZ" if hold else "XYZ"

    def lift_bottom_to(self, z):
        """Move the (held) body vertically so that its lowest edge is at z."""
        st = O.bodies[self.id].state
        st.pos = st.pos + Vector3(0, 0, z - self.bottom_z())

    def set_mass(self, mass, inertia):
        st = O.bodies[self.id].state
        st.mass = mass
        st.inertia = Vector3(*inertia)


def _clump(ids, mass, inertia):
    """Clump bodies `ids` (their own masses are placeholders) and give the clump the
    configured mass and inertia (kg, kg m2)."""
    for i in ids:
        st = O.bodies[i].state
        st.mass = mass / len(ids)
        st.inertia = Vector3(1e-6, 1e-6, 1e-6)
    cid = O.bodies.clump(ids)
    c = O.bodies[cid]
    c.state.mass = mass
    c.state.inertia = Vector3(*inertia)
    return cid


def join(cell, lid):
    """Make lid and cell one rigid body (the cell then hangs on the lid, which rests on
    the contents: with no vertical support from outside, all of cell + lid + contents
    weighs on the plate). The cell's clump id is kept; its mass becomes cell + lid."""
    lid.make_rigid()
    # YADE 2023.02a: addToClump of a clump (or of a member of another clump) trips an
    # assertion in Clump::addForceTorqueFromMembers; erasing the lid clump body (members
    # kept) first and adding its free members works
    O.bodies.erase(lid.id)
    O.bodies.addToClump(list(lid.members), cell.id)
    cell.set_mass(cell.mass + lid.mass, tuple(a + b for a, b in zip(cell.inertia, lid.inertia)))
    lid.id = None


def split(cell, lid):
    """Undo join(): the lid members leave the cell clump and become kinematic facets
    at rest (ready for the servo of the next load)."""
    for m in lid.members:
        O.bodies.releaseFromClump(m, cell.id)
    cell.set_mass(cell.mass, cell.inertia)
    lid.id = None
    lid.make_kinematic()


def add_rigid_cell(scene, diameter, height, segments, material, z0, mass):
    """PVC tube wall (no bottom) from z0 to z0 + height as one rigid clump of the given
    mass. Returns a RigidBody."""
    r = diameter / 2.0
    facets = geom.facetCylinder((0, 0, z0 + height / 2.0), r, height, segmentsNumber=segments,
                                wallMask=4, material=scene.contact.mat_id[material])
    ids = O.bodies.append(facets)
    inertia = (mass * (r * r / 2.0 + height * height / 12.0),) * 2 + (mass * r * r,)
    cid = _clump(ids, mass, inertia)
    return RigidBody(cid, ids, mass, inertia, z0)


class Lid:
    """The steel lid: a square plate of facets (demlib.loading.add_plate, circumscribing
    the cell: its corners stick out through the wall, harmless as facets never touch
    facets). Kinematic under the servo while a load is applied (loading.ServoPlate),
    a rigid clump of lid_mass_kg (a free dead weight) once unloaded, and joined to the
    cell for the tilt (join/split)."""

    def __init__(self, scene, cell_diameter, material, z, mass):
        from .loading import add_plate
        self.scene = scene
        self.members = add_plate(scene, z, cell_diameter, material)
        self.mass = mass
        xs = [O.bodies[i].state.pos[0] + v[0] for i in self.members for v in O.bodies[i].shape.vertices]
        half = 0.5 * (max(xs) - min(xs))
        self.inertia = (mass * half * half / 3.0,) * 2 + (2.0 * mass * half * half / 3.0,)
        self.id = None          # clump id while rigid
        self.ref = self.members[0]

    def z(self):
        return O.bodies[self.ref].state.pos[2]

    def make_rigid(self):
        """Kinematic facets -> one dynamic clump of the lid mass (translation z only)."""
        if self.id is None:
            self.id = _clump(self.members, self.mass, self.inertia)
            st = O.bodies[self.id].state
            st.vel = Vector3(0, 0, 0)
            st.blockedDOFs = "xyXYZ"

    def make_kinematic(self):
        """Rigid clump (or freed members) -> fixed kinematic facets at rest (for the servo)."""
        if self.id is not None:
            O.bodies.erase(self.id)     # members are kept
            self.id = None
        for m in self.members:
            b = O.bodies[m]
            b.dynamic = False
            b.state.vel = Vector3(0, 0, 0)
            b.state.angVel = Vector3(0, 0, 0)


def set_damped(ids, damped):
    for i in ids:
        O.bodies[i].state.isDamped = damped


# ------------------------------------------------------------------ fill
def pour_and_strike(scene, diameter, z_bottom, cell_top, pour_height, porosity, funnel_segments,
                    funnel_material, strike_level):
    """Loose random pour from z_bottom up to z_bottom + pour_height inside a temporary
    fixed funnel (a tube from cell_top up), settle, remove the funnel and the particles
    whose centre is above strike_level (struck level), settle. Returns the settle time (s)."""
    funnel_h = z_bottom + pour_height - cell_top + 2.0 * scene.radius
    funnel = []
    if funnel_h > 0:
        funnel = list(scene.add_cylinder(diameter, funnel_h, funnel_segments, funnel_material, z0=cell_top))
    scene.pour_cloud(diameter, z_bottom, pour_height, porosity)
    scene.set_timestep()
    t1 = scene.settle("pour")
    print(f"poured: {len(scene.live_spheres())} particles settled in {t1:.2f} s", flush=True)
    above = [b.id for b in scene.live_spheres() if b.state.pos[2] > strike_level]
    scene.remove_spheres(above)
    for i in funnel:
        O.bodies.erase(i)
    t2 = scene.settle("strike")
    return t1 + t2


# ------------------------------------------------------------------ gravity tilt
class Tilt:
    """Gravity of magnitude g rotated by the tilt angle about y: g (sin t, 0, -cos t)."""

    def __init__(self, scene):
        self.scene = scene
        self.g = scene.g
        self.angle_deg = 0.0

    def set(self, angle_deg):
        self.angle_deg = angle_deg
        t = math.radians(angle_deg)
        self.scene.newton.gravity = Vector3(self.g * math.sin(t), 0.0, -self.g * math.cos(t))


def remove_spilled(scene, box):
    """Erase the particles whose centre is outside box = (x_min, x_max, y_min, y_max,
    z_min) (m): they spilled off the table. Returns how many."""
    x0, x1, y0, y1, z0 = box
    gone = [b.id for b in scene.live_spheres()
            if not (x0 <= b.state.pos[0] <= x1 and y0 <= b.state.pos[1] <= y1) or b.state.pos[2] < z0]
    if gone:
        scene.remove_spheres(gone)
    return len(gone)


def force_sum(ids):
    """Sum of the contact forces acting on bodies `ids` (N), after a step."""
    f = Vector3(0, 0, 0)
    for i in ids:
        f += O.forces.f(i)
    return f


def stop_all(ids):
    for i in ids:
        st = O.bodies[i].state
        st.vel = Vector3(0, 0, 0)
        st.angVel = Vector3(0, 0, 0)


# ------------------------------------------------------------------ consolidation
def consolidate(scene, lid, cell, plate_ids, stress_pa, area, proc, curve, step_index, floor_z,
                cell_bottom_z=None):
    """Load the lid with the servo of demlib.loading to stress_pa (the cell held), then
    servo down to the lid's own weight and let the lid go as a free dead weight; settle.
    Appends spring-curve rows (step, t, lid stress, lid z, lid force, bearing-plate force)
    to `curve` at every guard check. Returns the step's loading record."""
    from .loading import ServoPlate, load_to
    cell.hold(True)
    if cell_bottom_z is not None and abs(cell.bottom_z() - cell_bottom_z) > 1e-9:
        # the cell sank during the previous tilt (it hangs on the lid): the operator lifts
        # it back to its gap before the next load
        cell.lift_bottom_to(cell_bottom_z)
        O.step()
    lid.make_kinematic()
    servo = ServoPlate(scene, lid.members, area, proc["plate_speed_max_m_s"], proc["servo_relaxation_time_s"],
                       proc["servo_control_interval_s"], floor_z=floor_z,
                       footprint_radius_m=0.5 * scene.rig["geometry"]["cell_inner_diameter_m"])
    t_start = O.time

    def record(t=None):
        curve.append((step_index, O.time - t_start, servo.stress_pa(), servo.position_m(), servo.force_n(),
                      -force_sum(plate_ids)[2] if plate_ids else None))

    print(f"step {step_index}: loading to {stress_pa:.0f} Pa (t={O.time:.2f} s)", flush=True)
    rec = load_to(scene, servo, stress_pa, proc["step_tolerance_ratio"], every=record)
    record()
    out = {"stress_reached_pa": rec["stress_pa"], "lid_z_loaded_m": rec["position_m"],
           "lid_force_loaded_n": rec["force_n"],
           "plate_force_loaded_n": -force_sum(plate_ids)[2] if plate_ids else None,
           "load_time_s": rec["time_s"]}
    w = lid.mass * scene.g / area
    print(f"step {step_index}: unloading to the lid weight {w:.0f} Pa (t={O.time:.2f} s)", flush=True)
    load_to(scene, servo, w, proc["step_tolerance_ratio"], every=record)
    record()
    servo.hold()
    lid.make_rigid()
    scene.settle(f"unloaded after {stress_pa:.0f} Pa")
    out["lid_z_unloaded_m"] = lid.z()
    return out


# ------------------------------------------------------------------ tilt test
def tilt_test(scene, tilt, cell, lid, plate_ids, spill_box, proc, record, step_index, restore=True):
    """One tilt test from the horizontal at rest.

    The lid is joined to the cell (one rigid body hanging on the contents through the lid
    and wall friction) which translates freely (rotations blocked). Tilt at
    tilt_rate_deg_s until the cell has slid slide_onset_displacement_m along the slope (static friction), hold
    that angle and time the travel of dynamic_travel_distance_m (dynamic friction: fit of
    x = v0 t + a t^2 / 2, mu_d = tan t - a / (g cos t)). If the cell stalls before the
    travel is done (moves less than 1 % of it in dynamic_stall_time_s, or the hold lasts
    dynamic_max_time_s), the tilt resumes until the cell has slid the onset distance again
    and the hold is repeated there (dynamic_restarts_count; between holds the table tilts at
    tilt_restart_rate_deg_s: the static reading is done, and mu_dynamic comes from the
    acceleration at the held angle, not from how fast it was reached); if max_tilt_deg is reached
    before a full travel, the cell sticks (sticks: true, mu_dynamic: null); a travel timed at
    a held angle above DYNAMIC_MAX_ANGLE_DEG (85) gives mu_dynamic: null with sticks: false
    (a = g (sin t - mu cos t) no longer depends on mu there). Then the cell
    is stopped (all velocities zeroed, as the operator catches it), the table tilted back
    and the scene settled (restore=False: not, the scene is discarded after the step).
    Particles that leave spill_box are erased and counted.

    With procedure.settle_before_tilt the freed cell first comes to rest at zero tilt (its
    drift is recorded as drift_before_tilt_m) and the slide is measured from there.

    Particle damping during the tilt follows proc['particle_damping_during_tilt']:
    'damped' (Cundall damping kept), 'undamped' (off from the start of the tilt),
    'undamped_when_sliding' (off from the onset on). The cell and lid are never damped
    while free.
    `record` gets rows (step, t, angle, slide displacement, cell z-gap, Fx, Fy, Fz on plate).
    Returns a dict of the step's measurements.
    """
    rate = proc["tilt_rate_deg_s"]
    restart_rate = proc["tilt_restart_rate_deg_s"]
    max_tilt = proc["max_tilt_deg"]
    onset_d = proc["slide_onset_displacement_m"]
    travel_d = proc["dynamic_travel_distance_m"]
    hold_max = proc["dynamic_max_time_s"]
    mode = proc["particle_damping_during_tilt"]
    if mode not in DAMPING_MODES:
        raise RigFailure(f"procedure.particle_damping_during_tilt: {mode!r} must be one of "
                         f"{', '.join(DAMPING_MODES)}")
    dt_rec = proc["record_interval_s"]
    n = max(1, int(round(dt_rec / O.dt)))
    dt_chunk = n * O.dt
    g = scene.g

    print(f"step {step_index}: tilting (t={O.time:.2f} s)", flush=True)
    join(cell, lid)
    set_damped([cell.id], False)
    cell.hold(False)
    drift = None
    if proc["settle_before_tilt"]:
        # freed at zero tilt, the cell can drift while the unloaded contents relax (wet fines
        # after 60 kPa: 4.3 mm before 0.5 deg of tilt, measured); that is not sliding
        x_free, y_free = cell.pos[0], cell.pos[1]
        scene.settle(f"cell freed before the tilt of step {step_index}")
        drift = math.hypot(cell.pos[0] - x_free, cell.pos[1] - y_free)
    if mode == "undamped":
        set_damped(scene.sphere_ids, False)
    x0 = cell.pos[0]
    t0 = O.time
    gap0 = cell.bottom_z()
    min_gap = gap0
    angle = 0.0
    spilled = [0]
    checks = 0

    def step_chunk():
        nonlocal checks, min_gap
        scene.advance(n)
        f = force_sum(plate_ids) if plate_ids else Vector3(0, 0, 0)
        x = cell.pos[0] - x0
        gap = cell.bottom_z()
        min_gap = min(min_gap, gap)
        record.append((step_index, O.time - t0, tilt.angle_deg, x, gap, f[0], f[1], f[2]))
        checks += 1
        if checks % 4 == 0:
            spilled[0] += remove_spilled(scene, spill_box)
            scene.check()
        return x, f

    def plate_ratio(f):
        return math.hypot(f[0], f[1]) / -f[2] if f[2] < 0 else None

    # --- static: tilt until the onset displacement
    onset_angle, onset_ratio = None, None
    x_prev, a_prev = 0.0, 0.0
    while True:
        angle = min(max_tilt, angle + rate * dt_chunk)
        tilt.set(angle)
        x, f = step_chunk()
        if x >= onset_d:
            # interpolate the angle at which x crossed the threshold
            frac = (onset_d - x_prev) / (x - x_prev) if x > x_prev else 1.0
            onset_angle = a_prev + frac * (angle - a_prev)
            onset_ratio = plate_ratio(f)
            break
        if angle >= max_tilt and x < onset_d:
            # hold at the max tilt for as long as a dynamic hold: does it start?
            t_hold = O.time
            while O.time - t_hold < hold_max and x < onset_d:
                x, f = step_chunk()
            if x >= onset_d:
                onset_angle, onset_ratio = angle, plate_ratio(f)
            break
        x_prev, a_prev = x, angle
    out = {"onset_angle_deg": onset_angle, "plate_force_ratio_onset": onset_ratio}

    # --- dynamic: hold the angle, time the travel; if the cell stops before it has
    # travelled the distance, tilt on until it has slid the onset distance again and
    # hold there (as an operator would), up to the max tilt
    mu_dyn, dyn_angle, travel_time, ratios = None, None, None, []
    restarts = 0
    stall_s = proc["dynamic_stall_time_s"]
    stall_d = 0.01 * travel_d
    if onset_angle is not None:
        if mode == "undamped_when_sliding":
            set_damped(scene.sphere_ids, False)
        while True:
            x_start = cell.pos[0] - x0
            t_start = O.time
            ts, xs = [0.0], [0.0]
            dyn_angle = angle
            done = False
            while True:
                x, f = step_chunk()
                ts.append(O.time - t_start)
                xs.append(x - x_start)
                r = plate_ratio(f)
                if r is not None:
                    ratios.append(r)
                if xs[-1] >= travel_d:
                    done = True
                    break
                # stalled: less than 1 % of the travel distance in the last stall_s
                back = [xv for tv, xv in zip(ts, xs) if tv >= ts[-1] - stall_s]
                if (ts[-1] > stall_s and xs[-1] - back[0] < stall_d) or ts[-1] > hold_max:
                    break
            if done:
                # interpolate the crossing time, fit x = v0 t + a t^2/2 over the travel
                k = len(xs) - 1
                frac = (travel_d - xs[k - 1]) / (xs[k] - xs[k - 1]) if xs[k] > xs[k - 1] else 1.0
                travel_time = ts[k - 1] + frac * (ts[k] - ts[k - 1])
                acc = _fit_acceleration(ts, xs)
                th = math.radians(dyn_angle)
                if dyn_angle <= DYNAMIC_MAX_ANGLE_DEG:      # above it cos t ~ 0 and mu is lost
                    mu_dyn = math.tan(th) - acc / (g * math.cos(th))
                out.update({"dynamic_acceleration_m_s2": acc})
                break
            if angle >= max_tilt:
                break
            restarts += 1
            ratios = []
            x_stop = cell.pos[0] - x0
            while angle < max_tilt:
                angle = min(max_tilt, angle + restart_rate * dt_chunk)
                tilt.set(angle)
                x, f = step_chunk()
                if x - x_stop >= onset_d:
                    break
        slid = cell.pos[0] - x0
        sticks = travel_time is None
    else:
        slid = cell.pos[0] - x0
        sticks = True
    out.update({
        "mu_static": math.tan(math.radians(onset_angle)) if onset_angle is not None else None,
        "mu_dynamic": mu_dyn,
        "dynamic_angle_deg": dyn_angle,
        "dynamic_travel_time_s": travel_time,
        "dynamic_restarts_count": restarts,
        "plate_force_ratio_sliding": (sum(ratios) / len(ratios)) if ratios else None,
        "sticks": bool(sticks),
        "max_tilt_deg": tilt.angle_deg,
        "slid_distance_m": slid,
        "cell_gap_min_m": min_gap,
        "cell_gap_start_m": gap0,
        "tilt_time_s": O.time - t0,
        "drift_before_tilt_m": drift,
    })
    if not restore:
        out["spilled_particles_count"] = spilled[0]
        return out
    # --- stop the cell, tilt back, settle
    stop_all([cell.id] + list(scene.sphere_ids))
    set_damped(scene.sphere_ids, True)
    cell.hold(True)
    split(cell, lid)
    back = proc["tilt_return_rate_deg_s"]
    while tilt.angle_deg > 0.0:
        tilt.set(max(0.0, tilt.angle_deg - back * dt_chunk))
        step_chunk()
    spilled[0] += remove_spilled(scene, spill_box)
    scene.settle(f"tilt back after step {step_index}")
    out["spilled_particles_count"] = spilled[0]
    return out


def _fit_acceleration(ts, xs):
    """Least-squares a of x = v0 t + a t^2 / 2 (x(0) = 0)."""
    s22 = s23 = s33 = s2x = s3x = 0.0
    for t, x in zip(ts, xs):
        p, q = t, 0.5 * t * t
        s22 += p * p
        s23 += p * q
        s33 += q * q
        s2x += p * x
        s3x += q * x
    det = s22 * s33 - s23 * s23
    if det <= 0:
        raise RigFailure("dynamic friction: too few points to fit the sliding acceleration "
                         "(record_interval_s too long for dynamic_travel_distance_m?)")
    return (s22 * s3x - s23 * s2x) / det


# ------------------------------------------------------------------ the whole rig
STEP_KEYS = ("mu_static", "mu_dynamic", "sticks", "max_tilt_deg", "onset_angle_deg", "dynamic_angle_deg",
             "dynamic_travel_time_s", "dynamic_restarts_count", "dynamic_acceleration_m_s2",
             "plate_force_ratio_onset", "plate_force_ratio_sliding", "slid_distance_m",
             "cell_gap_start_m", "cell_gap_min_m", "tilt_time_s", "lid_z_loaded_m", "lid_z_unloaded_m",
             "plate_force_loaded_n", "lid_force_loaded_n", "stress_reached_pa", "load_time_s",
             "spilled_particles_count", "drift_before_tilt_m",
             "wall_time_step_s")


FILL_MODES = ("sequential", "fresh")


def run_friction_rig(job, build, out_dir):
    """For each consolidation stress in order: consolidate, tilt test.

    build(scene) -> parts builds and fills the rig in a new Scene(job).
    procedure.fill_each_step: 'sequential' - one fill, the steps follow each other on it
    (the lab's procedure: the table returns to horizontal, the cell is put back);
    'fresh' - a new fill for every step (same seed, so the same fill: the steps differ
    only by their consolidation stress), for rigs whose sample is spoilt by a slide.
    `parts`: plate_ids (bearing plate: force readout; empty for the internal rig),
    cell (RigidBody, the sliding cell), cell_bottom_z_m (its nominal bottom edge),
    floor_z_m (lowest a lid may go), spill_box_m (x_min, x_max, y_min, y_max, z_min: a
    particle whose centre leaves it has spilled off the table: erased and counted),
    contents_volume_m3, settle_time_s. Writes friction.csv,
    spring_curve.csv, tilt_record.csv; returns the measurements."""
    import time
    from .jobio import write_csv
    from .scene import Scene

    def make_scene():
        scene = Scene(job)
        return scene, build(scene)

    scene, parts = make_scene()
    g, p = scene.rig["geometry"], scene.rig["procedure"]
    fresh = p["fill_each_step"] == "fresh"
    if p["fill_each_step"] not in FILL_MODES:
        raise RigFailure(f"procedure.fill_each_step: {p['fill_each_step']!r} must be one of {', '.join(FILL_MODES)}")
    d = g["cell_inner_diameter_m"]
    area = math.pi * d * d / 4.0

    def start(scene, parts):
        spheres = scene.live_spheres()
        if not spheres:
            raise RigFailure("fill: no particle left in the cell")
        top = max(b.state.pos[2] + b.shape.radius for b in spheres)
        lid = Lid(scene, d, g["lid_material"], top + p["plate_start_gap_m"], g["lid_mass_kg"])
        return lid, Tilt(scene)

    lid, tilt = start(scene, parts)
    particle_ids = list(scene.sphere_ids)
    mass_particles = scene.particle_mass_total()
    settle_s = parts["settle_time_s"]
    cohesion_updates = 0
    steps_done = 0          # time steps of the scenes already discarded (fresh fills)
    steps, curve, record = [], [], []
    keys = ("stress_pa",) + STEP_KEYS

    def write_records():
        write_csv(out_dir, "friction.csv", [k for k in keys], [[s.get(k) for k in keys] for s in steps])
        write_csv(out_dir, "spring_curve.csv",
                  ["step_index_count", "time_s", "lid_stress_pa", "lid_position_m", "lid_force_n",
                   "plate_force_n"], curve)
        write_csv(out_dir, "tilt_record.csv",
                  ["step_index_count", "time_s", "tilt_deg", "slide_displacement_m", "cell_gap_m",
                   "plate_force_x_n", "plate_force_y_n", "plate_force_z_n"], record)

    try:
        for k, stress in enumerate(p["consolidation_stresses_pa"]):
            w0 = time.time()
            if fresh and k:
                cohesion_updates += getattr(scene.contact, "n_updates", 0) or 0
                steps_done += O.iter
                scene, parts = make_scene()
                lid, tilt = start(scene, parts)
            cell, plate_ids = parts["cell"], parts["plate_ids"]
            spilled = sum(s.get("spilled_particles_count", 0) for s in steps)
            if k and not fresh and lid.z() < parts["floor_z_m"] + 4.0 * scene.radius:
                raise RigFailure(f"step {k}: the lid is at z={lid.z():.4f} m, less than two particle diameters "
                                 f"above the sliding cell's bottom: the cell has lost its contents ({spilled} "
                                 "particles spilled in the slides of the previous steps); the test is not valid "
                                 "beyond this step")
            cons = consolidate(scene, lid, cell, plate_ids, stress, area, p, curve, k, parts["floor_z_m"],
                               parts["cell_bottom_z_m"])
            res = tilt_test(scene, tilt, cell, lid, plate_ids, parts["spill_box_m"], p, record, k,
                            restore=not fresh)
            res.update(cons)
            res["wall_time_step_s"] = time.time() - w0
            res["stress_pa"] = stress
            steps.append(res)
            print(f"step {k}: {stress:.0f} Pa  mu_static={res['mu_static']}  mu_dynamic={res['mu_dynamic']}  "
                  f"sticks={res['sticks']}  angle={res['onset_angle_deg']}  ratio={res['plate_force_ratio_onset']}  "
                  f"gap {res['cell_gap_start_m']:.4f}->{res['cell_gap_min_m']:.4f}  "
                  f"({res['wall_time_step_s']:.1f} s wall)", flush=True)
    except RigFailure:
        write_records()     # the partial records help to see what went wrong (no result.json)
        raise
    write_records()
    out = {k: [s.get(k) for s in steps] for k in keys}
    out["spring_curve"] = {
        "step_index_count": [r[0] for r in curve],
        "lid_stress_pa": [r[2] for r in curve],
        "lid_position_m": [r[3] for r in curve],
        "lid_force_n": [r[4] for r in curve],
        "plate_force_n": [r[5] for r in curve],
    }
    weight = (g["cell_mass_kg"] + g["lid_mass_kg"] + mass_particles) * scene.g
    out.update({
        "n_particles": len(particle_ids),
        "n_particles_end": len(scene.sphere_ids),
        "fill_each_step": p["fill_each_step"],
        "particle_mass_kg": mass_particles,
        "bulk_density_kg_m3": mass_particles / parts["contents_volume_m3"],
        "self_weight_stress_pa": weight / area,
        "settle_time_s": settle_s,
        "timestep_s": O.dt,
        "steps": steps_done + O.iter,
        "particle_damping_during_tilt": p["particle_damping_during_tilt"],
    })
    if getattr(scene.contact, "n_updates", None) is not None:
        out["cohesion_update_count"] = cohesion_updates + scene.contact.n_updates
    # friction vs stress against the lab curve (CSV, PNG, misfit): pycal.post.friction; an
    # error here is a bug: the run fails (exit 4, not kept as a verdict), nothing is hidden
    from pycal.post import friction as post
    res = dict(out, rig=scene.job["rig"], material=scene.job["material"], seed=scene.job["seed"], job=scene.job)
    done = post.write_outputs([res], out_dir)
    out["misfits"] = done["misfits"]
    out["output_files"] = [os.path.basename(f) for f in done["files"]]
    return out
