"""ucs: unconfined compression of the lifted sample (a check)."""
from ._cells import CELL, COMPRESSION_RESULT, LIFT, POUR, SERVO
from .descriptor import RigDescriptor, fill_phases, lift_phases, particle_fits_cell, waits


def phases(job, wait, settle_key):
    steps = job["rig_config"]["procedure"]["load_steps_pa"]
    return (fill_phases(job, wait, settle_key) + lift_phases(job, wait, settle_key)
            + waits("load steps", len(steps), "rig.procedure.load_steps_pa", wait))


DESCRIPTOR = RigDescriptor(
    name="ucs", script="ucs.py",
    geometry=CELL + ("table_material", "plate_material", "table_radius_m", "plate_diameter_m"),
    procedure=POUR + LIFT + ("load_steps_pa",) + SERVO,
    phases=phases, result_keys=("stress_pa", "strain", "n_particles"), replicas_max=8,
    check_job=particle_fits_cell, post="compression", lab_curves=("ucs",),
    comparisons=(("bulk_stiffness", "stiffness_pa", "bulk_stiffness_pa", None, "loading"),
                 ("bulk_density", "bulk_density_kg_m3", "bulk_density_kg_m3", None, "loading")))
