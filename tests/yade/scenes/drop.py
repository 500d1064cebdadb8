"""Restitution: one particle dropped on the steel table (facets), library contact model.

Gravity is on (the library's NewtonIntegrator with dampGravity=True), but the particle
starts 1 mm above the table with a downward speed, so the speed just before contact
is essentially the launch speed; v_in = |vz| at the last step before the first
contact, v_out = vz at the first step after the contact opened.
"""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))
import _common  # noqa: E402

from yade import O, utils  # noqa: E402


def main():
    job, p, out = _common.load()
    from yade_scripts.demlib.scene import Scene
    sc = Scene(job)
    sc.add_table(0.1, "steel")
    r = sc.radius
    b = O.bodies.append(utils.sphere((0, 0, r + 0.001), r, material=sc.contact.mat_id[job["material"]]))
    O.bodies[b].state.vel = (0, 0, -p["impact_speed_m_s"])
    sc.set_timestep()
    v_in = v_out = None
    in_contact_steps = 0
    for _ in range(200000):
        vz_before = O.bodies[b].state.vel[2]
        O.step()
        n = O.bodies[b].intrs()
        touching = any(i.isReal for i in n)
        if touching:
            if v_in is None:
                v_in = -vz_before
            in_contact_steps += 1
        elif v_in is not None:
            v_out = O.bodies[b].state.vel[2]
            break
    _common.finish(out, {"v_in_m_s": v_in, "v_out_m_s": v_out, "ratio": v_out / v_in,
                         "contact_steps": in_contact_steps, "timestep_s": O.dt,
                         "damping": sc.newton.damping})


_common.run_main(main)
