"""How many time steps a job can take, estimated from the job alone before it runs.

steps = longest simulated time of the rig (s) / time step (s).

- Time step (s): what the rigs use, numerics.timestep_safety_factor x YADE's
  PWaveTimeStep, i.e. the smallest radius / sqrt(E / density) over the particle
  spheres. For clump materials the smallest member a lump of the job's size classes
  can have (lump rule of pycal/lump_geometry.py at the class's minimum size):
  the run's own time step, set by the lumps actually drawn, is that or longer.
- Longest simulated time (s): the sum of the rig's phases, each at its limit: a rest
  wait (settle, load step) ends after at most numerics.max_settle_time_s (plus one rest
  check interval) or the rig fails; a cylinder lift ends by its own time limit
  (1.5 x the lift height / lift speed + 1 s); a tilt test tilts to max_tilt_deg, holds,
  resumes and tilts back; the transfer rig runs its feed time and its holdup wait
  (docs/rigs.md lists each rig's phases; each rig's descriptor, pycal/rigs/<rig>.py,
  states them).

A job above numerics.max_estimated_steps_count is refused at job resolution with one
line naming the values that drive the estimate (pycal.jobs.resolve_job).
"""
import math

from .errors import ConfigError
from .lump_geometry import particle_radii

DT_KEYS = ("contact.youngs_modulus_pa", "particles.density_kg_m3", "particles.diameter_m")


# ---------------------------------------------------------------- time step

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

def _phases(job):
    """[(phase, longest simulated time s, the config key that sets it)] of the job's rig
    (its descriptor's phases, pycal/rigs/<rig>.py)."""
    from . import rigs
    num = job["rig_config"]["numerics"]
    wait = num["max_settle_time_s"] + num["rest_check_interval_s"]
    return rigs.get(job["rig"]).phases(job, wait, "rig.numerics.max_settle_time_s")


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
    scale = job["rig_config"]["geometry"].get("scale", 1)
    if scale != 1 and not keys:       # a scaled rig: its lengths drive the lift, pour and slides
        why += f" (at geometry.scale {scale:g}: every length of the rig x {scale:g})"
        if "rig.geometry.scale" in overrides:
            raise ConfigError("--set", f"rig.geometry.scale={scale:g}", why)
        raise ConfigError(f"configs/rigs/{job['rig']}.yaml", "geometry.scale", why)
    if keys:
        value = overrides[keys[0]]
        shown = f"{value:g}" if isinstance(value, (int, float)) and not isinstance(value, bool) else value
        raise ConfigError("--set", f"{keys[0]}={shown}", why)
    raise ConfigError("configs/numerics.yaml", "max_estimated_steps_count", why)
