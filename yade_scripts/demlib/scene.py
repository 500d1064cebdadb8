"""Scene building shared by every rig (runs inside YADE).

World: the YADE scene itself (materials and contact law, engines, gravity, time step),
one per process. Scene: one copy of a rig in it (its bodies, rest criterion and blow-up
guards), placed at `origin`; a lone job has one, a batch job one per seed (the
replicas of demlib.replicas, side by side along x, each its own collision group). Every
number comes from the job; nothing is defaulted here. Rig phases are generators
(demlib.phases): Scene.settle, Scene.run_for.
"""
import math
import random

from yade import O, utils, geom, pack
from yade.wrapper import ForceResetter, InsertionSortCollider, InteractionLoop, NewtonIntegrator
from yade import Vector3

from .contact_models import make_contact_model
from .jobio import RigFailure, OverlapLimitExceeded
from . import vtk_output
from .phase_clock import CLOCK
from .phases import Barrier, steps_of


class World:
    """The YADE scene of a process: O.reset(), the contact law of the job's materials, the
    engines, gravity.

    Several Scenes (replicas) may share it: each owns a collision group (Body.mask bit:
    bodies of different replicas never interact) and `owner` maps a body id to the
    replica's index. interactions_of(index) gives a replica's real contacts."""

    def __init__(self, job):
        self.num = job["rig_config"]["numerics"]
        self.g = self.num["gravity_m_s2"]
        vtk_output.end_scene()       # a world before this one (a fresh fill per step, a sequential replica) writes its last snapshot
        O.reset()
        self.contact = make_contact_model(job, gravity=self.g)   # the law of pycal.contact_rules.law_of_job
        self.newton = NewtonIntegrator(gravity=(0, 0, -self.g), damping=self.contact.damping(),
                                       dampGravity=self.contact.damp_gravity, label="newton")
        O.engines = [
            ForceResetter(),
            InsertionSortCollider(self.contact.bounding_functors(), label="collider"),
            InteractionLoop(self.contact.geometry_functors(), self.contact.ip2_functors(), [self.contact.law2()]),
        ] + self.contact.extra_engines() + [self.newton]
        vtk_output.begin_scene(job)  # VTK snapshots for ParaView when the job asks for them (--vtk)
        self.owner = {}              # body id -> replica index
        self.shared = False          # several replicas (demlib.replicas.run_batch)
        self.erased_count = 0        # bodies erased so far (invalidates the contacts sorted by replica)
        self._by_owner_key = None
        self._by_owner = {}

    def claim(self, index, first_id):
        """Bodies from id first_id on (just made by replica `index`) join its collision group."""
        mask = 1 << index
        for i in range(first_id, len(O.bodies)):
            b = O.bodies[i]
            if b is not None and i not in self.owner:
                b.mask = mask
                self.owner[i] = index

    def interactions_of(self, index):
        """The real interactions of replica `index` (all of them in a lone world); one pass
        over O.interactions per time step, shared by the replicas that ask."""
        if not self.shared:
            return [i for i in O.interactions if i.isReal]
        key = (O.iter, self.erased_count)
        if self._by_owner_key != key:
            by = {}
            owner = self.owner
            for i in O.interactions:
                if i.isReal:
                    by.setdefault(owner.get(i.id1, owner.get(i.id2)), []).append(i)
            self._by_owner, self._by_owner_key = by, key
        return self._by_owner.get(index, [])

    def erase(self, ids):
        """Erase bodies (a clump with its members)."""
        for i in ids:
            b = O.bodies[i]
            if b is not None:
                O.bodies.erase(i, b.isClump)
        self.erased_count += 1

    def retire(self, index):
        """Erase every body of replica `index` (it has finished or failed): the others go on
        without paying for it."""
        ids = sorted(i for i, k in self.owner.items() if k == index)
        clumps = [i for i in ids if O.bodies[i] is not None and O.bodies[i].isClump]
        self.erase(clumps + [i for i in ids if i not in clumps])
        for i in ids:
            del self.owner[i]

    def set_timestep(self):
        """dt = timestep_safety_factor x critical P-wave step of every particle of the world (s)."""
        dt = self.num["timestep_safety_factor"] * utils.PWaveTimeStep()
        if not (0 < dt < 1e-2):
            raise RigFailure(f"time step {dt} s is not plausible (are there particles?)")
        O.dt = dt
        return dt


class Scene:
    """One rig (a replica) in a World: its bodies, rest criterion and guards.

    job: the job of this rig and seed; world: the World it shares (default: a new one,
    the lone scene of a process); origin: where its rig axis stands (m); index: its
    collision group. Geometry helpers take coordinates relative to the origin;
    particle_positions() gives them relative to it too.
    numerics: the job's `rig_config.numerics` (time step factor, rest thresholds, guards).
    """

    def __init__(self, job, world=None, origin=(0.0, 0.0, 0.0), index=0):
        self.job = job
        self.rig = job["rig_config"]
        self.num = self.rig["numerics"]
        self.g = self.num["gravity_m_s2"]
        self.material = job["material"]
        if world is None:
            world = World(job)
            random.seed(job["seed"])
        self.world = world
        self.index = index
        self.origin = Vector3(*origin)
        self.contact = world.contact
        self.newton = world.newton
        self.radius = self.length_scale()
        self.sphere_ids = []
        self.box_min = Vector3(-1, -1, -1)   # rig's bounding box for the escape guard (set by geometry)
        self.box_max = Vector3(1, 1, 1)
        self.n_guard_checks = 0

    def length_scale(self):
        """Particle radius (m) that scales the rest criterion and the guards."""
        return self.contact.radius(self.material)

    # ---------- geometry ----------
    def at(self, x, y, z):
        """A point given relative to the scene's origin, in world coordinates (m)."""
        o = self.origin
        return Vector3(o[0] + x, o[1] + y, o[2] + z)

    def add_cylinder(self, diameter, height, segments, material, z0=0.0):
        """Side wall of a cylinder (facets), axis z through the origin, bottom edge at z0.
        Returns facet ids."""
        facets = geom.facetCylinder(self.at(0, 0, z0 + height / 2.0), diameter / 2.0, height,
                                    segmentsNumber=segments, wallMask=4,
                                    material=self.contact.mat_id[material])
        return O.bodies.append(facets)

    def add_table(self, half_width, material, z=0.0):
        """Square horizontal plate (two facets) at height z. Returns facet ids."""
        facets = geom.facetBox(self.at(0, 0, z), (half_width, half_width, 0), wallMask=1,
                               material=self.contact.mat_id[material])
        return O.bodies.append(facets)

    def set_domain(self, lo, hi):
        """Bounding box of the rig (m); particles beyond it plus the margin have escaped."""
        m = self.num["domain_margin_m"]
        self.box_min = self.at(*lo) - Vector3(m, m, m)
        self.box_max = self.at(*hi) + Vector3(m, m, m)

    # ---------- particles ----------
    def pour_cloud(self, diameter, z_bottom, column_height, porosity):
        """Loose non-overlapping random spheres in a vertical cylinder of the given
        diameter (m) from z_bottom up (m), seeded by the job's seed. Returns their ids."""
        r = self.radius
        inner = diameter / 2.0 - r * 1.01
        sp = pack.SpherePack()
        lo = self.at(-inner - r, -inner - r, z_bottom)
        hi = self.at(inner + r, inner + r, z_bottom + column_height)
        volume_box = (hi - lo)[0] * (hi - lo)[1] * (hi - lo)[2]
        n_max = int((1.0 - porosity) * volume_box / (4.0 / 3.0 * math.pi * r ** 3))
        sp.makeCloud(lo, hi, rMean=r, rRelFuzz=0.0, num=max(n_max, 1), seed=self.job["seed"] + 1)
        mat = self.contact.mat_id[self.material]
        ids = []
        ox, oy = self.origin[0], self.origin[1]
        for centre, rad in sp:
            if math.hypot(centre[0] - ox, centre[1] - oy) <= inner and centre[2] - rad >= z_bottom:
                ids.append(O.bodies.append(utils.sphere(centre, rad, material=mat)))
        if not ids:
            raise RigFailure("pour: no particle fits in the pour column")
        self.sphere_ids.extend(ids)
        return ids

    def remove_spheres(self, ids):
        ids = set(ids)
        for i in ids:
            O.bodies.erase(i)
        self.world.erased_count += 1
        self.sphere_ids = [i for i in self.sphere_ids if i not in ids]

    def live_spheres(self):
        return [O.bodies[i] for i in self.sphere_ids if O.bodies[i] is not None]

    # ---------- time step, rest, guards ----------
    def set_timestep(self):
        """dt = timestep_safety_factor x critical P-wave step of the particles (s), set now
        (a lone scene; a replica procedure yields timestep() instead)."""
        return self.world.set_timestep()

    def timestep(self):
        """The Barrier that sets the time step once every replica has its particles: a
        procedure does `dt = yield scene.timestep()`."""
        return Barrier(self.world.set_timestep)

    def kinetic_energy_ratio(self):
        """Kinetic energy of the particles / (their weight x one diameter) (-); of
        translation only if the rig's numerics say rest_kinetic_energy: translational
        (pycal.configs.NUMERICS_CHOICES)."""
        spheres = self.live_spheres()
        if not spheres:
            return 0.0
        rotation = self.num["rest_kinetic_energy"] == "total"
        ke = sum(0.5 * b.state.mass * b.state.vel.squaredNorm()
                 + (0.5 * sum(b.state.inertia[k] * b.state.angVel[k] ** 2 for k in range(3)) if rotation else 0.0)
                 for b in spheres)
        ref = sum(b.state.mass for b in spheres) * self.g * 2.0 * self.radius
        return ke / ref

    def unbalanced_force_ratio(self):
        """Mean |contact force + weight| of the particles / mean contact force (-).
        (YADE's utils.unbalancedForce leaves out NewtonIntegrator's gravity.)"""
        forces = [i.phys.normalForce.norm() for i in self.interactions()]
        mean_contact = sum(forces) / len(forces) if forces else 0.0
        if mean_contact == 0.0:
            return 0.0
        grav = self.newton.gravity
        # with global damping a of the contact forces only (gravity undamped), a body at rest
        # is held by (1 - a) x its contact force: that is the force to balance against gravity
        held = 1.0 - self.newton.damping if not self.newton.dampGravity else 1.0
        bodies = self.dynamic_bodies()
        resid = sum((held * self.body_force(b) + grav * b.state.mass).norm() for b in bodies) / len(bodies)
        return resid / mean_contact

    def dynamic_bodies(self):
        """The bodies that move freely (here the particle spheres)."""
        return self.live_spheres()

    def body_force(self, body):
        """Contact force on a body of dynamic_bodies() (N)."""
        return O.forces.f(body.id)

    def is_at_rest(self):
        if self.kinetic_energy_ratio() > self.num["rest_kinetic_energy_ratio"]:
            return False
        return self.unbalanced_force_ratio() < self.num["rest_unbalanced_force_ratio"]

    def check(self):
        """Blow-up guard: NaN, escape from the rig's box, overlap beyond the limit."""
        self.n_guard_checks += 1
        for b in self.live_spheres():
            p = b.state.pos
            if any(math.isnan(x) or math.isinf(x) for x in p):
                raise RigFailure(f"blow-up: particle {b.id} has position {p} at t={O.time:.4f} s")
            if any(p[k] < self.box_min[k] or p[k] > self.box_max[k] for k in range(3)):
                raise RigFailure(f"blow-up: particle {b.id} left the rig domain at {tuple(round(x, 4) for x in p)} "
                                 f"(t={O.time:.4f} s): it escaped or passed through a wall")
        for i in self.interactions():
            if i.geom.penetrationDepth > self.overlap_limit_m(i):
                raise OverlapLimitExceeded(f"blow-up: overlap {i.geom.penetrationDepth:.3g} m between bodies {i.id1} and "
                                 f"{i.id2} exceeds {self.num['max_overlap_fraction']} x radius at t={O.time:.4f} s "
                                 "(particles pass through each other or a wall)")

    def interactions(self):
        """The real interactions (contacts) of this rig's bodies."""
        return self.world.interactions_of(self.index)

    def overlap_limit_m(self, interaction):
        """Largest overlap (m) the guard accepts on a contact: max_overlap_fraction x radius."""
        return self.num["max_overlap_fraction"] * self.radius

    @staticmethod
    def advance(steps):
        """Run `steps` time steps now. O.step() in a loop: O.run(n, True) costs a fixed
        ~8-40 ms per call for its wait (measured 27 % of a 250-step chunk)."""
        CLOCK.steps(steps)

    def run_for(self, seconds, every=None):
        """Phase (generator): advance simulated time by `seconds`, checking the guards every
        rest interval. `every(t)` is called at each check if given."""
        chunk = steps_of(self.num["rest_check_interval_s"], O.dt)
        steps = int(math.ceil(seconds / O.dt))
        done = 0
        while done < steps:
            n = min(chunk, steps - done)
            yield n
            done += n
            self.check()
            if every is not None:
                every(O.time)

    def settle(self, what="settle"):
        """Phase (generator): run until at rest (kinetic energy and unbalanced force below the
        thresholds). Returns the simulated time it took (s)."""
        t0 = O.time
        chunk = steps_of(self.num["rest_check_interval_s"], O.dt)
        while True:
            yield chunk
            self.check()
            if self.is_at_rest():
                return O.time - t0
            if O.time - t0 > self.num["max_settle_time_s"]:
                raise RigFailure(f"{what}: no rest after {self.num['max_settle_time_s']} s of simulated time "
                                 f"(kinetic energy ratio {self.kinetic_energy_ratio():.3g}, "
                                 f"unbalanced force ratio {self.unbalanced_force_ratio():.3g})")

    # ---------- measurements ----------
    def particle_mass_total(self):
        return sum(b.state.mass for b in self.live_spheres())

    def particle_positions(self):
        """[(x, y, z, r)] of the live particles (m), relative to the scene's origin."""
        o = self.origin
        return [(b.state.pos[0] - o[0], b.state.pos[1] - o[1], b.state.pos[2] - o[2], b.shape.radius)
                for b in self.live_spheres()]
