"""The default contact law: Hertz-Mindlin with a contact dashpot (runs inside YADE).

YADE: FrictMat / PartialSatMat materials, Ip2_PartialSatMat_PartialSatMat_MindlinPhys and
Ip2_FrictMat_FrictMat_MindlinPhys, Law2_ScGeom_MindlinPhys_Mindlin(includeMoment=True),
facets as flat Hertz walls (Ig2_Facet_Sphere_ScGeom(hertzian=True)). Per pair (material
with material, material with each boundary), from the job:

- restitution e: the Tsuji dashpot of each contact (en MatchMaker), given as
  contact_rules.restitution_input(e, global damping) so that a bounce comes out at e;
- Coulomb friction mu: frictAngle MatchMaker, atan(mu);
- rolling resistance mu_r: an elastic-plastic rolling spring, moment limit
  mu_r x R x |Fn| with R = contact_rules.rolling_radius (the particle's own radius on a
  wall, the smaller sphere between two spheres, a clump member's own radius), stiffness
  k_r = rolling_stiffness_factor x k_t,ref x R^2; twisting: an elastic spring
  k_tw = twisting_stiffness_factor x k_t,ref x R^2 (contact_rules.moment_stiffness), with
  k_t,ref of the particle material (the softer one between two materials) at radius R;
- cohesion (DMT adhesion of the law: a constant pull while in contact, the contact ends at
  zero overlap): `force_fraction` pull-off = f x the lighter particle's weight;
  `hysteretic` = that + pressure_fraction x the largest compressive force so far;
  `linear` = stiffness_fraction x (contact stiffness x overlap) at the largest overlap so
  far (Hertz: k_n delta = 1.5 F_n). The last two are raised every update_interval_s; the
  compressive force is the one the contact carries (its elastic force less its own pull:
  the adhesion presses a contact too, and counting that would let it feed itself).

YADE's Ip2 sets maxBendPl = eta x Rmean, kr = krot, ktw = ktwist and the adhesion
4 pi R* gamma from single values per Ip2 class, when a contact is created, and never
updates a contact. Two Ip2 classes give two groups natively: contacts of the main
particle material with itself (PartialSatMat, its own Ip2: exact for equal spheres) and
every other contact (FrictMat Ip2: its values are those of the main material on the main
boundary group). Contacts whose pair needs other values get them from a PyRunner that
visits the contacts made since its last visit (every `contact_update_interval_count`
steps; no PyRunner when every pair is native).
"""
import math

import __main__

from yade import O
from yade.wrapper import (FrictMat, PartialSatMat, MatchMaker, Ip2_FrictMat_FrictMat_MindlinPhys,
                          Ip2_PartialSatMat_PartialSatMat_MindlinPhys, Law2_ScGeom_MindlinPhys_Mindlin,
                          Bo1_Sphere_Aabb, Bo1_Facet_Aabb, Ig2_Sphere_Sphere_ScGeom, Ig2_Facet_Sphere_ScGeom,
                          PyRunner, Sphere)

from pycal import contact_rules as rules

from .contact_base import PairTable

NEW_CONTACT_HOOK = "_pycal_hertz_new_contacts"
ADHESION_HOOK = "_pycal_hertz_adhesion_update"


class HertzMindlinContactModel(PairTable):
    """Materials, Ip2/Law2 functors and per-contact hooks of the hertz_mindlin law."""

    law_name = "hertz_mindlin"

    def __init__(self, job, gravity=9.81):
        super().__init__(job, gravity)
        num = self.numerics
        self.global_damping = float(num["global_damping_ratio"])
        self.roll_factor = float(num["rolling_stiffness_factor"])
        self.twist_factor = float(num["twisting_stiffness_factor"])
        self.hook_interval = int(num["contact_update_interval_count"])
        self.main = self._main_material()
        for name, p in self.particles.items():
            c = p["contact"]
            cls = PartialSatMat if name == self.main else FrictMat
            self.mat_id[name] = O.materials.append(cls(young=c["youngs_modulus_pa"], poisson=c["poisson_ratio"],
                                                       density=p["particles"]["density_kg_m3"], label=name))
        for name, b in self.boundaries.items():
            self.mat_id[name] = O.materials.append(FrictMat(young=b["youngs_modulus_pa"], poisson=b["poisson_ratio"],
                                                            density=b["density_kg_m3"], label=name))
        self.name_of = {v: k for k, v in self.mat_id.items()}
        self.native_wall = self._native_wall()
        self.pair_values = {}        # (mat id, mat id) -> (mu_r, cohesion dict)
        for a, b in self.pair_names():
            if self.is_boundary_pair(a, b):
                continue
            p = self.pair(a, b)
            self.pair_values[(self.mat_id[a], self.mat_id[b])] = self.pair_values[(self.mat_id[b], self.mat_id[a])] = \
                (p["rolling_resistance_coefficient"], p["cohesion"])
        self.hooked = {k for k in self.pair_values if not self._is_native(*k)}
        self.adhesive_updates = {k: v[1] for k, v in self.pair_values.items()
                                 if v[1]["model"] in ("hysteretic", "linear")}
        self.n_new_contact_visits = 0
        self.n_updates = 0

    # ---------- the two native groups
    def _main_material(self):
        """The sphere material that makes most of the mass (a single-material job: itself)."""
        spheres = [n for n in self.particles if not self.is_clump(n)]
        if not spheres:
            return None
        mset = self.job.get("material_set")
        if mset is None:
            return spheres[0]
        return max(spheres, key=lambda n: (mset["components"][n]["mass_fraction"], n))

    def _wall_values(self, wall):
        p = self.pair(self.main, wall)
        return (p["rolling_resistance_coefficient"], self._constant_pull(p["cohesion"]))

    def _native_wall(self):
        """The boundary whose values with the main material the FrictMat Ip2 carries: the one
        shared by most boundaries (ties: the first in the job's order)."""
        if self.main is None or not self.boundaries:
            return None
        groups = {}
        for b in self.boundaries:
            groups.setdefault(self._wall_values(b), []).append(b)
        return max(groups.values(), key=len)[0]

    def _is_native(self, ia, ib):
        """True when both Ip2 defaults already give this material pair its values (for
        spheres of the material's own radius and facet walls)."""
        a, b = self.name_of[ia], self.name_of[ib]
        if a == b == self.main:
            return True
        if self.main in (a, b) and self.native_wall is not None:
            other = b if a == self.main else a
            if other in self.boundaries:
                return self._wall_values(other) == self._wall_values(self.native_wall)
        return False

    @staticmethod
    def _constant_pull(coh):
        """The part of the pull-off set when a contact is made: (model, force_fraction)."""
        if coh["model"] in ("force_fraction", "hysteretic"):
            return coh["force_fraction"]
        return 0.0

    def kt_ref(self, materials, radius):
        """k_t,ref (N/m) of a contact: the smallest of its particle materials' reference
        tangential stiffness at the rolling radius (walls do not count)."""
        return min(rules.reference_tangential_stiffness(self.particles[n]["contact"]["youngs_modulus_pa"],
                                                        self.particles[n]["contact"]["poisson_ratio"], radius)
                   for n in materials if n in self.particles)

    def _ip2_defaults(self, partner):
        """eta, krot, ktwist, gamma of an Ip2 so that its contacts of the main material with
        `partner` (itself: sphere-sphere of equal radii; a boundary: a flat facet) get their values."""
        r = self.radius(self.main)
        p = self.pair(self.main, partner)
        if partner == self.main:
            r_mean, r_eq = r, 0.5 * r
        else:
            r_wall = rules.HERTZ_FACET_FACTOR * r
            r_mean, r_eq = 0.5 * (r_wall + r), r_wall * r / (r_wall + r)
        kt = self.kt_ref([self.main], r)
        mu_r = p["rolling_resistance_coefficient"]
        pull = self._constant_pull(p["cohesion"]) * self.particle_mass(self.main) * self.gravity
        return dict(eta=mu_r * r / r_mean,
                    krot=rules.moment_stiffness(self.roll_factor, kt, r) if mu_r > 0 else 0.0,
                    ktwist=rules.moment_stiffness(self.twist_factor, kt, r),
                    gamma=pull / (4.0 * math.pi * r_eq))

    # ---------- functors
    def restitution_matches(self):
        out = []
        for a, b in self.pair_names():
            e = 0.5 if self.is_boundary_pair(a, b) else self.pair(a, b)["restitution_coefficient"]
            out.append((self.mat_id[a], self.mat_id[b], rules.restitution_input(e, self.global_damping)))
        return out

    def ip2_functors(self):
        en = MatchMaker(matches=self.restitution_matches(), algo="avg")
        fric = MatchMaker(matches=self.friction_matches(), algo="avg")
        if self.main is None:      # clumps only: every contact through the hook
            return [Ip2_FrictMat_FrictMat_MindlinPhys(en=en, frictAngle=fric)]
        wall = self._ip2_defaults(self.native_wall) if self.native_wall else {}
        return [Ip2_PartialSatMat_PartialSatMat_MindlinPhys(en=en, frictAngle=fric, **self._ip2_defaults(self.main)),
                Ip2_FrictMat_FrictMat_MindlinPhys(en=en, frictAngle=fric, **wall)]

    def law2(self):
        adhesive = any(v[1]["model"] != "none" for v in self.pair_values.values())
        return Law2_ScGeom_MindlinPhys_Mindlin(includeMoment=True, includeAdhesion=adhesive)

    def bounding_functors(self):
        return [Bo1_Sphere_Aabb(), Bo1_Facet_Aabb()]

    def geometry_functors(self):
        return [Ig2_Sphere_Sphere_ScGeom(), Ig2_Facet_Sphere_ScGeom(hertzian=True)]

    def damping(self):
        return self.global_damping

    def extra_engines(self):
        engines = []
        if self.hooked:
            setattr(__main__, NEW_CONTACT_HOOK, self.set_new_contacts)
            self._last_visit = -1
            engines.append(PyRunner(iterPeriod=self.hook_interval, initRun=True, command=NEW_CONTACT_HOOK + "()",
                                    label="hertz_new_contacts"))
        if self.adhesive_updates:
            interval = min(c["update_interval_s"] for c in self.adhesive_updates.values())
            setattr(__main__, ADHESION_HOOK, self.update_adhesion)
            engines.append(PyRunner(virtPeriod=interval, command=ADHESION_HOOK + "()", label="hertz_adhesion"))
        return engines

    # ---------- per-contact values
    def contact_values(self, interaction):
        """(maxBendPl m, kr N m/rad, ktw N m/rad, constant pull-off N) of a real contact."""
        b1, b2 = O.bodies[interaction.id1], O.bodies[interaction.id2]
        mu_r, coh = self.pair_values[(b1.material.id, b2.material.id)]
        radii = [b.shape.radius if isinstance(b.shape, Sphere) else None for b in (b1, b2)]
        r = rules.rolling_radius(*radii)
        kt = self.kt_ref([self.name_of[b1.material.id], self.name_of[b2.material.id]], r)
        kr = rules.moment_stiffness(self.roll_factor, kt, r) if mu_r > 0 else 0.0
        ktw = rules.moment_stiffness(self.twist_factor, kt, r)
        pull = self._constant_pull(coh)
        if pull > 0:
            pull *= min(self._particle_mass(b) for b in (b1, b2)) * self.gravity
        return mu_r * r, kr, ktw, pull

    @staticmethod
    def _particle_mass(body):
        """Mass of the particle a body belongs to (a clump member: its clump); a wall: inf."""
        if body.isClumpMember:
            return O.bodies[body.clumpId].state.mass
        return body.state.mass if body.dynamic else math.inf

    def set_new_contacts(self):
        """Give the contacts made since the last visit whose pair is not native their values."""
        self.n_new_contact_visits += 1
        last, self._last_visit = self._last_visit, O.iter
        hooked = self.hooked
        for i in O.interactions:
            if i.iterMadeReal <= last or not i.isReal:
                continue
            if (O.bodies[i.id1].material.id, O.bodies[i.id2].material.id) not in hooked:
                continue
            ph = i.phys
            ph.maxBendPl, ph.kr, ph.ktw, ph.adhesionForce = self.contact_values(i)

    def update_adhesion(self):
        """Raise each hysteretic / linear contact's pull-off to its value at the current
        compressive force when that is more than it has (the pull-off keeps its largest value)."""
        self.n_updates += 1
        pairs = self.adhesive_updates
        for i in O.interactions:
            if not i.isReal:
                continue
            coh = pairs.get((O.bodies[i.id1].material.id, O.bodies[i.id2].material.id))
            if coh is None:
                continue
            ph = i.phys
            # the compressive force the contact carries: the elastic Hertz force less the pull
            # of its own adhesion (which presses the contact too: counting it would make the
            # adhesion feed itself); the viscous part is left out (impact peaks)
            pressed = ph.kno * i.geom.penetrationDepth ** 1.5 - ph.adhesionForce
            if pressed <= 0.0:
                continue
            if coh["model"] == "hysteretic":
                target = self._base_pull(i, coh) + coh["pressure_fraction"] * pressed
            else:      # linear: stiffness_fraction x k_n x overlap (Hertz: k_n x overlap = 1.5 x force)
                target = coh["stiffness_fraction"] * 1.5 * pressed
            if target > ph.adhesionForce:
                ph.adhesionForce = target

    def _base_pull(self, interaction, coh):
        b1, b2 = O.bodies[interaction.id1], O.bodies[interaction.id2]
        return coh["force_fraction"] * min(self._particle_mass(b) for b in (b1, b2)) * self.gravity
