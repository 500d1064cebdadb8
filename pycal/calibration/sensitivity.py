"""What drives a prediction's miss: the calibrated values moved together in a screening
design (`./run.sh pycal sensitivity PREDICTION`), or one at a time.

Not part of `./run.sh calibrate`: the study predicts with its seed spread and verdicts;
this command asks, for one prediction of its validation section, how each calibrated
value moves the first missed response (or a response named with --response).

Factors: each calibrated parameter of the prediction's material (set), as the stages set
it: the keys one stage sets to one value (e.g. rolling resistance on the material, steel
and PVC) move together; plus the prediction's `sensitivity_extra` keys (start values no
stage fits). Levels: the calibrated value (low) and the value x (1 + relative_step_fraction)
(high), the step of the study's `validation.sensitivity` settings.

- design `screening` (default): a Plackett-Burman design (pycal.stats.screening): N runs
  (N the smallest multiple of 4 above the factor count), each on the same seeds_per_run
  seeds, so every run informs every effect. Effect = mean at high - mean at low; its
  standard error from the design's unused columns (none when the factors fill every
  column). N x seeds_per_run runs in all.
- design `one-at-a-time`: each factor alone at its high level on the validation's seeds
  (validation.sensitivity.seeds_count), paired seed by seed with the prediction's own
  runs at the calibrated values: factors x seeds runs.

Outputs in the study folder: sensitivity-<prediction>-<design>.json / .csv (factor,
keys, value, moved to, effect, SE, rank) and plots/sensitivity-<prediction>-<design>.png.
"""
import math

import numpy as np

from ..errors import ConfigError, RunError
from ..files import finite, write_csv, write_json
from ..jobs import override_value, resolve_job
from ..plotting import new_figure, save_png
from ..stats import screening
from .calibrated import run_overrides
from .validation import compare_results, movable, paired_change

DESIGNS = ("screening", "one-at-a-time")


def factors(study, pred, extra):
    """[{'label', 'keys', 'value'}]: the calibrated parameters of the prediction's
    overrides (keys one stage sets to one value are one factor) and its
    sensitivity_extra keys (value read from the resolved job)."""
    groups = []                     # (component prefix, key list) of every stage parameter
    for material, stages in study.cfg["materials"].items():
        for st in stages:
            groups += [(material, tuple(keys)) for keys in st["parameter_keys"] if len(keys) > 1]
    out, placed = [], {}
    for key, value in extra.items():
        if key.startswith("rig.") or not movable(value):
            continue
        comp, _, bare = key.partition(".")
        if comp not in study.cfg["materials"]:          # a lone material: keys carry no prefix
            comp, bare, prefix = pred["material"], key, ""
        else:
            prefix = comp + "."
        group = next((keys for m, keys in groups if m == comp and bare in keys), None)
        ident = (prefix, group) if group else (prefix, (bare,))
        if ident in placed and out[placed[ident]]["value"] == value:
            out[placed[ident]]["keys"].append(key)
            continue
        placed[ident] = len(out)
        label = prefix + (group[0] if group else bare)
        if group:
            label += f" (+ {len(group) - 1} key(s) set to the same value)"
        out.append({"label": label, "keys": [key], "value": value})
    if pred.get("sensitivity_extra"):
        job = resolve_job(pred["rig"], pred["material"], extra)
        for key in pred["sensitivity_extra"]:
            out.append({"label": key + " (start value)", "keys": [key], "value": override_value(job, key)})
    return out


def moved(extra, factor, step):
    """The overrides with one factor at its high level."""
    return dict(extra, **{k: factor["value"] * (1 + step) for k in factor["keys"]})


def response_of(results, cmp):
    """Mean response of one design row's runs, as the validation compares it (a curve
    comparison: the mean RMS band z); NaN when no run gave a value."""
    return compare_results(results, cmp)["sim_mean"]


def run_screening(study, pred, extra, facs, step, seeds, cmp):
    """The Plackett-Burman rows on `seeds` each; returns the factor rows (effect, se)."""
    design = screening.plackett_burman(len(facs))
    ys = []
    for i, levels in enumerate(design):
        over = dict(extra)
        for f, lev in zip(facs, levels):
            if lev > 0:
                over = moved(over, f, step)
        study.log(f"  design run {i + 1}/{len(design)}: high " +
                  (", ".join(f["label"].split(" (")[0] for f, lev in zip(facs, levels) if lev > 0) or "none"))
        res = study.run_seeds(pred["rig"], pred["material"], over, seeds)
        y = response_of(res, cmp)
        if math.isnan(y):
            raise RunError(f"design run {i + 1}: no value of {cmp['response']} on seeds {study.last_seeds}")
        ys.append(y)
    effects = screening.main_effects(design, ys)
    se = screening.effect_standard_error(effects, len(facs))
    rows = [dict(f, moved_to=f["value"] * (1 + step), effect=float(e), effect_se=se)
            for f, e in zip(facs, effects[:len(facs)])]
    return rows, {"design_runs_count": len(design), "seeds": list(seeds), "responses": ys,
                  "noise_columns_count": len(design) - 1 - len(facs)}


def run_one_at_a_time(study, pred, extra, facs, step, seeds, cmp):
    """Each factor alone at its high level, paired by seed with the calibrated runs."""
    base = study.run_seeds(pred["rig"], pred["material"], extra, seeds)
    base_by_seed = dict(zip(study.last_seeds, base))
    rows = []
    for f in facs:
        try:
            res = study.run_seeds(pred["rig"], pred["material"], moved(extra, f, step), seeds)
        except RunError as exc:
            rows.append(dict(f, moved_to=f["value"] * (1 + step), effect=None, effect_se=None, error=str(exc)))
            continue
        ch = paired_change(dict(zip(study.last_seeds, res)), base_by_seed, cmp)
        rows.append(dict(f, moved_to=f["value"] * (1 + step), effect=ch["change"], effect_se=ch["change_se"]))
        study.log(f"  {f['label']}: {ch['change']:+.3g}")
    return rows, {"seeds": list(seeds)}


def run(study, name, design="screening", seeds_per_run=1, response=None):
    """Sensitivity of prediction `name` of the study's validation section; writes and
    returns {'prediction', 'design', 'response', 'factors': rows ranked by |effect|, ...}."""
    section = study.cfg.get("validation") or {}
    preds = {p["name"]: p for p in section.get("predictions", [])}
    if name not in preds:
        raise ConfigError(str(study.config_path), "validation.predictions",
                          f"no prediction named {name!r} (there are: {', '.join(preds) or 'none'})")
    if design not in DESIGNS:
        raise ConfigError("--design", design, f"must be one of {', '.join(DESIGNS)}")
    pred = preds[name]
    cmps = {c["response"]: c for c in pred["compare"]}
    if response is not None and response not in cmps:
        raise ConfigError("--response", response, f"not a response of {name} (there are: {', '.join(cmps)})")
    cmp = cmps[response] if response else pred["compare"][0]
    step = (section.get("sensitivity") or {}).get("relative_step_fraction", 0.2)
    extra = run_overrides(study.overrides, pred)
    facs = factors(study, pred, extra)
    study.section = f"sensitivity/{name}"
    if not facs:
        raise ConfigError(str(study.config_path), f"validation.predictions.{name}",
                          "no calibrated value to move (run ./run.sh calibrate first)")
    if design == "screening":
        seeds = study.seeds_from_base(seeds_per_run)
        study.log(f"[sensitivity] {name}: {len(facs)} factors, Plackett-Burman design of "
                  f"{screening.design_size(len(facs))} runs x {len(seeds)} seed(s), step x{1 + step:g}, "
                  f"response {cmp['response']}")
        rows, info = run_screening(study, pred, extra, facs, step, seeds, cmp)
    else:
        seeds = study.seeds_from_base((section.get("sensitivity") or {}).get("seeds_count", 3))
        study.log(f"[sensitivity] {name}: {len(facs)} factors one at a time x {len(seeds)} seeds, "
                  f"step x{1 + step:g}, response {cmp['response']}")
        rows, info = run_one_at_a_time(study, pred, extra, facs, step, seeds, cmp)
    rows.sort(key=lambda r: -abs(r["effect"]) if r.get("effect") is not None and not math.isnan(r["effect"]) else 0)
    for k, r in enumerate(rows):
        r["rank"] = k + 1
    out = {"prediction": name, "design": design, "response": cmp["response"], "relative_step_fraction": step,
           "runs_requested": study.runs_requested, "factors": rows, **info}
    write(study, out)
    return out


def write(study, out):
    """sensitivity-<prediction>-<design>.json / .csv and its bar plot."""
    stem = f"sensitivity-{out['prediction']}-{out['design']}"
    write_json(study.out / f"{stem}.json", finite(out), default=str)
    cols = ["rank", "factor", "keys", "value", "moved_to", "effect", "effect_se"]
    write_csv(study.out / f"{stem}.csv", cols,
              [[r["rank"], r["label"], " ".join(r["keys"]), r["value"], r["moved_to"], r.get("effect"),
                r.get("effect_se")] for r in out["factors"]])
    rows = [r for r in out["factors"] if r.get("effect") is not None and not math.isnan(r["effect"])]
    fig, ax = new_figure(figsize=(7.5, 0.35 * len(rows) + 1.6))
    ys = np.arange(len(rows))[::-1]
    ax.barh(ys, [r["effect"] for r in rows], xerr=[r.get("effect_se") or 0.0 for r in rows], color="C0",
            capsize=3)
    ax.set_yticks(ys)
    ax.set_yticklabels([r["label"].split(" (")[0] for r in rows], fontsize=7)
    ax.axvline(0.0, color="k", lw=0.8)
    ax.set_xlabel(f"change of {out['response']} when the value moves x{1 + out['relative_step_fraction']:g}")
    ax.set_title(f"sensitivity: {out['prediction']} ({out['design']}), +- 1 SE", fontsize=9)
    fig.tight_layout()
    save_png(fig, study.out / "plots" / f"{stem}.png")
