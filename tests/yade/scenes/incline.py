"""Sliding onset: a particle that cannot roll (rotations blocked, blockedDOFs='XYZ')
rests on the steel table; gravity is tilted to the angle t (ramped, then held), which
is the same as tilting the table. It slides iff tan(t) > particle-steel friction.

Measures the displacement down the slope after the hold and the final speed.
"""
import math, os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))
import _common  # noqa: E402

from yade import O, utils, Vector3  # noqa: E402


def main():
    job, p, out = _common.load()
    from yade_scripts.demlib.scene import Scene
    sc = Scene(job)
    sc.add_table(0.5, "steel")
    r = sc.radius
    # inside one facet (on the shared diagonal a sphere would touch both facets)
    b = O.bodies.append(utils.sphere((0.03, 0.01, r), r, material=sc.contact.mat_id[job["material"]]))
    O.bodies[b].state.blockedDOFs = "XYZ"
    sc.set_timestep()
    g = sc.g
    O.run(int(p["settle_s"] / O.dt), True)                 # rest on the flat table
    x0 = O.bodies[b].state.pos[0]
    t_end = math.atan(p["tan_angle"])
    n_ramp = max(1, int(p["ramp_s"] / O.dt))
    chunk = 200
    for k in range(0, n_ramp, chunk):
        t = t_end * min(1.0, (k + chunk) / n_ramp)
        sc.newton.gravity = Vector3(g * math.sin(t), 0, -g * math.cos(t))
        O.run(chunk, True)
    sc.newton.gravity = Vector3(g * math.sin(t_end), 0, -g * math.cos(t_end))
    x1 = O.bodies[b].state.pos[0]
    v1 = O.bodies[b].state.vel.norm()
    O.run(int(p["hold_s"] / O.dt), True)
    st = O.bodies[b].state
    fn = ft = 0.0
    for i in O.bodies[b].intrs():
        if i.isReal:
            fn += i.phys.normalForce.norm()
            ft += i.phys.shearForce.norm()
    _common.finish(out, {"tan_angle": p["tan_angle"], "angle_deg": math.degrees(t_end),
                         "slide_during_ramp_m": x1 - x0, "slide_total_m": st.pos[0] - x0,
                         "slide_during_hold_m": st.pos[0] - x1, "damping": sc.newton.damping, "final_speed_m_s": st.vel.norm(),
                         "speed_at_hold_m_s": v1,
                         "ft_over_fn": ft / fn if fn else None, "timestep_s": O.dt})


_common.run_main(main)
