"""Key groups several rigs share (the cell and its pour, the cylinder lift, the servo
plate, the tilt table, the pile reading)."""
CELL = ("cell_inner_diameter_m", "cell_height_m", "cell_facet_segments_count", "cell_material")
POUR = ("pour_height_factor", "pour_porosity_ratio", "strike_level_height_m")
LIFT = ("lift_speed_m_s", "lift_clearance_m")
SERVO = ("plate_speed_max_m_s", "step_tolerance_ratio", "plate_start_gap_m", "servo_relaxation_time_s",
         "servo_control_interval_s")
TILT = ("consolidation_stresses_pa",) + SERVO + (
    "fill_each_step", "tilt_rate_deg_s", "pre_tilt_rate_deg_s", "pre_tilt_slide_fraction", "settle_before_tilt",
    "tilt_restart_rate_deg_s", "tilt_return_rate_deg_s", "slide_onset_displacement_m", "measure_dynamic_friction",
    "dynamic_travel_distance_m", "dynamic_max_time_s", "dynamic_stall_time_s", "max_tilt_deg", "record_interval_s",
    "particle_damping_during_tilt")
PILE_READING = ("sector_half_width_deg", "silhouette_slice_height_m", "exclude_bottom_m", "exclude_apex_m")
AOR_RESULT = ("aor_mean_deg", "aor_left_deg", "aor_right_deg", "aor_front_deg", "aor_back_deg",
              "aor_sectors_count", "n_particles", "pile_height_m")
COMPRESSION_RESULT = ("stress_pa", "strain", "bulk_density_kg_m3", "n_particles")
FRICTION_RESULT = ("steps", "stress_pa", "mu_static", "mu_dynamic", "n_particles")
FRICTION_RESPONSES = ("friction_offset_mu_static", "friction_offset_mu_dynamic", "friction_angle_offset_deg",
                      "friction_band_z_mu_static", "friction_band_z_mu_dynamic")

# compression misfits: (name of the misfit, simulated key, lab quantity, factor applied to the lab values, branch)
LOADING_COMPARISONS = (("bulk_stiffness", "stiffness_pa", "bulk_stiffness_pa", None, "loading"),
                       ("solid_fraction", "solid_fraction", "solid_fraction", None, "loading"))
