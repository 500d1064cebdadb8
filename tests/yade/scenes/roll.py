"""Rolling resistance: two particles of the job's material launched in pure rolling, one on
the steel table (facets), one over the top of a fixed sphere of radius `anvil_radius_m`
made of the job's second material `anvil` (two different pair values in one scene). The
second starts half its predicted distance before the top, so that gravity does no net work
over the path. Measures the largest distance each centre travelled (along x / along its arc).
`damping`: 'config' keeps the configured global damping, a number replaces it."""
import math, os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))
import _common  # noqa: E402

from yade import O, utils  # noqa: E402


def main():
    job, p, out = _common.load()
    from yade_scripts.demlib.scene import Scene
    sc = Scene(job)
    sc.add_table(0.6, "steel")
    r = sc.radius
    mat = sc.contact.mat_id[job["material"]]
    big = p["anvil_radius_m"]
    centre = (0.0, 2.0, -big)                       # top of the anvil at (0, 2, 0), away from the table
    O.bodies.append(utils.sphere(centre, big, material=sc.contact.mat_id["anvil"], fixed=True))
    phi0 = -0.5 * p["anvil_start_arc_m"] / (big + r)  # start angle before the top (path of the centre)
    on_anvil = O.bodies.append(utils.sphere((centre[0] + (big + r) * math.sin(phi0), centre[1],
                                             centre[2] + (big + r) * math.cos(phi0)), r, material=mat))
    on_table = O.bodies.append(utils.sphere((-0.4, 0, r), r, material=mat))
    sc.set_timestep()
    O.bodies[on_anvil].state.blockedDOFs = "xyzXYZ"  # held while the table particle settles
    sc.advance(int(0.1 / O.dt))
    O.bodies[on_anvil].state.blockedDOFs = ""
    if p["damping"] != "config":
        sc.newton.damping = float(p["damping"])
    v0 = p["launch_speed_m_s"]
    for b, phi in ((on_table, 0.0), (on_anvil, phi0)):
        st = O.bodies[b].state
        st.vel = (v0 * math.cos(phi), 0, -v0 * math.sin(phi))
        st.angVel = (0, v0 / r, 0)
    x0 = O.bodies[on_table].state.pos[0]
    travel = {on_table: 0.0, on_anvil: 0.0}
    stopped = {on_table: False, on_anvil: False}
    slip = 0.0
    t0 = O.time
    while O.time - t0 < p["max_time_s"] and not all(stopped.values()):
        sc.advance(250)
        st = O.bodies[on_table].state
        travel[on_table] = max(travel[on_table], st.pos[0] - x0)
        slip = max(slip, abs(st.vel[0] - st.angVel[1] * r))
        sa = O.bodies[on_anvil].state
        phi = math.atan2(sa.pos[0] - centre[0], sa.pos[2] - centre[2])
        travel[on_anvil] = max(travel[on_anvil], (phi - phi0) * (big + r))
        for b in stopped:
            stopped[b] = O.bodies[b].state.vel.norm() < 1e-4 and O.time - t0 > 0.05
    values = {}
    for b, name in ((on_table, "table"), (on_anvil, "anvil")):
        i = [i for i in O.bodies[b].intrs() if i.isReal]
        values[name] = {"max_bend_per_fn_m": getattr(i[0].phys, "maxBendPl", getattr(i[0].phys, "maxRollPl", None)) if i else None}
    _common.finish(out, {"table_distance_m": travel[on_table], "anvil_distance_m": travel[on_anvil],
                         "max_slip_speed_m_s": slip, "radius_m": r, "damping": sc.newton.damping,
                         "contacts": values, "timestep_s": O.dt, "law": sc.contact.law_name})


_common.run_main(main)
