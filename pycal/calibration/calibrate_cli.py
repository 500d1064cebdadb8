"""`pycal calibrate`: run a calibration study and write its report (the main job)."""
import os
import time
from pathlib import Path

from .. import CONFIG_DIR

DEFAULT_STUDY = CONFIG_DIR / "calibrations" / "zinc_ore.yaml"

# Parts of the method the engine does not run yet, said at the end of every study.
NOT_YET = ["the CCS and UCS curves as calibration targets (CCS is compared and plotted, UCS predicted in the "
           "validation section)"]


def _cmd_calibrate(args):
    from ..runner import make_executor, DEFAULT_RUNS_DIR
    from ..report import write_report
    from .study import Study, cost_per_material
    from .study_config import load_study
    runs = Path(args.runs or DEFAULT_RUNS_DIR)
    cfg = load_study(args.config)          # a bad config stops here: nothing run, nothing written
    workers = args.workers
    if workers is None:
        # a point runs seeds_count jobs at once: one worker per seed (3 on 2 cores) keeps
        # both cores busy to the end of a point instead of leaving one idle for the last seed
        workers = max(os.cpu_count() or 1, int(cfg["seeds_count"]))
    from ..replicas import ReplicaExecutor
    executor = ReplicaExecutor(make_executor(args.executor, scheduler=args.scheduler, runs_dir=runs,
                                             workers=workers, timeout_s=args.timeout_s),
                               args.replicas, args.replica_layout)
    # (a Dask executor stops the cluster it started when the process exits)
    study = Study(args.config, executor, Path(args.out or runs / "study"), seed_base=args.seed_base)
    t0 = time.time()
    print(f"calibration study {study.cfg['name']} ({args.config}): {len(study.seeds)} seeds per point, "
          f"new at every point of a stage (seeds {study.seeds[0]}, {study.seeds[0] + 1}, ...), runs cached in {runs}; interrupt at any time "
          f"and run again to resume")
    rows = study.run()
    report = write_report(study.out)
    calibrated = [r for r in rows if r["kind"] != "inherit"]
    print(f"\n{sum(r['met'] for r in calibrated)} of {len(calibrated)} calibrated stages met their tolerance "
          f"({time.time() - t0:.0f} s, {study.runs_requested} runs requested, cached ones not re-simulated):")
    for r in rows:
        flag = "met    " if r["met"] else "NOT met"
        for p in r["parameters"] or [None]:
            shown = (f"{p['label']} = {p['estimate']:.4g} [{p['low']:.4g}, {p['high']:.4g}] (tolerance "
                     f"+-{p['tolerance']:.3g})" if p else r["message"])
            print(f"  {flag} {r['material']:7s} {r['stage']:24s} {shown}: {r['stop_reason']}")
    for m, c in cost_per_material(rows).items():
        print(f"  {m}: {c['runs_requested']} runs requested, {c['runs_simulated']} simulated, "
              f"{c['elapsed_s']:.0f} s")
    print("not run by this engine yet: " + "; ".join(NOT_YET))
    print(f"calibrated materials: {study.out / 'calibrated'}\nreport: {report}")


def register(sub):
    from ..executors import add_executor_args
    s = sub.add_parser("calibrate", help="run a calibration study (default: the shipped zinc-ore study) "
                                         "and write the calibrated materials and the report")
    s.add_argument("--config", default=str(DEFAULT_STUDY), help="study config (configs/calibrations/*.yaml)")
    s.add_argument("--runs", default=None, help="runs directory: the job cache (default runs/)")
    s.add_argument("--out", default=None, help="study output folder (default <runs>/study)")
    s.add_argument("--seed-base", type=int, default=1,
                   help="first seed of every point: seeds N, N+1, ... (default 1); another base gives an "
                        "independent calibration whose intervals should overlap this one's")
    add_executor_args(s, default_workers="cores, at least seeds_count")
    s.set_defaults(func=_cmd_calibrate)
