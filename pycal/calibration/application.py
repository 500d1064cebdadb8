"""Application: design runs with the calibrated values (e.g. the transfer chute).

Unlike validation there is no lab test behind these runs: they answer the user's design
question with the calibrated material (impact stress against the design formula, holdup,
plugging), with the seed spread. The study config's `application:` section:

    application:
      seeds_count: 3
      runs:
        - name: transfer_wet
          rig: transfer
          material: mixed-wet                 # a set: its components take their calibrated values
          responses: [impact_stress_pa, design_impact_stress_pa, holdup_mass_kg, plugged]

A numeric response is reported as seed mean +- SD; a true/false one (plugged) as the
number of seeds where it was true. Outputs: <study>/application.csv, application.json,
plots/application-<name>.png; summary.json "applied"; the report's Application section.
"""
import math
from pathlib import Path

from ..errors import RunError
from ..files import finite, write_csv, write_json
from ..post import mean_std
from ..plotting import new_figure, save_png
from .calibrated import run_overrides


def check(section, c, key="application"):
    """Validate the `application:` section of a study config (c: the config checker)."""
    c.keys(section, key, ["runs"], ["seeds_count"])
    if "seeds_count" in section:
        c.number(section["seeds_count"], f"{key}.seeds_count", 1)
    runs = section["runs"]
    if not isinstance(runs, list) or not runs:
        c.fail(f"{key}.runs", "must be a non-empty list")
    names = set()
    for i, r in enumerate(runs):
        k = f"{key}.runs[{i}]"
        c.keys(r, k, ["name", "rig", "material", "responses"], ["rig_overrides"])
        if r["name"] in names:
            c.fail(f"{k}.name", f"{r['name']!r} is used twice")
        names.add(r["name"])
        if not isinstance(r["responses"], list) or not r["responses"]:
            c.fail(f"{k}.responses", "must be a non-empty list of result.json keys")


def summarise(results, response):
    """One response over the seeds: {'response', 'kind': 'number'|'flag', 'mean', 'sd', 'n',
    'true_count'} (NaN and missing values left out and not counted)."""
    values = [r.get(response) for r in results]
    if any(isinstance(v, bool) for v in values):
        flags = [bool(v) for v in values if isinstance(v, bool)]
        return {"response": response, "kind": "flag", "mean": None, "sd": None, "n": len(flags),
                "true_count": sum(flags)}
    nums = [float(v) for v in values if isinstance(v, (int, float)) and not math.isnan(float(v))]
    mean, sd = mean_std(nums) if nums else (math.nan, math.nan)
    return {"response": response, "kind": "number", "mean": mean, "sd": sd, "n": len(nums), "true_count": None}


def run(study):
    """Run the study's application section (if any); returns the rows (also written out)."""
    section = study.cfg.get("application")
    if not section:
        return []
    seeds = study.seeds_from_base(section.get("seeds_count", len(study.seeds)))
    rows = []
    for spec in section["runs"]:
        study.log(f"[application] {spec['name']}: {spec['rig']} on {spec['material']} with the calibrated values")
        study.section = f"application/{spec['name']}"
        extra = run_overrides(study.overrides, spec)
        row = {"name": spec["name"], "rig": spec["rig"], "material": spec["material"], "responses": [],
               "seeds": [], "error": None, "plot": None}
        try:
            results = study.run_seeds(spec["rig"], spec["material"], extra, seeds)
        except RunError as exc:
            row["error"] = str(exc)
            rows.append(row)
            continue
        row["seeds"] = list(study.last_seeds)
        row["responses"] = [summarise(results, name) for name in spec["responses"]]
        for s in row["responses"]:
            study.log(f"  {s['response']}: " + (f"{s['true_count']} of {s['n']} seeds" if s["kind"] == "flag"
                                                  else f"{s['mean']:.4g} +/- {s['sd']:.2g} (n={s['n']})"))
        rows.append(row)
    plot_path = plot(study.out, rows)
    for r in rows:
        r["plot"] = plot_path
    write(study.out, rows)
    return rows


def plot(out, rows):
    """One panel per numeric response: each run's seed mean +- SD side by side."""
    names = []
    for r in rows:
        names += [s["response"] for s in r["responses"] if s["kind"] == "number" and s["response"] not in names]
    if not names:
        return None
    fig, axes = new_figure(ncols=len(names), figsize=(2.6 * len(names) + 1, 3.4))
    axes = axes if hasattr(axes, "__len__") else [axes]
    for ax, name in zip(axes, names):
        for i, r in enumerate(rows):
            s = next((x for x in r["responses"] if x["response"] == name), None)
            if s and s["n"]:
                ax.errorbar([i], [s["mean"]], yerr=[s["sd"]], fmt="o", capsize=4, color=f"C{i}")
        ax.set_xticks(range(len(rows)))
        ax.set_xticklabels([r["name"] for r in rows], rotation=20, ha="right", fontsize=8)
        ax.set_title(name, fontsize=8)
    fig.suptitle("application: seed mean +- SD with the calibrated values", fontsize=9)
    fig.tight_layout()
    rel = Path("plots") / "application.png"
    save_png(fig, Path(out) / rel)
    return str(rel)


COLUMNS = ["name", "rig", "material", "response", "mean", "sd", "n", "true_count", "error"]


def write(out, rows):
    """application.csv (one row per response) and application.json."""
    table = []
    for r in rows:
        for s in r["responses"] or [{}]:
            table.append([r["name"], r["rig"], r["material"]] + [s.get(k, "") for k in COLUMNS[3:8]]
                         + [r["error"] or ""])
    write_csv(Path(out) / "application.csv", COLUMNS, table)
    write_json(Path(out) / "application.json", finite(rows), default=str)
