"""The tilt-table friction rigs (wall_friction, internal_friction; runs inside YADE).

- build_sliding_cell: the set-up both rigs share (the sliding cell as a rigid body, the
  rig's box, the loose pour struck level);
- pour_and_strike: loose pour through the cell(s) and a temporary funnel, strike level;
- consolidate: load the lid to a stress, record the spring curve, unload to dead weight;
- run_friction_rig: for each consolidation stress, consolidate and run one tilt test
  (demlib.tilt_test); the rigid bodies are in demlib.tilt_bodies.

Every number comes from the job (rig_config.geometry / procedure / numerics).
"""
import math
import os

from yade import O

from .jobio import RigFailure
from .phase_clock import CLOCK
from .phases import drive
from .tilt_bodies import Lid, add_rigid_cell, force_sum
from .tilt_test import Tilt, tilt_test


# ------------------------------------------------------------------ set-up and fill
def build_sliding_cell(scene, plate_ids, cell_bottom_z, fill_top_z, column_m, box_xy, floor_z,
                       contents_height_m):
    """The part of the set-up both friction rigs share, after each has added its own
    plate or table (and fixed cell): the sliding cell (geometry.cell_*: a rigid clump of
    cell_mass_kg held in place) with its bottom edge at cell_bottom_z (m), the rig's box
    box_xy = (x_min, x_max, y_min, y_max) (m) up to column_m + 0.1 m, and a loose pour
    from z = 0 over column_m (m) through a funnel above fill_top_z, struck at
    procedure.strike_level_height_m. Returns the `parts` dict of run_friction_rig."""
    g, p = scene.rig["geometry"], scene.rig["procedure"]
    d, h = g["cell_inner_diameter_m"], g["cell_height_m"]
    cell = add_rigid_cell(scene, d, h, g["cell_facet_segments_count"], g["cell_material"], cell_bottom_z,
                          g["cell_mass_kg"])
    cell.hold(True)
    x0, x1, y0, y1 = box_xy
    scene.set_domain((x0, y0, -0.05), (x1, y1, column_m + 0.1))
    settle_s = pour_and_strike(scene, d, 0.0, fill_top_z, column_m, p["pour_porosity_ratio"],
                               g["cell_facet_segments_count"], g["cell_material"], p["strike_level_height_m"])
    return {"plate_ids": list(plate_ids), "cell": cell, "settle_time_s": settle_s, "cell_bottom_z_m": cell_bottom_z,
            "floor_z_m": floor_z, "spill_box_m": (x0, x1, y0, y1, -2.0 * scene.radius),
            "contents_volume_m3": math.pi * d * d / 4.0 * contents_height_m}


def pour_and_strike(scene, diameter, z_bottom, cell_top, pour_height, porosity, funnel_segments,
                    funnel_material, strike_level):
    """Loose random pour from z_bottom up to z_bottom + pour_height inside a temporary
    fixed funnel (a tube from cell_top up), settle, remove the funnel and the particles
    whose centre is above strike_level (struck level), settle. Returns the settle time (s)."""
    funnel_h = z_bottom + pour_height - cell_top + 2.0 * scene.radius
    funnel = []
    if funnel_h > 0:
        funnel = list(scene.add_cylinder(diameter, funnel_h, funnel_segments, funnel_material, z0=cell_top))
    scene.pour_cloud(diameter, z_bottom, pour_height, porosity)
    scene.set_timestep()
    with CLOCK.phase("pour"):
        t1 = drive(scene.settle("pour"))
    print(f"poured: {len(scene.live_spheres())} particles settled in {t1:.2f} s", flush=True)
    above = [b.id for b in scene.live_spheres() if b.state.pos[2] > strike_level]
    scene.remove_spheres(above)
    for i in funnel:
        O.bodies.erase(i)
    with CLOCK.phase("strike"):
        t2 = drive(scene.settle("strike"))
    return t1 + t2


# ------------------------------------------------------------------ consolidation
def consolidate(scene, lid, cell, plate_ids, stress_pa, area, proc, curve, step_index, floor_z,
                cell_bottom_z=None):
    """Load the lid with the servo of demlib.loading to stress_pa (the cell held), then
    servo down to the lid's own weight and let the lid go as a free dead weight; settle.
    Appends spring-curve rows (step, t, lid stress, lid z, lid force, bearing-plate force)
    to `curve` at every guard check. Returns the step's loading record."""
    from .loading import ServoPlate, load_to
    cell.hold(True)
    if cell_bottom_z is not None and abs(cell.bottom_z() - cell_bottom_z) > 1e-9:
        # the cell sank during the previous tilt (it hangs on the lid): the operator lifts
        # it back to its gap before the next load
        cell.lift_bottom_to(cell_bottom_z)
        CLOCK.steps(1)
    lid.make_kinematic()
    servo = ServoPlate(scene, lid.members, area, proc["plate_speed_max_m_s"], proc["servo_relaxation_time_s"],
                       proc["servo_control_interval_s"], floor_z=floor_z,
                       footprint_radius_m=0.5 * scene.rig["geometry"]["cell_inner_diameter_m"])
    t_start = O.time

    def record(t=None):
        curve.append((step_index, O.time - t_start, servo.stress_pa(), servo.position_m(), servo.force_n(),
                      -force_sum(plate_ids)[2] if plate_ids else None))

    print(f"step {step_index}: loading to {stress_pa:.0f} Pa (t={O.time:.2f} s)", flush=True)
    rec = drive(load_to(scene, servo, stress_pa, proc["step_tolerance_ratio"], every=record))
    record()
    out = {"stress_reached_pa": rec["stress_pa"], "lid_z_loaded_m": rec["position_m"],
           "lid_force_loaded_n": rec["force_n"],
           "plate_force_loaded_n": -force_sum(plate_ids)[2] if plate_ids else None,
           "load_time_s": rec["time_s"]}
    w = lid.mass * scene.g / area
    print(f"step {step_index}: unloading to the lid weight {w:.0f} Pa (t={O.time:.2f} s)", flush=True)
    drive(load_to(scene, servo, w, proc["step_tolerance_ratio"], every=record))
    record()
    servo.hold()
    lid.make_rigid()
    drive(scene.settle(f"unloaded after {stress_pa:.0f} Pa"))
    out["lid_z_unloaded_m"] = lid.z()
    return out


# ------------------------------------------------------------------ the whole rig
STEP_KEYS = ("mu_static", "mu_dynamic", "sticks", "max_tilt_deg", "onset_angle_deg", "dynamic_angle_deg",
             "dynamic_travel_time_s", "dynamic_restarts_count", "dynamic_acceleration_m_s2",
             "plate_force_ratio_onset", "plate_force_ratio_sliding", "slid_distance_m",
             "cell_gap_start_m", "cell_gap_min_m", "tilt_time_s", "lid_z_loaded_m", "lid_z_unloaded_m",
             "plate_force_loaded_n", "lid_force_loaded_n", "stress_reached_pa", "load_time_s",
             "spilled_particles_count", "drift_before_tilt_m", "pre_tilt_end_deg",
             "cell_rotation_onset_deg", "wall_time_step_s")
RECORD_KEYS = ("stress_pa",) + STEP_KEYS          # columns of friction.csv, per-step arrays of result.json
SPRING_COLUMNS = ["step_index_count", "time_s", "lid_stress_pa", "lid_position_m", "lid_force_n", "plate_force_n"]
TILT_COLUMNS = ["step_index_count", "time_s", "tilt_deg", "slide_displacement_m", "cell_gap_m",
                "plate_force_x_n", "plate_force_y_n", "plate_force_z_n"]

FILL_MODES = ("sequential", "fresh")


def write_records(out_dir, steps, curve, record):
    """friction.csv (one row per step), spring_curve.csv, tilt_record.csv."""
    from .jobio import write_csv
    write_csv(out_dir, "friction.csv", list(RECORD_KEYS), [[s.get(k) for k in RECORD_KEYS] for s in steps])
    write_csv(out_dir, "spring_curve.csv", SPRING_COLUMNS, curve)
    write_csv(out_dir, "tilt_record.csv", TILT_COLUMNS, record)


def _start(scene, p, d):
    """The lid (p: procedure, d: cell diameter m) on top of a fresh fill, and the tilt."""
    spheres = scene.live_spheres()
    if not spheres:
        raise RigFailure("fill: no particle left in the cell")
    top = max(b.state.pos[2] + b.shape.radius for b in spheres)
    g = scene.rig["geometry"]
    return Lid(scene, d, g["lid_material"], top + p["plate_start_gap_m"], g["lid_mass_kg"]), Tilt(scene)


def _check_contents(scene, lid, parts, steps, k):
    """Sequential fills: the lid must stay two particle diameters above the floor."""
    spilled = sum(s.get("spilled_particles_count", 0) for s in steps)
    if lid.z() < parts["floor_z_m"] + 4.0 * scene.radius:
        raise RigFailure(f"step {k}: the lid is at z={lid.z():.4f} m, less than two particle diameters "
                         f"above the sliding cell's bottom: the cell has lost its contents ({spilled} "
                         "particles spilled in the slides of the previous steps); the test is not valid "
                         "beyond this step")


def run_friction_rig(job, build, out_dir):
    """For each consolidation stress in order: consolidate, tilt test.

    build(scene) -> parts builds and fills the rig in a new Scene(job).
    procedure.fill_each_step: 'sequential' - one fill, the steps follow each other on it
    (the lab's procedure: the table returns to horizontal, the cell is put back);
    'fresh' - a new fill for every step (same seed, so the same fill: the steps differ
    only by their consolidation stress), for rigs whose sample is spoilt by a slide.
    `parts` (build_sliding_cell): plate_ids (bearing plate: force readout; empty for the
    internal rig), cell (RigidBody, the sliding cell), cell_bottom_z_m (its nominal bottom
    edge), floor_z_m (lowest a lid may go), spill_box_m (x_min, x_max, y_min, y_max,
    z_min: a particle whose centre leaves it has spilled off the table: erased and
    counted), contents_volume_m3, settle_time_s. Writes friction.csv, spring_curve.csv,
    tilt_record.csv; returns the measurements."""
    import time
    from .scene import Scene

    def make_scene():
        with CLOCK.phase("build_and_fill"):
            scene = Scene(job)
            return scene, build(scene)

    scene, parts = make_scene()
    g, p = scene.rig["geometry"], scene.rig["procedure"]
    fresh = p["fill_each_step"] == "fresh"
    if p["fill_each_step"] not in FILL_MODES:
        raise RigFailure(f"procedure.fill_each_step: {p['fill_each_step']!r} must be one of {', '.join(FILL_MODES)}")
    d = g["cell_inner_diameter_m"]
    area = math.pi * d * d / 4.0
    lid, tilt = _start(scene, p, d)
    particle_ids = list(scene.sphere_ids)
    mass_particles = scene.particle_mass_total()
    settle_s = parts["settle_time_s"]
    cohesion_updates = 0
    steps_done = 0          # time steps of the scenes already discarded (fresh fills)
    steps, curve, record = [], [], []
    try:
        for k, stress in enumerate(p["consolidation_stresses_pa"]):
            w0 = time.time()
            if fresh and k:
                cohesion_updates += getattr(scene.contact, "n_updates", 0) or 0
                steps_done += O.iter
                scene, parts = make_scene()
                lid, tilt = _start(scene, p, d)
            if k and not fresh:
                _check_contents(scene, lid, parts, steps, k)
            with CLOCK.phase("consolidate"):
                cons = consolidate(scene, lid, parts["cell"], parts["plate_ids"], stress, area, p, curve, k,
                                   parts["floor_z_m"], parts["cell_bottom_z_m"])
            res = tilt_test(scene, tilt, parts["cell"], lid, parts["plate_ids"], parts["spill_box_m"], p, record, k,
                            restore=not fresh)
            res.update(cons)
            res["wall_time_step_s"] = time.time() - w0
            res["stress_pa"] = stress
            steps.append(res)
            print(f"step {k}: {stress:.0f} Pa  mu_static={res['mu_static']}  mu_dynamic={res['mu_dynamic']}  "
                  f"sticks={res['sticks']}  angle={res['onset_angle_deg']}  ratio={res['plate_force_ratio_onset']}  "
                  f"gap {res['cell_gap_start_m']:.4f}->{res['cell_gap_min_m']:.4f}  "
                  f"({res['wall_time_step_s']:.1f} s wall)", flush=True)
    except RigFailure:
        write_records(out_dir, steps, curve, record)     # the partial records help to see what went wrong
        raise
    write_records(out_dir, steps, curve, record)
    out = {k: [s.get(k) for s in steps] for k in RECORD_KEYS}
    out["spring_curve"] = {name: [r[i] for r in curve] for i, name in enumerate(SPRING_COLUMNS) if name != "time_s"}
    weight = (g["cell_mass_kg"] + g["lid_mass_kg"] + mass_particles) * scene.g
    out.update({
        "n_particles": len(particle_ids),
        "n_particles_end": len(scene.sphere_ids),
        "fill_each_step": p["fill_each_step"],
        "particle_mass_kg": mass_particles,
        "bulk_density_kg_m3": mass_particles / parts["contents_volume_m3"],
        "self_weight_stress_pa": weight / area,
        "settle_time_s": settle_s,
        "timestep_s": O.dt,
        "steps": steps_done + O.iter,
        "particle_damping_during_tilt": p["particle_damping_during_tilt"],
    })
    if any("drive_weight_n" in s for s in steps):      # shear_drive: force_ramp
        out["drive_weight_n"] = [s.get("drive_weight_n") for s in steps]
    if getattr(scene.contact, "n_updates", None) is not None:
        out["cohesion_update_count"] = cohesion_updates + scene.contact.n_updates
    # friction vs stress against the lab curve (CSV, PNG, misfit): pycal.post.friction; an
    # error here is a bug: the run fails (exit 4, not kept as a verdict), nothing is hidden
    from pycal.post import friction as post
    res = dict(out, rig=scene.job["rig"], material=scene.job["material"], seed=scene.job["seed"], job=scene.job)
    with CLOCK.phase("outputs"):
        done = post.write_outputs([res], out_dir)
    out["misfits"] = done["misfits"]
    out["output_files"] = [os.path.basename(f) for f in done["files"]]
    return out
