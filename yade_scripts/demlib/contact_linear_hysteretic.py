"""Hysteretic cohesion on the linear_cundall contact law (runs inside YADE).

Cohesion model `hysteretic` (pycal.contact_rules.COHESION_MODELS): the pull-off force of a
contact grows with the largest compressive force it has carried, as in Luding's
elasto-plastic adhesive law (pull-off proportional to the largest overlap), but on the
same contact law as every other model (CohFrictMat + Law2_ScGeom6D_CohFrictPhys_
CohesionMoment): linear springs, per-pair Coulomb friction, rolling and twisting
resistance and Cundall damping are all kept.

    pull-off (= bond shear strength) = force_fraction x weight of the lighter particle
                                       + pressure_fraction x largest compressive force so far

The first term is the bond that every new contact gets (as `force_fraction`); the
second is added by a PyRunner every `update_interval_s` of simulated time (not every
step): for each cohesive contact it raises normalAdhesion and shearAdhesion to the
value above if the current compressive force is the largest so far (the bond strength
stores that maximum, so no per-contact history is kept in Python). At its first visit
a bond is made non-fragile in shear (it keeps its strength while sliding: shear
strength = bond + mu Fn, so static and dynamic friction stay close, as the lab saw for
wet fines) and breaks, with its contact, at the first plastic stretch in tension
(unpMax = 0), as a Luding contact keeps its adhesion while it exists. Until its first
visit a new bond is fragile (a bond broken in that window is re-formed at the visit).
Forces are sampled at the update interval: a load peak shorter than that is missed
(quasi-static rigs: harmless).

Relation to Luding's law (k1 loading, kp unloading, kc adhesive stiffness): after a
loading to f_max = k1 d_max the pull-off force is f_max kc (1 - k1/kp) / (k1 (1 + kc/kp)),
so pressure_fraction = kc (kp - k1) / (k1 (kp + kc)). Commercial codes call the same
idea an "adhesive stiffness fraction" acting on the (largest) overlap.

What is lost against LudingMat: the plastic (history-dependent) normal spring itself:
here loading and unloading stiffness are the same linear kn, only the attraction
remembers the load.
"""
import __main__

from yade import O
from yade.wrapper import PyRunner

from .contact_linear import LinearCundallContactModel
from .jobio import RigFailure

HOOK = "_pycal_hysteretic_update"


class HystereticContactModel(LinearCundallContactModel):
    """LinearCundallContactModel + the `hysteretic` cohesion model (see the module doc)."""

    MODEL = "hysteretic"

    def __init__(self, job, gravity=9.81):
        super().__init__(job, gravity)
        self._pairs = {}          # (mat id, mat id) -> (base pull-off N, pressure_fraction)
        self._body_mat = {}       # body id -> material id (YADE does not reuse body ids)
        self.n_updates = 0
        intervals = []
        names = list(self.particles)
        for i, a in enumerate(names):
            for b in names + list(self.boundaries):
                if b in names and names.index(b) < i:
                    continue
                coh = self.pair(a, b)["cohesion"]
                if coh["model"] != self.MODEL:
                    continue
                base = self._base_force(a, b, coh)
                ia, ib = self.mat_id[a], self.mat_id[b]
                self._pairs[(ia, ib)] = self._pairs[(ib, ia)] = (base, coh["pressure_fraction"])
                intervals.append(coh["update_interval_s"])
        self.interval = min(intervals) if intervals else None

    def _base_force(self, a, b, coh):
        masses = [self.particle_mass(n) for n in (a, b) if n in self.particles and not self.is_clump(n)]
        if not masses:
            raise RigFailure(f"materials.{a}.interactions.{b}.cohesion: hysteretic cohesion needs a sphere "
                             "material in the pair")
        return coh["force_fraction"] * min(masses) * self.gravity

    def cohesion_force(self, a, b):
        coh = self.pair(a, b)["cohesion"]
        if coh["model"] == self.MODEL:
            return self._base_force(a, b, coh)
        return super().cohesion_force(a, b)

    def extra_engines(self):
        """The periodic bond update (a PyRunner on simulated time)."""
        if not self._pairs:
            return []
        setattr(__main__, HOOK, self.update)
        return [PyRunner(virtPeriod=self.interval, command=HOOK + "()", label="hysteretic_cohesion")]

    def _mat(self, i):
        m = self._body_mat.get(i)
        if m is None:
            m = O.bodies[i].material.id
            self._body_mat[i] = m
        return m

    def update(self):
        """Raise each cohesive contact's bond to base + pressure_fraction x its current
        compressive force when that is more than it has (no loop over steps)."""
        self.n_updates += 1
        pairs, mat = self._pairs, self._mat
        for it in O.interactions:
            if not it.isReal:
                continue
            par = pairs.get((mat(it.id1), mat(it.id2)))
            if par is None:
                continue
            ph = it.phys
            fn = ph.normalForce.dot(it.geom.normal)      # > 0: compression
            if fn <= 0.0:
                continue
            if ph.fragile:
                # first visit: the bond keeps its strength when it slides (shear is plastic,
                # strength = bond + mu Fn) and breaks, with its contact, only in tension
                # (unpMax = 0: at the first plastic stretch)
                ph.fragile = False
                ph.unpMax = 0.0
            target = par[0] + par[1] * fn
            if target > ph.normalAdhesion or ph.cohesionBroken:
                ph.normalAdhesion = max(target, ph.normalAdhesion)
                ph.shearAdhesion = ph.normalAdhesion
                ph.cohesionBroken = False
