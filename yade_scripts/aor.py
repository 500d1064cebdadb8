"""Rig 2: cylinder-lift angle of repose (docs/rigs.md, docs/lab-tests.md section 4).

Fill the 145 x 95 mm PVC cylinder standing on the steel table (rigs.fill_cell: pour,
settle, strike level), lift the cylinder kinematically at lift_speed_m_s until its
bottom edge is lift_clearance_m above the highest particle top, remove it, settle the
pile to rest and measure the four sector angles (pycal/post/aor.py documents the
method). Particles that roll off the table are erased (n_fallen_off).
Outputs: pile_particles.csv, pile_profile.csv, pile_side.png, result.json.
A batch job (several seeds) builds one rig per seed side by side (demlib.replicas).
Run: yade -j1 -x -n yade_scripts/aor.py job.json
"""
import os
import sys

from yade_scripts.demlib.jobio import run_rig
from yade_scripts.demlib import rigs, replicas


def pile_result(scene, out_dir, info, prefix="aor", files="pile", title="AoR"):
    keys, m = rigs.measure_pile(scene, out_dir, prefix=prefix, files=files,
                                title=f"{title} {scene.material} seed {scene.job['seed']}")
    out = dict(keys)
    out.update({"n_particles": m["n_particles"], "pile_height_m": m["pile_height_m"],
                "pile_radius_m": m["pile_radius_m"]})
    out.update(info)
    return out


def procedure(scene, out_dir):
    """The pile of one seed (a generator: demlib.phases); returns the measurements."""
    info, _ = yield from rigs.cylinder_lift_pile(scene)
    return pile_result(scene, out_dir, info)


main = replicas.rig_main(procedure, half_width_m=rigs.table_half_width)

if __name__ == "__main__" and os.path.basename(sys.argv[0]) == "aor.py":
    run_rig(main)
