"""The first contact law of the project, `linear_cundall` (runs inside YADE). Kept under its
own name for comparison and to reproduce old results; the default is contact_hertz.

Contact law: linear spring, Coulomb friction, elastic-plastic rolling resistance and
fragile cohesion: `CohFrictMat` + `Ip2_CohFrictMat_CohFrictMat_CohFrictPhys` +
`Law2_ScGeom6D_CohFrictPhys_CohesionMoment` (always_use_moment_law, incremental form): a
rolling law that holds a static heap and acts exactly on facets too, but without any
contact dashpot.

Mapping of config values (SI) to YADE:
- Young's modulus E, radius R: normal stiffness kn = 2 Ea Ra Eb Rb / (Ea Ra + Eb Rb)
  (sphere-sphere of one material: E R; sphere on a facet of a much stiffer wall: ~2 E R).
- Poisson ratio nu -> YADE's `poisson` (which is the ratio ks/kn, not Poisson's ratio):
  ks/kn = 2 (1 - nu) / (2 - nu), the Mindlin no-slip ratio.
- friction_coefficient mu per pair -> frictAngle MatchMaker atan(mu).
- rolling_resistance_coefficient eta per pair: moment limit = eta x R x |Fn|; YADE takes
  min(etaRoll_a x Ra, etaRoll_b x Rb) with Rb = 2 R on facets, so walls get etaRoll =
  eta / 2 and a pair whose requested value cannot be realised is an error
  (pycal.contact_rules checks it when the job is made).
  Twisting (spin about the contact normal) gets the same coefficient and stiffness
  factor: without it a particle on one contact spins for ever (zero torque is not damped).
- restitution e (one value for every pair of the scene): this law has no contact
  dashpot; e is realised by Cundall's
  non-viscous damping a of the net force: e = sqrt((1 - a) / (1 + a)) <=>
  a = (1 - e^2) / (1 + e^2) (checked by a drop test). Gravity is damped too
  (dampGravity=True): with gravity excluded, a resting particle's contact force sat
  up to +-a away from its weight in a tiny limit cycle (measured 0.34 N vs 0.22 N),
  which would corrupt every force measurement. Side effect (docs/contact-models.md): free
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
                          Law2_ScGeom6D_CohFrictPhys_CohesionMoment, Bo1_Sphere_Aabb, Bo1_Facet_Aabb,
                          Ig2_Sphere_Sphere_ScGeom6D, Ig2_Facet_Sphere_ScGeom6D)

from .contact_base import PairTable
from .jobio import RigFailure

WALL_RADIUS_FACTOR = 2.0   # YADE's facet-sphere ScGeom uses 2 x the sphere radius for the facet


def shear_ratio(nu):
    """ks/kn of a linear contact from Poisson's ratio nu (Mindlin no-slip)."""
    return 2.0 * (1.0 - nu) / (2.0 - nu)


def damping_from_restitution(e):
    """Cundall damping coefficient that gives restitution e on a linear contact."""
    return (1.0 - e * e) / (1.0 + e * e)


class LinearCundallContactModel(PairTable):
    """Creates the YADE materials of a job and the per-pair contact parameters of the
    linear_cundall law. Attributes: mat_id[name] -> YADE material id."""

    law_name = "linear_cundall"

    def __init__(self, job, gravity=9.81):
        super().__init__(job, gravity)
        self._build()

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

    def _build(self):
        for name, p in self.particles.items():
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
            # rolling of a wall: the largest value a particle material asks for (see wall_eta);
            # pycal.contact_rules refused the job if a pair cannot be realised this way
            eta = self.wall_eta(bname)
            m = CohFrictMat(young=b["youngs_modulus_pa"], poisson=shear_ratio(b["poisson_ratio"]),
                            density=b["density_kg_m3"], frictionAngle=0.0, etaRoll=eta,
                            alphaKr=2.0, etaTwist=eta, alphaKtw=2.0, momentRotationLaw=True,
                            isCohesive=True, fragile=True, normalCohesion=0, shearCohesion=0,
                            label=bname)
            self.mat_id[bname] = O.materials.append(m)

    def cohesion_force(self, a, b):
        """Pull-off force (N) of a bond between particle material a and partner b (force_fraction
        model; the hysteretic subclass adds its own)."""
        coh = self.pair(a, b)["cohesion"]
        if coh["model"] == "none":
            return 0.0
        if coh["model"] != "force_fraction":
            raise RigFailure(f"materials.{a}.interactions.{b}.cohesion.model: {coh['model']!r} "
                             "is not available in this contact law")
        # a clump partner acts like a wall: the pull-off is force_fraction x the weight of the
        # sphere particle (the method: fines-gravel adhesion = fines-wall adhesion). YADE's
        # bond is cohesion x min(R_sphere, r_member)^2 with cohesion = F / R_sphere^2, so it
        # is exact on members at least as large as the sphere and (r_member / R_sphere)^2
        # of F on smaller ones.
        masses = [self.particle_mass(n) for n in (a, b) if n in self.particles and not self.is_clump(n)]
        if not masses:
            raise RigFailure(f"materials.{a}.interactions.{b}.cohesion: cohesion without a sphere material "
                             "in the pair (clump - clump or clump - wall) is not supported")
        return coh["force_fraction"] * min(masses) * self.gravity

    def ip2_functors(self):
        """The Ip2 functor with per-pair friction and cohesion MatchMakers."""
        coh = []
        for a, b in self.pair_names():
            if self.is_boundary_pair(a, b):
                # boundary pairs (e.g. a rig's guide sphere on a facet): the cohesion MatchMakers
                # have no fallback value and an unlisted pair aborts YADE
                coh.append((self.mat_id[a], self.mat_id[b], 0.0))
                continue
            # YADE: adhesion = cohesion x min(R1, R2)^2 (facet radius is 2R, so min is R)
            coh.append((self.mat_id[a], self.mat_id[b], self.cohesion_force(a, b) / self._bond_radius(a, b) ** 2))
        return [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(
            setCohesionOnNewContacts=True,
            frictAngle=MatchMaker(matches=self.friction_matches(), algo="avg"),
            normalCohesion=MatchMaker(matches=coh, algo="avg"),
            shearCohesion=MatchMaker(matches=coh, algo="avg"))]

    def law2(self):
        return Law2_ScGeom6D_CohFrictPhys_CohesionMoment(always_use_moment_law=True,
                                                        useIncrementalForm=True)

    def bounding_functors(self):
        return [Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()]

    def geometry_functors(self):
        return [Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Facet_Sphere_ScGeom6D()]

    def damping(self):
        """Cundall damping realising the scene's one restitution (contact_rules checked it is one)."""
        e = next(p["restitution_coefficient"] for _, p in self._particle_pairs())
        return damping_from_restitution(e)

    def _particle_pairs(self):
        for a, b in self.pair_names():
            if not self.is_boundary_pair(a, b):
                yield (a, b), self.pair(a, b)

    @property
    def damp_gravity(self):
        return True
