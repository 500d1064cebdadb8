"""ccs_expansion: CCS with unloading (calibrates the particle stiffness)."""
from ._cells import CELL, COMPRESSION_RESULT, LOADING_COMPARISONS, POUR, SERVO
from .descriptor import RigDescriptor, fill_phases, particle_fits_cell, waits


def phases(job, wait, settle_key):
    p = job["rig_config"]["procedure"]
    n = len(p["load_steps_pa"]) + len(p["unload_steps_pa"])
    return fill_phases(job, wait, settle_key) + waits("load and unload steps", n, "rig.procedure.unload_steps_pa",
                                                      wait)


DESCRIPTOR = RigDescriptor(
    name="ccs_expansion", script="ccs_expansion.py",
    geometry=CELL + ("table_material", "plate_material"),
    procedure=POUR + ("load_steps_pa", "unload_steps_pa") + SERVO,
    phases=phases, result_keys=COMPRESSION_RESULT + ("unloading_stiffness_pa", "unloading_stress_pa"),
    responses=("unloading_stiffness_log_ratio",), replicas_max=8, check_job=particle_fits_cell,
    # lab curves: its own, and the sample's ccs curve for the loading branch
    post="compression", lab_curves=("ccs_expansion", "ccs"), pictures=("spring_curve.png",),
    comparisons=(("unloading_stiffness", "stiffness_pa", "particle_stiffness_pa", None, "unloading"),)
    + LOADING_COMPARISONS)
