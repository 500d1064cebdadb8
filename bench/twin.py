"""Full synthetic twin (a benchmark of the calibration engine on a case with a known answer).

    /usr/bin/python3 bench/twin.py [--workers N] [--out DIR] [--seeds-count N] [--without-wall-friction]

1. Hide a set of M2 parameters (HIDDEN below).
2. Simulate the lab targets with them, on seeds 101, 102, ... (not the study's seeds):
   cell-fill bulk density, angle of repose (lift 10 mm/s as the study), the CCS-expansion
   unloading stiffness curve and the wall friction curve (12, 40, 86 kPa). The curves go
   to <out>/twin_lab/curves/ in the labresults/ format (provenance: synthetic; bands
   +-30 % for the stiffness, +-0.03 for friction).
3. Calibrate M2 from its start values with the study engine (density, rolling
   resistance, density again, stiffness, wall friction), the curves read from twin_lab.
4. Compare: recovered vs hidden per parameter, runs, wall time. Writes <out>/twin.json
   and appends a line to bench/results.jsonl.

The short version (density only, real YADE) is tests/yade/test_synthetic_twin.py.
Runs in its own runs folder (<out>/runs): nothing comes from the main job's cache, so
the wall time is that of a calibration from scratch; a rerun resumes from that cache.
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
from pycal.jobs import resolve_job  # noqa: E402
from pycal.post import mean_std  # noqa: E402
from pycal.runner import LocalPool  # noqa: E402
from run_bench import _git_commit  # noqa: E402  (bench/ is this script's folder)

RESULTS = Path(__file__).resolve().parent / "results.jsonl"
MATERIAL = "M2"
ROLLING_KEYS = ["interactions.M2.rolling_resistance_coefficient",
                "interactions.steel.rolling_resistance_coefficient",
                "interactions.pvc.rolling_resistance_coefficient"]
HIDDEN = {"particles.density_kg_m3": 3600.0, "rolling_resistance": 0.15,
          "contact.youngs_modulus_pa": 2.0e7, "interactions.steel.friction_coefficient": 0.35}
LIFT = {"rig.procedure.lift_speed_m_s": 0.01}
WALL_STEPS = {"rig.procedure.consolidation_stresses_pa": [12000, 40000, 86000]}


def hidden_overrides(wall_friction=True):
    """The hidden values as material overrides. Without the wall friction stage the
    particle-steel friction is not hidden (it stays at the config's value on both sides):
    a hidden value the study never moves would bias the fill, AoR and CCS targets."""
    o = {k: v for k, v in HIDDEN.items() if k != "rolling_resistance"
         and (wall_friction or k != "interactions.steel.friction_coefficient")}
    o.update({k: HIDDEN["rolling_resistance"] for k in ROLLING_KEYS})
    return o


def simulate_targets(pool, seeds, lab, wall_friction=True):
    """Run the rigs with the hidden values; write the synthetic curves; return the scalar targets."""
    o = hidden_overrides(wall_friction)

    def run(rig, extra=None):
        return pool.run([resolve_job(rig, MATERIAL, {**o, **(extra or {})}, seed=s) for s in seeds])
    fill = run("fill")
    aor = run("aor", LIFT)
    exp = run("ccs_expansion")
    wall = run("wall_friction", WALL_STEPS) if wall_friction else []
    (lab / "curves").mkdir(parents=True, exist_ok=True)
    # unloading stiffness per unloading step, mean over seeds, band +-30 %
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
    (lab / "curves" / "ccs_expansion_gravel_dry.csv").write_text("\n".join(lines) + "\n")
    lines = ["# synthetic twin (bench/twin.py): wall friction with hidden " + json.dumps(o),
             "stress_pa,mu_static,mu_static_low,mu_static_high,mu_dynamic,mu_dynamic_low,mu_dynamic_high,provenance"]
    for k, s in enumerate(wall[0]["stress_pa"] if wall else []):
        ms = mean_std([r["mu_static"][k] for r in wall if r["mu_static"][k] is not None])[0]
        md = mean_std([r["mu_dynamic"][k] for r in wall if r["mu_dynamic"][k] is not None])[0]
        lines.append(f"{s:.0f},{ms:.4f},{ms - 0.03:.4f},{ms + 0.03:.4f},{md:.4f},{md - 0.03:.4f},{md + 0.03:.4f},synthetic")
    if wall:
        (lab / "curves" / "wall_friction_gravel_dry.csv").write_text("\n".join(lines) + "\n")
    # the lab's samples (particle density of the sample, ...), each listing only the curves the twin wrote
    samples = yaml.safe_load((LAB_DIR / "samples.yaml").read_text())
    for sample in samples["samples"].values():
        sample["curves"] = [c for c in sample.get("curves", []) if (lab / "curves" / f"{c}.csv").is_file()]
    (lab / "samples.yaml").write_text("# synthetic twin (bench/twin.py): labresults/samples.yaml, twin curves only\n"
                                      + yaml.safe_dump(samples, sort_keys=False))
    return {"bulk_density_kg_m3": mean_std([r["bulk_density_kg_m3"] for r in fill]),
            "aor_mean_deg": mean_std([r["aor_mean_deg"] for r in aor])}


STUDY = """# written by bench/twin.py: M2 from its start values against the twin's targets
name: twin
seeds_count: {seeds}
max_seeds_count: 9
max_runs_count: 600
materials:
  M2:
    - {{stage: density, rig: fill, tolerance_percent: 1.0, max_iterations_count: 5, target: {{value: {rho}}}}}
    - stage: rolling_resistance
      rig: aor
      response: aor_mean_deg
      target: {{value: {aor}}}
      tolerance_deg: 2.0
      rig_overrides: {{rig.procedure.lift_speed_m_s: 0.01}}
      parameter: {{keys: {rolling_keys}, start: 0.35, bounds: [0.02, 1.5], response_increases: true}}
      max_iterations_count: 6
    - {{stage: density, name: density_recheck, rig: fill, tolerance_percent: 1.0, max_iterations_count: 5, target: {{value: {rho}}}}}
    - stage: stiffness
      rig: ccs_expansion
      lab_dir: twin_lab
      response: unloading_stiffness_log_ratio
      target: {{value: 0.0}}
      tolerance_log_ratio: 0.15
      parameter: {{keys: [contact.youngs_modulus_pa], start: 6.0e6, bounds: [1.0e6, 1.0e9], response_increases: true}}
      max_iterations_count: 6
"""
WALL_STAGE = """    - stage: friction
      name: wall_friction
      rig: wall_friction
      lab_dir: twin_lab
      response: friction_offset_mu_static
      target: {value: 0.0}
      tolerance_mu: 0.02
      rig_overrides: {rig.procedure.consolidation_stresses_pa: [12000, 40000, 86000]}
      parameter: {keys: [interactions.steel.friction_coefficient], start: 0.5, bounds: [0.05, 1.2], response_increases: true,
                  response_slope_estimate: 1.0}
      max_iterations_count: 4
"""


def main(argv=None):
    p = argparse.ArgumentParser(prog="twin", description=__doc__.splitlines()[0])
    p.add_argument("--workers", type=int, default=None, help="parallel YADE processes (default: cores)")
    p.add_argument("--out", default=str(ROOT / "runs" / "twin"), help="twin folder (default runs/twin)")
    p.add_argument("--seeds-count", type=int, default=3, help="seeds per point (default 3)")
    p.add_argument("--without-wall-friction", action="store_true",
                   help="hide and recover density, rolling resistance and stiffness only (the wall friction "
                        "stage is most of the cost: at E ~2e7 Pa a 3-step curve takes minutes per seed)")
    args = p.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    pool = LocalPool(out / "runs", workers=args.workers, timeout_s=3600)
    t0 = time.time()
    wall = not args.without_wall_friction
    print(f"twin: simulating the targets with the hidden values {hidden_overrides(wall)}", flush=True)
    targets = simulate_targets(pool, list(range(101, 101 + args.seeds_count)), out / "twin_lab", wall)
    t_targets = time.time() - t0
    print(f"twin: targets {targets} ({t_targets:.0f} s)", flush=True)
    cfg = out / "twin.yaml"
    cfg.write_text(STUDY.format(seeds=args.seeds_count, rho=targets["bulk_density_kg_m3"][0],
                                aor=targets["aor_mean_deg"][0], rolling_keys=json.dumps(ROLLING_KEYS))
                   + (WALL_STAGE if wall else ""))
    study = Study(cfg, pool, out / "study")
    t1 = time.time()
    rows = study.run()
    t_cal = time.time() - t1
    found = study.overrides[MATERIAL]
    hidden = {k: v for k, v in HIDDEN.items() if wall or k != "interactions.steel.friction_coefficient"}
    recovered = {k: found.get(ROLLING_KEYS[0] if k == "rolling_resistance" else k) for k in hidden}
    errors = {k: (None if recovered[k] is None else (recovered[k] - v) / v) for k, v in hidden.items()}
    summary = {"bench": "twin", "material": MATERIAL, "hidden": hidden, "wall_friction": wall, "recovered": recovered,
               "relative_error": errors, "targets": targets,
               "stages": [{k: r.get(k) for k in ("stage", "value", "response_mean", "response_std", "target",
                                                  "tolerance", "met", "evaluations")} for r in rows],
               "runs_requested": study.runs_requested, "seeds_count": args.seeds_count,
               "wall_s_targets": round(t_targets, 1), "wall_s_calibration": round(t_cal, 1),
               "workers": pool.workers if hasattr(pool, "workers") else args.workers, "host": platform.node(),
               "git_commit": _git_commit(),
               "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}
    (out / "twin.json").write_text(json.dumps(summary, indent=1, default=str))
    with open(RESULTS, "a") as f:
        f.write(json.dumps(summary, default=str) + "\n")
    print("twin: parameter          hidden      recovered   error")
    for k, v in hidden.items():
        r = recovered[k]
        print(f"  {k:40s} {v:<11.4g} {'-' if r is None else f'{r:<11.4g}'} "
              f"{'-' if errors[k] is None else f'{100 * errors[k]:+.1f} %'}")
    print(f"twin: {sum(r['met'] for r in rows)}/{len(rows)} stages met, {study.runs_requested} runs requested, "
          f"targets {t_targets:.0f} s + calibration {t_cal:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
