"""Cohesion: sphere B hangs below a fixed sphere A of the same material, touching it
(a contact made at rest). Optionally B is first pressed up against A with
`press_weights` x its weight (ramped up from its own weight, so that it never leaves A)
and released slowly. Measures how far B fell in
`hold_time_s` (held: ~0; let go: it falls freely)."""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))
import _common  # noqa: E402

from yade import O, utils, Vector3  # noqa: E402


def main():
    job, p, out = _common.load()
    from yade_scripts.demlib.scene import Scene
    sc = Scene(job)
    r = sc.radius
    m = sc.contact.mat_id[job["material"]]
    a = O.bodies.append(utils.sphere((0, 0, 0.2), r, material=m, fixed=True))
    b = O.bodies.append(utils.sphere((0, 0, 0.2 - 2 * r + 1e-6), r, material=m))
    sc.set_timestep()
    w = O.bodies[b].state.mass * sc.g
    O.step()
    press = p.get("press_weights", 0.0)
    if press:      # press up against A from its own weight on (B never leaves A), then release slowly
        for k in range(41):
            f = w * (1.0 + (press - 1.0) * k / 10.0) if k <= 10 else press * w * (40 - k) / 30.0
            O.forces.setPermF(b, Vector3(0, 0, f))
            sc.advance(int(0.01 / O.dt))
        O.forces.setPermF(b, Vector3(0, 0, 0))
    z0 = O.bodies[b].state.pos[2]
    sc.advance(int(p["hold_time_s"] / O.dt))
    contact = [i for i in O.bodies[b].intrs() if i.isReal]
    _common.finish(out, {"fall_m": z0 - O.bodies[b].state.pos[2], "weight_n": w, "in_contact": bool(contact),
                         "adhesion_n": getattr(contact[0].phys, "adhesionForce", None) if contact else None,
                         "law": sc.contact.law_name})


_common.run_main(main)
