"""Restitution: one particle hits the steel table (inside one facet, away from the shared
edge where a sphere would touch two facets at once) or a fixed sphere of its own
material, at `impact_speed_m_s`, with gravity switched off (unless `gravity` is true) so
that the ratio is the contact's alone (gravity adds g x contact time to the deficit).
v_in = approach speed before the contact, v_out = speed after it opened."""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))
import _common  # noqa: E402

from yade import O, utils, Vector3  # noqa: E402


def main():
    job, p, out = _common.load()
    from yade_scripts.demlib.scene import Scene
    sc = Scene(job)
    if not p.get("gravity", False):
        sc.newton.gravity = Vector3(0, 0, 0)
    r = sc.radius
    mat = sc.contact.mat_id[job["material"]]
    if p["target"] == "plate":
        sc.add_table(0.1, "steel")
        x = (0.03, 0.01)
        z = r + 0.0005
    else:
        O.bodies.append(utils.sphere((0, 0, -r), r, material=mat, fixed=True))
        x = (0.0, 0.0)
        z = r + 0.0005
    b = O.bodies.append(utils.sphere((x[0], x[1], z), r, material=mat))
    O.bodies[b].state.vel = (0, 0, -p["impact_speed_m_s"])
    sc.set_timestep()
    v_in = v_out = None
    steps = 0
    for _ in range(200000):
        vz = O.bodies[b].state.vel[2]
        O.step()
        touching = any(i.isReal for i in O.bodies[b].intrs())
        if touching:
            steps += 1
            if v_in is None:
                v_in = -vz
        elif v_in is not None:
            v_out = O.bodies[b].state.vel[2]
            break
    _common.finish(out, {"v_in_m_s": v_in, "v_out_m_s": v_out, "ratio": v_out / v_in, "contact_steps": steps,
                         "timestep_s": O.dt, "damping": sc.newton.damping, "law": sc.contact.law_name})


_common.run_main(main)
