"""Rig 2 for a material set: cylinder-lift angle of repose of a mixed sample (M1 clumps
+ M2 + M3 spheres, docs/lab-tests.md section 4: the -50 mm sample).

Fill the 145 x 95 mm PVC cylinder on the steel table with the set's particles by mass
(demlib.mixed: generated mass split by the components' mass fractions and the M1
shapes' shares, random non-overlapping placement in a column, pour, settle, strike
level: spheres above the rim are removed, lumps stay), lift the cylinder at
lift_speed_m_s until clear, settle the pile, measure the sector angles of the whole
slope and of the upper half of the pile height (pycal/post/aor_mixed.py), and the share of the
pile's volume inside the cylinder's footprint (pycal.post.aor.footprint_fraction). Every particle
sphere, clump members included, is a particle of the profile.
Outputs: pile_particles.csv (with material and clump id), pile_profile.csv,
pile_upper_profile.csv, pile_side.png, result.json.
Run: yade -j1 -x -n yade_scripts/aor_mixed.py job.json
"""
import os
import sys

from yade_scripts.demlib.jobio import run_rig, write_csv
from yade_scripts.demlib import mixed, rigs, replicas


def build_pile(scene):
    """Phase: fill by mass, lift, settle (demlib.rigs.cylinder_lift_pile). Returns the entries of
    result.json about the run: the fill's masses and fractions, timings and counts."""
    pile, cell = yield from rigs.cylinder_lift_pile(scene, mixed.fill_cell_mixed)
    info = {k: v for k, v in cell.items() if k not in ("cylinder_ids", "table_ids", "settle_time_s", "steps")}
    info.update(pile)
    info["n_clumps_in_pile"] = len(scene.clumps)
    return info


def procedure(scene, out_dir):
    """The mixed pile (a generator: demlib.phases); lone jobs only: the time step comes from
    the lumps drawn, so replicas would share the smallest of their batch (no replicas)."""
    from pycal.post import aor as aor_post, aor_mixed as post
    job = scene.job
    info = yield from build_pile(scene)
    rows = scene.particle_rows()
    write_csv(out_dir, "pile_particles.csv", ["x_m", "y_m", "z_m", "radius_m", "material", "clump_id"], rows)
    whole, upper = post.measure(rows, scene.rig["measure"])
    write_csv(out_dir, "pile_profile.csv", aor_post.PROFILE_COLUMNS, aor_post.profile_rows(whole))
    write_csv(out_dir, "pile_upper_profile.csv", aor_post.PROFILE_COLUMNS, aor_post.profile_rows(upper))
    lift_mm_s = 1000 * scene.rig["procedure"]["lift_speed_m_s"]
    post.plot(rows, whole, upper, os.path.join(out_dir, "pile_side.png"),
              title=f"AoR {scene.material} seed {job['seed']} (lift {lift_mm_s:g} mm/s)")
    for line in post.missing_angles(whole, upper):
        print(line, flush=True)
    out = post.result_keys(whole, upper)
    out.update({"n_particles": whole["n_particles"], "pile_height_m": whole["pile_height_m"],
                "pile_radius_m": whole["pile_radius_m"],
                "pile_footprint_fraction": aor_post.footprint_fraction(
                    post.positions(rows), scene.rig["geometry"]["cell_inner_diameter_m"] / 2.0)})
    out.update(info)
    return out


main = replicas.rig_main(procedure, scene_class=mixed.MixedScene)

if __name__ == "__main__" and os.path.basename(sys.argv[0]) == "aor_mixed.py":
    run_rig(main)
