"""Liquid bridges: the viscoelastic-capillary contact family (runs inside YADE).

Cohesion model `liquid_bridge` (pycal.contact_rules.COHESION_MODELS), for the pair of a
particle material with itself (fines-fines): ViscElCapMat +
Ip2_ViscElCapMat_ViscElCapMat_ViscElCapPhys + Law2_ScGeom_ViscElCapPhys_Basic with
Willett's bridge force (CapillarType Willett_numeric), built from the job with the
interface of contact_base.PairTable (law `viscoelastic_capillary`). A bridge forms when two particles touch and acts
until their gap exceeds the rupture distance s_c = (1 + theta/2) V_b^(1/3) (Lian):
this is the law's adhesive distance beyond contact.

Parameters (SI):
- surface_tension_n_m gamma: the EFFECTIVE surface tension of the stand-in. Water has
  0.072 N/m; a bridge pulls with about 2 pi R gamma cos(theta), which for a 25 mm sphere
  of 2750 kg/m3 is 2.6 % of its weight, while on real fines of radius r it is
  1.5 gamma / (rho g r^2) times their weight (about 400 at r = 0.1 mm). A bulk of stand-ins
  has the fines' cohesive strength (tensile strength ~ bridge force / d^2, i.e. ~ gamma / d)
  when gamma_eff = gamma_water x (R_stand-in / r_fines): 0.072 x 12.5 / 0.5 = 1.8 N/m for
  1 mm fines (this is the scaling rule; gamma_eff is then tuned like any cohesion value);
- contact_angle_deg theta: wetting angle (0 for water on most minerals);
- bridge_liquid_fraction: share of the moisture held in bridges between particles (the
  rest sits in pores and agglomerates of the real fines);
- coordination_count Z: bridges per particle x 2 (each bridge is shared by two).
  Bridge volume V_b = bridge_liquid_fraction x (w m_p / rho_water) x 2 / Z, with w the
  material's moisture_percent_dry_basis / 100 and m_p the stand-in's (dry) mass.

The family replaces the whole scene's law (a pair of materials must agree on the
capillary settings, so walls carry the same values with Capillar off). What is lost
against the other laws:
- rolling and twisting resistance (every rolling_resistance_coefficient must be 0:
  ViscElMat's mR torque acts only while a particle spins and lets piles creep);
- cohesion/adhesion on any other pair (walls, other materials: model none only);
- restitution per pair: the law's own dashpot (en = et) takes one value per scene;
  NewtonIntegrator damping is 0 here (free fall at g).
Kept: per-pair Coulomb friction (MatchMaker), real Young's modulus and Poisson ratio
of particles and walls.

Known limitation (measured): with bridges the scene's unbalanced-force rest ratio stays
at 0.03 - 0.05 when the bulk is at rest (kinetic energy ratio ~3e-8; 5e-4 with
surface tension 0; a bridge-phase damping dcap = 0.5 or Cundall damping 0.1 did not
change it), so a job of this family needs numerics.rest_unbalanced_force_ratio ~0.08
(rig override) until the cause is found.
"""
import math

from yade import O
from yade.wrapper import (ViscElCapMat, MatchMaker, Ip2_ViscElCapMat_ViscElCapMat_ViscElCapPhys,
                          Law2_ScGeom_ViscElCapPhys_Basic, Bo1_Sphere_Aabb, Bo1_Facet_Aabb,
                          Ig2_Sphere_Sphere_ScGeom, Ig2_Facet_Sphere_ScGeom)

from pycal.contact_rules import CAPILLARY_LAW

from .contact_base import PairTable
from .contact_linear import shear_ratio
from .jobio import RigFailure

WATER_DENSITY_KG_M3 = 1000.0
MODEL = "liquid_bridge"
DETECTION_MARGIN_RATIO = 1.05     # interaction range = 1.05 x the rupture distance


class CapillaryContactModel(PairTable):
    """PairTable interface on the ViscElCap family (see the module doc)."""

    law_name = CAPILLARY_LAW

    def __init__(self, job, gravity=9.81):
        super().__init__(job, gravity)
        self._build()

    def _build(self):
        """Materials; pycal.contact_rules has checked the pairs (rolling 0, one bridge material,
        one restitution, no other cohesion)."""
        names = list(self.particles)
        self.bridge = next(((a, self.pair(a, a)["cohesion"]) for a in names
                            if self.pair(a, a)["cohesion"]["model"] == MODEL), None)
        if self.bridge is None:
            raise RigFailure(f"{MODEL}: no pair uses it")
        name, coh = self.bridge
        p = self.particles[name]
        if p["particles"]["shape"] != "sphere":
            raise RigFailure(f"{MODEL}: material {name} must be spheres")
        w = p.get("moisture_percent_dry_basis", 0.0) / 100.0
        if w <= 0:
            raise RigFailure(f"materials.{name}.moisture_percent_dry_basis must be > 0 for liquid bridges")
        liquid = w * self.particle_mass(name) / WATER_DENSITY_KG_M3
        self.bridge_volume = coh["bridge_liquid_fraction"] * liquid * 2.0 / coh["coordination_count"]
        theta = math.radians(coh["contact_angle_deg"])
        self.rupture_distance = (1.0 + 0.5 * theta) * self.bridge_volume ** (1.0 / 3.0)
        r = self.radius(name)
        self.detection_factor = 1.0 + DETECTION_MARGIN_RATIO * self.rupture_distance / (2.0 * r)
        self.bridge_force_max = 2.0 * math.pi * r * coh["surface_tension_n_m"] * math.cos(theta)
        cap = dict(CapillarType="Willett_numeric", Vb=self.bridge_volume, gamma=coh["surface_tension_n_m"],
                   theta=coh["contact_angle_deg"], dcap=0.0)
        e = self.pair(name, name)["restitution_coefficient"]
        for n in names:
            q = self.particles[n]
            c = q["contact"]
            m = ViscElCapMat(young=c["youngs_modulus_pa"], poisson=shear_ratio(c["poisson_ratio"]),
                             density=q["particles"]["density_kg_m3"], en=e, et=e,
                             frictionAngle=math.atan(self.pair(n, n)["friction_coefficient"]),
                             Capillar=(n == name), label=n, **cap)
            self.mat_id[n] = O.materials.append(m)
        for bname, bd in self.boundaries.items():
            m = ViscElCapMat(young=bd["youngs_modulus_pa"], poisson=shear_ratio(bd["poisson_ratio"]),
                             density=bd["density_kg_m3"], en=e, et=e, frictionAngle=0.0, Capillar=False,
                             label=bname, **cap)
            self.mat_id[bname] = O.materials.append(m)

    def cohesion_force(self, a, b):
        """Largest bridge force (N) of the pair (Willett at contact: 2 pi R gamma cos theta)."""
        return self.bridge_force_max if self.pair(a, b)["cohesion"]["model"] == MODEL else 0.0

    def ip2_functors(self):
        return [Ip2_ViscElCapMat_ViscElCapMat_ViscElCapPhys(frictAngle=MatchMaker(matches=self.friction_matches(),
                                                                                  algo="avg"))]

    def law2(self):
        return Law2_ScGeom_ViscElCapPhys_Basic()

    def damping(self):
        return 0.0

    def bounding_functors(self):
        return [Bo1_Sphere_Aabb(aabbEnlargeFactor=self.detection_factor), Bo1_Facet_Aabb()]

    def geometry_functors(self):
        return [Ig2_Sphere_Sphere_ScGeom(interactionDetectionFactor=self.detection_factor),
                Ig2_Facet_Sphere_ScGeom()]

    def extra_engines(self):
        return []
