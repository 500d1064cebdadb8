"""Rig 4c: unconfined compression (UCS) - a pile formed as in the AoR test, pressed by
the steel plate, material free to move sideways (docs/rigs.md).

Fill the cylinder on the table, lift it at lift_speed_m_s until clear and settle the
pile as the AoR rig does (rigs.cylinder_lift_pile), then a
circular steel plate of geometry.plate_diameter_m (a 32-gon of the same area, demlib
.loading.add_plate fit='equal_area') starts plate_start_gap_m above the pile top and is
servoed through procedure.load_steps_pa (demlib.loading, same rule as CCS).

- stress = upward force of the particles on the plate / plate area pi D^2 / 4;
- h0 = the plate's first-contact height = the pile top; strain = (h0 - z_plate) / h0;
- bulk density = mass of the particles whose centre lies within the plate's footprint
  (radius D/2 around the axis) / (plate area x z_plate): the bulk under the plate;
- bottom force = downward force on the table; wall force = 0 (no wall); force balance
  (plate + weight - bottom) / (plate + weight) with the weight of each step (particles
  that leave the table are erased, as in the AoR rig: also those squeezed out sideways,
  which can cross the table edge at several m/s).
- a free pile carries the plate on a few contacts: if one of them overlaps more than
  numerics.max_overlap_fraction x radius (M3-wet at its start value E = 2e7 Pa: 0.33 R at
  40 kPa, past 0.4 R on the way to 60 kPa, seed 1), loading stops there and result.json says so
  (load_stopped_at_pa, load_stop_reason, load_steps_completed_count); the curve holds
  the steps reached. The same when the pile cannot hold a step at rest within
  max_settle_time_s (it keeps creeping under the plate: the free pile yields; M2 seed 5 at
  90 kPa). A failure before the first step is still an error.
Outputs: result.json (per-step arrays), spring_curve.csv, lab_comparison.csv, PNGs.
A batch job (several seeds) builds one rig per seed side by side (demlib.replicas).
Run: yade -j1 -x -n yade_scripts/ucs.py job.json
"""
import math

from yade_scripts.demlib.jobio import run_rig, NoRestUnderLoad, OverlapLimitExceeded
from yade_scripts.demlib import rigs, loading, compression, replicas

PLATE_SEGMENTS = 32   # polygon of the circular plate (equal area: the stress area is exact)


def procedure(scene, out_dir):
    """Pile and load steps of one seed (a generator: demlib.phases)."""
    job = scene.job
    g, p = scene.rig["geometry"], scene.rig["procedure"]
    pile, cell = yield from rigs.cylinder_lift_pile(scene)
    d = g["plate_diameter_m"]
    area = math.pi * d * d / 4.0
    h0 = compression.top_of_bulk(scene)
    ids = loading.add_plate(scene, h0 + p["plate_start_gap_m"], d, g["plate_material"],
                            segments=PLATE_SEGMENTS, fit="equal_area")
    plate = loading.ServoPlate(scene, ids, area, p["plate_speed_max_m_s"], p["servo_relaxation_time_s"],
                               p["servo_control_interval_s"], floor_z=0.0, footprint_radius_m=d / 2.0)
    fallen = [pile["n_fallen_off"]]

    def erase_fallen(t):
        fallen[0] += rigs.remove_fallen(scene, -2.0 * scene.radius)

    ox, oy = scene.origin[0], scene.origin[1]

    def mass_in_volume(z):
        m = sum(b.state.mass for b in scene.live_spheres()
                if math.hypot(b.state.pos[0] - ox, b.state.pos[1] - oy) <= d / 2.0)
        return m, area * z

    rec = compression.StepRecorder(scene, plate, h0, cell["table_ids"], [], mass_in_volume,
                                   p["step_tolerance_ratio"], every=erase_fallen)
    pile_mass, pile_volume = mass_in_volume(h0)
    stop = {"load_stopped_at_pa": None, "load_stop_reason": None}
    for target in p["load_steps_pa"]:
        try:
            yield from rec.step(target, "loading")
        except (OverlapLimitExceeded, NoRestUnderLoad) as exc:
            # the few plate contacts of a free pile exceed the contact law's overlap range
            # before this stress, or the pile cannot stand still under it (it yields): the
            # curve ends at the last step reached (stated in result.json)
            if not rec.data["stress_pa"]:
                raise
            stop = {"load_stopped_at_pa": target, "load_stop_reason": str(exc)}
            print(f"UCS loading stopped before {target:g} Pa: {exc}", flush=True)
            break
    extra = {"reference_area_m2": area, "fill_settle_time_s": cell["settle_time_s"],
             "timestep_s": cell["timestep_s"], "lift_time_s": pile["lift_time_s"],
             "pile_settle_time_s": pile["settle_time_s"], "pile_height_m": h0, "n_fallen_off": fallen[0],
             "initial_bulk_density_kg_m3": pile_mass / pile_volume,
             "load_steps_completed_count": len(rec.data["stress_pa"]), **stop,
             "strain_reference": "h0 = pile top before loading (plate first-contact height)",
             "bulk_density_rule": "mass of particles with centre within the plate footprint / "
                                  "(plate area x plate height)"}
    return compression.finish(job, out_dir, scene, rec, extra)


main = replicas.rig_main(procedure, half_width_m=rigs.table_half_width)
run_rig(main)
