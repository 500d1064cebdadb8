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
            if p["particles"]["shape"] != "sphere":
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
            # rolling of a wall: the first particle material that touches it sets etaRoll
            eta = self.pair(names[0], bname)["rolling_resistance_coefficient"] / WALL_RADIUS_FACTOR
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
        for a in names:
            ra = self.radius(a)
            eta_a = self.pair(a, a)["rolling_resistance_coefficient"]
            for b in list(self.particles) + list(self.boundaries):
                want = self.pair(a, b)["rolling_resistance_coefficient"]
                if b in self.particles:
                    rb, eta_b = self.radius(b), self.pair(b, b)["rolling_resistance_coefficient"]
                else:
                    rb = WALL_RADIUS_FACTOR * ra
                    eta_b = self.pair(names[0], b)["rolling_resistance_coefficient"] / WALL_RADIUS_FACTOR
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
        masses = [self.particle_mass(n) for n in (a, b) if n in self.particles]
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
                r = min(self.radius(a), self.radius(b) if b in self.particles else self.radius(a))
                # YADE: adhesion = cohesion x min(R1, R2)^2 (facet radius is 2R, so min is R)
                coh.append((ia, ib, self.cohesion_force(a, b) / r ** 2))
        # boundary-boundary pairs (e.g. a sliding cell on a plate): frictionless unless a rig says otherwise
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
