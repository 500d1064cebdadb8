"""The runs of a study: a rig evaluated for a material at given values and seeds.

`Evaluator.run_seeds(rig, material, overrides, seeds)` is the one way a study, its
validation, application and sensitivity runs YADE: one result per seed asked (a seed the
rig refuses replaced by the next unused one), every job noted in the ledger (jobs.csv) under
the current `section` and counted against the run budget. `run_point` / `run_point_responses`
read responses at one parameter point of a stage, on seeds no earlier point of that stage
used. Study (study.py) is an Evaluator with stages; it provides `job_material` (the values
a stage's runs take), `cfg` and `stage_budget` for the progress line.
"""
import json
import math
import time

from ..errors import BudgetSpent, RunError
from ..executors.base import wrapped_chain
from ..jobs import resolve_job
from ..post import mean_std
from .eta import Eta, text as eta_text
from .names import format_params
from .study_config import stage_rigs


class Evaluator:
    """Runs and their bookkeeping (module doc)."""

    def __init__(self, executor, log, seeds, max_runs_count=None, budget_where="max_runs_count"):
        self.executor = executor
        self.log = log
        self.seeds = seeds            # the seeds of a stage's first point: seed base, base + 1, ...
        self.max_runs_count = max_runs_count
        self.budget_where = budget_where
        self.runs_requested = 0
        self.yade_versions = set()
        self.points, self.runs = [], []
        self.point_results = {}      # (material, stage, rig, point json) -> results of that point
        # (material, stage, rig) -> seeds used in that stage: every point gets seeds not used
        # before in its stage. The same seeds at every point would share each pour's offset
        # (how many spheres fit the fill cell is the seed's: 3.4 % SD) across all of the
        # stage's runs, which the response model takes as independent
        self._stage_seeds = {}
        self.last_seeds = []         # seeds actually run by the last run_seeds (replacements included)
        self.section = "study"       # what the runs are for now: '<material>/<stage>', 'validation/<name>' ...
        self.jobs = []               # every job asked: section, rig, seed, job id, status (outputs: jobs.csv)
        self.t0 = time.time()
        self.eta = Eta(_workers_of(executor), cores=_local_cores(executor))
        self.stage_budget = None      # the running stage: (budget, runs requested before it, its index)

    def runs_left(self):
        """Runs the study budget still allows (inf without max_runs_count)."""
        return math.inf if not self.max_runs_count else self.max_runs_count - self.runs_requested

    def run_seeds(self, rig, material, overrides, seeds, eta_material=None):
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
                raise BudgetSpent(f"{self.budget_where}: the study's run budget ({self.max_runs_count} runs) is spent")
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

    def missing_seeds(self, values, rig, response, extra):
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
        key = self.point_key(material, stage, rig, extra)
        used = self._stage_seeds.setdefault((material, stage, rig), [])
        count = count or len(self.seeds)
        seeds = self.seeds[:count] if not used else list(range(max(used) + 1, max(used) + 1 + count))
        results = self.run_seeds(rig, *self.job_material(material, stage, extra), seeds, eta_material=material)
        used += self.last_seeds
        values = [[math.nan if v is None else v for v in (response.value(r, lab_dir) for r in results)]
                  for response in responses]
        missing = [self.missing_seeds(vals, rig, response, extra) for response, vals in zip(responses, values)]
        # the runs behind the point (its pictures and lab-curve plots): those with a value to show
        self.point_results.setdefault(key, []).extend(
            r for seed, r in zip(self.last_seeds, results) if any(seed not in m for m in missing))
        for response, vals, miss in zip(responses, values, missing):
            kept = [(seed, v) for seed, v in zip(self.last_seeds, vals) if seed not in miss]
            self.book_point(material, stage, rig, extra, response, kept)
        return values

    def mark_seeds_used(self, material, stage, rig, seeds):
        """Seeds a stage's later points on `rig` must not take again (runs it has from elsewhere)."""
        self._stage_seeds.setdefault((material, stage, rig), []).extend(seeds)

    @staticmethod
    def point_key(material, stage, rig, extra):
        """The key of a point's results in point_results."""
        return material, stage, rig, json.dumps(extra, sort_keys=True)

    def book_point(self, material, stage, rig, extra, response, kept, note=""):
        """Note one point's values [(seed, value)] of a response in the study's runs and points
        (runs.csv, history.csv) and the log line."""
        params = {k: v for k, v in extra.items() if not k.startswith("rig.")}
        for seed, v in kept:
            self.runs.append({"material": material, "stage": stage, "rig": rig, "parameters": params,
                              "seed": seed, "response": response.name, "value": v})
        scalar = [v for _, v in kept if not isinstance(v, list)]
        m, s = mean_std(scalar) if scalar else (math.nan, math.nan)
        self.points.append({"material": material, "stage": stage, "rig": rig, "parameters": params,
                            "response": response.name, "mean": m, "std": s, "n": len(kept),
                            "seeds": [seed for seed, _ in kept]})
        shown = f"{m:.4g} +/- {s:.2g}" if scalar else f"{len(kept)} vectors"
        self.log(f"  {format_params(params)} -> {response.name} {shown} (n {len(kept)}; "
                 f"{note or self.progress_text()})")

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
                 for r in stage_rigs(st)]                       # an inherit stage runs no rig
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


def _local_cores(executor):
    """This machine's cores when the runs go to local processes (through wrappers), else None."""
    import os
    from ..executors.local import LocalPool
    return os.cpu_count() if any(isinstance(e, LocalPool) for e in wrapped_chain(executor)) else None


def _workers_of(executor):
    """Parallel YADE processes of an executor (through wrappers), 1 when it does not say."""
    return next((e.workers for e in wrapped_chain(executor) if isinstance(getattr(e, "workers", None), int)), 1)
