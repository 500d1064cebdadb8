"""Creep of a heap at rest: the AoR rig's pile (fill, lift the cylinder, settle to the rest
criterion), then `creep_time_s` more; measures the largest displacement of any particle
over that time (a heap held by rolling resistance and friction must not creep)."""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))
import _common  # noqa: E402

from yade import O, Vector3  # noqa: E402


def main():
    job, p, out = _common.load()
    from yade_scripts.demlib.scene import Scene
    from yade_scripts.demlib import rigs
    from yade_scripts.demlib.phases import drive
    sc = Scene(job)
    cell = drive(rigs.fill_cell(sc))
    drive(rigs.lift_cylinder(sc, cell["cylinder_ids"], sc.rig["procedure"]["lift_speed_m_s"],
                             sc.rig["procedure"]["lift_clearance_m"]))
    t_settle, _ = drive(rigs.settle_pile(sc, "pile settle"))
    start = {b.id: Vector3(b.state.pos) for b in sc.live_spheres()}
    sc.advance(int(round(p["creep_time_s"] / O.dt)))
    moved = max((O.bodies[i].state.pos - p0).norm() for i, p0 in start.items())
    _common.finish(out, {"n_particles": len(start), "settle_time_s": t_settle, "max_creep_m": moved,
                         "kinetic_energy_ratio": sc.kinetic_energy_ratio(), "law": sc.contact.law_name})


_common.run_main(main)
