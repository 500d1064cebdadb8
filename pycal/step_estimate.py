"""How many time steps a job can take, estimated from the job alone before it runs.

steps = longest simulated time of the rig (s) / time step (s).

- Time step (s): what the rigs use, numerics.timestep_safety_factor x YADE's
  PWaveTimeStep, i.e. the smallest radius / sqrt(E / density) over the particle
  spheres. For clump materials the smallest member a lump of the job's size classes
  can have (lump rule of yade_scripts/demlib/clumps.py at the class's minimum size):
  the run's own time step, set by the lumps actually drawn, is that or longer.
- Longest simulated time (s): the sum of the rig's phases, each at its limit: a rest
  wait (settle, load step) ends after at most numerics.max_settle_time_s (plus one rest
  check interval) or the rig fails; a cylinder lift ends by its own time limit
  (1.5 x the lift height / lift speed + 1 s); a tilt test tilts to max_tilt_deg, holds,
  resumes and tilts back; the transfer rig runs its feed time and its holdup wait
  (docs/rigs.md lists each rig's phases).

A job above numerics.max_estimated_steps_count is refused at job resolution with one
line naming the values that drive the estimate (pycal.jobs.resolve_job).
"""
import math

from .errors import ConfigError

DT_KEYS = ("contact.youngs_modulus_pa", "particles.density_kg_m3", "particles.diameter_m")


# ---------------------------------------------------------------- time step

def _clump_member_radius(mat, class_names=None):
    """Smallest member-sphere radius (m) of a clump material over its size classes (the
    ones named, or all) and the shapes they use."""
    from yade_scripts.demlib.clumps import box_dims, member_radius   # numpy only, no YADE
    p = mat["particles"]
    radii = []
    for sc in p["size_classes"]:
        if class_names is not None and sc["name"] not in class_names:
            continue
        for shape, pct in sc["shape_percent"].items():
            if pct > 0:
                s = p["shapes"][shape]
                radii.append(member_radius(box_dims(s["vertical_aspect_ratio"], s["horizontal_aspect_ratio"],
                                                    sc["min_size_m"])))
    return min(radii)


def particle_radii(job):
    """{material: smallest particle-sphere radius (m)} of the job's materials."""
    classes = {name: c.get("size_classes") for name, c in job.get("material_set", {}).get("components", {}).items()}
    out = {}
    for name, mat in job["materials"].items():
        if mat["particles"]["shape"] == "clump":
            out[name] = _clump_member_radius(mat, classes.get(name))
        else:
            out[name] = 0.5 * mat["particles"]["diameter_m"]
    return out


def critical_timestep(job):
    """(time step s, material that sets it, its radius m): safety factor x the smallest
    radius / sqrt(E / density) (YADE's PWaveTimeStep over the particle spheres)."""
    best = None
    for name, r in particle_radii(job).items():
        mat = job["materials"][name]
        wave = r / math.sqrt(mat["contact"]["youngs_modulus_pa"] / mat["particles"]["density_kg_m3"])
        if best is None or wave < best[0]:
            best = (wave, name, r)
    factor = job["rig_config"]["numerics"]["timestep_safety_factor"]
    return factor * best[0], best[1], best[2]


# ---------------------------------------------------------------- longest simulated time per rig

def _largest_size_m(job):
    """Largest particle size (m): sphere diameter or lump size-class maximum."""
    sizes = []
    for mat in job["materials"].values():
        p = mat["particles"]
        sizes += [p["diameter_m"]] if p["shape"] == "sphere" else [sc["max_size_m"] for sc in p["size_classes"]]
    return max(sizes)


def _phases(job):
    """[(phase, longest simulated time s, the config key that sets it)] of the job's rig."""
    rig = job["rig_config"]
    num, p, script = rig["numerics"], rig["procedure"], rig["script"]
    wait = num["max_settle_time_s"] + num["rest_check_interval_s"]
    settle_key = "rig.numerics.max_settle_time_s"
    fill = [("pour and strike (2 rest waits)", 2 * wait, settle_key)]

    def lift():
        height = p["strike_level_height_m"] + 2 * _largest_size_m(job) + p["lift_clearance_m"]
        return [("cylinder lift", 1.5 * height / p["lift_speed_m_s"] + 1.0 + num["rest_check_interval_s"],
                 "rig.procedure.lift_speed_m_s"),
                ("pile settle (1 rest wait)", wait, settle_key)]

    def waits(name, n, key):
        return [(f"{name} ({n} rest waits)", n * wait, key)]

    if script == "fill.py":
        return fill
    if script in ("aor.py", "aor_mixed.py"):
        return fill + lift()
    if script == "surcharge.py":
        return fill + lift() + [("vibration", p["vibration_duration_s"], "rig.procedure.vibration_duration_s"),
                                ("settle after vibration (1 rest wait)", wait, settle_key)]
    if script == "ccs.py":
        return fill + waits("load steps", len(p["load_steps_pa"]), "rig.procedure.load_steps_pa")
    if script == "ccs_expansion.py":
        return fill + waits("load and unload steps", len(p["load_steps_pa"]) + len(p["unload_steps_pa"]),
                            "rig.procedure.unload_steps_pa")
    if script == "ucs.py":
        return fill + lift() + waits("load steps", len(p["load_steps_pa"]), "rig.procedure.load_steps_pa")
    if script in ("wall_friction.py", "internal_friction.py"):
        return fill + _tilt_phases(p, wait, settle_key)
    if script == "transfer.py":          # no fill, no rest wait: the feed and the holdup wait, run to the end
        return [("feed", p["feed_time_s"], "rig.procedure.feed_time_s"),
                ("holdup wait after the feed", p["holdup_wait_s"], "rig.procedure.holdup_wait_s")]
    # a rig without its own rule: its fill only (add the rule here with the rig)
    return fill


def _tilt_phases(p, wait, settle_key):
    """Per consolidation step: load, unload, settle the lid (and the freed cell), the tilt
    (static tilt to max_tilt_deg and a hold, tilting on after stalls to max_tilt_deg and
    a hold), and the tilt back with a settle (sequential) or a new fill (fresh)."""
    n = len(p["consolidation_stresses_pa"])
    per_step_waits = 3 + (1 if p["settle_before_tilt"] else 0)
    max_tilt, hold = p["max_tilt_deg"], p["dynamic_max_time_s"]
    tilt = max_tilt / p["tilt_rate_deg_s"] + hold
    if p["measure_dynamic_friction"]:
        tilt += max_tilt / p["tilt_restart_rate_deg_s"] + hold
    out = [(f"load, unload, settle ({n} steps x {per_step_waits} rest waits)", n * per_step_waits * wait, settle_key),
           (f"tilt to {max_tilt:g} deg and hold ({n} steps)", n * tilt, "rig.procedure.tilt_rate_deg_s")]
    if p["fill_each_step"] == "fresh":
        out.append((f"a new fill per step ({n - 1} x 2 rest waits)", (n - 1) * 2 * wait, settle_key))
    else:
        out.append((f"tilt back and settle ({n} steps)", n * (max_tilt / p["tilt_return_rate_deg_s"] + wait),
                    "rig.procedure.tilt_return_rate_deg_s"))
    return out


# ---------------------------------------------------------------- the estimate and the refusal

def estimate(job):
    """{'steps_count', 'timestep_s', 'simulated_time_s', 'material', 'radius_m',
    'phases': [(phase, s, key)]} of a resolved job (see the module doc)."""
    dt, material, radius = critical_timestep(job)
    phases = _phases(job)
    t = sum(s for _, s, _ in phases)
    return {"steps_count": t / dt, "timestep_s": dt, "simulated_time_s": t, "material": material,
            "radius_m": radius, "phases": phases}


def check(job):
    """Refuse a job whose estimated step count is above numerics.max_estimated_steps_count:
    ConfigError naming the value that drives it (an override if one does, else the limit)
    and both factors (time step and simulated time)."""
    limit = job["rig_config"]["numerics"]["max_estimated_steps_count"]
    e = estimate(job)
    if e["steps_count"] <= limit:
        return e
    mat = job["materials"][e["material"]]
    longest = max(e["phases"], key=lambda ph: ph[1])
    why = (f"{job['rig']} with {job['material']} would take up to {e['steps_count']:.3g} time steps, more than "
           f"numerics.max_estimated_steps_count {limit:.3g}: time step {e['timestep_s']:.3g} s (from "
           f"{e['material']}: contact.youngs_modulus_pa {mat['contact']['youngs_modulus_pa']:g}, "
           f"particles.density_kg_m3 {mat['particles']['density_kg_m3']:g}, radius {e['radius_m']:g} m) "
           f"over up to {e['simulated_time_s']:.3g} s simulated ({longest[1]:.3g} s of it {longest[0]}); "
           "if this is intended, raise the limit with --set rig.numerics.max_estimated_steps_count=N")
    overrides = job.get("overrides") or {}
    keys = [k for k in overrides if k.endswith(DT_KEYS) or k == "rig.numerics.timestep_safety_factor"]
    keys += [k for k in overrides if k == longest[2]]
    if keys:
        value = overrides[keys[0]]
        shown = f"{value:g}" if isinstance(value, (int, float)) and not isinstance(value, bool) else value
        raise ConfigError("--set", f"{keys[0]}={shown}", why)
    raise ConfigError("configs/numerics.yaml", "max_estimated_steps_count", why)
