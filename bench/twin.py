"""Synthetic twins: the calibration engine against hidden M2 parameters it must recover.

    /usr/bin/python3 bench/twin.py --hidden particle_density_kg_m3=3600 rolling_resistance_coefficient=0.15 \\
        youngs_modulus_pa=2e7 steel_friction_coefficient=0.35 [--out DIR] [--workers N]
    /usr/bin/python3 bench/twin.py --twins twins.yaml        # a list of twins

twins.yaml: a list of {name: NAME, hidden: {parameter: value, ...}}. Parameters that
can be hidden (the others stay at the config's values on both sides):

    particle_density_kg_m3          particles.density_kg_m3           (stage density)
    rolling_resistance_coefficient  M2, steel and PVC rolling resistance  (stage rolling_resistance)
    youngs_modulus_pa               contact.youngs_modulus_pa         (stage stiffness)
    steel_friction_coefficient      interactions.steel.friction_coefficient (stage wall_friction)

Per twin:
1. simulate the lab targets with the hidden values on seeds 101, 102, ... (not the
   study's): cell-fill bulk density, angle of repose (lift 10 mm/s as the study), the
   CCS-expansion unloading stiffness curve and the wall friction curve (12, 40, 90 kPa: the study's steps),
   the curves written to <out>/<twin>/twin_lab/ in the labresults/ format; each target
   carries its standard error (it is a mean over the target seeds);
2. calibrate M2 from its start values with the shipped study's M2 stages for the hidden
   parameters (tolerances and budgets as configs/calibrations/zinc_ore.yaml; the final
   rolling resistance + density pass when both are hidden);
3. per parameter: estimate, 95 % interval, error vs the hidden value and whether the
   hidden value lies inside the interval; runs per twin.
Writes <out>/twins.json and <out>/twins.md (a markdown table) and appends one line per
twin to bench/results.jsonl. Runs are cached in <out>/runs (shared by the twins: a rerun
resumes; nothing comes from the main job's cache).
"""
import argparse
import datetime
import json
import platform
import sys
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from pycal import LAB_DIR  # noqa: E402
from pycal.calibration.study import Study  # noqa: E402
from pycal.calibration.study_config import load_study  # noqa: E402
from pycal.files import finite, write_json, write_text  # noqa: E402
from pycal.gitinfo import git_commit  # noqa: E402
from pycal.jobs import resolve_job  # noqa: E402
from pycal.post import mean_std  # noqa: E402
from pycal.post import responses  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results.jsonl"
SHIPPED = ROOT / "configs" / "calibrations" / "zinc_ore.yaml"
MATERIAL = "M2"
ROLLING_KEYS = ["interactions.M2.rolling_resistance_coefficient",
                "interactions.steel.rolling_resistance_coefficient",
                "interactions.pvc.rolling_resistance_coefficient"]
HIDDEN_KEYS = {"particle_density_kg_m3": ["particles.density_kg_m3"],
               "rolling_resistance_coefficient": ROLLING_KEYS,
               "youngs_modulus_pa": ["contact.youngs_modulus_pa"],
               "steel_friction_coefficient": ["interactions.steel.friction_coefficient"]}
STAGE_OF = {"particle_density_kg_m3": "density", "rolling_resistance_coefficient": "rolling_resistance",
            "youngs_modulus_pa": "stiffness", "steel_friction_coefficient": "wall_friction"}
LIFT = {"rig.procedure.lift_speed_m_s": 0.01}
WALL_STEPS = {"rig.procedure.consolidation_stresses_pa": [12000, 40000, 90000]}


class TwinError(Exception):
    """A bad twin definition (command line or YAML): one line, exit 2."""


def parse_hidden(items, where="--hidden"):
    """['particle_density_kg_m3=3600', ...] or a dict -> {name: float}, names checked."""
    pairs = items.items() if isinstance(items, dict) else [i.split("=", 1) if "=" in i else (i, None) for i in items]
    out = {}
    for name, value in pairs:
        if name not in HIDDEN_KEYS:
            raise TwinError(f"{where}: {name}: not a parameter a twin can hide ({', '.join(HIDDEN_KEYS)})")
        try:
            out[name] = float(value)
        except (TypeError, ValueError):
            raise TwinError(f"{where}: {name}: {value!r} is not a number") from None
        if not out[name] > 0:
            raise TwinError(f"{where}: {name}: {out[name]} must be > 0")
    if not out:
        raise TwinError(f"{where}: no hidden parameter given")
    return out


def load_twins(path):
    """[(name, hidden dict)] from a YAML list of {name, hidden}."""
    path = Path(path)
    if not path.is_file():
        raise TwinError(f"{path}: file not found")
    data = yaml.safe_load(path.read_text())
    if not isinstance(data, list) or not data:
        raise TwinError(f"{path}: must be a list of {{name: NAME, hidden: {{parameter: value}}}}")
    twins = []
    for i, t in enumerate(data):
        if not isinstance(t, dict) or set(t) - {"name", "hidden"} or "hidden" not in t:
            raise TwinError(f"{path}: [{i}]: needs `hidden` (and optionally `name`), nothing else")
        twins.append((str(t.get("name", f"twin{i + 1}")), parse_hidden(t["hidden"], f"{path}: [{i}].hidden")))
    if len({n for n, _ in twins}) != len(twins):
        raise TwinError(f"{path}: twin names must differ")
    return twins


def hidden_overrides(hidden):
    """The hidden values as material overrides."""
    return {k: v for name, v in hidden.items() for k in HIDDEN_KEYS[name]}


def _per_seed(results, name, lab):
    """(mean, standard error) of a response over the target seeds."""
    values = [responses.get(name).value(r, lab) for r in results]
    m, s = mean_std(values)
    return m, s / len(values) ** 0.5


def simulate_targets(executor, hidden, seeds, lab):
    """Run the rigs at the hidden values, write the twin's curves and samples.yaml into
    `lab`; returns {response: (target, standard error)} of the stages to run."""
    o = hidden_overrides(hidden)

    def run(rig, extra=None):
        """One result per target seed; a seed the rig refuses is replaced by the next one above
        them (as the study replaces its own), at most as many times as there are seeds."""
        results, batch, next_seed = [], list(seeds), max(seeds) + 1
        while batch:
            out = executor.run([resolve_job(rig, MATERIAL, {**o, **(extra or {})}, seed=s) for s in batch],
                               raise_on_error=False)
            results += [r for r in out if r is not None]
            refused = len(batch) - sum(r is not None for r in out)
            if refused:
                print(f"twin: {rig}: {refused} target seed(s) refused: {getattr(executor, 'last_errors', [])}; "
                      f"replaced from seed {next_seed}", file=sys.stderr)
            if next_seed + refused > max(seeds) + 1 + len(seeds):
                raise TwinError(f"{rig}: more than {len(seeds)} target seeds refused at the hidden values")
            batch = list(range(next_seed, next_seed + refused))
            next_seed += refused
        return results
    (lab / "curves").mkdir(parents=True, exist_ok=True)
    out = {}
    if {"particle_density_kg_m3", "rolling_resistance_coefficient"} & set(hidden):
        out["bulk_density_kg_m3"] = _per_seed(run("fill"), "bulk_density_kg_m3", lab)
    if "rolling_resistance_coefficient" in hidden:
        out["aor_mean_deg"] = _per_seed(run("aor", LIFT), "aor_mean_deg", lab)
    if "youngs_modulus_pa" in hidden:
        exp = run("ccs_expansion")
        rows = {}
        for r in exp:
            for b, s, k in zip(r["branch"], r["target_stress_pa"], r["stiffness_pa"]):
                if b == "unloading" and k is not None:
                    rows.setdefault(float(s), []).append(k)
        lines = ["# synthetic twin (bench/twin.py): unloading stiffness with hidden " + json.dumps(o),
                 "stress_pa,particle_stiffness_pa,particle_stiffness_pa_low,particle_stiffness_pa_high,provenance"]
        for s in sorted(rows):
            m = mean_std(rows[s])[0]
            lines.append(f"{s:.0f},{m:.6g},{0.7 * m:.6g},{1.3 * m:.6g},synthetic")
        write_text(lab / "curves" / "ccs_expansion_gravel_dry.csv", "\n".join(lines) + "\n")
    if "steel_friction_coefficient" in hidden:
        wall = run("wall_friction", WALL_STEPS)
        lines = ["# synthetic twin (bench/twin.py): wall friction with hidden " + json.dumps(o),
                 "stress_pa,mu_static,mu_static_low,mu_static_high,mu_dynamic,mu_dynamic_low,mu_dynamic_high,provenance"]
        for k, s in enumerate(wall[0]["stress_pa"]):
            ms = mean_std([r["mu_static"][k] for r in wall if r["mu_static"][k] is not None])[0]
            md = mean_std([r["mu_dynamic"][k] for r in wall if r["mu_dynamic"][k] is not None])[0]
            lines.append(f"{s:.0f},{ms:.4f},{ms - 0.03:.4f},{ms + 0.03:.4f},{md:.4f},{md - 0.03:.4f},"
                         f"{md + 0.03:.4f},synthetic")
        write_text(lab / "curves" / "wall_friction_gravel_dry.csv", "\n".join(lines) + "\n")
    # the lab's samples, each listing only the curves the twin wrote
    samples = yaml.safe_load((LAB_DIR / "samples.yaml").read_text())
    for sample in samples["samples"].values():
        sample["curves"] = [c for c in sample.get("curves", []) if (lab / "curves" / f"{c}.csv").is_file()]
    write_text(lab / "samples.yaml", "# synthetic twin (bench/twin.py): labresults/samples.yaml, twin "
                                            "curves only\n" + yaml.safe_dump(samples, sort_keys=False))
    if "youngs_modulus_pa" in hidden:
        out["unloading_stiffness_log_ratio"] = _per_seed(exp, "unloading_stiffness_log_ratio", lab)
    if "steel_friction_coefficient" in hidden:
        out["friction_offset_mu_static"] = _per_seed(wall, "friction_offset_mu_static", lab)
    return out


def final_pass_stage(density, rolling):
    """A joint pass over rolling resistance and density, from the shipped study's two stages
    (their rigs, overrides, bounds and tolerances): the twin's last stage, both values again."""
    roll = rolling["parameter"]
    dens = density["parameter"]
    aor = {"rig": rolling["rig"], "response": rolling["response"], "target": dict(rolling["target"])}
    if rolling.get("rig_overrides"):
        aor["rig_overrides"] = dict(rolling["rig_overrides"])
    fill = {"rig": density["rig"], "response": "bulk_density_kg_m3", "target": dict(density["target"])}
    if density.get("rig_overrides"):
        fill["rig_overrides"] = dict(density["rig_overrides"])
    return {"stage": "joint", "name": "rolling_density_final", "responses": [aor, fill],
            "parameters": [{"keys": list(roll["keys"]), "bounds": list(roll["bounds"]),
                            "tolerance_coefficient": roll["tolerance_coefficient"]},
                           {"keys": ["particles.density_kg_m3"], "bounds": list(dens["bounds"]), "scale": "log",
                            "tolerance_kg_m3": dens["tolerance_kg_m3"]}],
            "max_runs_count": 48}


def twin_study(name, hidden, targets, seeds_count, final_pass=True, target_seeds_count=3):
    """The study config (a dict) of one twin: the shipped M2 stages for the hidden
    parameters, targets set to the twin's (with their standard errors, each estimated
    from target_seeds_count seeds: the inversion draws the target from a Student-t)."""
    n = {"standard_error_seeds_count": int(target_seeds_count)}
    shipped = yaml.safe_load(SHIPPED.read_text())["materials"][MATERIAL]
    by_label = {st.get("name", st["stage"]): st for st in shipped}
    stages = []
    for hid, label in STAGE_OF.items():
        if hid not in hidden:
            continue
        st = json.loads(json.dumps(by_label[label]))
        response = st.get("response", "bulk_density_kg_m3")
        value, se = targets[response]
        unit = responses.get(response).unit
        band = {k: v for k, v in st.get("target", {}).items() if k.startswith("band_")}
        st["target"] = {"value": round(float(value), 6), f"standard_error_{unit}": round(float(se), 6), **n, **band}
        if label in ("stiffness", "wall_friction"):
            st["lab_dir"] = "twin_lab"
            st["target"] = {"value": 0.0, f"standard_error_{unit}": round(float(se), 6), **n, **band}
        stages.append(st)
    if final_pass and {"particle_density_kg_m3", "rolling_resistance_coefficient"} <= set(hidden):
        st = final_pass_stage(by_label["density"], by_label["rolling_resistance"])
        for r in st["responses"]:
            value, se = targets[r["response"]]
            unit = responses.get(r["response"]).unit
            band = {k: v for k, v in r.get("target", {}).items() if k.startswith("band_")}
            r["target"] = {"value": round(float(value), 6), f"standard_error_{unit}": round(float(se), 6), **n,
                           **band}
        stages.append(st)
    return {"name": name, "description": f"synthetic twin (bench/twin.py), hidden {json.dumps(hidden)}",
            "seeds_count": seeds_count, "max_runs_count": 600, "materials": {MATERIAL: stages}}


def score(study, hidden):
    """Per hidden parameter: hidden, estimate, 95 % interval, relative error, inside."""
    out = {}
    for name, truth in hidden.items():
        key = HIDDEN_KEYS[name][0]
        est = study.overrides[MATERIAL].get(key)
        iv = study.intervals[MATERIAL].get(key)
        if est is None or iv is None:
            out[name] = {"hidden": truth, "estimate": None, "low": None, "high": None, "error": None,
                         "inside": False}
            continue
        _, low, high = iv
        out[name] = {"hidden": truth, "estimate": est, "low": low, "high": high, "error": (est - truth) / truth,
                     "inside": bool(low <= truth <= high)}
    return out


def run_twin(name, hidden, executor, out, seeds_count=3, target_seeds_count=3, seed_base=1, final_pass=True,
             log=print):
    """One twin end to end; returns its summary dict."""
    folder = Path(out) / name
    folder.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    log(f"twin {name}: simulating the targets with hidden {hidden}")
    targets = simulate_targets(executor, hidden, list(range(101, 101 + target_seeds_count)), folder / "twin_lab")
    t_targets = time.time() - t0
    cfg = folder / "twin.yaml"
    write_text(cfg, "# written by bench/twin.py\n" + yaml.safe_dump(
        twin_study(name, hidden, targets, seeds_count, final_pass, target_seeds_count), sort_keys=False))
    load_study(cfg)
    study = Study(cfg, executor, folder / "study", log=log, seed_base=seed_base)
    t1 = time.time()
    rows = study.run()
    return {"bench": "twin", "twin": name, "material": MATERIAL, "hidden": hidden,
            "targets": {k: {"value": v, "standard_error": s} for k, (v, s) in targets.items()},
            "parameters": score(study, hidden),
            "stages": [{"stage": r["stage"], "met": r["met"], "stop_reason": r["stop_reason"],
                        "runs_requested": r["runs_requested"]} for r in rows],
            "runs_requested": study.runs_requested, "seeds_count": seeds_count,
            "target_seeds_count": target_seeds_count, "seed_base": seed_base,
            "wall_s_targets": round(t_targets, 1), "wall_s_calibration": round(time.time() - t1, 1)}


def table(summaries):
    """The markdown table of bench/README.md: one row per twin and parameter, and the totals."""
    lines = ["| twin | parameter | hidden | estimate | 95 % interval | error | inside | runs |",
             "|---|---|---|---|---|---|---|---|"]
    pairs = inside = 0
    worst = 0.0
    for s in summaries:
        for k, (name, p) in enumerate(s["parameters"].items()):
            pairs += 1
            inside += p["inside"]
            if p["error"] is None:
                lines.append(f"| {s['twin']} | {name} | {p['hidden']:.4g} | - | - | - | no | "
                             f"{s['runs_requested'] if k == 0 else ''} |")
                worst = float("inf")
                continue
            worst = max(worst, abs(p["error"]))
            lines.append(f"| {s['twin']} | {name} | {p['hidden']:.4g} | {p['estimate']:.4g} | "
                         f"{p['low']:.4g} - {p['high']:.4g} | {100 * p['error']:+.1f} % | "
                         f"{'yes' if p['inside'] else 'no'} | {s['runs_requested'] if k == 0 else ''} |")
    lines.append("")
    lines.append(f"{inside} of {pairs} parameter-twin pairs inside their 95 % interval "
                 f"({100 * inside / pairs:.0f} %; goal >= 90 %); largest |error| {100 * worst:.1f} % (goal <= 10 %); "
                 f"runs per twin {', '.join(str(s['runs_requested']) for s in summaries)}.")
    return "\n".join(lines)


def main(argv=None, executor=None, results=RESULTS, commit=None):
    p = argparse.ArgumentParser(prog="twin", description=__doc__.splitlines()[0])
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--hidden", nargs="+", metavar="NAME=VALUE", help=f"one twin: {', '.join(HIDDEN_KEYS)}")
    g.add_argument("--twins", help="YAML file: a list of {name, hidden: {NAME: VALUE}}")
    p.add_argument("--name", default="twin", help="name of the --hidden twin (default twin)")
    p.add_argument("--out", default=str(ROOT / "runs" / "twins"), help="twins folder (default runs/twins)")
    p.add_argument("--workers", type=int, default=None, help="parallel YADE processes (default: cores)")
    p.add_argument("--seeds-count", type=int, default=3, help="seeds per calibration point (default 3)")
    p.add_argument("--target-seeds-count", type=int, default=3, help="seeds of the hidden targets (default 3)")
    p.add_argument("--seed-base", type=int, default=1, help="first seed of the calibration (default 1)")
    p.add_argument("--no-final-pass", action="store_true", help="skip the final rolling + density joint stage")
    args = p.parse_args(argv)
    try:
        twins = [(args.name, parse_hidden(args.hidden))] if args.hidden else load_twins(args.twins)
        if min(args.seeds_count, args.target_seeds_count) < 2:
            raise TwinError("--seeds-count, --target-seeds-count: must be >= 2 (a standard error needs two)")
    except TwinError as exc:
        print(f"twin: {exc}", file=sys.stderr)
        return 2
    out = Path(args.out)
    if executor is None:
        from pycal.runner import LocalPool
        executor = LocalPool(out / "runs", workers=args.workers, timeout_s=3600)
    if commit is None:
        commit = git_commit(short=True)
    summaries = []
    for name, hidden in twins:
        try:
            s = run_twin(name, hidden, executor, out, args.seeds_count, args.target_seeds_count, args.seed_base,
                         not args.no_final_pass)
        except TwinError as exc:
            print(f"twin: {name}: {exc}", file=sys.stderr)
            return 2
        s.update({"git_commit": commit, "host": platform.node(),
                  "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")})
        summaries.append(s)
        with open(results, "a") as f:
            f.write(json.dumps(s, default=str) + "\n")
    write_json(out / "twins.json", finite(summaries), default=str)
    text = table(summaries)
    write_text(out / "twins.md", text + "\n")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
