"""Rig 4b: CCS expansion - load the confined cell high, then release it in steps
(docs/rigs.md, docs/lab-tests.md section 8: the lab's particle-stiffness estimate).

Same cell, plate, servo and per-step record as ccs.py (demlib.compression); the load
steps procedure.load_steps_pa (branch 'loading') are followed by
procedure.unload_steps_pa (branch 'unloading', decreasing). Each unloading step's
stiffness is the secant d stress / d strain from the step before (the first from the
last loading point): result.json `unloading_stiffness_pa` (and `unloading_stress_pa`,
the stress each belongs to), besides the per-step arrays of every step.
A batch job (several seeds) builds one rig per seed side by side (demlib.replicas).
Run: yade -j1 -x -n yade_scripts/ccs_expansion.py job.json
"""

from yade_scripts.demlib.jobio import run_rig, RigFailure
from yade_scripts.demlib import compression, replicas, rigs


def procedure(scene, out_dir):
    """The load and unload steps of one seed (a generator: demlib.phases)."""
    job = scene.job
    p = job["rig_config"]["procedure"]
    load, unload = p["load_steps_pa"], p["unload_steps_pa"]
    if any(b >= a for a, b in zip([load[-1]] + unload[:-1], unload)):
        raise RigFailure(f"procedure.unload_steps_pa {unload}: must decrease, starting below the top load "
                         f"{load[-1]} Pa")
    cell, plate, rec, extra = yield from compression.confined_setup(scene)
    for target in load:
        yield from rec.step(target, "loading")
    for target in unload:
        yield from rec.step(target, "unloading")
    return compression.finish(job, out_dir, scene, rec, extra)


main = replicas.rig_main(procedure, half_width_m=rigs.table_half_width)
run_rig(main)
