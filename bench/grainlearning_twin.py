"""Peer comparison: GrainLearning 2.0.5 calibrating the same synthetic twin as bench/twin.py.

A bench-only dependency (PyPI), never installed by ./run.sh:

    /usr/bin/python3 -m venv --system-site-packages bench/out/glvenv
    bench/out/glvenv/bin/pip install grainlearning==2.0.5
    bench/out/glvenv/bin/python bench/grainlearning_twin.py --twin-dir runs/twins/<twin> \\
        [--samples 15] [--iterations 6] [--seeds-count 1] [--workers 2]

The twin folder is one bench/twin.py wrote (its targets and hidden values, twin.json /
results line): GrainLearning's iterative Bayesian filter gets the same targets (cell-fill
bulk density and angle of repose, each weighed by its relative standard error squared, as
the project's engine weighs by the target's standard error) and calls this project's job
runner for every sample (fill + aor at the sample's particle density and rolling resistance, `--seeds-count` seeds each, lift 10 mm/s as the study), with
the runs cached in <twin-dir>/grainlearning/runs. Hidden parameters it calibrates: particle
density and rolling resistance (the twin must hide those two). Reports per parameter the
estimate (posterior mean of the last iteration), its +-2 sigma range, the error against the
hidden value, and the runs used; appends one JSON line to bench/results.jsonl.
"""
import argparse
import datetime
import json
import statistics
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from pycal.gitinfo import git_commit  # noqa: E402
from pycal.jobs import resolve_job  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results.jsonl"
ROLLING_KEYS = ["interactions.M2.rolling_resistance_coefficient",
                "interactions.steel.rolling_resistance_coefficient",
                "interactions.pvc.rolling_resistance_coefficient"]
PARAMS = ["particle_density_kg_m3", "rolling_resistance_coefficient"]
BOUNDS = {"particle_density_kg_m3": (1500.0, 9000.0), "rolling_resistance_coefficient": (0.02, 1.5)}   # the study's
LIFT = {"rig.procedure.lift_speed_m_s": 0.01}


def load_twin(twin_dir):
    """(hidden values, targets {response: {value, standard_error}}) of a twin that
    bench/twin.py ran (its line in twins.json)."""
    twins = json.loads((Path(twin_dir).parent / "twins.json").read_text())
    name = Path(twin_dir).name
    twin = next(t for t in twins if t["twin"] == name)
    if set(PARAMS) - set(twin["hidden"]):
        raise SystemExit(f"{twin_dir}: the twin must hide {', '.join(PARAMS)}")
    return twin["hidden"], twin["targets"]


def estimates(system, hidden):
    """Per parameter: GrainLearning's estimate (posterior mean), its +-2 sigma range (from the
    coefficient of variation), the error against the hidden value and whether it lies inside."""
    est, cv = system.estimated_params[-1], system.estimated_params_cv[-1]
    rows = {}
    for i, name in enumerate(PARAMS):
        truth = hidden[name]
        lo, hi = est[i] * (1 - 2 * cv[i]), est[i] * (1 + 2 * cv[i])
        rows[name] = {"hidden": truth, "estimate": float(est[i]), "low": float(lo), "high": float(hi),
                      "error": float((est[i] - truth) / truth), "inside": bool(lo <= truth <= hi)}
    return rows


def main(argv=None):
    p = argparse.ArgumentParser(prog="grainlearning_twin", description=__doc__.splitlines()[0])
    p.add_argument("--twin-dir", required=True)
    p.add_argument("--samples", type=int, default=15, help="samples per iteration (GrainLearning's ensemble)")
    p.add_argument("--iterations", type=int, default=6, help="iterations at most")
    p.add_argument("--seeds-count", type=int, default=1, help="seeds per sample and rig (averaged)")
    p.add_argument("--workers", type=int, default=2)
    args = p.parse_args(argv)
    from grainlearning import BayesianCalibration
    from grainlearning.dynamic_systems import DynamicSystem
    from pycal.runner import LocalPool

    hidden, targets = load_twin(args.twin_dir)
    target = {k: v["value"] for k, v in targets.items()}
    rel_var = {k: (v["standard_error"] / v["value"]) ** 2 for k, v in targets.items()}
    out = Path(args.twin_dir) / "grainlearning"
    pool = LocalPool(out / "runs", workers=args.workers, timeout_s=3600)
    runs = {"count": 0}
    seed_next = {"seed": 1001}

    def simulate(calibration):
        """GrainLearning's callback (it passes the BayesianCalibration): fill + aor for every
        sample (seed means, kg/m3 and deg)."""
        system = calibration.system
        jobs, rows = [], []
        for density, rolling in system.param_data:
            o = {"particles.density_kg_m3": float(density), **{k: float(rolling) for k in ROLLING_KEYS}}
            seeds = list(range(seed_next["seed"], seed_next["seed"] + args.seeds_count))
            seed_next["seed"] += args.seeds_count
            jobs += [resolve_job("fill", "M2", o, seed=s) for s in seeds]
            jobs += [resolve_job("aor", "M2", {**o, **LIFT}, seed=s) for s in seeds]
            rows.append(len(seeds))
        results = pool.run(jobs, raise_on_error=False)
        runs["count"] += len(jobs)
        data, k = [], 0
        for n in rows:
            fill, aor = results[k:k + n], results[k + n:k + 2 * n]
            k += 2 * n
            bulk = [r["bulk_density_kg_m3"] for r in fill if r is not None]
            angle = [r["aor_mean_deg"] for r in aor if r is not None and r["aor_mean_deg"] is not None]
            # a sample the rig refused or that left no pile is far off (not a silent stand-in: 10 x off)
            data.append([[statistics.mean(bulk) if bulk else 10.0 * target["bulk_density_kg_m3"]],
                         [statistics.mean(angle) if angle else 10.0 * target["aor_mean_deg"]]])
        system.set_sim_data(np.array(data))

    calib = BayesianCalibration.from_dict({
        "num_iter": args.iterations,
        "callback": simulate,
        "system": {"system_type": DynamicSystem, "param_names": PARAMS,
                   "param_min": [BOUNDS[n][0] for n in PARAMS], "param_max": [BOUNDS[n][1] for n in PARAMS],
                   "num_samples": args.samples, "ctrl_data": [0.0],
                   "obs_data": [[target["bulk_density_kg_m3"]], [target["aor_mean_deg"]]],
                   # GrainLearning's covariance is relative (x obs^2): weigh each response by its
                   # relative target noise squared, as the project's engine weighs by the target SE
                   "inv_obs_weight": [rel_var["bulk_density_kg_m3"], rel_var["aor_mean_deg"]],
                   "sim_name": "twin"},
        "inference": {"Bayes_filter": {"ess_target": 0.3}, "sampling": {"max_num_components": 2}},
        "save_fig": -1,
    })
    calib.system.backup_sim_data()
    history = []                       # after each iteration: runs so far, estimate per parameter
    for _ in range(args.iterations):   # BayesianCalibration.run(), with the history kept
        stop = calib.run_one_iteration()
        history.append({"iteration": len(history) + 1, "runs_requested": runs["count"],
                        "parameters": estimates(calib.system, hidden)})
        print(f"after iteration {len(history)} ({runs['count']} runs): " + ", ".join(
            f"{n} {r['estimate']:.4g} ({100 * r['error']:+.1f} %)" for n, r in history[-1]["parameters"].items()),
            flush=True)
        if stop:
            break
    rows = history[-1]["parameters"]
    line = {"bench": "grainlearning_twin", "twin": Path(args.twin_dir).name, "hidden": hidden,
            "parameters": rows, "runs_requested": runs["count"], "iterations": len(history), "history": history,
            "samples_per_iteration": args.samples, "seeds_count": args.seeds_count,
            "grainlearning_version": "2.0.5", "git_commit": git_commit(short=True),
            "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}
    with open(RESULTS, "a") as f:
        f.write(json.dumps(line) + "\n")
    for name, r in rows.items():
        print(f"{name}: hidden {r['hidden']:.4g}, GrainLearning {r['estimate']:.4g} "
              f"[{r['low']:.4g}, {r['high']:.4g}], error {100 * r['error']:+.1f} %")
    print(f"runs: {runs['count']} in {len(history)} iterations")
    return 0


if __name__ == "__main__":
    sys.exit(main())
