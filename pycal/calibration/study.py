"""A calibration study: stages per material in the method's order (configs/calibrations/).

The driver: it runs the rigs, keeps every run, and asks pycal.stats what the runs say
(estimate, 95 % interval, stop or where next), the way GrainLearning keeps its
inference apart from its models. Stage kinds and config: pycal.calibration.study_config;
one-parameter stages: stage_1d; coupled parameters: stage_joint; outputs: outputs.

Every run goes through `Study._run_seeds` (one result per seed asked, a refused seed
replaced by the next unused one, the run budget counted there), and through one
executor (pycal.runner), which caches them: nothing is simulated twice, and a killed
study resumes where it stopped when started again with the same seeds (every decision
is a deterministic function of the runs).
"""
import copy
import json
import math
import time
from pathlib import Path

from ..configs import load_material
from ..executors.base import wrapped_chain
from ..errors import BudgetSpent, PycalError, RunError  # noqa: F401 (BudgetSpent: callers catch it here)
from ..jobs import resolve_job
from ..post import mean_std
from ..post import responses as responses_mod
from ..stats import stopping
from . import gallery, outputs, targets
from .held import held_values
from .provenance import study_provenance
from .eta import Eta, text as eta_text
from .verdicts import matches_lab
from .journal import Journal, fingerprint
from .names import format_params, group_label, unit_of_key
from .study_config import load_study, stage_rigs

SEED_SCHEME = "fresh seeds at every point"   # in the stage fingerprint: journals of the old scheme start afresh


class Study:
    """Runs a study config with an executor (runner.LocalPool or runner.YadeBatch).

    seed_base: the first seed of every point (seeds seed_base, seed_base + 1, ...)."""

    def __init__(self, config_path, executor, out_dir, log=print, seed_base=1):
        self.config_path = Path(config_path)
        self.cfg = load_study(config_path)
        self.executor = executor
        self.out = Path(out_dir) / self.cfg["name"]
        self.log = log
        if isinstance(seed_base, bool) or not isinstance(seed_base, int) or seed_base < 0:
            raise PycalError(f"--seed-base {seed_base!r}: must be a whole number >= 0")
        self.seed_base = seed_base
        self.seeds = self.seeds_from_base(self.cfg["seeds_count"])
        self.overrides = {m: {} for m in self.cfg["materials"]}
        self.intervals = {m: {} for m in self.cfg["materials"]}   # key -> (estimate, low, high) found so far
        self.value_source = {m: {} for m in self.cfg["materials"]}  # key -> the section that calibrated it
        self.stage_rows, self.points, self.runs = [], [], []
        self.validation_rows = []    # predictions of tests the calibration never saw (validation.py)
        self.run_at_check_rows = []  # stages that ran at other material values, at the calibrated ones
        self.application_rows = []   # design runs with the calibrated values (application.py)
        self.runs_requested = 0
        self.yade_versions = set()
        self.point_results = {}      # (material, stage, rig, point json) -> results of that point
        # (material, stage, rig) -> seeds used in that stage: every point gets seeds not used
        # before in its stage. The same seeds at every point would share each pour's offset
        # (how many spheres fit the fill cell is the seed's: 3.4 % SD) across all of the
        # stage's runs, which the response model takes as independent
        self._stage_seeds = {}
        self.last_seeds = []         # seeds actually run by the last _run_seeds (replacements included)
        self.section = "study"       # what the runs are for now: '<material>/<stage>', 'validation/<name>' ...
        self.jobs = []               # every job asked: section, rig, seed, job id, status (outputs: jobs.csv)
        self.t0 = time.time()
        self.eta = Eta(_workers_of(executor), cores=_local_cores(executor))
        # (material, stage) -> the material set its runs use (a stage's material_set), else absent
        self.stage_sets = {(m, st["label"]): st["material_set"] for m, sts in self.cfg["materials"].items()
                           for st in sts if st.get("material_set")}
        self.stage_budget = None      # the running stage: (budget, runs requested before it, its index)
        self.provenance = study_provenance(self.config_path)
        self.journal = Journal(self.out / "journal.json")
        # every target now: a broken lab file stops the study before any run
        self.targets = {}
        for mat, stages in self.cfg["materials"].items():
            for st in stages:
                specs = ([(st["response"], st["target"])] if st["kind"] != "joint" and st["kind"] != "inherit"
                         else [(r["response"], r["target"]) for r in st.get("responses", [])])
                self.targets[(mat, st["label"])] = [
                    targets.resolve(spec, responses_mod.get(name), mat, self.lab_dir(st)) for name, spec in specs]

    # ---------------------------------------------------------------- runs
    def runs_left(self):
        """Runs the study budget still allows (inf without max_runs_count)."""
        budget = self.cfg.get("max_runs_count")
        return math.inf if not budget else budget - self.runs_requested

    def job_material(self, material, stage, extra):
        """(material or material set, overrides) of the runs of `stage` at the point `extra`:
        the material with its values so far and `extra`; for a stage with a material_set,
        that set with every component's values so far (pycal.calibration.calibrated) and
        `extra`'s material keys as the stage's material's ('M3-wet.<key>')."""
        mset = self.stage_sets.get((material, stage))
        if not mset:
            return material, {**self.overrides[material], **extra}
        from .calibrated import overrides_for_material
        values = dict(self.overrides)
        values[material] = {**self.overrides[material], **{k: v for k, v in extra.items() if not k.startswith("rig.")}}
        return mset, {**{k: v for k, v in extra.items() if k.startswith("rig.")},
                      **overrides_for_material(values, mset)}

    def _run_seeds(self, rig, material, overrides, seeds, eta_material=None):
        """One result per seed asked, in order. A seed the rig refuses (one packing that
        does not come to rest in time) is replaced by the next unused seed above them,
        with a warning; more than one failure per three seeds asked means the parameter
        point itself cannot run: RunError. Every job asked counts against the study's
        run budget (BudgetSpent before a job would exceed it). self.last_seeds: the
        seeds that stand behind the results. eta_material: the material the run costs are
        booked to (default `material`; a set stage books them to the stage's material)."""
        wanted = list(seeds)
        results, used, failures, attempted = {}, {}, [], 0
        batch, next_seed = list(wanted), max(wanted) + 1
        while batch:
            if len(batch) > self.runs_left():
                raise BudgetSpent(f"{self.config_path}: max_runs_count: the study's run budget "
                                  f"({self.cfg['max_runs_count']} runs) is spent")
            jobs = [resolve_job(rig, material, overrides, seed=s) for s in batch]
            self.runs_requested += len(jobs)
            attempted += len(jobs)
            out = self.executor.run(jobs, raise_on_error=False)
            errors = list(getattr(self.executor, "last_errors", []))
            self.record_jobs(jobs, out)
            self.eta.add(eta_material or material, rig, out)
            slots = [s for s in wanted if s not in results]
            retry = []
            for slot, seed, r in zip(slots, batch, out):
                if r is None:
                    retry.append(slot)
                else:
                    results[slot], used[slot] = r, seed
                    version = (r.get("provenance") or {}).get("yade_version")
                    if version:
                        self.yade_versions.add(str(version))
            failures += errors or [f"{j['job_id']}: no result" for j, r in zip(jobs, out) if r is None]
            if len(failures) > max(1, len(wanted) // 3):
                raise RunError(f"{len(failures)} of {attempted} run(s) failed; first: {failures[0]}")
            for msg in errors:
                self.log(f"  WARNING: {msg}; replaced by seed {next_seed}")
            batch = list(range(next_seed, next_seed + len(retry)))
            next_seed += len(retry)
        self.last_seeds = [used[s] for s in wanted]
        return [results[s] for s in wanted]

    def record_jobs(self, jobs, results):
        """Note every job asked (with its result or None) in the jobs ledger (jobs.csv), under
        the current section."""
        self.jobs += [{"section": self.section, "material": j["material"], "rig": j["rig"], "seed": j["seed"],
                       "job_id": j["job_id"], "status": "ok" if r is not None else "failed",
                       "batch_job_id": ((r or {}).get("provenance") or {}).get("batch_job_id", "")}
                      for j, r in zip(jobs, results)]

    def _missing_seeds(self, values, rig, response, extra):
        """The seeds (of self.last_seeds) whose scalar response has no value (NaN: e.g. a pile
        too flat for any sector to have an angle), with a warning; when more than one in
        three seeds has none, the point cannot be measured: RunError (a one-parameter stage
        then backs off from it, as from a point the rig refuses)."""
        missing = [s for s, v in zip(self.last_seeds, values)
                   if not isinstance(v, list) and (v is None or math.isnan(v))]
        if not missing:
            return []
        where = format_params({k: v for k, v in extra.items() if not k.startswith("rig.")})
        if len(missing) > max(1, len(values) // 3):
            raise RunError(f"{rig}: {response.name} has no value on seeds {missing} of {list(self.last_seeds)} "
                           f"at {where} (the rig ran, the response could not be read: e.g. a pile too flat "
                           f"for an angle)")
        self.log(f"  WARNING: {rig}: {response.name} has no value on seed(s) {missing} at {where}; left out")
        return missing

    def run_point(self, material, stage, rig, extra, response, lab_dir, count=None):
        """Values of `response` (pycal.post.responses) at one parameter point: `count` runs
        (default seeds_count) with the material's current overrides + `extra`. Every point
        (and a point run again) gets its stage's next unused seeds on this rig: the stage's
        runs are independent draws of the random fill. A seed without a value is left out
        (self.last_seeds: the seeds behind the values returned)."""
        values = self.run_point_responses(material, stage, rig, extra, [response], lab_dir, count)[0]
        keep = [i for i, v in enumerate(values) if isinstance(v, list) or not math.isnan(v)]
        self.last_seeds = [self.last_seeds[i] for i in keep]
        return [values[i] for i in keep]

    def run_point_responses(self, material, stage, rig, extra, responses, lab_dir, count=None):
        """Values of several responses read from the same runs of one point (e.g. the pile's
        angle before and after the vibration, both from one surcharge run): one list per
        response, in the order of self.last_seeds, NaN where a seed has no value for that
        response (RunError when more than one seed in three has none for any response)."""
        key = (material, stage, rig, json.dumps(extra, sort_keys=True))
        used = self._stage_seeds.setdefault((material, stage, rig), [])
        count = count or len(self.seeds)
        seeds = self.seeds[:count] if not used else list(range(max(used) + 1, max(used) + 1 + count))
        results = self._run_seeds(rig, *self.job_material(material, stage, extra), seeds, eta_material=material)
        used += self.last_seeds
        values = [[math.nan if v is None else v for v in (response.value(r, lab_dir) for r in results)]
                  for response in responses]
        missing = [self._missing_seeds(vals, rig, response, extra) for response, vals in zip(responses, values)]
        # the runs behind the point (its pictures and lab-curve plots): those with a value to show
        self.point_results.setdefault(key, []).extend(
            r for seed, r in zip(self.last_seeds, results) if any(seed not in m for m in missing))
        params = {k: v for k, v in extra.items() if not k.startswith("rig.")}
        for response, vals, miss in zip(responses, values, missing):
            kept = [(seed, v) for seed, v in zip(self.last_seeds, vals) if seed not in miss]
            for seed, v in kept:
                self.runs.append({"material": material, "stage": stage, "rig": rig, "parameters": params,
                                  "seed": seed, "response": response.name, "value": v})
            scalar = [v for _, v in kept if not isinstance(v, list)]
            m, s = mean_std(scalar) if scalar else (math.nan, math.nan)
            self.points.append({"material": material, "stage": stage, "rig": rig, "parameters": params,
                                "response": response.name, "mean": m, "std": s, "n": len(kept),
                                "seeds": [seed for seed, _ in kept]})
            shown = f"{m:.4g} +/- {s:.2g}" if scalar else f"{len(kept)} vectors"
            self.log(f"  {format_params(params)} -> {response.name} {shown} (n {len(kept)}; {self.progress_text()})")
        return values

    def progress_text(self):
        """'9/18 runs; left <= ~35 min': runs of the stage / its budget, and the time
        left at most in the study's stages from here to the validation section
        (pycal.calibration.eta: an upper bound from the CPU per run measured so far)."""
        elapsed = f"{time.time() - self.t0:.0f} s"
        if self.stage_budget is None:
            return f"study runs {self.runs_requested}, {elapsed}"
        budget, before, index = self.stage_budget
        done = self.runs_requested - before
        stages = [(m, st) for m, sts in self.cfg["materials"].items() for st in sts]
        m_here, st_here = stages[index]
        here = [(m_here, r, (budget - done) / len(stage_rigs(st_here))) for r in stage_rigs(st_here)]
        later = [(m, r, st["max_runs_count"] / len(stage_rigs(st))) for m, st in stages[index + 1:]
                 if st["kind"] != "inherit" for r in stage_rigs(st)]
        study_s, unknown = self.eta.bound_s(here + later)
        return f"{done}/{budget} runs; left <= {eta_text(study_s, unknown)}"

    def nearest_point_results(self, material, stage, rig, extra):
        """Results of the point run in this stage on `rig` nearest to `extra` (relative
        distance over the parameters), and that point's parameters; (None, None) if none."""
        best, best_d = None, math.inf
        for (m, s, r, key), results in self.point_results.items():
            if (m, s, r) != (material, stage, rig):
                continue
            p = json.loads(key)
            d = sum(abs(math.log(p[k] / v)) if p.get(k, 0) > 0 and v > 0 else abs(p.get(k, 0) - v)
                    for k, v in extra.items() if isinstance(v, (int, float)) and not k.startswith("rig."))
            if d < best_d:
                best, best_d = (results, p), d
        return best if best else (None, None)

    # ---------------------------------------------------------------- helpers for the stages
    def lab_dir(self, st):
        """The stage's lab data folder (`lab_dir`, relative to the study config; laid out as
        labresults/, e.g. a synthetic twin's), else None = labresults/."""
        return (self.config_path.parent / st["lab_dir"]) if st.get("lab_dir") else None

    def start_value(self, material, key):
        """The value a material key has in its config (configs/materials/<material>.yaml)."""
        node = load_material(material)
        for part in key.split("."):
            node = node[part]
        return node

    def current_value(self, material, key):
        """The value a material key has at this point of the study (calibrated or config)."""
        if key in self.overrides[material]:
            return self.overrides[material][key]
        return self.start_value(material, key)

    def stage_journal(self, material, st):
        """The journal of a stage (pycal.calibration.journal), keyed by what it starts from:
        its config, the seeds, its targets and the material's values so far (a stage on a
        material set: every component's)."""
        tg = [t.__dict__ for t in self.targets[(material, st["label"])]]
        values = self.job_material(material, st["label"], {})[1]    # a set stage: every component's values
        return self.journal.stage(f"{material}/{st['label']}",
                                  fingerprint(st, self.seeds, sorted(values.items()), tg, SEED_SCHEME))

    def seeds_from_base(self, count):
        """`count` seeds from the study's seed base: seed_base, seed_base + 1, ..."""
        return list(range(self.seed_base, self.seed_base + int(count)))

    def _stage_cost(self, material, st, elapsed_s, simulated_count):
        """(runs simulated, wall time s) of a stage over every process that worked on it:
        a resumed study replays a stage's runs from the cache in seconds, so each process
        adds its own share to the stage's journal entry (a killed process's share is lost)."""
        entry = self.journal.data.get(f"{material}/{st['label']}")
        if entry is None:                       # a stage with no journal (inherit, or failed at its start)
            return simulated_count, elapsed_s
        entry["elapsed_s"] = entry.get("elapsed_s", 0.0) + elapsed_s
        entry["runs_simulated"] = entry.get("runs_simulated", 0) + simulated_count
        self.journal.save()
        return entry["runs_simulated"], entry["elapsed_s"]

    def set_value(self, material, keys, value, interval=None):
        """Carry a calibrated value (and its (estimate, low, high)) into the next stages."""
        for k in keys:
            self.overrides[material][k] = value
            self.value_source[material][k] = self.section
            if interval is not None:
                self.intervals[material][k] = interval

    # ---------------------------------------------------------------- stages
    def stage_inherit(self, material, st):
        """Copy a value found for another material, with its interval and verdict."""
        src = st["from"]
        row = next((r for r in self.stage_rows if r["material"] == src["material"] and r["stage"] == src["stage"]),
                   None)
        params = (row or {}).get("parameters") or []
        if "key" in src:
            params = [p for p in params if src["key"] in p["keys"]]
        base = {"parameters": [], "responses": [], "met": False, "points_count": 0}
        if row is None or len(params) != 1 or not math.isfinite(params[0]["estimate"]):
            why = ("ran no stage called so" if row is None else
                   "has several parameters: name one with from.key" if len(params) > 1 else "found no value")
            carried = self.overrides.get(src["material"], {}).get(src.get("key"))
            if row is not None and len(params) <= 1 and isinstance(carried, (int, float)):
                # the stage failed, but an earlier stage of the source calibrated the key: that
                # value (the one the source material carries now) beats the config's guess
                lo_hi = self.intervals.get(src["material"], {}).get(src["key"], (carried, math.nan, math.nan))
                self.set_value(material, st["keys"], carried, lo_hi)
                p = {"label": group_label(st["keys"]), "keys": list(st["keys"]), "estimate": carried,
                     "low": lo_hi[1], "high": lo_hi[2], "tolerance": math.nan,
                     "unit": unit_of_key(st["keys"][0]) or "", "scale": "linear",
                     "band_low": math.nan, "band_high": math.nan}
                return {**base, "parameters": [p], "stop_reason": "inherited from an earlier stage",
                        "message": f"{src['material']} {src['stage']} {why}: took the value {src['material']} "
                                   f"carries from an earlier stage ({carried:.4g}), not met"}
            return {**base, "stop_reason": "not inherited",
                    "message": f"{src['material']} {src['stage']} {why} (the config value is kept)"}
        p = params[0]
        value = p["estimate"]
        self.set_value(material, st["keys"], value, (p["estimate"], p["low"], p["high"]))
        copied = {**p, "keys": list(st["keys"]), "label": group_label(st["keys"])}
        msg = f"from {src['material']} {src['stage']}"
        if not row["met"]:
            # the closest value the source measured beats the config's guess as a start; it
            # stays marked not met so nobody mistakes it for a calibrated value
            msg += f", which did not meet its tolerance ({row['stop_reason']})"
        return {**base, "parameters": [copied], "met": bool(row["met"]),
                "stop_reason": f"inherited: {row['stop_reason']}", "message": msg}

    def run(self):
        """Run every stage in order; returns the stage rows. Outputs are rewritten after each."""
        from . import stage_1d, stage_joint
        n_stages = sum(len(s) for s in self.cfg["materials"].values())
        k = 0
        for material, stages in self.cfg["materials"].items():
            for st in stages:
                k += 1
                t_stage, runs_before = time.time(), self.runs_requested
                simulated_before = getattr(self.executor, "simulated_count", 0)
                rig = ", ".join(stage_rigs(st))
                self.section = f"{material}/{st['label']}"
                self.log(f"[stage {k}/{n_stages}] {material}: {st['label']}" + (f" on {rig}" if rig else ""))
                held = held_values(self, material, st)
                self.stage_budget = (st.get("max_runs_count", 0), self.runs_requested, k - 1)
                if st["kind"] == "inherit":
                    row = self.stage_inherit(material, st)
                else:
                    fn = stage_joint.run if st["kind"] == "joint" else stage_1d.run
                    try:
                        row = fn(self, material, st)
                    except (RunError, BudgetSpent) as exc:
                        # the start point cannot run (or no budget is left): the stage is not
                        # met, the study goes on with the values found so far
                        row = failed_row(self, material, st, exc)
                simulated, elapsed = self._stage_cost(material, st, time.time() - t_stage,
                                                      getattr(self.executor, "simulated_count", 0) - simulated_before)
                row.update({"material": material, "stage": st["label"], "kind": st["kind"],
                            "runs_requested": self.runs_requested - runs_before,
                            "runs_simulated": simulated, "elapsed_s": round(elapsed, 1),
                            "material_set": st.get("material_set")})
                row.setdefault("plots", [])
                row["held"] = held
                row["matches_lab"] = matches_lab(row)
                row["gallery"] = gallery.stage_pictures(self, material, st, row) if st["kind"] != "inherit" else []
                row["aor_seeds"] = gallery.aor_seed_angles(self, material, st, row) if st["kind"] != "inherit" else {}
                self.stage_rows.append(row)
                for p in row["parameters"]:
                    self.log(f"  -> {p['label']} = {p['estimate']:.4g} [{p['low']:.4g}, {p['high']:.4g}] "
                             f"(tolerance +-{p['tolerance']:.3g}): {'MET' if row['met'] else 'not met'}, "
                             f"{row['stop_reason']}")
                if not row["parameters"]:
                    self.log(f"  -> not met: {row['message']}")
                outputs.write_all(self)
        self.stage_budget = None
        from . import run_at_check
        self.section = "run_at_check"
        run_at_check.run(self)                           # stages that ran at other values, at the calibrated ones
        outputs.write_all(self)
        from . import validation
        self.validation_rows = validation.run(self)      # predictions with the calibrated values
        outputs.write_all(self)
        from . import application
        self.application_rows = application.run(self)    # design runs with the calibrated values
        outputs.write_all(self)
        return self.stage_rows

    def calibrated_material(self, material):
        """The material config with the calibrated values (loads as a material config)."""
        from ..jobs import _set_path
        mat = copy.deepcopy(load_material(material))
        for k, v in self.overrides[material].items():
            _set_path(mat, k, v, f"calibrated {material}")
        mat["provenance"] = f"calibrated by study {self.cfg['name']} ({self.config_path.name})"
        return mat


def failed_row(study, material, st, exc):
    """The row of a stage that could not run its start point (or had no budget left)."""
    params = [st["parameter"]] if "parameter" in st else st.get("parameters", [])
    tg = study.targets.get((material, st["label"]), [])
    names = [st["response"]] if "response" in st else [r["response"] for r in st.get("responses", [])]
    return {"parameters": [{"label": p["label"], "keys": p["keys"], "unit": p["unit"], "estimate": math.nan,
                            "low": math.nan, "high": math.nan, "tolerance": p["tolerance"]
                            if not p["tolerance_is_percent"] else math.nan, "band_low": math.nan,
                            "band_high": math.nan} for p in params],
            "responses": [{"response": n, "target": t.value, "band": t.band, "standard_error": t.standard_error,
                           "target_source": t.source} for n, t in zip(names, tg)],
            "met": False, "stop_reason": "runs failed" if isinstance(exc, RunError) else stopping.STUDY_BUDGET,
            "message": str(exc), "points_count": 0}


def _local_cores(executor):
    """This machine's cores when the runs go to local processes (through wrappers), else None."""
    import os
    from ..executors.local import LocalPool
    return os.cpu_count() if any(isinstance(e, LocalPool) for e in wrapped_chain(executor)) else None


def _workers_of(executor):
    """Parallel YADE processes of an executor (through wrappers), 1 when it does not say."""
    return next((e.workers for e in wrapped_chain(executor) if isinstance(getattr(e, "workers", None), int)), 1)


def cost_per_material(stage_rows):
    """{material: {runs_requested, runs_simulated, elapsed_s}} summed over its stages
    (elapsed: of this invocation; a resumed study replays cached runs in seconds)."""
    out = {}
    for r in stage_rows:
        c = out.setdefault(r["material"], {"runs_requested": 0, "runs_simulated": 0, "elapsed_s": 0.0})
        for k in c:
            c[k] += r.get(k, 0) or 0
    return out
