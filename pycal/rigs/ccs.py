"""ccs: confined compression (a check; its curves feed the CCS expansion's)."""
from ._cells import CELL, COMPRESSION_RESULT, LOADING_COMPARISONS, POUR, SERVO
from .descriptor import RigDescriptor, fill_phases, particle_fits_cell, waits


def phases(job, wait, settle_key):
    steps = job["rig_config"]["procedure"]["load_steps_pa"]
    return fill_phases(job, wait, settle_key) + waits("load steps", len(steps), "rig.procedure.load_steps_pa", wait)


DESCRIPTOR = RigDescriptor(
    name="ccs", script="ccs.py",
    geometry=CELL + ("table_material", "plate_material"), procedure=POUR + ("load_steps_pa",) + SERVO,
    phases=phases, result_keys=COMPRESSION_RESULT, replicas_max=8, check_job=particle_fits_cell,
    post="compression", lab_curves=("ccs",),
    comparisons=LOADING_COMPARISONS + (("bulk_density", "bulk_density_kg_m3", "solid_fraction",
                                        "lab_particle_density", "loading"),))
