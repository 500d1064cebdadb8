"""internal_friction: two stacked cells on a tilt table (calibrates particle-particle
friction). No replicas (gravity is rotated for the whole scene)."""
from ._cells import CELL, FRICTION_RESPONSES, FRICTION_RESULT, POUR, TILT
from ..rig_contract import TILT_OPTION_DEFAULTS
from .descriptor import RigDescriptor, check_tilt_options, particle_fits_cell, tilt_phases


def check_internal_friction_job(job):
    """A particle larger than the cell, or an audit option on a sequential fill (ConfigError)."""
    particle_fits_cell(job)
    check_tilt_options(job)


DESCRIPTOR = RigDescriptor(
    name="internal_friction", script="internal_friction.py",
    geometry=CELL + ("cell_gap_m", "cell_mass_kg", "lid_mass_kg", "table_material", "table_half_width_m",
                     "lid_material"),
    procedure=POUR + TILT, phases=tilt_phases, result_keys=FRICTION_RESULT, responses=FRICTION_RESPONSES,
    optional=tuple(f"procedure.{k}" for k in TILT_OPTION_DEFAULTS),   # the audit options (issue 28): left out,
    # the rig runs as it always has (same job ids)
    check_job=check_internal_friction_job, post="friction",
    pictures=("friction_vs_stress.png",))
