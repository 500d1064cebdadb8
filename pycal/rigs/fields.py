"""Every key a rig config may hold, once: its type, unit and range, with the reason.

A key means the same in every rig that has it (cell_height_m is a cell's height in the
fill, the CCS and the friction cells), so its check lives here once; a rig descriptor
(pycal/rigs/<rig>.py) lists which of these keys its config holds. Ranges rule out what
cannot be built or run, not what is unusual: a rig config is the user's experiment.
"""
from dataclasses import dataclass

from ..contact_rules import CONTACT_MODELS


@dataclass(frozen=True)
class Field:
    kind: str                  # number | integer | bool | choice | boundary | stress_list
    lo: float = None           # lower bound (None: none)
    hi: float = None           # upper bound (None: none)
    lo_open: bool = False      # lo itself refused
    hi_open: bool = False      # hi itself refused
    choices: tuple = ()        # kind choice
    reason: str = ""           # why the range (shown with a refusal)
    scales: str = ""           # under geometry.scale s (pycal/rigs/scaling.py): "length" x s, "area" x s^2
                               # (a mass whose weight loads an area: its stress kept), "" kept as it is


def positive(reason="must be > 0"):
    return Field("number", 0.0, lo_open=True, reason=reason)


def non_negative(reason="must be >= 0"):
    return Field("number", 0.0, reason=reason)


def fraction(reason="a fraction"):
    return Field("number", 0.0, 1.0, lo_open=True, reason=reason)


def count(lo=1, reason=""):
    return Field("integer", lo, reason=reason)


LENGTH = positive("a length")
RIG_LENGTH = Field("number", 0.0, lo_open=True, reason="a length", scales="length")   # a length of the rig itself
RIG_GAP = Field("number", 0.0, reason="must be >= 0", scales="length")              # a gap of the rig (may be 0)
TIME = positive("a duration")
SPEED = positive("a speed: 0 never ends")
RATE = positive("a tilt rate: 0 never ends")
MASS = positive("a mass")
LOAD_MASS = Field("number", 0.0, lo_open=True, reason="a mass", scales="area")   # lid, ring: stress kept

FIELDS = {
    # ------------------------------------------------------------- geometry
    "scale": Field("number", 1.0, reason="the rig's lengths x this (1: the lab's size); below 1 the rig holds fewer "
                   "grains than the lab's own, which is what the scale is there to avoid"),
    "cell_inner_diameter_m": RIG_LENGTH,
    "cell_height_m": RIG_LENGTH,
    "cell_facet_segments_count": count(3, "a polygon needs >= 3 sides (the shipped cells use 32)"),
    "cell_material": Field("boundary"),
    "cell_gap_m": Field("number", 0.0, lo_open=True, reason="the gap between the two cells is the shear plane: > 0",
                        scales="length"),
    "cell_gap_to_plate_m": RIG_GAP,
    "cell_mass_kg": LOAD_MASS,
    "lid_mass_kg": LOAD_MASS,
    "lid_material": Field("boundary"),
    "table_material": Field("boundary"),
    "table_half_width_m": RIG_LENGTH,
    "table_radius_m": RIG_LENGTH,
    "plate_material": Field("boundary"),
    "plate_diameter_m": RIG_LENGTH,
    "plate_length_m": LENGTH,
    "plate_half_width_m": RIG_LENGTH,
    "plate_front_length_m": RIG_LENGTH,
    "plate_back_length_m": RIG_GAP,
    "plate_inclination_deg": Field("number", 0.0, 90.0, hi_open=True, reason="a plate between flat and vertical"),
    "impact_point_from_plate_top_m": non_negative(),
    "stream_width_m": LENGTH,
    "slice_width_m": LENGTH,
    # ------------------------------------------------------------- procedure
    "pour_height_factor": Field("number", 1.0, reason="the pour column is at least the cell"),
    "pour_porosity_ratio": Field("number", 0.0, 1.0, lo_open=True, hi_open=True, reason="a porosity"),
    "pour_solid_fraction": Field("number", 0.0, 0.64, lo_open=True, reason="a solid fraction of a loose pour "
                                 "(random close packing of spheres is 0.64)"),
    "pour_max_attempts_count": count(1),
    "placement_max_attempts_count": count(1),
    "fill_solid_fraction": Field("number", 0.0, 0.74, lo_open=True, reason="a solid fraction (0.74: densest "
                                 "sphere packing)"),
    "fill_overfill_ratio": Field("number", 1.0, reason="the column holds at least the cell's volume"),
    "strike_level_height_m": RIG_LENGTH,
    "lift_speed_m_s": SPEED,
    "lift_clearance_m": RIG_GAP,
    "load_steps_pa": Field("stress_list", reason="stresses > 0"),
    "unload_steps_pa": Field("stress_list", reason="stresses > 0"),
    "consolidation_stresses_pa": Field("stress_list", reason="stresses > 0"),
    "plate_speed_max_m_s": SPEED,
    "plate_start_gap_m": RIG_GAP,
    "step_tolerance_ratio": fraction("a relative tolerance on a load step"),
    "servo_relaxation_time_s": TIME,
    "servo_control_interval_s": TIME,
    "fill_each_step": Field("choice", choices=("fresh", "sequential")),
    "tilt_rate_deg_s": RATE,
    "pre_tilt_rate_deg_s": RATE,
    "pre_tilt_slide_fraction": Field("number", 0.0, 1.0, reason="a fraction of the onset distance"),
    "settle_before_tilt": Field("bool"),
    "tilt_restart_rate_deg_s": RATE,
    "tilt_return_rate_deg_s": RATE,
    "slide_onset_displacement_m": LENGTH,
    "measure_dynamic_friction": Field("bool"),
    "dynamic_travel_distance_m": LENGTH,
    "dynamic_max_time_s": TIME,
    "dynamic_stall_time_s": TIME,
    "max_tilt_deg": Field("number", 0.0, 90.0, lo_open=True, reason="a tilt between flat and vertical"),
    "record_interval_s": TIME,
    "particle_damping_during_tilt": Field("choice", choices=("damped", "undamped", "undamped_when_sliding")),
    "sliding_cell_rotations": Field("choice", choices=("blocked", "free")),
    "lid_during_tilt": Field("choice", choices=("joined", "free")),
    "shear_drive": Field("choice", choices=("tilt", "force_ramp")),
    "slide_read_at": Field("choice", choices=("body", "shear_plane")),
    "vibration_frequency_hz": positive("a frequency"),
    "vibration_amplitude_horizontal_m": non_negative(),
    "vibration_amplitude_vertical_m": non_negative(),
    "vibration_duration_s": TIME,
    "design_belt_speed_m_s": SPEED,
    "design_drop_height_m": non_negative(),
    "design_mass_flow_kg_s": positive("a mass flow"),
    "design_belt_bulk_density_kg_m3": positive("a bulk density"),
    "injection_height_m": LENGTH,
    "injection_layer_thickness_m": LENGTH,
    "feed_time_s": TIME,
    "holdup_wait_s": non_negative(),
    # ------------------------------------------------------------- measure
    "fill_height_rule": Field("choice", choices=("centre_above_rim_removed",)),
    "exclude_apex_m": non_negative(),
    "exclude_bottom_m": non_negative(),
    "upper_exclude_apex_m": non_negative(),
    "silhouette_slice_height_m": LENGTH,
    "upper_silhouette_slice_height_m": LENGTH,
    "upper_fit_from_height_fraction": Field("number", 0.0, 1.0, hi_open=True, reason="a fraction of the pile height"),
    "sector_half_width_deg": Field("number", 0.0, 90.0, lo_open=True, reason="half a sector: four sectors "
                                   "cover the circle at 45"),
    "force_sample_interval_count": count(1),
    "frame_interval_s": TIME,
    "steady_from_s": non_negative(),
    "speed_gauge_height_m": LENGTH,
    "stress_profile_bin_m": LENGTH,
    "plug_outflow_ratio": fraction("a ratio of outflow to inflow"),
    # ------------------------------------------------------------- numerics (configs/numerics.yaml and a rig's own)
    "contact_model": Field("choice", choices=tuple(CONTACT_MODELS)),
    "global_damping_ratio": Field("number", 0.0, 0.9, reason="Cundall damping: 0 <= ratio < 1"),
    "rolling_stiffness_factor": non_negative(),
    "twisting_stiffness_factor": non_negative(),
    "contact_update_interval_count": count(1),
    "timestep_safety_factor": Field("number", 0.0, 1.0, lo_open=True, reason="a fraction of YADE's "
                                    "PWaveTimeStep: above 1 the integration is unstable"),
    "rest_kinetic_energy": Field("choice", choices=("total", "translational")),
    "rest_unbalanced_force_ratio": positive(),
    "rest_kinetic_energy_ratio": positive(),
    "rest_check_interval_s": TIME,
    "max_settle_time_s": TIME,
    "max_overlap_fraction": Field("number", 0.0, 2.0, lo_open=True, reason="an overlap as a fraction of the radius"),
    "domain_margin_m": LENGTH,
    "gravity_m_s2": positive("gravity"),
    "max_estimated_steps_count": positive("a step count"),
}
