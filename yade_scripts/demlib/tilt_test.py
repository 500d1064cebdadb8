"""One tilt test of the friction rigs (runs inside YADE).

The table is tilted by rotating the gravity vector about the scene's y axis: the
bearing plate stays in the plane z = 0 and "down the slope" is +x, so the sliding
displacement is simply the x displacement of the rigid cell. (procedure.shear_drive:
force_ramp instead pushes the cell with a horizontal force W tan(angle) under vertical
gravity: ForceDrive.)

tilt_test() runs the phases in order:
1. free the cell: the lid is joined to it (one rigid body hanging on the contents) and
   it translates freely (rotations blocked; procedure.lid_during_tilt and
   sliding_cell_rotations: free change either, for the internal-friction audit); with
   procedure.settle_before_tilt it first comes to rest at zero tilt (its drift is
   recorded, the slide is measured from there);
2. static friction: tilt (at pre_tilt_rate_deg_s until the cell has slid
   pre_tilt_slide_fraction of the onset distance, then at the lab's tilt_rate_deg_s)
   until the cell has slid slide_onset_displacement_m (mu_static = tan of that angle);
3. dynamic friction (procedure.measure_dynamic_friction: true): hold that angle and time
   the travel of dynamic_travel_distance_m (fit of x = v0 t + a t^2 / 2, mu_dynamic =
   tan t - a / (g cos t)); a stalled cell makes the tilt resume (at
   tilt_restart_rate_deg_s) to the next onset, where the hold is repeated
   (dynamic_restarts_count). false: the step ends at the onset (mu_dynamic null, sticks
   only when there was no onset up to max_tilt_deg);
4. stop the cell, tilt back and settle (not when the scene is discarded after the step).
"""
import math

from yade import O
from yade import Quaternion, Vector3

from .jobio import RigFailure
from .phase_clock import CLOCK
from .phases import drive
from .tilt_bodies import force_sum, join, set_damped, split, stop_all
from pycal.post.friction import DYNAMIC_MAX_ANGLE_DEG  # pure Python: one rule for rig and post
from pycal.rig_contract import tilt_option

DAMPING_MODES = ("damped", "undamped", "undamped_when_sliding")


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


class ForceDrive:
    """The shear drive of procedure.shear_drive: force_ramp (the case study's own DEM model
    of the internal-friction cell): gravity stays vertical and a horizontal force
    F = W tan(angle) pushes the mobile cell down +x (W: the weight on the shear plane, N),
    so the ratio F / W follows the tilted table's tan(angle) and an onset at `angle` reads
    the same mu_static = tan(angle). It stands in for Tilt (the same set(angle_deg)); the
    angle is capped at MAX_ANGLE_DEG (F = 11 W: a cell that has not slid by then sticks)."""
    MAX_ANGLE_DEG = 85.0

    def __init__(self, scene, body_id, weight_n):
        self.scene, self.body_id, self.weight_n = scene, body_id, weight_n
        self.angle_deg = 0.0

    def set(self, angle_deg):
        self.angle_deg = angle_deg
        f = self.weight_n * math.tan(math.radians(min(angle_deg, self.MAX_ANGLE_DEG)))
        O.forces.setPermF(self.body_id, Vector3(f, 0.0, 0.0))

    def release(self):
        O.forces.setPermF(self.body_id, Vector3(0.0, 0.0, 0.0))


def weight_on_shear_plane(scene, cell, lid, shear_plane_z):
    """(cell + lid + the particles whose centre is above shear_plane_z) x g (N): what the
    shear plane of the internal-friction cell carries under vertical gravity."""
    m = cell.mass + lid.mass
    m += sum(b.state.mass for b in scene.live_spheres() if b.state.pos[2] > shear_plane_z)
    return m * scene.g


def remove_spilled(scene, box):
    """Erase the particles whose centre is outside box = (x_min, x_max, y_min, y_max,
    z_min) (m): they spilled off the table. Returns how many."""
    x0, x1, y0, y1, z0 = box
    gone = [b.id for b in scene.live_spheres()
            if not (x0 <= b.state.pos[0] <= x1 and y0 <= b.state.pos[1] <= y1) or b.state.pos[2] < z0]
    if gone:
        scene.remove_spheres(gone)
    return len(gone)


def plate_ratio(f):
    """Tangential / normal force of the particles on the bearing plate (None without load)."""
    return math.hypot(f[0], f[1]) / -f[2] if f[2] < 0 else None


class TiltRecorder:
    """Advances a tilt test chunk by chunk (record_interval_s) and records each chunk:
    rows (step, t, angle, slide displacement, cell z-gap, Fx, Fy, Fz on the plate) go to
    `record`; every 4th chunk the spilled particles are erased (counted) and the guards
    checked. The slide is the cell's x displacement from where the recorder started."""

    def __init__(self, scene, tilt, cell, plate_ids, spill_box, record, step_index, record_interval_s):
        self.scene, self.tilt, self.cell = scene, tilt, cell
        self.plate_ids, self.spill_box, self.record, self.step_index = plate_ids, spill_box, record, step_index
        self.n = max(1, int(round(record_interval_s / O.dt)))
        self.dt_chunk = self.n * O.dt
        self.x0 = cell.slide_point()[0]
        self.ori0 = Quaternion(cell.body.state.ori)
        self.t0 = O.time
        self.gap0 = cell.bottom_z()
        self.min_gap = self.gap0
        self.spilled = 0
        self.checks = 0

    def slide(self):
        """Slide displacement of the cell down the slope so far (m)."""
        return self.cell.slide_point()[0] - self.x0

    def rotation_deg(self):
        """How far the cell has turned since the recorder started (deg, any axis): 0 while its
        rotations are blocked (sliding_cell_rotations: blocked)."""
        turn = self.cell.body.state.ori * self.ori0.conjugate()
        angle = abs(math.degrees(turn.toAxisAngle()[1])) % 360.0
        return min(angle, 360.0 - angle)

    def chunk(self):
        """Advance one chunk; returns (slide displacement m, force of the particles on the plate N)."""
        self.scene.advance(self.n)
        f = force_sum(self.plate_ids) if self.plate_ids else Vector3(0, 0, 0)
        x = self.cell.slide_point()[0] - self.x0
        gap = self.cell.bottom_z()
        self.min_gap = min(self.min_gap, gap)
        self.record.append((self.step_index, O.time - self.t0, self.tilt.angle_deg, x, gap, f[0], f[1], f[2]))
        self.checks += 1
        if self.checks % 4 == 0:
            self.spilled += remove_spilled(self.scene, self.spill_box)
            self.scene.check()
        return x, f


def free_the_cell(scene, cell, lid, proc, step_index):
    """Join lid and cell, free the cell's translations (never damped); with
    settle_before_tilt let it come to rest at zero tilt. Returns its drift (m) or None.
    The audit options (pycal.rig_contract.TILT_OPTION_DEFAULTS): lid_during_tilt: free
    leaves the lid free on the contents instead of joining it; sliding_cell_rotations:
    free lets the cell turn too (slide_read_at: shear_plane reads its slide at the centre
    of its bottom rim instead of its centre of mass)."""
    if tilt_option(proc, "lid_during_tilt") == "joined":
        join(cell, lid)
    else:
        lid.free()
    set_damped([cell.id], False)
    cell.hold(False, rotations_free=tilt_option(proc, "sliding_cell_rotations") == "free",
              read_at_shear_plane=tilt_option(proc, "slide_read_at") == "shear_plane")
    if not proc["settle_before_tilt"]:
        return None
    # freed at zero tilt, the cell can drift while the unloaded contents relax (wet fines
    # after 60 kPa: 4.3 mm before 0.5 deg of tilt, measured); that is not sliding
    p_free = Vector3(cell.slide_point())
    with CLOCK.phase("settle_before_tilt"):
        drive(scene.settle(f"cell freed before the tilt of step {step_index}"))
    p_now = cell.slide_point()
    return math.hypot(p_now[0] - p_free[0], p_now[1] - p_free[1])


def static_onset(run, proc):
    """Tilt until the cell has slid slide_onset_displacement_m (the angle interpolated at
    the crossing): at pre_tilt_rate_deg_s while the cell has slid less than
    pre_tilt_slide_fraction x that distance (the contents barely strained: quasi-static
    at either rate), then at the lab's tilt_rate_deg_s up to the onset (a pre-tilt rate
    not above the lab rate: the lab rate from zero). At max_tilt_deg hold for
    dynamic_max_time_s to see whether it starts. Returns ({'onset_angle_deg',
    'plate_force_ratio_onset', 'pre_tilt_end_deg'}, the angle reached (deg));
    onset_angle_deg None when the cell did not slide; pre_tilt_end_deg the angle where the
    lab rate took over (None without a pre-tilt); cell_rotation_onset_deg how far the cell
    had turned by then (at the onset, or at the end of the hold when it did not slide)."""
    rate, max_tilt = proc["tilt_rate_deg_s"], proc["max_tilt_deg"]
    onset_d, hold_max = proc["slide_onset_displacement_m"], proc["dynamic_max_time_s"]
    pre_rate, pre_until = proc["pre_tilt_rate_deg_s"], proc["pre_tilt_slide_fraction"] * onset_d
    pre = pre_rate > rate
    angle, pre_end = 0.0, None
    onset_angle, onset_ratio = None, None
    x_prev, a_prev = 0.0, 0.0
    while True:
        angle = min(max_tilt, angle + (pre_rate if pre else rate) * run.dt_chunk)
        run.tilt.set(angle)
        x, f = run.chunk()
        if pre and x >= pre_until:
            pre, pre_end = False, angle
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
                x, f = run.chunk()
            if x >= onset_d:
                onset_angle, onset_ratio = angle, plate_ratio(f)
            break
        x_prev, a_prev = x, angle
    return {"onset_angle_deg": onset_angle, "plate_force_ratio_onset": onset_ratio, "pre_tilt_end_deg": pre_end,
            "cell_rotation_onset_deg": run.rotation_deg()}, angle


def _hold(run, travel_d, stall_s, hold_max, ratios):
    """Hold the current angle until the cell has travelled travel_d from here (True) or
    has stalled (< 1 % of travel_d in the last stall_s) or the hold lasted hold_max
    (False). Appends the plate force ratios. Returns (done, times s, travel m)."""
    x_start = run.slide()
    t_start = O.time
    ts, xs = [0.0], [0.0]
    stall_d = 0.01 * travel_d
    while True:
        x, f = run.chunk()
        ts.append(O.time - t_start)
        xs.append(x - x_start)
        r = plate_ratio(f)
        if r is not None:
            ratios.append(r)
        if xs[-1] >= travel_d:
            return True, ts, xs
        back = [xv for tv, xv in zip(ts, xs) if tv >= ts[-1] - stall_s]
        if (ts[-1] > stall_s and xs[-1] - back[0] < stall_d) or ts[-1] > hold_max:
            return False, ts, xs


def dynamic_travel(run, proc, angle):
    """Hold the onset angle and time the travel (module doc, phase 3), starting at the
    angle reached by static_onset. Returns the dynamic entries of the step's record."""
    travel_d, hold_max = proc["dynamic_travel_distance_m"], proc["dynamic_max_time_s"]
    max_tilt, restart_rate = proc["max_tilt_deg"], proc["tilt_restart_rate_deg_s"]
    onset_d, stall_s = proc["slide_onset_displacement_m"], proc["dynamic_stall_time_s"]
    out = {}
    mu_dyn, dyn_angle, travel_time, ratios, restarts = None, None, None, [], 0
    while True:
        dyn_angle = angle
        done, ts, xs = _hold(run, travel_d, stall_s, hold_max, ratios)
        if done:
            # interpolate the crossing time, fit x = v0 t + a t^2/2 over the travel
            k = len(xs) - 1
            frac = (travel_d - xs[k - 1]) / (xs[k] - xs[k - 1]) if xs[k] > xs[k - 1] else 1.0
            travel_time = ts[k - 1] + frac * (ts[k] - ts[k - 1])
            acc = fit_acceleration(ts, xs)
            th = math.radians(dyn_angle)
            if dyn_angle <= DYNAMIC_MAX_ANGLE_DEG:      # above it cos t ~ 0 and mu is lost
                mu_dyn = math.tan(th) - acc / (run.scene.g * math.cos(th))
            out["dynamic_acceleration_m_s2"] = acc
            break
        if angle >= max_tilt:
            break
        # stalled: tilt on until the cell has slid the onset distance again, hold there
        restarts += 1
        ratios = []
        x_stop = run.slide()
        while angle < max_tilt:
            angle = min(max_tilt, angle + restart_rate * run.dt_chunk)
            run.tilt.set(angle)
            x, f = run.chunk()
            if x - x_stop >= onset_d:
                break
    out.update({"mu_dynamic": mu_dyn, "dynamic_angle_deg": dyn_angle, "dynamic_travel_time_s": travel_time,
                "dynamic_restarts_count": restarts,
                "plate_force_ratio_sliding": (sum(ratios) / len(ratios)) if ratios else None})
    return out


def tilt_back(run, scene, cell, lid, proc):
    """Stop the cell and the particles (as the operator catches it), hold the cell, take
    the lid off it, tilt back at tilt_return_rate_deg_s and settle."""
    stop_all([cell.id] + list(scene.sphere_ids))
    set_damped(scene.sphere_ids, True)
    cell.hold(True)
    split(cell, lid)
    back = proc["tilt_return_rate_deg_s"]
    while run.tilt.angle_deg > 0.0:
        run.tilt.set(max(0.0, run.tilt.angle_deg - back * run.dt_chunk))
        run.chunk()
    run.spilled += remove_spilled(scene, run.spill_box)
    drive(scene.settle(f"tilt back after step {run.step_index}"))


def tilt_test(scene, tilt, cell, lid, plate_ids, spill_box, proc, record, step_index, restore=True):
    """One tilt test from the horizontal at rest (module doc: phases 1 - 4).

    If max_tilt_deg is reached before a full travel, the cell sticks (sticks: true,
    mu_dynamic: null); a travel timed at a held angle above DYNAMIC_MAX_ANGLE_DEG (85)
    gives mu_dynamic: null with sticks: false (a = g (sin t - mu cos t) no longer depends
    on mu there). restore=False: no tilt back (the scene is discarded after the step).
    Particles that leave spill_box are erased and counted.

    Particle damping during the tilt follows proc['particle_damping_during_tilt']:
    'damped' (Cundall damping kept), 'undamped' (off from the start of the tilt),
    'undamped_when_sliding' (off from the onset on). The cell and lid are never damped
    while free.
    `record` gets rows (step, t, angle, slide displacement, cell z-gap, Fx, Fy, Fz on plate).
    Returns a dict of the step's measurements.
    """
    mode = proc["particle_damping_during_tilt"]
    if mode not in DAMPING_MODES:
        raise RigFailure(f"procedure.particle_damping_during_tilt: {mode!r} must be one of "
                         f"{', '.join(DAMPING_MODES)}")
    print(f"step {step_index}: tilting (t={O.time:.2f} s)", flush=True)
    drift = free_the_cell(scene, cell, lid, proc, step_index)
    if mode == "undamped":
        set_damped(scene.sphere_ids, False)
    weight = None
    if tilt_option(proc, "shear_drive") == "force_ramp":
        # the shear plane: the middle of the gap under the mobile cell (internal_friction)
        plane_z = cell.bottom_z() - 0.5 * scene.rig["geometry"]["cell_gap_m"]
        weight = weight_on_shear_plane(scene, cell, lid, plane_z)
        tilt = ForceDrive(scene, cell.id, weight)
    run = TiltRecorder(scene, tilt, cell, plate_ids, spill_box, record, step_index, proc["record_interval_s"])
    with CLOCK.phase("tilt_static"):
        out, angle = static_onset(run, proc)
    if weight is not None:
        tilt.release()
        out["drive_weight_n"] = weight
    slid = out["onset_angle_deg"] is not None
    if slid and proc["measure_dynamic_friction"]:
        if mode == "undamped_when_sliding":
            set_damped(scene.sphere_ids, False)
        with CLOCK.phase("tilt_dynamic"):
            out.update(dynamic_travel(run, proc, angle))
        sticks = out["dynamic_travel_time_s"] is None
    else:
        # no onset up to max_tilt_deg (the cell sticks), or static friction only (a stage that
        # reads mu_static: the step ends at the onset, the same computation up to it)
        out.update({"mu_dynamic": None, "dynamic_angle_deg": None, "dynamic_travel_time_s": None,
                    "dynamic_restarts_count": 0, "plate_force_ratio_sliding": None})
        sticks = not slid
    onset = out["onset_angle_deg"]
    out.update({
        "mu_static": math.tan(math.radians(onset)) if onset is not None else None,
        "sticks": bool(sticks),
        "max_tilt_deg": tilt.angle_deg,
        "slid_distance_m": run.slide(),
        "cell_gap_min_m": run.min_gap,
        "cell_gap_start_m": run.gap0,
        "tilt_time_s": O.time - run.t0,
        "drift_before_tilt_m": drift,
    })
    if restore:
        with CLOCK.phase("tilt_back"):
            tilt_back(run, scene, cell, lid, proc)
    out["spilled_particles_count"] = run.spilled
    return out


def fit_acceleration(ts, xs):
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
