"""Rig 4a: confined compression (CCS) in the 145 x 95 mm cell (docs/rigs.md).

Fill the cell (pour, strike level, settle: demlib.rigs.fill_cell), put the steel plate
procedure.plate_start_gap_m above the highest particle top, then for each of
procedure.load_steps_pa servo the plate (demlib.loading) until the stress is within
step_tolerance_ratio of the target and the bulk is at rest, and record the step.

- stress = upward force of the particles on the plate / cell cross-section pi D^2 / 4;
- h0 = the plate's first-contact height = the highest particle top before loading;
  strain = (h0 - z_plate) / h0; bulk density = particle mass / (pi D^2 / 4 x z_plate)
  (table at z = 0); solid fraction = bulk density / particle density;
- bottom force = downward force of the particles on the table facets, wall force =
  downward (friction) force on the cylinder facets; force balance error =
  (plate + weight - bottom - wall) / (plate + weight);
- stiffness = secant d stress / d strain between steps (first from zero).
Outputs: result.json (per-step arrays), spring_curve.csv, lab_comparison.csv, PNGs.
A batch job (several seeds) builds one rig per seed side by side (demlib.replicas).
Run: yade -j1 -x -n yade_scripts/ccs.py job.json
"""

from yade_scripts.demlib.jobio import run_rig
from yade_scripts.demlib import compression, replicas, rigs


def procedure(scene, out_dir):
    """The load steps of one seed (a generator: demlib.phases)."""
    cell, plate, rec, extra = yield from compression.confined_setup(scene)
    for target in scene.rig["procedure"]["load_steps_pa"]:
        yield from rec.step(target, "loading")
    return compression.finish(scene.job, out_dir, scene, rec, extra)


main = replicas.rig_main(procedure, half_width_m=rigs.table_half_width)
run_rig(main)
