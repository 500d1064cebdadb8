"""fill: the struck cell fill (calibrates the particle density)."""
from ._cells import CELL, POUR
from .descriptor import RigDescriptor, fill_phases, particle_fits_cell

DESCRIPTOR = RigDescriptor(
    name="fill", script="fill.py",
    geometry=CELL + ("table_material",), procedure=POUR, measure=("fill_height_rule",),
    phases=fill_phases,
    result_keys=("bulk_density_kg_m3", "mass_kg", "n_particles", "solid_fraction"),
    responses=("bulk_density_kg_m3",), replicas_max=8, check_job=particle_fits_cell)
