"""A calibration study: stages per material in the method's order (configs/calibrations/).

Each stage moves one parameter group (several config keys set to one value) until a
rig response matches its lab target, or copies values from another material. The
values found are carried into the next stage. All runs go through one executor
(pycal.runner), so nothing is simulated twice and a killed study resumes where it
stopped when started again.

Outputs in <out>/<study name>/:
  calibrated/<material>.yaml   the material config with the calibrated values (loads as a config)
  stages.csv                   one row per stage: parameter, value, response, target, met
  history.csv                  every evaluated point: stage, x, response mean/std/n
  summary.json                 everything above plus provenance
"""
import copy
import csv
import json
import math
import os
import time
from pathlib import Path

import yaml

from .. import CONFIG_DIR
from ..configs import load_material, load_yaml, _Checker
from ..errors import ConfigError, RunError
from ..jobs import resolve_job, _set_path
from ..post import mean_std
from .root1d import solve_monotone

STAGE_KEYS = {
    "density": (["stage", "rig", "tolerance_percent"], ["max_iterations_count", "target"]),
    "rolling_resistance": (["stage", "rig", "response", "target", "parameter"],
                           ["tolerance_deg", "max_iterations_count", "rig_overrides", "set"]),
    "cohesion": (["stage", "rig", "response", "target", "parameter"],
                 ["tolerance_deg", "tolerance_mu", "max_iterations_count", "rig_overrides", "set"]),
    "stiffness": (["stage", "rig", "response", "target", "parameter"],
                  ["tolerance_log_ratio", "max_iterations_count", "rig_overrides", "set"]),
    "friction": (["stage", "rig", "response", "target", "parameter"],
                 ["tolerance_mu", "max_iterations_count", "rig_overrides", "set"]),
    "joint": (["stage", "rig", "response", "parameters", "tolerance_rms_z"],
              ["max_iterations_count", "rig_overrides", "set"]),
    "inherit": (["stage", "from", "keys"], []),
}
# every stage may also have `name` (default: its stage type; `inherit` refers to it)
# `set`: material keys given fixed values from this stage on (e.g. a cohesion model switched)
TOLERANCE_KEYS = ("tolerance_log_ratio", "tolerance_mu", "tolerance_deg")   # the stage's tolerance, in response units


def _friction_targets(result, lab_dir):
    from ..post import friction
    return friction.load_targets(result["rig"], friction.lab_sample_of(result), lab_dir)


def derived_responses(lab_dir=None):
    """Responses computed from a whole result against the lab curves of lab_dir (default
    labresults/): name -> function(result) -> float."""
    from ..post.compression import unloading_stiffness_log_ratio
    from ..post.friction import friction_offset
    return {"unloading_stiffness_log_ratio": lambda r: unloading_stiffness_log_ratio(r, lab_dir=lab_dir),
            "friction_offset_mu_static":
                lambda r: friction_offset(r, "mu_static", targets=_friction_targets(r, lab_dir)),
            "friction_offset_mu_dynamic":
                lambda r: friction_offset(r, "mu_dynamic", targets=_friction_targets(r, lab_dir))}


def vector_responses(lab_dir=None):
    """Residual vectors computed from a whole result (name -> function(result) -> list)."""
    from ..post.friction import friction_band_z
    return {"friction_band_z_mu_static":
                lambda r: friction_band_z(r, "mu_static", targets=_friction_targets(r, lab_dir)),
            "friction_band_z_mu_dynamic":
                lambda r: friction_band_z(r, "mu_dynamic", targets=_friction_targets(r, lab_dir))}


def response_value(result, response, lab_dir=None):
    derived = derived_responses(lab_dir)
    return float(derived[response](result)) if response in derived else float(result[response])


def load_study(path):
    """Validated study config (file, key and reason in every error)."""
    path = Path(path)
    data = load_yaml(path)
    c = _Checker(path)
    c.keys(data, "", ["name", "materials", "seeds_count"],
           ["description", "max_runs_count", "design_case", "max_seeds_count"])
    c.number(data["seeds_count"], "seeds_count", 1)
    if "max_seeds_count" in data:
        c.number(data["max_seeds_count"], "max_seeds_count", data["seeds_count"])
    if "max_runs_count" in data:
        c.number(data["max_runs_count"], "max_runs_count", 1)
    for mat, stages in data["materials"].items():
        load_material(mat)
        if not isinstance(stages, list):
            c.fail(f"materials.{mat}", "must be a list of stages")
        names = set()
        for i, st in enumerate(stages):
            key = f"materials.{mat}[{i}]"
            if not isinstance(st, dict) or st.get("stage") not in STAGE_KEYS:
                c.fail(f"{key}.stage", f"must be one of {', '.join(STAGE_KEYS)}")
            req, opt = STAGE_KEYS[st["stage"]]
            c.keys(st, key, req, opt + (["name"] if st["stage"] == "inherit" else ["name", "lab_dir"]))
            label = stage_label(st)
            if label in names:
                c.fail(f"{key}.name", f"two stages of {mat} are called {label!r}: give them different names")
            names.add(label)
            for k in st.get("set", {}):
                if str(k).startswith("rig."):
                    c.fail(f"{key}.set.{k}", "only material keys may be set here (rig keys: rig_overrides)")
            if "target" in st:
                t = st["target"]
                if not isinstance(t, dict) or not ("value" in t or {"sample", "test"} <= set(t)):
                    c.fail(f"{key}.target", "must be {sample: KEY, test: NAME} or {value: NUMBER}")
            for k in st.get("rig_overrides", {}):
                if not str(k).startswith("rig."):
                    c.fail(f"{key}.rig_overrides.{k}", "only rig keys (rig.procedure...) may be overridden here")
            if "parameter" in st:
                p = st["parameter"]
                c.keys(p, f"{key}.parameter", ["keys", "start", "bounds"],
                       ["response_increases", "response_slope_estimate"])
                if "response_slope_estimate" in p and not p["response_slope_estimate"] > 0:
                    c.fail(f"{key}.parameter.response_slope_estimate",
                           f"{p['response_slope_estimate']}: must be > 0 (|d response / d parameter|)")
                lo, hi = p["bounds"]
                if not lo <= p["start"] <= hi:
                    c.fail(f"{key}.parameter.start", f"{p['start']} outside bounds {p['bounds']}")
            if st["stage"] == "joint":
                if st["response"] not in vector_responses():
                    c.fail(f"{key}.response", f"must be one of {', '.join(vector_responses())}")
                if not isinstance(st["parameters"], list) or len(st["parameters"]) < 2:
                    c.fail(f"{key}.parameters", "a joint stage moves a list of at least two parameter groups")
                for j, p in enumerate(st["parameters"]):
                    c.keys(p, f"{key}.parameters[{j}]", ["keys", "bounds"], ["start"])
                    lo, hi = p["bounds"]
                    if not lo < hi or ("start" in p and not lo <= p["start"] <= hi):
                        c.fail(f"{key}.parameters[{j}]", f"start {p.get('start')} / bounds {p['bounds']} invalid")
    return data


def row_values(row):
    """{parameter: value} of a stage row (a joint stage has several)."""
    return row.get("values") or {row["parameter"]: row["value"]}


def stage_label(st):
    """The name of a stage in outputs and `inherit`: its `name`, else its stage type."""
    return st.get("name", st["stage"])


class Study:
    """Runs a study config with an executor (runner.LocalPool or runner.YadeBatch)."""

    def __init__(self, config_path, executor, out_dir, log=print):
        self.config_path = Path(config_path)
        self.cfg = load_study(config_path)
        self.executor = executor
        self.out = Path(out_dir) / self.cfg["name"]
        self.log = log
        self.seeds = list(range(1, int(self.cfg["seeds_count"]) + 1))
        self.max_seeds = int(self.cfg.get("max_seeds_count", self.cfg["seeds_count"]))
        self.overrides = {m: {} for m in self.cfg["materials"]}
        self.stage_rows, self.history = [], []
        self.runs_requested = 0
        self.point_results = {}      # (material, stage label, parameters json) -> results of that point
        self.vector_length = {}      # (material, stage label) -> residuals per point of a joint stage
        self.t0 = time.time()

    # ---------- evaluation ----------
    def _run_seeds(self, rig, material, overrides, seeds):
        """(results, next unused seed): one good run per seed asked for. A seed the rig
        refuses (one packing that does not come to rest within the rig's time limit -
        found on M3-dry: 1 seed of 3 at 2741 of 3000 Pa) is replaced by the next unused
        seed, with a warning; more than one failure per three seeds asked means the
        parameter point itself cannot run: RunError."""
        wanted, results, failures, attempted = len(seeds), [], [], 0
        batch, next_seed = list(seeds), max(seeds) + 1
        while batch:
            jobs = [resolve_job(rig, material, overrides, seed=s) for s in batch]
            self.runs_requested += len(jobs)
            attempted += len(jobs)
            budget = self.cfg.get("max_runs_count")
            if budget and self.runs_requested > budget:
                raise ConfigError(str(self.config_path), "max_runs_count",
                                  f"run budget of {budget} spent; raise it to continue")
            out = self.executor.run(jobs, raise_on_error=False)
            results += [r for r in out if r is not None]
            errors = list(getattr(self.executor, "last_errors", []))
            failures += errors or [f"{j['job_id']}: no result" for j, r in zip(jobs, out) if r is None]
            if len(failures) > max(1, wanted // 3):
                raise RunError(f"{len(failures)} of {attempted} run(s) failed; first: {failures[0]}")
            for msg in errors:
                self.log(f"  WARNING: {msg}; replaced by seed {next_seed}")
            n_missing = wanted - len(results)
            batch, next_seed = list(range(next_seed, next_seed + n_missing)), next_seed + n_missing
        return results, next_seed

    def evaluate(self, rig, material, extra, response, stage_name, tolerance=None, lab_dir=None, target=None):
        """(mean, std, n) of `response` over the seeds with the current overrides + extra.

        Noise-aware: while the standard error 2 std / sqrt(n) is larger than the
        tolerance, more seeds are added (up to max_seeds_count), so that a point is not
        judged "within tolerance" only because it is noisy. With a `target`, only while
        the verdict is in doubt: mean +- 2 std / sqrt(n) overlaps target +- tolerance. A
        point clearly off the target (M2 wall friction, first point: -0.117 +- 0.025)
        already says which way to go; more seeds there cost runs and change nothing."""
        overrides = {**self.overrides[material], **extra}
        results, next_seed = self._run_seeds(rig, material, overrides, self.seeds)
        values = [response_value(r, response, lab_dir) for r in results]
        m, s = mean_std(values)

        def in_doubt():
            err = 2 * s / math.sqrt(len(values))
            return err > tolerance and (target is None or abs(m - target) - err < tolerance)
        while tolerance is not None and len(values) < self.max_seeds and in_doubt():
            more = list(range(next_seed, next_seed + min(self.max_seeds, 2 * len(values)) - len(values)))
            new, next_seed = self._run_seeds(rig, material, overrides, more)
            results += new
            values += [response_value(r, response, lab_dir) for r in new]
            m, s = mean_std(values)
        self.point_results[(material, stage_name, json.dumps(extra, sort_keys=True))] = results
        self.history.append({"material": material, "stage": stage_name, "rig": rig,
                             "parameters": dict(extra), "response": response,
                             "mean": m, "std": s, "n": len(values)})
        self.log(f"  {material} {stage_name}: {extra} -> {response} = {m:.4g} +/- {s:.2g} "
                 f"(runs requested {self.runs_requested}, elapsed {time.time() - self.t0:.0f} s)")
        return m, s, len(values)

    # ---------- stages ----------
    def stage_density(self, material, st):
        """Particle density from the cell fill (pycal.calibration.density), with the
        values calibrated so far held fixed."""
        from .density import fit_density, DENSITY_KEY
        fixed = {k: v for k, v in self.overrides[material].items() if k != DENSITY_KEY}
        fit = fit_density(material, seeds=len(self.seeds), tolerance_percent=st["tolerance_percent"],
                          max_iterations=st.get("max_iterations_count", 5), executor=self.executor,
                          out_dir=self.out / "density" / material, first_seed=self.seeds[0],
                          start_density=self.overrides[material].get(DENSITY_KEY),
                          overrides=fixed, progress=lambda m: self.log("  " + m),
                          target_bulk_density_kg_m3=st.get("target", {}).get("value"))
        self.runs_requested += len(self.seeds) * fit.iterations
        for h in fit.history:
            self.history.append({"material": material, "stage": stage_label(st), "rig": st["rig"],
                                 "parameters": {DENSITY_KEY: h.particle_density_kg_m3},
                                 "response": "bulk_density_kg_m3", "mean": h.bulk_density_mean_kg_m3,
                                 "std": h.bulk_density_std_kg_m3, "n": h.n_seeds})
        self.overrides[material][DENSITY_KEY] = fit.particle_density_kg_m3
        return {"parameter": DENSITY_KEY, "value": fit.particle_density_kg_m3,
                "response": "bulk_density_kg_m3", "response_mean": fit.bulk_density_mean_kg_m3,
                "response_std": fit.bulk_density_std_kg_m3, "target": fit.target_bulk_density_kg_m3,
                "tolerance": fit.target_bulk_density_kg_m3 * st["tolerance_percent"] / 100.0,
                "met": fit.tolerance_met, "message": fit.message, "evaluations": fit.iterations}

    def stage_monotone(self, material, st):
        """One parameter group moved until a response that is monotone in it meets the
        target. A stiffness spans decades: it is solved in log(E), values rounded to 3
        significant digits (so that reruns hit the job cache)."""
        p = st["parameter"]
        self.overrides[material].update(st.get("set", {}))
        target = lab_target(st["target"])
        tol = next((st[k] for k in TOLERANCE_KEYS if k in st), 2.0)
        fixed = dict(st.get("rig_overrides", {}))   # e.g. a measured-equivalent faster lift
        log = st["stage"] == "stiffness"
        to_x = (lambda u: float(f"{math.exp(u):.3g}")) if log else (lambda u: u)
        to_u = math.log if log else (lambda x: x)

        def evaluate(u):
            x = to_x(u)
            return self.evaluate(st["rig"], material, {**fixed, **{k: x for k in p["keys"]}},
                                 st["response"], stage_label(st), tolerance=tol, lab_dir=self.lab_dir(st),
                                 target=target)

        sol = solve_monotone(evaluate, target, to_u(p["start"]), to_u(p["bounds"][0]), to_u(p["bounds"][1]),
                             tol, max_evaluations=st.get("max_iterations_count", 6),
                             increasing=p.get("response_increases"),
                             first_step=math.log(4.0) if log else None,
                             slope_estimate=p.get("response_slope_estimate"),
                             show=lambda u: f"{to_x(u):.4g}")
        value = to_x(sol.x)
        for k in p["keys"]:
            self.overrides[material][k] = value
        chosen = {**fixed, **{k: value for k in p["keys"]}}
        plots = self.stage_plots(material, stage_label(st), st["rig"],
                                 self.point_results.get((material, stage_label(st), json.dumps(chosen, sort_keys=True))),
                                 self.lab_dir(st))
        return {"plots": plots, "parameter": "+".join(p["keys"]), "value": value, "response": st["response"],
                "response_mean": sol.point.mean, "response_std": sol.point.std, "target": target,
                "tolerance": tol, "met": sol.met, "message": sol.message,
                "evaluations": len(sol.history)}

    def stage_plots(self, material, label, rig, results, lab_dir=None):
        """Lab-vs-simulation curves of a stage's chosen point into plots/<material>-<label>/
        (friction rigs: seeds pooled; compression rigs: the first seed); PNG paths
        relative to the study folder. Plots never stop a study."""
        if not results:
            return []
        out = self.out / "plots" / f"{material}-{label}"
        try:
            if rig in ("wall_friction", "internal_friction"):
                from ..post import friction
                files = friction.write_outputs(results, str(out), lab_dir=lab_dir)["files"]
            elif rig in ("ccs", "ccs_expansion", "ucs"):
                from ..post import compression
                out.mkdir(parents=True, exist_ok=True)
                files = compression.write_outputs(results[0], str(out), lab_dir=lab_dir)["files"]
            else:
                return []
        except Exception as exc:     # noqa: BLE001 - a plot must not cost the calibration
            self.log(f"  WARNING: plots of {material} {label} not written: {type(exc).__name__}: {exc}")
            return []
        return [str(Path(f).relative_to(self.out)) for f in files if str(f).endswith(".png")]

    def evaluate_vector(self, rig, material, extra, response, stage_name, lab_dir=None):
        """Residual vector of `response` averaged over the seeds, element by element (a
        step no seed reached stays None); the history gets its RMS."""
        from .joint import rms
        overrides = {**self.overrides[material], **extra}
        try:
            results, _ = self._run_seeds(rig, material, overrides, self.seeds)
        except RunError as exc:
            # a parameter pair where the rig cannot run (e.g. a blow-up) is a bad point for
            # the fit, not the end of it: every residual counts as not reached
            n = self.vector_length.get((material, stage_name))
            if n is None:
                raise
            self.history.append({"material": material, "stage": stage_name, "rig": rig, "parameters": dict(extra),
                                 "response": f"RMS {response}", "mean": math.nan, "std": math.nan, "n": 0})
            self.log(f"  {material} {stage_name}: {extra} -> runs failed, counted as a bad point: {exc}")
            return [None] * n
        vectors = [vector_responses(lab_dir)[response](r) for r in results]
        mean = []
        for k in range(max(len(v) for v in vectors)):
            vals = [v[k] for v in vectors if k < len(v) and v[k] is not None]
            mean.append(sum(vals) / len(vals) if vals else None)
        per_seed = [rms(v) for v in vectors]
        self.vector_length[(material, stage_name)] = len(mean)
        self.point_results[(material, stage_name, json.dumps(extra, sort_keys=True))] = results
        self.history.append({"material": material, "stage": stage_name, "rig": rig, "parameters": dict(extra),
                             "response": f"RMS {response}", "mean": rms(mean),
                             "std": mean_std(per_seed)[1], "n": len(results)})
        self.log(f"  {material} {stage_name}: {extra} -> RMS {response} = {rms(mean):.3g} "
                 f"(z {['-' if z is None else round(z, 2) for z in mean]}; runs requested {self.runs_requested}, "
                 f"elapsed {time.time() - self.t0:.0f} s)")
        return mean

    def lab_dir(self, st):
        """The stage's lab data folder (`lab_dir`, relative to the study config; laid out as
        labresults/, e.g. a synthetic twin's curves), else None = labresults/."""
        return (self.config_path.parent / st["lab_dir"]) if "lab_dir" in st else None

    def current_value(self, material, key):
        """The value a material key has at this point of the study (calibrated or config)."""
        if key in self.overrides[material]:
            return self.overrides[material][key]
        node = load_material(material)
        for part in key.split("."):
            node = node[part]
        return node

    def stage_joint(self, material, st):
        """Several coupled parameter groups fitted together to the band z of a lab curve
        (pycal.calibration.joint: scipy least squares). A parameter without `start`
        starts from its current value (e.g. one inherited from another material)."""
        from .joint import solve_joint
        self.overrides[material].update(st.get("set", {}))
        fixed = dict(st.get("rig_overrides", {}))
        params = st["parameters"]
        label = stage_label(st)

        def extra_of(xs):
            e = dict(fixed)
            for p, x in zip(params, xs):
                for k in p["keys"]:
                    e[k] = x
            return e

        x0 = [p["start"] if "start" in p else self.current_value(material, p["keys"][0]) for p in params]
        x0 = [min(p["bounds"][1], max(p["bounds"][0], x)) for p, x in zip(params, x0)]
        sol = solve_joint(lambda xs: self.evaluate_vector(st["rig"], material, extra_of(xs), st["response"], label,
                                                          self.lab_dir(st)),
                          x0, [p["bounds"][0] for p in params], [p["bounds"][1] for p in params],
                          st["tolerance_rms_z"], max_evaluations=st.get("max_iterations_count", 10))
        for p, x in zip(params, sol.x):
            for k in p["keys"]:
                self.overrides[material][k] = x
        plots = self.stage_plots(material, label, st["rig"],
                                 self.point_results.get((material, label, json.dumps(extra_of(sol.x), sort_keys=True))),
                                 self.lab_dir(st))
        return {"plots": plots, "parameter": " ; ".join("+".join(p["keys"]) for p in params), "value": sol.x[0],
                "values": {"+".join(p["keys"]): x for p, x in zip(params, sol.x)},
                "response": f"RMS {st['response']}", "response_mean": sol.rms, "response_std": math.nan,
                "target": 0.0, "tolerance": st["tolerance_rms_z"], "met": sol.met, "message": sol.message,
                "evaluations": len(sol.history)}

    def stage_inherit(self, material, st):
        src = st["from"]
        row = next((r for r in self.stage_rows
                    if r["material"] == src["material"] and r["stage"] == src["stage"]), None)   # stage = label
        if row is None:
            raise ConfigError(str(self.config_path), f"materials.{material}.from",
                              f"stage {src['stage']} of {src['material']} must run before")
        row_out = {"parameter": "+".join(st["keys"]), "value": row["value"], "response": "",
                   "response_mean": math.nan, "response_std": math.nan, "target": math.nan,
                   "tolerance": math.nan, "met": bool(row["met"]), "evaluations": 0,
                   "message": f"from {src['material']} {src['stage']}"}
        if math.isnan(row["value"]):
            return {**row_out, "met": False,
                    "message": f"not inherited: {src['material']} {src['stage']} found no value (config value kept)"}
        if not row["met"]:
            # the closest value the source stage measured is a better start than the
            # config's guess (M3-wet's cohesion stage at the start rolling resistance 0.35
            # stood at 59 deg without any cohesion); it stays marked as not met
            row_out["message"] = (f"inherited from {src['material']} {src['stage']}, which did not meet its "
                                  f"target: its closest value")
        for k in st["keys"]:
            self.overrides[material][k] = row["value"]
        return row_out

    @staticmethod
    def _stage_target(st):
        """The stage's target value for the tables (NaN where it has none or it cannot be read)."""
        try:
            return lab_target(st["target"]) if "target" in st else math.nan
        except Exception:      # noqa: BLE001 - a table entry, never a reason to stop
            return math.nan

    def run(self):
        stage_fn = {"density": self.stage_density, "rolling_resistance": self.stage_monotone,
                    "cohesion": self.stage_monotone, "stiffness": self.stage_monotone,
                    "friction": self.stage_monotone, "joint": self.stage_joint,
                    "inherit": self.stage_inherit}
        n_stages = sum(len(s) for s in self.cfg["materials"].values())
        k = 0
        for material, stages in self.cfg["materials"].items():
            for st in stages:
                k += 1
                t_stage, runs_before = time.time(), self.runs_requested
                simulated_before = getattr(self.executor, "simulated_count", 0)
                self.log(f"[stage {k}/{n_stages}] {material}: {stage_label(st)}"
                         + (f" on rig {st['rig']}" if "rig" in st else ""))
                try:
                    row = stage_fn[st["stage"]](material, st)
                except RunError as exc:
                    # the rig cannot run at some parameter value: the stage is not met, the
                    # study goes on with the values found so far
                    row = {"parameter": "+".join(st.get("parameter", {}).get("keys", [])), "value": math.nan,
                           "response": st.get("response", ""), "response_mean": math.nan,
                           "response_std": math.nan, "target": self._stage_target(st),
                           "tolerance": next((st[k] for k in TOLERANCE_KEYS if k in st), math.nan),
                           "met": False, "message": f"runs failed: {exc}", "evaluations": 0}
                row.update({"material": material, "stage": stage_label(st), "kind": st["stage"],
                            "runs_requested": self.runs_requested - runs_before,
                            "runs_simulated": getattr(self.executor, "simulated_count", 0) - simulated_before,
                            "elapsed_s": round(time.time() - t_stage, 1)})
                self.stage_rows.append(row)
                self.log(f"  -> {', '.join(f'{k} = {v:.4g}' for k, v in row_values(row).items())}: "
                         + ("target met" if row["met"] else f"NOT met {row['message']}"))
                self.write_outputs()
        return self.stage_rows

    # ---------- outputs ----------
    def calibrated_material(self, material):
        mat = copy.deepcopy(load_material(material))
        for k, v in self.overrides[material].items():
            _set_path(mat, k, v, f"calibrated {material}")
        mat["provenance"] = f"calibrated by study {self.cfg['name']} ({self.config_path.name})"
        return mat

    def write_outputs(self):
        self.out.mkdir(parents=True, exist_ok=True)
        (self.out / "calibrated").mkdir(exist_ok=True)
        for m in self.cfg["materials"]:
            _atomic(self.out / "calibrated" / f"{m}.yaml",
                    yaml.safe_dump(self.calibrated_material(m), sort_keys=False))
        cols = ["material", "stage", "parameter", "value", "response", "response_mean",
                "response_std", "target", "tolerance", "met", "evaluations", "runs_requested",
                "runs_simulated", "elapsed_s", "message"]
        _atomic_csv(self.out / "stages.csv", cols, [[r.get(c, "") for c in cols] for r in self.stage_rows])
        hcols = ["material", "stage", "rig", "parameters", "response", "mean", "std", "n"]
        _atomic_csv(self.out / "history.csv", hcols,
                    [[json.dumps(h[c]) if c == "parameters" else h[c] for c in hcols] for h in self.history])
        summary = {"study": self.cfg, "stages": self.stage_rows, "history": self.history,
                   "overrides": self.overrides, "runs_requested": self.runs_requested,
                   "elapsed_s": time.time() - self.t0}
        _atomic(self.out / "summary.json", json.dumps(summary, indent=1, default=str))


def lab_target(target):
    """The target of a stage: {value: X} as given (e.g. a synthetic twin's hidden truth),
    or the mean lab angle (left/right) of {sample, test}."""
    if "value" in target:
        return float(target["value"])
    from .. import labdata
    return labdata.aor_target_deg(target["sample"], target["test"])


def _atomic(path, text):
    tmp = Path(str(path) + ".part")
    tmp.write_text(text)
    os.replace(tmp, path)


def _atomic_csv(path, columns, rows):
    tmp = Path(str(path) + ".part")
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        w.writerows(rows)
    os.replace(tmp, path)


def cost_per_material(stage_rows):
    """{material: {runs_requested, runs_simulated, elapsed_s}} summed over its stages
    (elapsed: of this invocation; a resumed study replays cached runs in seconds)."""
    out = {}
    for r in stage_rows:
        c = out.setdefault(r["material"], {"runs_requested": 0, "runs_simulated": 0, "elapsed_s": 0.0})
        for k in c:
            c[k] += r.get(k, 0) or 0
    return out
