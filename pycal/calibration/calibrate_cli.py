"""`pycal calibrate`: run a calibration study and write its report (the main job)."""
import os
import time
from pathlib import Path

from .. import CONFIG_DIR

DEFAULT_STUDY = CONFIG_DIR / "calibrations" / "zinc_ore.yaml"

# Stages of method.md that the engine does not run yet, said at the end of every study.
NOT_YET = ["wet fines-fines cohesion against the wet internal-friction curve (the wet wall curve is fitted)",
           "a second pass over rolling resistance and density after the friction stages moved the friction",
           "UCS and CCS curves as calibration targets (they are compared and plotted, not fitted)",
           "mixed -50 mm sample with non-round M1 lumps"]


def _cmd_calibrate(args):
    from ..runner import make_executor, DEFAULT_RUNS_DIR
    from ..report import write_report
    from .study import Study, row_values, load_study, cost_per_material
    runs = Path(args.runs or DEFAULT_RUNS_DIR)
    workers = args.workers
    if workers is None:
        # a point runs seeds_count jobs at once: one worker per seed (3 on 2 cores) keeps
        # both cores busy to the end of a point instead of leaving one idle for the last seed
        workers = max(os.cpu_count() or 1, int(load_study(args.config)["seeds_count"]))
    executor = make_executor(args.executor, scheduler=args.scheduler, runs_dir=runs, workers=workers,
                             timeout_s=args.timeout_s)
    # (a Dask executor stops the cluster it started when the process exits)
    study = Study(args.config, executor, Path(args.out or runs / "study"))
    t0 = time.time()
    print(f"calibration study {study.cfg['name']} ({args.config}): {len(study.seeds)} seeds per point, "
          f"runs cached in {runs}; interrupt at any time and run again to resume")
    rows = study.run()
    report = write_report(study.out)
    met = [r for r in rows if r["met"]]
    print(f"\n{len(met)} of {len(rows)} stage targets met ({time.time() - t0:.0f} s, "
          f"{study.runs_requested} runs requested, cached ones not re-simulated):")
    for r in rows:
        flag = "met    " if r["met"] else "NOT met"
        resp = (f"{r['response']} {r['response_mean']:.4g} +/- {r['response_std']:.2g} vs lab "
                f"{r['target']:.4g} (tolerance {r['tolerance']:.3g})") if r["response"] else r["message"]
        values = ", ".join(f"{k.split('+')[0]} = {v:.4g}" for k, v in row_values(r).items())
        print(f"  {flag} {r['material']:7s} {r['stage']:18s} {values}: {resp}")
    for m, c in cost_per_material(rows).items():
        print(f"  {m}: {c['runs_requested']} runs requested, {c['runs_simulated']} simulated, "
              f"{c['elapsed_s']:.0f} s")
    print("stages of the method not run by this engine yet: " + "; ".join(NOT_YET))
    print(f"calibrated materials: {study.out / 'calibrated'}\nreport: {report}")


def register(sub):
    from ..executors import add_executor_args
    s = sub.add_parser("calibrate", help="run a calibration study (default: the shipped zinc-ore study) "
                                         "and write the calibrated materials and the report")
    s.add_argument("--config", default=str(DEFAULT_STUDY), help="study config (configs/calibrations/*.yaml)")
    s.add_argument("--runs", default=None, help="runs directory: the job cache (default runs/)")
    s.add_argument("--out", default=None, help="study output folder (default <runs>/study)")
    add_executor_args(s, default_workers="cores, at least seeds_count")
    s.set_defaults(func=_cmd_calibrate)
