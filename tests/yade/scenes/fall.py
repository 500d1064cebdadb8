"""Free flight: one particle of the job's material falls from rest with no contact.
Measures the drop after `fall_time_s` (theory: g t^2 / 2, whatever the damping:
global damping acts on contact forces only)."""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))
import _common  # noqa: E402

from yade import O, utils  # noqa: E402


def main():
    job, p, out = _common.load()
    from yade_scripts.demlib.scene import Scene
    sc = Scene(job)
    r = sc.radius
    b = O.bodies.append(utils.sphere((0, 0, 1.0), r, material=sc.contact.mat_id[job["material"]]))
    sc.set_timestep()
    n = int(round(p["fall_time_s"] / O.dt))
    sc.advance(n)
    _common.finish(out, {"drop_m": 1.0 - O.bodies[b].state.pos[2], "time_s": O.time, "speed_m_s": -O.bodies[b].state.vel[2],
                         "gravity_m_s2": sc.g, "damping": sc.newton.damping, "law": sc.contact.law_name})


_common.run_main(main)
