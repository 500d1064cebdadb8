"""What every contact law of a scene needs from the job (runs inside YADE; no YADE import
here): the particle materials and boundaries, their per-pair properties, radii, masses.

Each law (contact_hertz, contact_linear, contact_capillary) subclasses PairTable and
offers the interface Scene builds its engines from:
    mat_id[name]             YADE material id of a particle material or a boundary
    law_name                 the name recorded in result.json (pycal.contact_rules)
    ip2_functors(), law2()   the InteractionLoop physics and law functors
    bounding_functors(), geometry_functors(), extra_engines()
    damping(), damp_gravity  NewtonIntegrator's global damping and whether it acts on gravity
"""
import math

from pycal import contact_rules

from .jobio import RigFailure


class PairTable:
    """The job's materials and boundaries, and the properties of each pair."""

    law_name = None

    def __init__(self, job, gravity=9.81):
        self.job = job
        self.gravity = gravity
        self.particles = job["materials"]
        self.boundaries = job["boundaries"]
        self.numerics = job["rig_config"]["numerics"]
        self.mat_id = {}
        try:
            contact_rules.check_job(job)
        except contact_rules.ContactRuleError as exc:
            raise RigFailure(f"contact law: {exc}") from None
        for name, p in self.particles.items():
            if p["particles"]["shape"] not in ("sphere", "clump"):
                raise RigFailure(f"material {name}: shape {p['particles']['shape']!r} is not supported")

    def radius(self, name):
        """Particle radius of a sphere material (m)."""
        return 0.5 * self.particles[name]["particles"]["diameter_m"]

    def is_clump(self, name):
        """True for a particle material made of clumps of spheres (M1 lumps, demlib.clumps)."""
        return name in self.particles and self.particles[name]["particles"]["shape"] == "clump"

    def particle_mass(self, name):
        """Mass of one sphere of a sphere material (kg)."""
        r = self.radius(name)
        return self.particles[name]["particles"]["density_kg_m3"] * 4.0 / 3.0 * math.pi * r ** 3

    def pair(self, a, b):
        """Interaction properties of particle material a with partner b (material or boundary)."""
        if a in self.particles and b in self.particles[a]["interactions"]:
            return self.particles[a]["interactions"][b]
        if b in self.particles and a in self.particles[b]["interactions"]:
            return self.particles[b]["interactions"][a]
        raise RigFailure(f"no interaction properties for the pair {a} - {b}")

    def pair_names(self):
        """Every (a, b) of the scene once: particle materials with each other and with every
        boundary (a a particle material), then boundary - boundary pairs."""
        names, bnames = list(self.particles), list(self.boundaries)
        out = []
        for i, a in enumerate(names):
            out += [(a, b) for b in names[i:] + bnames]
        for i, a in enumerate(bnames):
            out += [(a, b) for b in bnames[i:]]
        return out

    def is_boundary_pair(self, a, b):
        return a in self.boundaries and b in self.boundaries

    def friction_matches(self):
        """[(mat id, mat id, friction angle rad)] of every pair (boundary - boundary: 0; they
        never touch but an unlisted pair would abort YADE's MatchMaker)."""
        out = []
        for a, b in self.pair_names():
            mu = 0.0 if self.is_boundary_pair(a, b) else self.pair(a, b)["friction_coefficient"]
            out.append((self.mat_id[a], self.mat_id[b], math.atan(mu)))
        return out

    def lighter_weight(self, a, b):
        """Weight (N) of the lighter particle of a pair of materials: spheres by their own
        mass; a clump material has no single mass, and a wall is infinitely heavy, so they do
        not count (a lump with a sphere: the sphere's weight). None if neither is a sphere."""
        masses = [self.particle_mass(n) for n in (a, b) if n in self.particles and not self.is_clump(n)]
        return min(masses) * self.gravity if masses else None

    def extra_engines(self):
        return []

    @property
    def damp_gravity(self):
        return False
