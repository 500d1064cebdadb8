"""aor_mixed: angle of repose of a material set (the -50 mm sample). No replicas: its
time step comes from the lumps drawn, replicas would share the smallest of the batch."""
from ._cells import AOR_RESULT, CELL, LIFT, PILE_READING
from .aor import phases
from .descriptor import RigDescriptor, particle_fits_cell

DESCRIPTOR = RigDescriptor(
    name="aor_mixed", script="aor_mixed.py",
    geometry=CELL + ("table_material", "table_radius_m"),
    procedure=("fill_solid_fraction", "fill_overfill_ratio", "pour_solid_fraction", "pour_max_attempts_count",
               "strike_level_height_m") + LIFT,
    measure=PILE_READING + ("upper_fit_from_height_fraction", "upper_silhouette_slice_height_m",
                            "upper_exclude_apex_m"),
    phases=phases, result_keys=AOR_RESULT + ("aor_upper_mean_deg", "pile_footprint_fraction"),
    responses=("aor_mean_deg", "pile_footprint_fraction"),
    accepts_material_sets=True, check_job=particle_fits_cell, post="aor_mixed",
    pictures=("pile_side.png",))
