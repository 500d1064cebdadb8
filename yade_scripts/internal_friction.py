"""Rig 6: internal friction (docs/rigs.md, docs/lab-tests.md sections 8-9).

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
from yade_scripts.demlib.jobio import run_rig
from yade_scripts.demlib import tilt as tl
from yade_scripts.demlib.tilt_bodies import add_bearing_plate


def build(scene):
    """Square table, the fixed cell on it, the mobile cell cell_gap_m above, pour (column =
    pour_height_factor x the height of both cells and the gap), strike at the mobile rim;
    contents volume = both cells and the gap. No plate force (the table is not read)."""
    g, p = scene.rig["geometry"], scene.rig["procedure"]
    d, h, gap = g["cell_inner_diameter_m"], g["cell_height_m"], g["cell_gap_m"]
    half = g["table_half_width_m"]
    add_bearing_plate(scene, -half, half, half, g["table_material"])
    scene.add_cylinder(d, h, g["cell_facet_segments_count"], g["cell_material"], z0=0.0)   # fixed cell
    mobile_bottom = h + gap
    top = mobile_bottom + h
    return tl.build_sliding_cell(scene, [], cell_bottom_z=mobile_bottom, fill_top_z=top,
                                 column_m=p["pour_height_factor"] * top, box_xy=(-half, half, -half, half),
                                 floor_z=mobile_bottom, contents_height_m=top)


def main(job, out_dir):
    return tl.run_friction_rig(job, build, out_dir)


run_rig(main)
