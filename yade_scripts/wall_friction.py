"""Rig 5: tilt-table wall friction (method.md rig 5, lab-tests.md sections 8-9).

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
import math

from yade_scripts.demlib.jobio import run_rig
from yade_scripts.demlib import tilt as tl


def build(scene):
    g, p = scene.rig["geometry"], scene.rig["procedure"]
    d, h, gap = g["cell_inner_diameter_m"], g["cell_height_m"], g["cell_gap_to_plate_m"]
    plate = tl.add_bearing_plate(scene, -g["plate_back_length_m"], g["plate_front_length_m"],
                                 g["plate_half_width_m"], g["plate_material"])
    cell = tl.add_rigid_cell(scene, d, h, g["cell_facet_segments_count"], g["cell_material"], gap,
                             g["cell_mass_kg"])
    cell.hold(True)
    column = p["pour_height_factor"] * h
    scene.set_domain((-g["plate_back_length_m"], -g["plate_half_width_m"], -0.05),
                     (g["plate_front_length_m"], g["plate_half_width_m"], column + 0.1))
    settle_s = tl.pour_and_strike(scene, d, 0.0, gap + h, column, p["pour_porosity_ratio"],
                                  g["cell_facet_segments_count"], g["cell_material"], p["strike_level_height_m"])
    spill_box = (-g["plate_back_length_m"], g["plate_front_length_m"], -g["plate_half_width_m"],
                 g["plate_half_width_m"], -2.0 * scene.radius)
    return {"plate_ids": list(plate), "cell": cell, "settle_time_s": settle_s, "cell_bottom_z_m": gap,
            "floor_z_m": 0.0, "spill_box_m": spill_box, "contents_volume_m3": math.pi * d * d / 4.0 * h}


def main(job, out_dir):
    return tl.run_friction_rig(job, build, out_dir)


run_rig(main)
