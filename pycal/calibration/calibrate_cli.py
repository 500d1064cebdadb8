"""`pycal calibrate`: run a calibration study and write its report (the main job)."""
import os
import time
from pathlib import Path

from .. import CONFIG_DIR

DEFAULT_STUDY = CONFIG_DIR / "calibrations" / "zinc_ore.yaml"

# Parts of the method the engine does not run yet, said at the end of every study.
NOT_YET = ["the CCS and UCS curves as calibration targets (CCS is compared and plotted, UCS predicted in the "
           "validation section)"]


def _study(args):
    """The study of the command line (config checked first: a bad one stops here, nothing
    run, nothing written) with its executor."""
    from ..runner import make_executor, DEFAULT_RUNS_DIR
    from ..replicas import ReplicaExecutor
    from .study import Study
    from .study_config import load_study
    runs = Path(args.runs or DEFAULT_RUNS_DIR)
    cfg = load_study(args.config)
    workers = args.workers
    if workers is None:
        # a point runs seeds_count jobs at once: one worker per seed (3 on 2 cores) keeps
        # both cores busy to the end of a point instead of leaving one idle for the last seed
        workers = max(os.cpu_count() or 1, int(cfg["seeds_count"]))
    executor = ReplicaExecutor(make_executor(args.executor, scheduler=args.scheduler, runs_dir=runs,
                                             workers=workers, timeout_s=args.timeout_s),
                               args.replicas, args.replica_layout)
    # (a Dask executor stops the cluster it started when the process exits)
    return Study(args.config, executor, Path(args.out or runs / "study"), seed_base=args.seed_base,
                 use_library=args.library), runs


def _cmd_calibrate(args):
    from ..report import write_report
    from .stages import calibrates
    from .study import cost_per_material
    study, runs = _study(args)
    t0 = time.time()
    print(f"calibration study {study.cfg['name']} ({args.config}):\n  {len(study.seeds)} seeds per point, "
          f"new at every point of a stage (seeds {study.seeds[0]}, {study.seeds[0] + 1}, ...)\n"
          f"  runs cached in {runs}; interrupt at any time and run again to resume")
    rows = study.run()
    report = write_report(study.out)
    calibrated = [r for r in rows if calibrates(r["kind"])]
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


def _cmd_sensitivity(args):
    from . import sensitivity
    from .calibrated import load_study_overrides
    study, runs = _study(args)
    study.overrides = load_study_overrides(study.out)
    out = sensitivity.run(study, args.prediction, design=args.design, seeds_per_run=args.seeds_per_run,
                          response=args.response)
    print(f"\n{out['prediction']}: change of {out['response']} per calibrated value moved "
          f"x{1 + out['relative_step_fraction']:g} ({out['design']}, {out['runs_requested']} runs requested):")
    for r in out["factors"]:
        eff = "failed" if r.get("effect") is None else f"{r['effect']:+.3g}"
        se = f" +- {r['effect_se']:.2g}" if r.get("effect_se") is not None else ""
        print(f"  {r['rank']:2d}. {r['label']}: {eff}{se}")
    print(f"written: {study.out}/sensitivity-{out['prediction']}-{out['design']}.csv")


def _common_args(s):
    from ..executors import add_executor_args
    s.add_argument("--config", default=str(DEFAULT_STUDY), help="study config (configs/calibrations/*.yaml)")
    s.add_argument("--runs", default=None, help="runs directory: the job cache (default runs/)")
    s.add_argument("--out", default=None, help="study output folder (default <runs>/study)")
    s.add_argument("--seed-base", type=int, default=1,
                   help="first seed of every point: seeds N, N+1, ... (default 1); another base gives an "
                        "independent calibration whose intervals should overlap this one's")
    s.add_argument("--library", action="store_true",
                   help="one-parameter stages start from the matching runs already in the runs folder (the library: "
                        "after a changed lab number, most runs are there); not with another --seed-base on the same "
                        "runs folder (its runs would not be independent)")
    add_executor_args(s, default_workers="cores, at least seeds_count")


def register(sub):
    s = sub.add_parser("calibrate", help="run a calibration study (default: the shipped zinc-ore study) "
                                         "and write the calibrated materials and the report")
    _common_args(s)
    s.set_defaults(func=_cmd_calibrate)
    s = sub.add_parser("sensitivity", help="what drives a prediction of the study's validation section: the "
                                           "calibrated values moved in a screening design (after calibrate)")
    s.add_argument("prediction", help="a prediction's name (validation.predictions of the study config)")
    s.add_argument("--design", default="screening", choices=["screening", "one-at-a-time"],
                   help="screening (default): a Plackett-Burman design, every run moves several values; "
                        "one-at-a-time: each value alone on the validation's sensitivity seeds")
    s.add_argument("--seeds-per-run", type=int, default=1,
                   help="seeds of each screening design run (default 1)")
    s.add_argument("--response", default=None,
                   help="the response to explain (default: the prediction's first comparison)")
    _common_args(s)
    s.set_defaults(func=_cmd_sensitivity)

