"""internal_friction: two stacked cells on a tilt table (calibrates particle-particle
friction). No replicas (gravity is rotated for the whole scene)."""
from ._cells import CELL, FRICTION_RESPONSES, FRICTION_RESULT, POUR, TILT
from .descriptor import RigDescriptor, particle_fits_cell, tilt_phases

DESCRIPTOR = RigDescriptor(
    name="internal_friction", script="internal_friction.py",
    geometry=CELL + ("cell_gap_m", "cell_mass_kg", "lid_mass_kg", "table_material", "table_half_width_m",
                     "lid_material"),
    procedure=POUR + TILT, phases=tilt_phases, result_keys=FRICTION_RESULT, responses=FRICTION_RESPONSES,
    check_job=particle_fits_cell, post="friction",
    pictures=("friction_vs_stress.png",))
