"""Rolling resistance on a wall: a particle launched in pure rolling on the steel table
stops after the distance the rolling law predicts (see test_contact_physics.py).

The particle first settles on the table (configured damping), then NewtonIntegrator's
damping is set to test_scene.damping ('config' keeps the configured value) and the
particle is given v0 along x and the matching spin v0 / R about y.
Measures the largest distance travelled along x and the time it took.
"""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))
import _common  # noqa: E402

from yade import O, utils  # noqa: E402


def main():
    job, p, out = _common.load()
    from yade_scripts.demlib.scene import Scene
    from yade_scripts.demlib import contact
    sc = Scene(job)
    sc.add_table(0.6, "steel")
    r = sc.radius
    b = O.bodies.append(utils.sphere((-0.4, 0, r), r, material=sc.contact.mat_id[job["material"]]))
    sc.set_timestep()
    O.run(int(0.1 / O.dt), True)
    if p["damping"] != "config":
        sc.newton.damping = float(p["damping"])
    st = O.bodies[b].state
    v0 = p["launch_speed_m_s"]
    st.vel = (v0, 0, 0)
    st.angVel = (0, v0 / r, 0)
    x0, t0 = st.pos[0], O.time
    xmax, tstop = x0, 0.0
    slip_max = 0.0
    chunk = 250
    while O.time - t0 < p["max_time_s"]:
        O.run(chunk, True)
        x = st.pos[0]
        slip_max = max(slip_max, abs(st.vel[0] - st.angVel[1] * r))
        if x > xmax:
            xmax, tstop = x, O.time - t0
        elif st.vel[0] <= 0 and O.time - t0 > tstop + 0.05:
            break
    wall = [m for m in O.materials if m.label == "steel"][0]
    part = O.materials[sc.contact.mat_id[job["material"]]]
    i = [i for i in O.bodies[b].intrs() if i.isReal]
    _common.finish(out, {"stop_distance_m": xmax - x0, "stop_time_s": tstop,
                         "damping": sc.newton.damping, "radius_m": r,
                         "wall_etaRoll": wall.etaRoll, "particle_etaRoll": part.etaRoll,
                         "wall_radius_factor": contact.WALL_RADIUS_FACTOR,
                         "geom_radius1_m": i[0].geom.refR1 if i else None,
                         "geom_radius2_m": i[0].geom.refR2 if i else None,
                         "max_roll_moment_per_fn_m": i[0].phys.maxRollPl if i else None,
                         "max_slip_speed_m_s": slip_max, "timestep_s": O.dt})


_common.run_main(main)
