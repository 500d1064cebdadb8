"""Validation: predictions of tests the calibration never saw, with the calibrated values.

The study config's `validation:` section lists predictions; each runs one rig on a
material or material set with the values the stages found (nothing is fitted here) and
compares responses with the lab, with the seed spread:

    validation:
      seeds_count: 5
      sensitivity: {relative_step_fraction: 0.2, seeds_count: 3}   # for predictions that ask and miss
      predictions:
        - name: mixed_dry_pile
          rig: aor_mixed
          material: mixed-dry                 # a set: its components take their calibrated values
          rig_overrides: {rig.procedure.lift_speed_m_s: 0.01}
          sensitivity: true                   # if it misses: which calibrated value drives it
          compare:
            - {response: aor_left_deg, lab: {table: angle_of_repose, sample: sample50_dry, column: left_deg},
               band_deg: 2.0}
            - {response: ucs, lab: {curve: ucs_fines_dry}}      # a compression curve: band z per lab step

A scalar comparison is inside when |sim mean - lab| <= band (its z = (sim - lab) / band);
a curve comparison is inside when its RMS band z is <= 1 (pycal.post.compression). A
prediction that misses and asks for a sensitivity (`sensitivity: true`, settings in the
section) names the command that finds what drives the miss (`./run.sh pycal sensitivity
NAME`, pycal.calibration.sensitivity: a screening design over every calibrated value and
the `sensitivity_extra` keys); the main job does not run it.
paired_change: the change of a response from base runs to moved runs, paired by seed (a
curve comparison: each seed's mean RMS band z), used by the one-at-a-time design.
Outputs: <study>/validation.csv, validation.json, plots/validation-<name>.png.
"""
import json
import math
from pathlib import Path

from .. import labdata
from ..errors import ConfigError, RunError
from ..files import finite, write_csv, write_json
from ..post import mean_std
from ..post import compression as post_compression
from ..post import lab_curves
from ..plotting import new_figure, save_png
from ..jobs import override_value, resolve_job
from . import run_pictures
from .calibrated import run_overrides

CURVE = "ucs"   # compare: {response: ucs, lab: {curve: NAME}}: the result's curves against that lab curve


def check(section, c, key="validation"):
    """Validate the `validation:` section of a study config (c: the config checker)."""
    c.keys(section, key, ["predictions"], ["seeds_count", "sensitivity"])
    if "seeds_count" in section:
        c.number(section["seeds_count"], f"{key}.seeds_count", 2)
    if "sensitivity" in section:
        s = section["sensitivity"]
        c.keys(s, f"{key}.sensitivity", ["relative_step_fraction"], ["seeds_count"])
        c.number(s["relative_step_fraction"], f"{key}.sensitivity.relative_step_fraction", 0, 1, lo_open=True)
    preds = section["predictions"]
    if not isinstance(preds, list) or not preds:
        c.fail(f"{key}.predictions", "must be a non-empty list")
    names = set()
    for i, p in enumerate(preds):
        k = f"{key}.predictions[{i}]"
        c.keys(p, k, ["name", "rig", "material", "compare"], ["rig_overrides", "sensitivity", "sensitivity_extra"])
        if p.get("sensitivity") and "sensitivity" not in section:
            c.fail(f"{k}.sensitivity", "needs the section's sensitivity settings (validation.sensitivity)")
        if "sensitivity_extra" in p:
            check_extra(p, c, k)
        if p["name"] in names:
            c.fail(f"{k}.name", f"{p['name']!r} is used twice")
        names.add(p["name"])
        for j, cmp in enumerate(p["compare"]):
            ck = f"{k}.compare[{j}]"
            bands = [b for b in cmp if b.startswith("band_")]
            c.keys(cmp, ck, ["response", "lab"], bands)
            lab = cmp["lab"]
            if cmp["response"] == CURVE:
                c.keys(lab, f"{ck}.lab", ["curve"])
            else:
                c.keys(lab, f"{ck}.lab", ["table", "sample", "column"])
                if len(bands) != 1:
                    c.fail(ck, "a scalar comparison needs one band_<unit> (the lab value's band)")


def movable(value):
    """A value the sensitivity can move by a relative step: a non-zero number."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and value != 0


def check_extra(p, c, k):
    """`sensitivity_extra`: keys of values no stage fits (start values) that the sensitivity
    moves too; each must address a non-zero number of the prediction's material (set)."""
    if not p.get("sensitivity"):
        c.fail(f"{k}.sensitivity_extra", "needs sensitivity: true")
    keys = p["sensitivity_extra"]
    if not isinstance(keys, list) or not all(isinstance(x, str) for x in keys):
        c.fail(f"{k}.sensitivity_extra", "must be a list of override keys (e.g. "
                                          "M3-wet.interactions.M3-wet.cohesion.force_fraction)")
    job = resolve_job(p["rig"], p["material"], p.get("rig_overrides", {}))
    for x in keys:
        v = override_value(job, x)
        if not movable(v):
            c.fail(f"{k}.sensitivity_extra", f"{x}: not a non-zero number of {p['material']} (value {v!r})")


def lab_value(spec):
    """A lab scalar: row `sample` of labresults/<table>.csv, column `column` (None if empty)."""
    df = labdata.load_table(spec["table"])
    row = df[df["sample"] == spec["sample"]]
    if row.empty or spec["column"] not in df.columns:
        raise ConfigError(f"labresults/{spec['table']}.csv", spec["column"], f"no value for sample {spec['sample']}")
    v = row.iloc[0][spec["column"]]
    return None if v is None or (isinstance(v, float) and math.isnan(v)) else float(v)


def compare_results(results, cmp):
    """One comparison over the seeds' results: sim mean and SD, lab value, band, z, inside."""
    if cmp["response"] == CURVE:
        targets = lab_curves.load_targets([cmp["lab"]["curve"]])
        if not targets:
            raise ConfigError("labresults/curves", cmp["lab"]["curve"], "no such lab curve")
        targets["_particle_density"] = float(labdata.load_samples()["material"]["particle_density_kg_m3"])
        zs = []
        for r in results:
            zs += [v["rms_z"] for v in post_compression.compare(r, targets).values() if v["rms_z"] is not None]
        mean, sd = mean_std(zs) if zs else (math.nan, math.nan)
        return {"response": f"{cmp['lab']['curve']} (RMS band z)", "sim_mean": mean, "sim_sd": sd, "n": len(zs),
                "lab": 0.0, "band": 1.0, "z": mean, "inside": bool(zs) and mean <= 1.0}
    values = [r.get(cmp["response"]) for r in results]
    values = [v for v in values if v is not None and not (isinstance(v, float) and math.isnan(v))]
    lab = lab_value(cmp["lab"])
    band = next(v for k, v in cmp.items() if k.startswith("band_"))
    mean, sd = mean_std(values) if values else (math.nan, math.nan)
    z = (mean - lab) / band if values and lab is not None else math.nan
    return {"response": cmp["response"], "sim_mean": mean, "sim_sd": sd, "n": len(values), "lab": lab,
            "band": band, "z": z, "inside": bool(values) and lab is not None and abs(z) <= 1.0}


def run(study):
    """Run the study's validation section (if any); returns the rows (also written out)."""
    section = study.cfg.get("validation")
    if not section:
        return []
    seeds = study.seeds_from_base(section.get("seeds_count", len(study.seeds)))
    rows = []
    for pred in section["predictions"]:
        study.log(f"[validation] {pred['name']}: {pred['rig']} on {pred['material']} with the calibrated values")
        study.section = f"validation/{pred['name']}"
        extra = run_overrides(study.overrides, pred)
        try:
            results = study.run_seeds(pred["rig"], pred["material"], extra, seeds)
        except RunError as exc:
            rows.append({"prediction": pred["name"], "rig": pred["rig"], "material": pred["material"],
                         "comparisons": [], "error": str(exc)})
            continue
        comps = [compare_results(results, cmp) for cmp in pred["compare"]]
        row = {"prediction": pred["name"], "rig": pred["rig"], "material": pred["material"], "comparisons": comps,
               "seeds": list(study.last_seeds), "error": None,
               "plot": plot(study, pred["name"], comps),
               "gallery": run_pictures.prediction_pictures(study, pred["name"], pred["rig"], results),
               "seed_values": run_pictures.seed_values(study, results, [c["response"] for c in pred["compare"]])}
        missed = [c for c, cmp in zip(comps, pred["compare"]) if not c["inside"]]
        if missed and pred.get("sensitivity"):
            # what drives the miss is its own command (pycal.calibration.sensitivity): not in the main job
            row["sensitivity_command"] = (f"./run.sh pycal sensitivity {pred['name']} --response "
                                          f"{pred['compare'][comps.index(missed[0])]['response']}")
            study.log(f"  what drives the miss: {row['sensitivity_command']}")
        for c in comps:
            sim = (f"{c['sim_mean']:.4g} +/- {c['sim_sd']:.2g} (n={c['n']})" if c["n"]
                   else "no value on any seed")
            study.log(f"  {c['response']}: {sim} vs lab {c['lab'] if c['lab'] is not None else '-'} +/- "
                      f"{c['band']}: {'inside' if c['inside'] else 'MISSED'}")
        rows.append(row)
        write(study, rows)
    return rows


def paired_change(moved_by_seed, base_by_seed, cmp):
    """Mean change of a response from the base runs to the moved runs over the seeds both
    have: {change, change_se (None below 2 pairs), seeds}. A curve comparison pairs each
    seed's mean RMS band z."""
    seeds = sorted(set(moved_by_seed) & set(base_by_seed))
    if not seeds:
        return {"change": math.nan, "change_se": None, "seeds": [],
                "error": "no seed in common with the prediction's runs (each was replaced)"}
    diffs, used = [], []
    for s in seeds:
        if cmp["response"] == CURVE:     # the seed's mean RMS band z over its curves
            a, b = (compare_results([r[s]], cmp)["sim_mean"] for r in (moved_by_seed, base_by_seed))
        else:
            a, b = moved_by_seed[s].get(cmp["response"]), base_by_seed[s].get(cmp["response"])
        if all(isinstance(v, (int, float)) and not math.isnan(v) for v in (a, b)):
            diffs.append(a - b)
            used.append(s)
    if not diffs:
        return {"change": math.nan, "change_se": None, "seeds": []}
    mean, sd = mean_std(diffs)
    return {"change": mean, "change_se": sd / math.sqrt(len(diffs)) if len(diffs) > 1 else None, "seeds": used}


def plot(study, name, comps):
    """Simulated mean +- SD against the lab value and its band, one bar per comparison."""
    fig, ax = new_figure(figsize=(max(4.5, 1.3 * len(comps) + 2), 3.6))
    labelled = False
    for i, c in enumerate(comps):
        if c["lab"] is not None:
            ax.fill_between([i - 0.35, i + 0.35], c["lab"] - c["band"], c["lab"] + c["band"], color="0.85",
                            label="lab band" if i == 0 else None)
            ax.plot([i - 0.35, i + 0.35], [c["lab"]] * 2, color="k", lw=1, label="lab" if i == 0 else None)
        if c["n"] == 0:                  # no seed gave a value (e.g. a pile too flat for an angle)
            ax.annotate("no value\non any seed", (i, c["lab"] if c["lab"] is not None else 0.0), ha="center",
                        va="bottom", fontsize=7, color="C3")
            continue
        ax.errorbar([i], [c["sim_mean"]], yerr=[c["sim_sd"]], fmt="o", color="C0", capsize=4,
                    label=None if labelled else "predicted (seed mean +- SD)")
        labelled = True
    ax.set_xticks(range(len(comps)))
    ax.set_xticklabels([c["response"] for c in comps], rotation=20, ha="right", fontsize=8)
    ax.set_title(f"validation: {name}", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    rel = Path("plots") / f"validation-{name}.png"
    save_png(fig, study.out / rel)
    return str(rel)


COLUMNS = ["prediction", "rig", "material", "response", "sim_mean", "sim_sd", "n", "lab", "band", "z",
           "inside", "error"]


def write(study, rows):
    """validation.csv (one row per comparison) and validation.json."""
    table = []
    for r in rows:
        for c in r["comparisons"] or [{}]:
            table.append([r["prediction"], r["rig"], r["material"]] + [c.get(k, "") for k in COLUMNS[3:11]]
                         + [r["error"] or ""])
    write_csv(study.out / "validation.csv", COLUMNS, table)
    write_json(study.out / "validation.json", finite(rows), default=str)
