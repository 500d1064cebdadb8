"""aor: cylinder-lift angle of repose (calibrates rolling resistance, wet cohesion)."""
from ._cells import AOR_RESULT, CELL, LIFT, PILE_READING, POUR
from .descriptor import RigDescriptor, fill_phases, lift_phases, particle_fits_cell


def phases(job, wait, settle_key):
    return fill_phases(job, wait, settle_key) + lift_phases(job, wait, settle_key)


DESCRIPTOR = RigDescriptor(
    name="aor", script="aor.py",
    geometry=CELL + ("table_material", "table_radius_m"), procedure=POUR + LIFT, measure=PILE_READING,
    phases=phases, result_keys=AOR_RESULT, responses=("aor_mean_deg",), replicas_max=8,
    check_job=particle_fits_cell, post="aor", pictures=("pile_side.png",))
