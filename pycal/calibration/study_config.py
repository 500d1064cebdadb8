"""The study config (configs/calibrations/*.yaml): validated and made explicit.

Every error names the file, the dotted key and the reason (exit 2 from the CLI), and
the whole file is checked before any run starts. `load_study` returns the config with
each stage normalised: defaults filled in, so the driver reads one shape per kind.

Stage kinds (one module each in pycal/calibration/stages/, registered there: how a kind's
config is checked, how it runs, whether it calibrates)
  density, rolling_resistance, cohesion, stiffness, friction   one parameter group, one response
  joint      2-3 parameter groups, one or more responses (rigs): a posterior over them
  inherit    copy a value (and its interval) found for another material
Every normalised stage has `kind`, `label`, `responses` ([{rig, response, target,
rig_overrides}]; none for inherit) and `parameter_keys` (the key lists it sets).

A parameter group:
  keys        config keys set to one value (e.g. rolling resistance on M2, steel, PVC)
  bounds      [lo, hi] in the keys' unit
  start       first point (default: the value the study has reached, inside the bounds)
  scale       linear | log (default log for stiffness and density: they span a range of ratios)
  tolerance_<unit> or tolerance_percent   the stop rule: the 95 % interval within +- this
              of the estimate, in the parameter's unit (unit = the keys' suffix:
              tolerance_coefficient, tolerance_pa, tolerance_kg_m3, tolerance_fraction)
  response_increases         1-D stages: the direction physics gives the response (required)
  response_slope_estimate    1-D stages, optional: |d response / d parameter| from physics
A 1-D stage's material_set (optional): the stage runs its rig on that set of
configs/material_sets/ (its material must be a component; the other components take the
values the study has found for them) and moves its material's keys, e.g. the weight part
of the wet fines' hold on gravel on the wet -50 mm pile.
A stage's run_at (optional): material keys and the values the stage's runs use instead of
the study's current ones, not carried into the calibrated set (e.g. the friction stages
at a cheaper Young's modulus the friction responses are measured not to depend on).
A target: {value: X} | {sample: KEY, test: angle_of_repose} | {} (bulk density: the
material's lab sample), with optional band_<unit> (the lab band: plotted, and the
parameter range it allows) and standard_error_<unit> (the target is itself a mean,
e.g. a twin's: widens the interval), <unit> = the response's unit, with
standard_error_seeds_count (how many values that standard error was estimated from:
the target is then drawn from a Student-t with n - 1 degrees of freedom).
"""
import copy
from pathlib import Path

from ..configs import _Checker, load_material, load_yaml
from . import stages as stage_kinds
from .stages.checks import _check_removed, stage_label


def load_study(path):
    """Validated study config with normalised stages (file, key and reason in every error)."""
    path = Path(path)
    data = load_yaml(path)
    c = _Checker(path)
    _check_removed(c, data, "")
    c.keys(data, "", ["name", "materials", "seeds_count"], ["description", "max_runs_count", "design_case",
                                                            "run_at_checks", "validation", "application"])
    if "run_at_checks" in data:
        c.keys(data["run_at_checks"], "run_at_checks", [], ["seeds_count"])
        c.number(data["run_at_checks"].get("seeds_count", 1), "run_at_checks.seeds_count", 1)
    if "validation" in data:
        from . import validation
        validation.check(data["validation"], c)
    if "application" in data:
        from . import application
        application.check(data["application"], c)
    c.string(data["name"], "name")
    seeds = int(c.number(data["seeds_count"], "seeds_count", 1))
    if "max_runs_count" in data:
        c.number(data["max_runs_count"], "max_runs_count", 1)
    if not isinstance(data["materials"], dict) or not data["materials"]:
        c.fail("materials", "must map material names to lists of stages")
    out = copy.deepcopy(data)
    done = set()
    for mat, stages in data["materials"].items():
        from ..configs import material_names
        if mat not in material_names():
            c.fail(f"materials.{mat}", f"unknown material {mat!r} (configs/materials: {', '.join(material_names())})")
        mat_cfg = copy.deepcopy(load_material(mat))
        if not isinstance(stages, list):
            c.fail(f"materials.{mat}", "must be a list of stages")
        names, norm = set(), []
        for i, st in enumerate(stages):
            key = f"materials.{mat}[{i}]"
            if not isinstance(st, dict) or st.get("stage") not in stage_kinds.names():
                c.fail(f"{key}.stage", f"must be one of {', '.join(stage_kinds.names())}")
            label = stage_label(st)
            if label in names:
                c.fail(f"{key}.name", f"two stages of {mat} are called {label!r}: give them different names")
            names.add(label)
            n = stage_kinds.get(st["stage"]).normalise(c, st, key, mat, mat_cfg, seeds, done)
            n["config_key"] = key
            norm.append(n)
            done.add((mat, label))
        out["materials"][mat] = norm
    out["raw"] = data
    return out


def stage_rigs(st):
    """The rigs a normalized stage runs: its responses' rigs ([] for an inherit)."""
    return [r["rig"] for r in st["responses"]]
