"""Per-pair values read back from the contacts: a rig fill (cell fill of the job's rig;
a material set job: the mixed fill), then for every real contact the materials, the
radii of its sphere bodies, the particle masses and what the contact law holds
(friction, rolling limit per unit normal force, rolling and twisting stiffness, adhesion).
Contacts are sampled again `extra_time_s` later, so that contacts made after the
pour (by particles rearranging) are read too."""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))
import _common  # noqa: E402

from yade import O, Sphere  # noqa: E402


def rows(sc):
    out = []
    name = {v: k for k, v in sc.contact.mat_id.items()}
    for i in O.interactions:
        if not i.isReal:
            continue
        bodies = [O.bodies[i.id1], O.bodies[i.id2]]

        def mass(b):
            if b.isClumpMember:
                return O.bodies[b.clumpId].state.mass
            return b.state.mass if b.dynamic else None
        ph = i.phys
        out.append({"materials": [name[b.material.id] for b in bodies], "read_iter": O.iter,
                    "radii_m": [b.shape.radius if isinstance(b.shape, Sphere) else None for b in bodies],
                    "masses_kg": [mass(b) for b in bodies],
                    "made_real_iter": i.iterMadeReal,
                    "friction": ph.tangensOfFrictionAngle, "max_bend_per_fn_m": ph.maxBendPl,
                    "kr": ph.kr, "ktw": ph.ktw, "adhesion_n": ph.adhesionForce, "kso": ph.kso,
                    "young_pa": [b.material.young for b in bodies], "poisson": [b.material.poisson for b in bodies],
                    "ref_radii_m": [i.geom.refR1, i.geom.refR2]})
    return out


def main():
    job, p, out = _common.load()
    from yade_scripts.demlib import rigs, mixed
    from yade_scripts.demlib.phases import drive
    if "material_set" in job:
        sc = mixed.MixedScene(job)
        drive(mixed.fill_cell_mixed(sc))
    else:
        from yade_scripts.demlib.scene import Scene
        sc = Scene(job)
        drive(rigs.fill_cell(sc))
    first = rows(sc)
    sc.advance(int(round(p["extra_time_s"] / O.dt)) + sc.contact.hook_interval)
    _common.finish(out, {"contacts": first + rows(sc), "gravity_m_s2": sc.g, "iter": O.iter,
                         "law": sc.contact.law_name})


_common.run_main(main)
