"""Replicas sharing one scene (demlib.replicas.Driver), with procedures of the test's own:

- `overlap`: `replicas_count` replicas standing at the SAME place (origin 0): each has
  its own steel table and drops one particle from `drop_height_m`. Bodies of different
  replicas overlap in space all along; their collision groups must keep them apart.
  Measures per replica the particle's rest height, and the number of contacts seen
  between bodies of different replicas (checked every step). Each replica reports, when
  it finishes, the bodies left in the scene and their collision masks (Body.mask; the
  replicas that finished before it have been erased).
- `failure`: `replicas_count` replicas side by side, each a particle resting on its own
  table; replica `fail_index` raises RigFailure after `fail_after_steps`; the others run
  `run_steps` and report their particle's height and the steps they ran.
"""
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))
import _common  # noqa: E402

from yade import O, utils  # noqa: E402


def main():
    job, p, out = _common.load()
    from yade_scripts.demlib.scene import Scene, World
    from yade_scripts.demlib import replicas
    from yade_scripts.demlib.jobio import RigFailure
    world = World(job)
    world.shared = True
    n = p["replicas_count"]
    spacing = 0.0 if p["case"] == "overlap" else 1.0
    cross = {"contacts": 0}

    def procedure(scene, k):
        scene.add_table(0.1, "steel")
        scene.set_domain((-0.1, -0.1, -0.05), (0.1, 0.1, 0.5))
        r = scene.radius
        ids = [O.bodies.append(utils.sphere(scene.at(0.01 * k, 0.0, p["drop_height_m"] + r), r,
                                            material=scene.contact.mat_id[scene.material]))]
        scene.sphere_ids.extend(ids)
        yield scene.timestep()
        if p["case"] == "overlap":
            for _ in range(p["run_steps"]):
                yield 1
                owner = world.owner
                cross["contacts"] += sum(1 for i in O.interactions
                                         if i.isReal and owner[i.id1] != owner[i.id2])
        else:
            done = 0
            while done < p["run_steps"]:
                yield 100
                done += 100
                scene.check()
                if k == p["fail_index"] and done >= p["fail_after_steps"]:
                    raise RigFailure(f"test failure of replica {k}")
        b = O.bodies[ids[0]]
        return {"z_m": b.state.pos[2] - scene.origin[2], "radius_m": r, "iter": O.iter,
                "bodies_left": sum(1 for x in O.bodies if x is not None),
                "masks": sorted({x.mask for x in O.bodies if x is not None})}

    runs = []
    for k in range(n):
        sc = Scene(dict(job, seed=k + 1), world=world, origin=(k * spacing, 0.0, 0.0), index=k)
        runs.append((sc, procedure(sc, k)))
    outcomes = replicas.Driver(world, runs, retire=True).run()
    _common.finish(out, {"replicas": [{"status": o["status"], "measurements": o["measurements"],
                                       "error": str(o["error"]) if o["error"] else None,
                                       "steps_count": o["steps_count"]} for o in outcomes],
                         "cross_contacts": cross["contacts"]})


_common.run_main(main)
