"""wall_friction: tilt-table wall friction (calibrates particle-steel friction). No
replicas: gravity is rotated for the whole scene, replicas would share one tilt."""
from ._cells import CELL, FRICTION_RESPONSES, FRICTION_RESULT, POUR, TILT
from .descriptor import RigDescriptor, particle_fits_cell, tilt_phases

DESCRIPTOR = RigDescriptor(
    name="wall_friction", script="wall_friction.py",
    geometry=CELL + ("cell_gap_to_plate_m", "cell_mass_kg", "lid_mass_kg", "plate_material", "plate_back_length_m",
                     "plate_front_length_m", "plate_half_width_m", "lid_material"),
    procedure=POUR + TILT, phases=tilt_phases, result_keys=FRICTION_RESULT, responses=FRICTION_RESPONSES,
    check_job=particle_fits_cell, post="friction",
    pictures=("friction_vs_stress.png",))
