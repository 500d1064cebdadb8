"""Particles leaving the table: one is launched along +x from the table's centre at
`launch_speed_m_s` (as a particle squeezed out of a loaded pile), one rests on the table.
Every rest-check interval the rig's rule (demlib.rigs.remove_fallen) erases what left the
table, then the blow-up guard runs, for `time_s` of simulated time. Measures which
particles are left, how many were erased and the guard's message if it fired."""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))
import _common  # noqa: E402

from yade import O, utils  # noqa: E402


def main():
    job, p, out = _common.load()
    from yade_scripts.demlib.scene import Scene
    from yade_scripts.demlib import rigs
    from yade_scripts.demlib.jobio import RigFailure
    sc = Scene(job)
    half = rigs.table_half_width(job["rig_config"]["geometry"])
    sc.add_table(half, "steel")
    sc.set_domain((-half, -half, -0.05), (half, half, 0.3))
    r = sc.radius
    mat = sc.contact.mat_id[job["material"]]
    flyer = O.bodies.append(utils.sphere((0.0, 0.0, r), r, material=mat))
    rester = O.bodies.append(utils.sphere((0.0, 0.5 * half, r), r, material=mat))
    sc.sphere_ids.extend([flyer, rester])       # the scene's particles (what the rig rules see)
    sc.set_timestep()
    O.bodies[flyer].state.vel = (p["launch_speed_m_s"], 0, 0)
    chunk = rigs.steps_of(sc.num["rest_check_interval_s"], O.dt)
    erased, failure = 0, None
    try:
        while O.time < p["time_s"]:
            sc.advance(chunk)
            erased += rigs.remove_fallen(sc, -2.0 * r)
            sc.check()
    except RigFailure as exc:
        failure = str(exc)
    left = sorted(b.id for b in sc.live_spheres())
    _common.finish(out, {"erased_count": erased, "left_ids": left, "flyer_id": flyer, "rester_id": rester,
                         "failure": failure, "table_half_width_m": half, "radius_m": r})


_common.run_main(main)
