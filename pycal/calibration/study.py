"""A calibration study: stages per material in the method's order (configs/calibrations/).

The driver: it runs the rigs, keeps every run, and asks pycal.stats what the runs say
(estimate, 95 % interval, stop or where next), the way GrainLearning keeps its
inference apart from its models. The study config: study_config; the stage kinds (their
checks and runners): stages/; one-parameter stages run in stage_1d, coupled parameters in
stage_joint; outputs: outputs.

Every run goes through `Evaluator.run_seeds` (pycal/calibration/evaluator.py: one result
per seed asked, a refused seed replaced by the next unused one, the run budget counted
there), and through one executor (pycal.runner), which caches them: nothing is simulated twice, and a killed
study resumes where it stopped when started again with the same seeds (every decision
is a deterministic function of the runs).
"""
import copy
import math
import time
from pathlib import Path

from ..configs import load_material
from ..errors import BudgetSpent, PycalError, RunError  # noqa: F401 (BudgetSpent: callers catch it here)
from ..post import responses as responses_mod
from ..stats import stopping
from . import gallery, outputs, stages as stage_kinds, targets
from .held import held_values
from .provenance import study_provenance
from .evaluator import Evaluator
from .verdicts import matches_lab
from .journal import Journal, fingerprint
from .study_config import load_study, stage_rigs

SEED_SCHEME = "fresh seeds at every point"   # in the stage fingerprint: journals of the old scheme start afresh


class Study(Evaluator):
    """Runs a study config with an executor (runner.LocalPool or runner.YadeBatch).

    seed_base: the first seed of every point (seeds seed_base, seed_base + 1, ...);
    use_library: a one-parameter stage starts from the matching runs already in the runs
    folder (pycal/calibration/library_start.py); False (default): every stage from its own runs
    only, so that a study run again in a new output folder on the same runs folder asks for the
    same jobs, and a study of another seed base stays independent of this one."""

    def __init__(self, config_path, executor, out_dir, log=print, seed_base=1, use_library=False):
        self.config_path = Path(config_path)
        self.cfg = load_study(config_path)
        self.out = Path(out_dir) / self.cfg["name"]
        if isinstance(seed_base, bool) or not isinstance(seed_base, int) or seed_base < 0:
            raise PycalError(f"--seed-base {seed_base!r}: must be a whole number >= 0")
        self.seed_base = seed_base
        self.use_library = use_library   # one-parameter stages start from the runs already made (library_start.py)
        super().__init__(executor, log, self.seeds_from_base(self.cfg["seeds_count"]), self.cfg.get("max_runs_count"),
                         f"{self.config_path}: max_runs_count")
        self.overrides = {m: {} for m in self.cfg["materials"]}
        self.intervals = {m: {} for m in self.cfg["materials"]}   # key -> (estimate, low, high) found so far
        self.value_source = {m: {} for m in self.cfg["materials"]}  # key -> the section that calibrated it
        self.stage_rows = []
        self.validation_rows = []    # predictions of tests the calibration never saw (validation.py)
        self.run_at_check_rows = []  # stages that ran at other material values, at the calibrated ones
        self.application_rows = []   # design runs with the calibrated values (application.py)
        # (material, stage) -> the material set its runs use (a stage's material_set), else absent
        self.stage_sets = {(m, st["label"]): st["material_set"] for m, sts in self.cfg["materials"].items()
                           for st in sts if st.get("material_set")}
        self.provenance = study_provenance(self.config_path)
        self.journal = Journal(self.out / "journal.json")
        # every target now: a broken lab file stops the study before any run
        self.targets = {}
        for mat, stages in self.cfg["materials"].items():
            for st in stages:
                self.targets[(mat, st["label"])] = [
                    targets.resolve(r["target"], responses_mod.get(r["response"]), mat, self.lab_dir(st))
                    for r in st["responses"]]

    # ---------------------------------------------------------------- helpers for the stages
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

    def first_value(self, material, group):
        """A parameter group's first point: its `start`, else the value the study has reached,
        inside the group's bounds."""
        if group["start"] is not None:
            return group["start"]
        lo, hi = group["bounds"]
        return min(max(self.current_value(material, group["keys"][0]), lo), hi)

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

    def apply_set(self, material, values):
        """A stage's `set`: material keys its runs (and the later stages') take, not calibrated."""
        self.overrides[material].update(values)

    def set_value(self, material, keys, value, interval=None):
        """Carry a calibrated value (and its (estimate, low, high)) into the next stages."""
        for k in keys:
            self.overrides[material][k] = value
            self.value_source[material][k] = self.section
            if interval is not None:
                self.intervals[material][k] = interval

    def run(self):
        """Run every stage in order; returns the stage rows. Outputs are rewritten after each."""
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
                kind = stage_kinds.get(st["kind"])
                try:
                    row = kind.run(self, material, st)
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
                row.setdefault("runs_from_library", 0)
                row["held"] = held
                row["matches_lab"] = matches_lab(row)
                row["gallery"] = gallery.stage_pictures(self, material, st, row) if kind.calibrates else []
                row["aor_seeds"] = gallery.aor_seed_angles(self, material, st, row) if kind.calibrates else {}
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


def cost_per_material(stage_rows):
    """{material: {runs_requested, runs_simulated, elapsed_s}} summed over its stages
    (elapsed: of this invocation; a resumed study replays cached runs in seconds)."""
    out = {}
    for r in stage_rows:
        c = out.setdefault(r["material"], {"runs_requested": 0, "runs_simulated": 0, "elapsed_s": 0.0})
        for k in c:
            c[k] += r.get(k, 0) or 0
    return out
