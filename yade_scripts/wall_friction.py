"""Rig 5: tilt-table wall friction (docs/rigs.md, docs/lab-tests.md sections 8-9).

The filled cell (a rigid clump of PVC facets standing cell_gap_to_plate_m above the
steel bearing plate, so only the material touches the plate) carries a steel lid.
For each consolidation stress, in order, on the same fill (the lab procedure: the
consolidation history grows from step to step):
  load the lid to the stress and record the spring curve (lid force and plate force vs
  lid position), unload to the dead weight of cell + lid + contents, tilt the table
  (rotate gravity) at tilt_rate_deg_s until the cell has slid slide_onset_displacement_m
  (mu_static = tan of that angle), hold the angle and time the travel of
  dynamic_travel_distance_m (mu_dynamic = tan t - a / (g cos t)), stop, tilt back.
The plate's tangential / normal force is recorded too (at onset and while sliding).
Run: yade -j1 -x -n yade_scripts/wall_friction.py job.json
"""
from yade_scripts.demlib.jobio import run_rig
from yade_scripts.demlib import tilt as tl
from yade_scripts.demlib.tilt_bodies import add_bearing_plate


def build(scene):
    """Bearing plate, the cell cell_gap_to_plate_m above it, pour (column = pour_height_factor
    x cell height), strike at the rim; contents volume = the cell's (pi D^2 / 4 x H)."""
    g, p = scene.rig["geometry"], scene.rig["procedure"]
    h, gap = g["cell_height_m"], g["cell_gap_to_plate_m"]
    back, front, half = g["plate_back_length_m"], g["plate_front_length_m"], g["plate_half_width_m"]
    plate = add_bearing_plate(scene, -back, front, half, g["plate_material"])
    return tl.build_sliding_cell(scene, plate, cell_bottom_z=gap, fill_top_z=gap + h,
                                 column_m=p["pour_height_factor"] * h, box_xy=(-back, front, -half, half),
                                 floor_z=0.0, contents_height_m=h)


def main(job, out_dir):
    return tl.run_friction_rig(job, build, out_dir)


run_rig(main)
