"""Rig 2: cylinder-lift angle of repose (docs/rigs.md, docs/lab-tests.md section 4).

Fill the 145 x 95 mm PVC cylinder standing on the steel table (rigs.fill_cell: pour,
settle, strike level), lift the cylinder kinematically at lift_speed_m_s until its
bottom edge is lift_clearance_m above the highest particle top, remove it, settle the
pile to rest and measure the four sector angles (pycal/post/aor.py documents the
method). Particles that roll off the table are erased (n_fallen_off).
Outputs: pile_particles.csv, pile_profile.csv, pile_side.png, result.json.
Run: yade -j1 -x -n yade_scripts/aor.py job.json
"""
import os
import sys

from yade_scripts.demlib.jobio import run_rig
from yade_scripts.demlib.scene import Scene
from yade_scripts.demlib import rigs


def pile_result(scene, out_dir, info, prefix="aor", files="pile", title="AoR"):
    keys, m = rigs.measure_pile(scene, out_dir, prefix=prefix, files=files,
                                title=f"{title} {scene.material} seed {scene.job['seed']}")
    out = dict(keys)
    out.update({"n_particles": m["n_particles"], "pile_height_m": m["pile_height_m"],
                "pile_radius_m": m["pile_radius_m"]})
    out.update(info)
    return out


def main(job, out_dir):
    scene = Scene(job)
    info, _ = rigs.cylinder_lift_pile(scene)
    return pile_result(scene, out_dir, info)


if __name__ == "__main__" and os.path.basename(sys.argv[0]) == "aor.py":
    run_rig(main)
