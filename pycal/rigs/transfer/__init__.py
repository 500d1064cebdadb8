"""transfer: a belt stream on an inclined steel plate (application: impact stress,
holdup, plugging). No fill and no replicas (a periodic cell). The stream's geometry: stream.py."""
from ..descriptor import RigDescriptor
from . import stream


def phases(job, wait, settle_key):
    p = job["rig_config"]["procedure"]       # no rest wait: the feed and the holdup wait, run to the end
    return [("feed", p["feed_time_s"], "rig.procedure.feed_time_s"),
            ("holdup wait after the feed", p["holdup_wait_s"], "rig.procedure.holdup_wait_s")]


def check_job(job):
    stream.check_job(job)


DESCRIPTOR = RigDescriptor(
    name="transfer", script="transfer.py",
    geometry=("plate_material", "plate_inclination_deg", "plate_length_m", "impact_point_from_plate_top_m",
              "slice_width_m", "stream_width_m"),
    procedure=("design_drop_height_m", "design_belt_speed_m_s", "design_mass_flow_kg_s",
               "design_belt_bulk_density_kg_m3", "injection_height_m", "injection_layer_thickness_m",
               "placement_max_attempts_count", "feed_time_s", "holdup_wait_s"),
    measure=("steady_from_s", "plug_outflow_ratio", "record_interval_s", "force_sample_interval_count",
             "speed_gauge_height_m", "stress_profile_bin_m", "frame_interval_s"),
    phases=phases, result_keys=("impact_stress_pa", "throughput_in_kg_s", "throughput_out_kg_s"),
    accepts_material_sets=True, check_job=check_job, post="transfer",
    scale_refused="the transfer rig is the design chute at its own size (the plate, the stream and the drop of the "
                  "design case), not a lab rig to hold more grains")
