"""What a rig is, for pycal: one RigDescriptor per rig (pycal/rigs/<rig>.py).

It names the rig's config keys (checked against pycal/rigs/fields.py), its phases for
the step estimate (pycal.step_estimate), how many replicas one YADE run may hold
(pycal.replicas), the result keys a complete result.json must hold (the cache trusts a
result only with them; docs/rigs.md documents them), the responses a study stage may
read from it, its post-processing (module, lab curves, misfits) and any check that
needs the whole job (a particle larger than the cell).
"""
from dataclasses import dataclass
from typing import Callable, Optional

# every result.json holds these (docs/rigs.md "What every rig shares")
SHARED_RESULT_KEYS = ("rig", "material", "seed", "job", "job_id", "provenance", "timestep_s")


@dataclass(frozen=True)
class RigDescriptor:
    name: str
    script: str                                     # yade_scripts/<script>
    geometry: tuple                                 # required keys of each section (pycal/rigs/fields.py)
    procedure: tuple
    measure: tuple = ()
    optional: tuple = ()                            # keys a config may leave out ("section.key")
    phases: Callable = None                         # (job, wait_s, settle_key) -> [(phase, longest s, key)]
    result_keys: tuple = ()                         # beside SHARED_RESULT_KEYS
    responses: tuple = ()                           # named responses (pycal.post.responses) it gives
    replicas_max: int = 0                           # 0: no replicas (one seed per YADE run)
    accepts_material_sets: bool = False
    check_job: Optional[Callable] = None            # (job) -> None or raises ConfigError
    post: str = ""                                  # its post-processing module (pycal/post/<post>.py; its
                                                    # trace_picture(folder, job, path), if any, draws a run's
                                                    # records for the report)
    lab_curves: tuple = ()                          # rigs whose lab curves <rig>_<sample> it is compared with
    comparisons: tuple = ()                         # (misfit, result key, lab quantity, lab factor, branch)
    pictures: tuple = ()                            # pictures a run writes that the report shows (file names)
    scale_refused: str = ""                         # why geometry.scale cannot be other than 1 ("": it can;
                                                    # pycal/rigs/scaling.py)

    def keys(self, section):
        """The keys a config's section may hold: required, optional, and geometry.scale
        (every rig's, optional: pycal/rigs/scaling.py)."""
        extra = ("scale",) if section == "geometry" else ()
        return tuple(getattr(self, section)) + tuple(k.split(".", 1)[1] for k in self.optional
                                                       if k.startswith(section + ".")) + extra

    def required_result_keys(self):
        return SHARED_RESULT_KEYS + tuple(self.result_keys)


# ---------------------------------------------------------------- phases shared by rigs

def largest_size_m(job):
    """Largest particle size (m): sphere diameter or lump size-class maximum (of the
    size classes a material set uses, if the job is one)."""
    used = {name: c.get("size_classes") for name, c in job.get("material_set", {}).get("components", {}).items()}
    sizes = []
    for name, mat in job["materials"].items():
        p = mat["particles"]
        if p["shape"] == "sphere":
            sizes.append(p["diameter_m"])
        else:
            sizes += [sc["max_size_m"] for sc in p["size_classes"] if used.get(name) in (None, []) or
                      sc["name"] in used[name]]
    return max(sizes)


def fill_phases(job, wait, settle_key):
    return [("pour and strike (2 rest waits)", 2 * wait, settle_key)]


def lift_phases(job, wait, settle_key):
    p, num = job["rig_config"]["procedure"], job["rig_config"]["numerics"]
    height = p["strike_level_height_m"] + 2 * largest_size_m(job) + p["lift_clearance_m"]
    return [("cylinder lift", 1.5 * height / p["lift_speed_m_s"] + 1.0 + num["rest_check_interval_s"],
             "rig.procedure.lift_speed_m_s"),
            ("pile settle (1 rest wait)", wait, settle_key)]


def waits(name, n, key, wait):
    return [(f"{name} ({n} rest waits)", n * wait, key)]


def tilt_phases(job, wait, settle_key):
    """Per consolidation step: load, unload, settle the lid (and the freed cell), the tilt
    (static tilt to max_tilt_deg and a hold, tilting on after stalls to max_tilt_deg and
    a hold), and the tilt back with a settle (sequential) or a new fill (fresh)."""
    p = job["rig_config"]["procedure"]
    n = len(p["consolidation_stresses_pa"])
    per_step_waits = 3 + (1 if p["settle_before_tilt"] else 0)
    max_tilt, hold = p["max_tilt_deg"], p["dynamic_max_time_s"]
    tilt = max_tilt / p["tilt_rate_deg_s"] + hold
    if p["measure_dynamic_friction"]:
        tilt += max_tilt / p["tilt_restart_rate_deg_s"] + hold
    out = fill_phases(job, wait, settle_key)
    out += [(f"load, unload, settle ({n} steps x {per_step_waits} rest waits)", n * per_step_waits * wait, settle_key),
            (f"tilt to {max_tilt:g} deg and hold ({n} steps)", n * tilt, "rig.procedure.tilt_rate_deg_s")]
    if p["fill_each_step"] == "fresh":
        out.append((f"a new fill per step ({n - 1} x 2 rest waits)", (n - 1) * 2 * wait, settle_key))
    else:
        out.append((f"tilt back and settle ({n} steps)", n * (max_tilt / p["tilt_return_rate_deg_s"] + wait),
                    "rig.procedure.tilt_return_rate_deg_s"))
    return out


def config_source(job, section, key):
    """Where a rig key of `job` came from, for an error line: '--set' when an override set
    it, else the rig's config file."""
    return "--set" if f"rig.{section}.{key}" in (job.get("overrides") or {}) else f"configs/rigs/{job['rig']}.yaml"


def particle_fits_cell(job):
    """A ConfigError when the largest particle is not smaller than the cell's diameter
    or height (the rig could not hold one particle)."""
    from ..errors import ConfigError
    g = job["rig_config"]["geometry"]
    size = largest_size_m(job)
    for key in ("cell_inner_diameter_m", "cell_height_m"):
        if key in g and size >= g[key]:
            raise ConfigError(config_source(job, "geometry", key), f"geometry.{key}", f"{g[key]:g} m does not hold one particle of "
                              f"{job['material']} ({size:g} m)")


def check_tilt_options(job):
    """A ConfigError when an audit option (procedure.sliding_cell_rotations: free,
    lid_during_tilt: free, shear_drive: force_ramp) is asked of a sequential fill (a cell
    that tipped, or a lid that slid off with the contents, is not put back for the next
    step: only fill_each_step: fresh starts each step anew), or the force drive with
    measure_dynamic_friction (the dynamic formula is the tilted table's)."""
    from ..errors import ConfigError
    from ..rig_contract import TILT_OPTION_DEFAULTS, tilt_option
    p = job["rig_config"]["procedure"]
    for key, default in TILT_OPTION_DEFAULTS.items():
        if tilt_option(p, key) != default and p["fill_each_step"] != "fresh":
            raise ConfigError(config_source(job, "procedure", key), f"procedure.{key}", f"{p[key]!r} needs procedure.fill_each_step: fresh "
                              "(the cell or lid is not put back between steps)")
    if tilt_option(p, "shear_drive") == "force_ramp" and p["measure_dynamic_friction"]:
        raise ConfigError(config_source(job, "procedure", "shear_drive"), "procedure.shear_drive", "'force_ramp' needs "
                          "procedure.measure_dynamic_friction: false (mu_dynamic is read on the tilted table)")
