"""Materials and the contact law, built from the job (runs inside YADE).

Contact law: linear spring, Coulomb friction, elastic-plastic rolling resistance and
fragile cohesion: `CohFrictMat` + `Ip2_CohFrictMat_CohFrictMat_CohFrictPhys` +
`Law2_ScGeom6D_CohFrictPhys_CohesionMoment` (always_use_moment_law, incremental form).
yade-notes.md: this is the rolling law that holds a static heap and acts exactly on
facets too.

Mapping of config values (SI) to YADE:
- Young's modulus E, radius R: normal stiffness kn = 2 Ea Ra Eb Rb / (Ea Ra + Eb Rb)
  (sphere-sphere of one material: E R; sphere on a facet of a much stiffer wall: ~2 E R).
- Poisson ratio nu -> YADE's `poisson` (which is the ratio ks/kn, not Poisson's ratio):
  ks/kn = 2 (1 - nu) / (2 - nu), the Mindlin no-slip ratio.
- friction_coefficient mu per pair -> frictAngle MatchMaker atan(mu).
- rolling_resistance_coefficient eta per pair: moment limit = eta x R x |Fn|; YADE takes
  min(etaRoll_a x Ra, etaRoll_b x Rb) with Rb = 2 R on facets, so walls get etaRoll =
  eta / 2 and a pair whose requested value cannot be realised is an error.
  Twisting (spin about the contact normal) gets the same coefficient and stiffness
  factor: without it a particle on one contact spins for ever (zero torque is not damped).
- restitution e: this law has no contact dashpot; e is realised by Cundall's
  non-viscous damping a of the net force: e = sqrt((1 - a) / (1 + a)) <=>
  a = (1 - e^2) / (1 + e^2) (checked by a drop test). Gravity is damped too
  (dampGravity=True): with gravity excluded, a resting particle's contact force sat
  up to +-a away from its weight in a tiny limit cycle (measured 0.34 N vs 0.22 N),
  which would corrupt every force measurement. Side effect, stated in the README: free
  fall and flow accelerate at (1 - a) g; e = 0.3 gives a = 0.835.
- cohesion `force_fraction` f per pair: a bond forms at each new contact with pull-off
  force and shear strength f x (weight of the lighter particle); it breaks once
  (fragile) and forms again at the next new contact.
- clump materials (`shape: clump`, the M1 lumps of demlib.clumps): the member spheres
  carry the material; rolling resistance must be 0 on every pair with them; cohesion
  with a sphere partner acts as with a wall (force_fraction x the sphere's weight).
"""
import math

from yade import O
from yade.wrapper import (CohFrictMat, MatchMaker, Ip2_CohFrictMat_CohFrictMat_CohFrictPhys,
                          Law2_ScGeom6D_CohFrictPhys_CohesionMoment)

from .jobio import RigFailure

WALL_RADIUS_FACTOR = 2.0   # YADE's facet-sphere ScGeom uses 2 x the sphere radius for the facet


def shear_ratio(nu):
    """ks/kn of a linear contact from Poisson's ratio nu (Mindlin no-slip)."""
    return 2.0 * (1.0 - nu) / (2.0 - nu)


def damping_from_restitution(e):
    """Cundall damping coefficient that gives restitution e on a linear contact."""
    return (1.0 - e * e) / (1.0 + e * e)


class ContactModel:
    """Creates the YADE materials of a job and the per-pair contact parameters.

    Attributes: mat_id[name] -> YADE material id, for particle materials and boundaries.
    """

    def __init__(self, job, gravity=9.81):
        self.job = job
        self.gravity = gravity
        self.particles = job["materials"]
        self.boundaries = job["boundaries"]
        self.mat_id = {}
        self._build()

    def radius(self, name):
        """Particle radius of a sphere material (m)."""
        return 0.5 * self.particles[name]["particles"]["diameter_m"]

    def is_clump(self, name):
        """True for a particle material made of clumps of spheres (M1 lumps, demlib.clumps)."""
        return name in self.particles and self.particles[name]["particles"]["shape"] == "clump"

    def wall_eta(self, bname):
        """etaRoll of a boundary: the largest rolling coefficient any particle material asks
        for on it, halved (facet radius 2R). With one particle material this is that
        material's value; a material asking less must have its own etaRoll at its value."""
        return max(self.pair(n, bname)["rolling_resistance_coefficient"] for n in self.particles) / WALL_RADIUS_FACTOR

    def _bond_radius(self, a, b):
        """Radius r of YADE's bond strength cohesion x r^2 for the pair a - b: the smaller
        sphere radius of the pair (facets: 2R; clumps: see cohesion_force); 1 when
        neither side is a sphere material (no cohesion allowed there)."""
        radii = [self.radius(n) for n in (a, b) if n in self.particles and not self.is_clump(n)]
        return min(radii) if radii else 1.0

    def particle_mass(self, name):
        r = self.radius(name)
        return self.particles[name]["particles"]["density_kg_m3"] * 4.0 / 3.0 * math.pi * r ** 3

    def pair(self, a, b):
        """Interaction properties of particle material a with partner b (material or boundary)."""
        if a in self.particles and b in self.particles[a]["interactions"]:
            return self.particles[a]["interactions"][b]
        if b in self.particles and a in self.particles[b]["interactions"]:
            return self.particles[b]["interactions"][a]
        raise RigFailure(f"no interaction properties for the pair {a} - {b}")

    def _build(self):
        names = list(self.particles)
        for name in names:
            p = self.particles[name]
            if p["particles"]["shape"] not in ("sphere", "clump"):
                raise RigFailure(f"material {name}: shape {p['particles']['shape']!r} is not supported by this rig")
            c = p["contact"]
            self_pair = self.pair(name, name)
            m = CohFrictMat(young=c["youngs_modulus_pa"], poisson=shear_ratio(c["poisson_ratio"]),
                            density=p["particles"]["density_kg_m3"],
                            frictionAngle=math.atan(self_pair["friction_coefficient"]),
                            etaRoll=self_pair["rolling_resistance_coefficient"], alphaKr=2.0,
                            etaTwist=self_pair["rolling_resistance_coefficient"], alphaKtw=2.0, momentRotationLaw=True,
                            isCohesive=True, fragile=True, normalCohesion=0, shearCohesion=0,
                            label=name)
            self.mat_id[name] = O.materials.append(m)
        for bname, b in self.boundaries.items():
            # rolling of a wall: the largest value a particle material asks for (see wall_eta)
            eta = self.wall_eta(bname)
            m = CohFrictMat(young=b["youngs_modulus_pa"], poisson=shear_ratio(b["poisson_ratio"]),
                            density=b["density_kg_m3"], frictionAngle=0.0, etaRoll=eta,
                            alphaKr=2.0, etaTwist=eta, alphaKtw=2.0, momentRotationLaw=True,
                            isCohesive=True, fragile=True, normalCohesion=0, shearCohesion=0,
                            label=bname)
            self.mat_id[bname] = O.materials.append(m)
        self._check_rolling()

    def _check_rolling(self):
        """Every requested per-pair rolling coefficient must be what YADE will use."""
        names = list(self.particles)
        # clump materials: member radii vary, so only rolling resistance 0 has one meaning
        # (YADE's min(eta_a R_a, eta_b R_b) is 0 whatever the radii): the clump's own value
        # and every pair value with it, asked from either side, must be 0
        for a in names:
            if not self.is_clump(a):
                continue
            for b in names + list(self.boundaries):
                for x, y in ((a, b), (b, a)):
                    if x in self.particles and y in self.particles[x]["interactions"] and \
                            self.particles[x]["interactions"][y]["rolling_resistance_coefficient"] != 0:
                        raise RigFailure(
                            f"materials.{x}.interactions.{y}.rolling_resistance_coefficient: "
                            f"{self.particles[x]['interactions'][y]['rolling_resistance_coefficient']} cannot be "
                            f"realised: {a} is made of clumps, which take rolling resistance 0 (the shape does it)")
        for a in names:
            if self.is_clump(a):
                continue
            ra = self.radius(a)
            eta_a = self.pair(a, a)["rolling_resistance_coefficient"]
            for b in list(self.particles) + list(self.boundaries):
                if self.is_clump(b):
                    continue
                want = self.pair(a, b)["rolling_resistance_coefficient"]
                if b in self.particles:
                    rb, eta_b = self.radius(b), self.pair(b, b)["rolling_resistance_coefficient"]
                else:
                    rb = WALL_RADIUS_FACTOR * ra
                    eta_b = self.wall_eta(b)
                got = min(eta_a * ra, eta_b * rb) / min(ra, rb)
                if abs(got - want) > 1e-9:
                    raise RigFailure(
                        f"materials.{a}.interactions.{b}.rolling_resistance_coefficient: {want} cannot be "
                        f"realised by the rolling law (YADE uses min of both sides: {got:.4g}); "
                        f"a pair's value must not exceed either material's own value")

    def cohesion_force(self, a, b):
        """Pull-off force (N) of a bond between particle material a and partner b."""
        coh = self.pair(a, b)["cohesion"]
        if coh["model"] == "none":
            return 0.0
        if coh["model"] != "force_fraction":
            raise RigFailure(f"materials.{a}.interactions.{b}.cohesion.model: {coh['model']!r} "
                             "is not available in this contact law")
        if coh["adhesive_distance_m"] > 0:
            raise RigFailure(f"materials.{a}.interactions.{b}.cohesion.adhesive_distance_m: "
                             f"{coh['adhesive_distance_m']} > 0 is not supported by the fragile-bond law "
                             "(bonds act in contact only); set it to 0")
        # a clump partner acts like a wall: the pull-off is force_fraction x the weight of the
        # sphere particle (method.md: fines-gravel adhesion = fines-wall adhesion). YADE's
        # bond is cohesion x min(R_sphere, r_member)^2 with cohesion = F / R_sphere^2, so it
        # is exact on members at least as large as the sphere and (r_member / R_sphere)^2
        # of F on smaller ones.
        masses = [self.particle_mass(n) for n in (a, b) if n in self.particles and not self.is_clump(n)]
        if not masses:
            raise RigFailure(f"materials.{a}.interactions.{b}.cohesion: cohesion without a sphere material "
                             "in the pair (clump - clump or clump - wall) is not supported")
        return coh["force_fraction"] * min(masses) * self.gravity

    def ip2(self):
        """The Ip2 functor with per-pair friction and cohesion MatchMakers."""
        fric, coh = [], []
        names = list(self.particles)
        partners = names + list(self.boundaries)
        for i, a in enumerate(names):
            for b in partners:
                if b in names and names.index(b) < i:
                    continue
                ia, ib = self.mat_id[a], self.mat_id[b]
                fric.append((ia, ib, math.atan(self.pair(a, b)["friction_coefficient"])))
                r = self._bond_radius(a, b)
                # YADE: adhesion = cohesion x min(R1, R2)^2 (facet radius is 2R, so min is R)
                coh.append((ia, ib, self.cohesion_force(a, b) / r ** 2))
        # boundary-boundary pairs (e.g. a rig's guide sphere on a facet): frictionless, no
        # cohesion. They must be listed: the cohesion MatchMakers have no fallback value and
        # an unlisted pair aborts YADE ("MatchMaker: no match for (i,j)").
        bnames = list(self.boundaries)
        for i, a in enumerate(bnames):
            for b in bnames[i:]:
                fric.append((self.mat_id[a], self.mat_id[b], 0.0))
                coh.append((self.mat_id[a], self.mat_id[b], 0.0))
        return Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(
            setCohesionOnNewContacts=True,
            frictAngle=MatchMaker(matches=fric, algo="avg"),
            normalCohesion=MatchMaker(matches=coh, algo="avg"),
            shearCohesion=MatchMaker(matches=coh, algo="avg"))

    def law2(self):
        return Law2_ScGeom6D_CohFrictPhys_CohesionMoment(always_use_moment_law=True,
                                                        useIncrementalForm=True)

    def damping(self):
        """Cundall damping realising the restitution of the (first) particle material."""
        es = {self.particles[n]["contact"]["restitution"] for n in self.particles}
        if len(es) > 1:
            raise RigFailure(f"one restitution per scene is supported (damping is global): {sorted(es)}")
        return damping_from_restitution(es.pop())
