"""The check of every stage that ran at other material values (`run_at`): its response with
the final calibrated set, at the calibrated values themselves (e.g. the stiffness stage's
Young's modulus where the friction stage ran at a cheaper one).

A friction stage may run at a Young's modulus the friction responses were measured not to
depend on (bench/README.md); the calibrated set keeps the stiffness stage's value. This
section runs each such stage's rig once more per seed (study config `run_at_checks:
{seeds_count: N}`, default 1) with every calibrated value and the stage's own rig
overrides, and sets the response beside the stage's target and its model at the estimate:
if the two E's did not give the same friction, it shows here. All checks go to the
executor at once (they run in parallel). Outputs: run_at_checks.csv, summary.json
("run_at_checks") and the report.
"""
import math

from ..files import write_csv
from ..jobs import resolve_job
from ..post import mean_std
from ..post import responses as responses_mod

COLUMNS = ["material", "stage", "rig", "response", "run_at", "calibrated_at", "value_mean", "value_sd", "n",
           "stage_at_estimate", "target", "band", "error"]


def _scalar(v):
    """A vector response (band z per lab step) as its mean over the steps it reached."""
    if isinstance(v, list):
        vals = [x for x in v if x is not None]
        return sum(vals) / len(vals) if vals else math.nan
    return math.nan if v is None else float(v)


def run(study):
    """Run the checks; returns the rows (also in study.run_at_check_rows)."""
    cfg = study.cfg.get("run_at_checks") or {}
    seeds = study.seeds_from_base(int(cfg.get("seeds_count", 1)))
    todo = []                      # (material, stage, response spec, stage row)
    rows_by_label = {(r["material"], r["stage"]): r for r in study.stage_rows}
    for material, stages in study.cfg["materials"].items():
        for st in stages:
            if not st.get("run_at") or (material, st["label"]) not in rows_by_label:
                continue
            for k, spec in enumerate(st["responses"]):
                todo.append((material, st, spec, rows_by_label[(material, st["label"])], k))
    if not todo:
        return []
    study.log(f"[run_at checks] {len(todo)} stage response(s) that ran at other values, now at the calibrated "
              f"ones, {len(seeds)} seed(s) each")
    jobs = []
    for material, st, spec, _, _ in todo:
        over = dict(study.overrides[material], **spec["rig_overrides"])
        jobs += [resolve_job(spec["rig"], material, over, seed=s) for s in seeds]
    study.runs_requested += len(jobs)
    results = study.executor.run(jobs, raise_on_error=False)
    study.record_jobs(jobs, results)
    rows = []
    for i, (material, st, spec, stage_row, k) in enumerate(todo):
        res = [r for r in results[i * len(seeds):(i + 1) * len(seeds)] if r is not None]
        response = responses_mod.get(spec["response"])
        target = study.targets[(material, st["label"])][k]
        vals, error = [], None
        for r in res:
            try:
                vals.append(_scalar(response.value(r, study.lab_dir(st))))
            except (ValueError, KeyError) as exc:
                error = str(exc)
        vals = [v for v in vals if not math.isnan(v)]
        if not res:
            error = error or "every run failed"
        mean, sd = mean_std(vals) if vals else (math.nan, math.nan)
        if len(vals) < 2:
            sd = math.nan                # one run has no spread (mean_std would say 0)
        responses = stage_row.get("responses") or []
        resp_row = responses[k] if k < len(responses) else {}
        at_values = {key: study.overrides[material].get(key) for key in st["run_at"]}
        rows.append({"material": material, "stage": st["label"], "rig": spec["rig"], "response": spec["response"],
                     "run_at": st["run_at"], "calibrated_at": at_values, "value_mean": mean, "value_sd": sd,
                     "n": len(vals), "stage_at_estimate": resp_row.get("at_estimate", math.nan),
                     "target": target.value, "band": target.band, "error": error})
        study.log(f"  {material} {st['label']}: {spec['response']} = {mean:.4g} (n={len(vals)}) at "
                  f"{at_values} vs {resp_row.get('at_estimate', math.nan):.4g} at {st['run_at']} "
                  f"(target {target.value:.4g} +- {target.band:.3g})")
    study.run_at_check_rows = rows
    write_csv(study.out / "run_at_checks.csv", COLUMNS, [[r[c] if not isinstance(r[c], dict) else
                                                          " ".join(f"{a}={b}" for a, b in r[c].items())
                                                          for c in COLUMNS] for r in rows])
    return rows

