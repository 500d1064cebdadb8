"""surcharge: the AoR pile, vibrated, measured again (a check)."""
from ._cells import AOR_RESULT, CELL, LIFT, PILE_READING, POUR
from .aor import phases as aor_phases
from .descriptor import RigDescriptor, particle_fits_cell

VIBRATION = ("vibration_frequency_hz", "vibration_amplitude_horizontal_m", "vibration_amplitude_vertical_m",
             "vibration_duration_s")


def phases(job, wait, settle_key):
    p = job["rig_config"]["procedure"]
    return aor_phases(job, wait, settle_key) + [
        ("vibration", p["vibration_duration_s"], "rig.procedure.vibration_duration_s"),
        ("settle after vibration (1 rest wait)", wait, settle_key)]


DESCRIPTOR = RigDescriptor(
    name="surcharge", script="surcharge.py",
    geometry=CELL + ("table_material", "table_radius_m"), procedure=POUR + LIFT + VIBRATION, measure=PILE_READING,
    phases=phases, result_keys=AOR_RESULT + ("surcharge_mean_deg", "surcharge_sectors_count"),
    responses=("aor_mean_deg", "surcharge_mean_deg"), replicas_max=8, check_job=particle_fits_cell,
    post="aor", pictures=("pile_side.png", "surcharge_side.png"))
