"""Rig 6: internal friction (method.md rig 6, lab-tests.md sections 8-9).

A fixed PVC cell stands on the steel table; a mobile cell (a rigid clump of
cell_mass_kg) is stacked on it with a gap of cell_gap_m, so the shear plane runs
through the material between them. Both are filled by one pour through both and
struck level at the mobile cell's rim; a steel lid goes on top. Then, as the wall
friction rig, for each consolidation stress in order on the same fill: load the lid to
the stress (servo, spring curve recorded), unload to the dead weight, tilt the table
(rotate gravity) until the mobile cell has slid slide_onset_displacement_m on the
material below (mu_static = tan of that angle), hold and time the travel of
dynamic_travel_distance_m (mu_dynamic). If the mobile cell has not travelled that far
even at max_tilt_deg (90), the step reports sticks: true and the largest angle.
There is no plate force here: only tan(angle) is recorded.
Run: yade -j1 -x -n yade_scripts/internal_friction.py job.json
"""
import math

from yade_scripts.demlib.jobio import run_rig
from yade_scripts.demlib import tilt as tl


def build(scene):
    g, p = scene.rig["geometry"], scene.rig["procedure"]
    d, h, gap = g["cell_inner_diameter_m"], g["cell_height_m"], g["cell_gap_m"]
    half = g["table_half_width_m"]
    tl.add_bearing_plate(scene, -half, half, half, g["table_material"])
    scene.add_cylinder(d, h, g["cell_facet_segments_count"], g["cell_material"], z0=0.0)   # fixed cell
    mobile_bottom = h + gap
    cell = tl.add_rigid_cell(scene, d, h, g["cell_facet_segments_count"], g["cell_material"], mobile_bottom,
                             g["cell_mass_kg"])
    cell.hold(True)
    top = mobile_bottom + h
    column = p["pour_height_factor"] * top
    scene.set_domain((-half, -half, -0.05), (half, half, column + 0.1))
    settle_s = tl.pour_and_strike(scene, d, 0.0, top, column, p["pour_porosity_ratio"],
                                  g["cell_facet_segments_count"], g["cell_material"], p["strike_level_height_m"])
    return {"plate_ids": [], "cell": cell, "settle_time_s": settle_s, "cell_bottom_z_m": mobile_bottom,
            "floor_z_m": mobile_bottom, "spill_box_m": (-half, half, -half, half, -2.0 * scene.radius),
            "contents_volume_m3": math.pi * d * d / 4.0 * top}


def main(job, out_dir):
    return tl.run_friction_rig(job, build, out_dir)


run_rig(main)
