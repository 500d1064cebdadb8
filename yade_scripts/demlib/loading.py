"""Plate loading shared by the compression and friction rigs (runs inside YADE).

A horizontal rigid plate made of facets is moved kinematically (its facets are not
dynamic; NewtonIntegrator moves them with the velocity set here) by a proportional
servo towards a target stress = upward force of the particles on the plate / area.

API (kept stable; the friction rigs of issue 5 reuse it):

    ids = add_plate(scene, z, diameter, material, segments=4, centre=(0.0, 0.0),
                    fit="circumscribed")
        Horizontal polygon plate of facets at height z (m). fit='circumscribed' covers
        the whole circle of `diameter` (m) (a lid in a cell: the default square of 2
        facets), fit='equal_area' has the circle's area (a free plate). No interior
        vertex (see add_plate for why). Returns the facet ids.

    plate = ServoPlate(scene, ids, area_m2, speed_max_m_s, relaxation_time_s,
                       control_interval_s, floor_z=None, footprint_radius_m=None)
        floor_z: a plate lower than one radius above it is a blow-up (None: no check);
        footprint_radius_m: particles above the plate within this radius of its centre
        have passed through it (default: half the plate's x extent).
        plate.force_n()      upward force of the particles on the plate (N)
        plate.stress_pa()    force / area (Pa)
        plate.position_m()   plate height z (m)
        plate.n_contacts()   particle contacts on the plate
        plate.set_target(stress_pa); plate.hold() (velocity 0, target dropped; without
                             a target the servo leaves the velocity as set by hand)
        plate.run(seconds, every=None)   phase: advance time with the servo active and the
                                         blow-up guards checked (scene.check + plate guards)

    rec = yield from load_to(scene, plate, stress_pa, tolerance_ratio, max_time_s=None, every=None)
        Phase: servo until |stress - target| <= tolerance_ratio x target AND the servo has
        stopped (inside half the tolerance) AND scene.is_at_rest(); then holds the plate
        still and returns {'stress_pa', 'force_n', 'position_m', 'time_s', 'steps',
        'contacts_count'}. every(t) as in plate.run. Raises RigFailure with a clear message when
        the stress is not reached at rest within max_time_s (default: the job's
        numerics.max_settle_time_s) or when the guards trip ('blow-up: ...').

    rec = yield from release(scene, plate, clearance_m, max_time_s=None)
        Phase: raise the plate until it has no contact and is `clearance_m` above the highest
        particle top, then settle the bulk under its own weight.

Controller. err = F_target - F (N). The plate's stiffness as seen from the plate is
bounded above by K = sum of the normal stiffnesses of its contacts, so dz = err / K is
an under-estimate of the displacement needed (safe: never overshoots in a static
sense); the plate moves at v = dz / relaxation_time_s, limited to speed_max_m_s. With
no contact and a positive target it approaches at speed_max_m_s. Within half the
tolerance (|err| <= tolerance/2 x target, once load_to has set it) the plate stops, so
that the bulk can come to rest; it moves again if the bulk creeps out of that band.

Guards (besides Scene.check: NaN, escape, overlap > max_overlap_fraction x R): a
particle whose centre lies above the plate within its footprint has passed through
it, and a plate lower than one particle radius above floor_z has passed through the
bulk: both raise RigFailure('blow-up: ...').

Measured stress sits near the lower edge of the dead band (about -1 % of the target)
because the plate approaches from below; the record holds the measured value.

Stepping: the phases are generators (demlib.phases) that yield the steps to the next
servo update; whoever drives them steps YADE with O.step() in a Python loop (O.run(n,
True) costs a fixed ~40 ms per call in YADE 2023.02a: it polls).
"""
import math

from yade import O, utils
from yade import Vector3

from .jobio import NoRestUnderLoad, RigFailure
from .phases import steps_of


PLATE_FITS = ("circumscribed", "equal_area")


def strip_triangles(n):
    """Zig-zag triangulation of a convex n-gon (vertex indices): every vertex is on the rim,
    interior edges are chords shared by two triangles (no interior vertex)."""
    tris, i, j, left = [], 0, n - 1, True
    while j - i >= 2:
        if left:
            tris.append((i, i + 1, j))
            i += 1
        else:
            tris.append((i, j - 1, j))
            j -= 1
        left = not left
    return tris


def add_plate(scene, z, diameter, material, segments=4, centre=(0.0, 0.0), fit="circumscribed"):
    """Horizontal rigid plate at height z (m): a regular polygon of `segments` corners
    around `centre` (x, y in m, relative to the scene's origin), split into segments - 2 facets without an interior vertex.
    fit='circumscribed': the polygon contains the whole circle of `diameter` (m), for a
    lid in a cell of that diameter (the corners stick out into the wall: harmless, facets
    never touch facets); the default square (2 facets) is the lid of the confined rigs.
    fit='equal_area': the polygon has the area of that circle (a free plate, e.g. UCS).
    Returns the list of facet ids.

    Why no fan around a centre vertex: YADE gives a sphere one contact per facet it
    touches, so a sphere at a vertex shared by k facets gets k coincident contacts (k x
    the normal, tangential and rolling stiffness). With a 32-facet fan a particle under
    the plate centre had 5 such contacts, went numerically unstable in rotation at the
    usual time step (angular velocity flipping sign step by step, +-16 rad/s, kinetic
    energy ratio 6e-4 for ever) and the bulk never came to rest. Here a point of the
    plate is shared by at most 2 facets (along a chord), corners excepted."""
    segments = int(segments)
    if segments < 3:
        raise RigFailure(f"add_plate: {segments} segments, need >= 3")
    if fit not in PLATE_FITS:
        raise RigFailure(f"add_plate: fit {fit!r} must be one of {', '.join(PLATE_FITS)}")
    radius = 0.5 * diameter
    if fit == "circumscribed":
        r = radius / math.cos(math.pi / segments)
    else:
        r = radius * math.sqrt(2.0 * math.pi / (segments * math.sin(2.0 * math.pi / segments)))
    cx, cy = scene.origin[0] + centre[0], scene.origin[1] + centre[1]
    mat = scene.contact.mat_id[material]
    rim = [Vector3(cx + r * math.cos(2 * math.pi * k / segments),
                   cy + r * math.sin(2 * math.pi * k / segments), z) for k in range(segments)]
    facets = [utils.facet([rim[a], rim[b], rim[c]], material=mat, fixed=True)
              for a, b, c in strip_triangles(segments)]
    return list(O.bodies.append(facets))


class ServoPlate:
    """Stress-controlled kinematic plate (see the module doc)."""

    def __init__(self, scene, facet_ids, area_m2, speed_max_m_s, relaxation_time_s,
                 control_interval_s, floor_z=None, footprint_radius_m=None):
        if area_m2 <= 0 or speed_max_m_s <= 0 or relaxation_time_s <= 0 or control_interval_s <= 0:
            raise RigFailure("ServoPlate: area, speed limit, relaxation time and control interval must be > 0")
        self.scene = scene
        self.ids = list(facet_ids)
        self.area = float(area_m2)
        self.vmax = float(speed_max_m_s)
        self.tau = float(relaxation_time_s)
        self.control_interval_s = float(control_interval_s)
        self.floor_z = floor_z
        # footprint for the pass-through guard: centre of the plate and radius
        bodies = [O.bodies[i] for i in self.ids]
        xs = [b.state.pos[0] + v[0] for b in bodies for v in b.shape.vertices]
        ys = [b.state.pos[1] + v[1] for b in bodies for v in b.shape.vertices]
        self.cx, self.cy = 0.5 * (min(xs) + max(xs)), 0.5 * (min(ys) + max(ys))
        self.footprint_r = footprint_radius_m if footprint_radius_m is not None else 0.5 * (max(xs) - min(xs))
        self.target_force = None
        self.deadband_force = 0.0
        self.velocity = 0.0
        self._set_velocity(0.0)

    # ---------- measurements ----------
    def force_n(self):
        """Upward (+z) force of the particles on the plate (N), from the last step."""
        return sum(O.forces.f(i)[2] for i in self.ids)

    def stress_pa(self):
        return self.force_n() / self.area

    def position_m(self):
        return O.bodies[self.ids[0]].state.pos[2]

    def _contacts(self):
        for i in self.ids:
            for it in O.interactions.withBody(i):
                if it.isReal:
                    yield it

    def n_contacts(self):
        return sum(1 for _ in self._contacts())

    def contact_stiffness(self):
        """Sum of the normal stiffnesses of the plate's contacts (N/m)."""
        return sum(it.phys.kn for it in self._contacts())

    # ---------- control ----------
    def _set_velocity(self, v):
        self.velocity = v
        vel = Vector3(0, 0, v)
        for i in self.ids:
            O.bodies[i].state.vel = vel

    def set_target(self, stress_pa, deadband_ratio=0.0):
        """Servo towards stress_pa; stop inside |err| <= deadband_ratio x target."""
        self.target_force = stress_pa * self.area
        self.deadband_force = deadband_ratio * abs(self.target_force)

    def hold(self):
        """Stop the plate and drop the target (the plate stays where it is)."""
        self.target_force = None
        self._set_velocity(0.0)

    def control(self):
        """One controller update: set the plate velocity from the current force."""
        if self.target_force is None:      # no target: keep the velocity set by hand
            return
        err = self.target_force - self.force_n()       # > 0: push down
        if abs(err) <= self.deadband_force:
            self._set_velocity(0.0)
            return
        k = self.contact_stiffness()
        if k <= 0.0:
            v_down = self.vmax if err > 0 else -self.vmax
        else:
            v_down = err / k / self.tau
            v_down = max(-self.vmax, min(self.vmax, v_down))
        self._set_velocity(-v_down)

    # ---------- guards ----------
    def check(self):
        z = self.position_m()
        if self.floor_z is not None and z < self.floor_z + self.scene.radius:
            raise RigFailure(f"blow-up: the plate reached z={z:.4f} m, less than one particle radius above "
                             f"the floor (t={O.time:.4f} s): it passed through the bulk")
        for b in self.scene.live_spheres():
            p = b.state.pos
            if p[2] > z and math.hypot(p[0] - self.cx, p[1] - self.cy) < self.footprint_r:
                raise RigFailure(f"blow-up: particle {b.id} is above the plate (z={p[2]:.4f} m > plate "
                                 f"{z:.4f} m, t={O.time:.4f} s): it passed through the plate")

    # ---------- time stepping ----------
    def run(self, seconds, every=None):
        """Phase: advance `seconds` of simulated time with the servo acting every control
        interval and the guards checked every numerics.rest_check_interval_s;
        every(t) is called at each guard check if given. (Steps k = 0, 1, ...: the servo
        acts before step k when k % ctrl == 0, the guards after it when (k + 1) % chk == 0.)"""
        steps = int(math.ceil(seconds / O.dt))
        ctrl = steps_of(self.control_interval_s, O.dt)
        chk = steps_of(self.scene.num["rest_check_interval_s"], O.dt)
        k = 0
        while k < steps:
            if k % ctrl == 0:
                self.control()
            # run up to the next servo update or guard check, whichever comes first
            n = min((k // ctrl + 1) * ctrl, (k // chk + 1) * chk, steps) - k
            yield n
            k += n
            if k % chk == 0:
                self.scene.check()
                self.check()
                if every is not None:
                    every(O.time)


def load_to(scene, plate, stress_pa, tolerance_ratio, max_time_s=None, every=None):
    """Servo the plate to stress_pa until the stress is within tolerance_ratio of it and
    the bulk is at rest (scene.is_at_rest). Holds the plate and returns the record.
    every(t), if given, is called at each guard check (e.g. to erase particles that
    fell off an open table)."""
    if stress_pa <= 0:
        raise RigFailure(f"load_to: target stress {stress_pa} Pa must be > 0 (use release to unload fully)")
    if max_time_s is None:
        max_time_s = scene.num["max_settle_time_s"]
    t0, it0 = O.time, O.iter
    interval = scene.num["rest_check_interval_s"]
    plate.set_target(stress_pa, deadband_ratio=0.5 * tolerance_ratio)
    while True:
        yield from plate.run(interval, every)
        s = plate.stress_pa()
        if (plate.velocity == 0.0 and abs(s - stress_pa) <= tolerance_ratio * stress_pa
                and scene.is_at_rest()):
            plate.hold()
            return {"stress_pa": s, "force_n": plate.force_n(), "position_m": plate.position_m(),
                    "time_s": O.time - t0, "steps": O.iter - it0, "contacts_count": plate.n_contacts()}
        if O.time - t0 > max_time_s:
            msg = (f"load to {stress_pa:g} Pa: not reached at rest after {max_time_s:g} s of simulated time "
                   f"(stress {s:.5g} Pa, tolerance {tolerance_ratio:g}, plate at z={plate.position_m():.4f} m "
                   f"moving {plate.velocity:.3g} m/s, {plate.n_contacts()} plate contacts, kinetic energy ratio "
                   f"{scene.kinetic_energy_ratio():.3g}, unbalanced force ratio {scene.unbalanced_force_ratio():.3g})")
            plate.hold()
            raise NoRestUnderLoad(msg)


def release(scene, plate, clearance_m, max_time_s=None):
    """Lift the plate at its speed limit until it has no contact and its underside is
    clearance_m above the highest particle top; then hold it and settle the bulk."""
    if max_time_s is None:
        max_time_s = scene.num["max_settle_time_s"]
    t0 = O.time
    plate.hold()
    interval = scene.num["rest_check_interval_s"]
    while True:
        top = max(b.state.pos[2] + b.shape.radius for b in scene.live_spheres())
        if plate.n_contacts() == 0 and plate.position_m() >= top + clearance_m:
            break
        if O.time - t0 > max_time_s:
            raise RigFailure(f"release: the plate is still in contact after {max_time_s:g} s")
        plate._set_velocity(plate.vmax)
        yield from plate.run(interval)
    plate.hold()
    t_settle = yield from scene.settle("release")
    return {"position_m": plate.position_m(), "time_s": O.time - t0, "settle_time_s": t_settle}
