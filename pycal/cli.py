"""Command line: `python3 -m pycal COMMAND ...` (wrapped by `./run.sh pycal ...`).

Every user error prints one line `error: <file>: <field>: <reason>` and exits 2;
a failed simulation exits 3.
"""
import json
import sys

from .errors import ConfigError, PycalError, RunError


def _cmd_validate(args):
    from .configs import load_material, load_rig, material_names, rig_names, load_boundaries
    from . import labdata
    load_boundaries()
    for m in material_names():
        load_material(m)
    for r in rig_names():
        load_rig(r)
    from .configs import load_material_set, material_set_names
    for m in material_set_names():
        load_material_set(m)
    labdata.load_all()
    from . import CONFIG_DIR
    from .calibration.study_config import load_study
    studies = sorted((CONFIG_DIR / "calibrations").glob("*.yaml"))
    for path in studies:
        load_study(path)
    print(f"ok: {len(material_names())} materials, {len(material_set_names())} material sets, "
          f"{len(rig_names())} rigs, {len(studies)} calibration studies, lab data valid")


def _make_jobs(args):
    from .jobs import parse_set, resolve_job
    overrides = {}
    if args.calibrated:                       # a study's calibrated values first; --set on top
        from .calibration.calibrated import load_study_overrides, overrides_for_material
        overrides = overrides_for_material(load_study_overrides(args.calibrated), args.material)
    overrides.update(parse_set(args.set))
    seeds = list(range(args.seed, args.seed + args.seeds))
    jobs = [resolve_job(args.rig, args.material, overrides, seed=s) for s in seeds]
    if args.vtk is not None:                  # --vtk: snapshots for ParaView (pycal/vtk_output.py)
        from .vtk_output import with_vtk
        jobs = [with_vtk(j, args.vtk) for j in jobs]
    return jobs


def _cmd_run(args):
    from .runner import make_executor
    from .replicas import ReplicaExecutor, result_folder
    jobs = _make_jobs(args)
    inner = make_executor(args.executor, scheduler=args.scheduler, runs_dir=args.out, workers=args.workers,
                          timeout_s=args.timeout_s)
    with ReplicaExecutor(inner, args.replicas, args.replica_layout) as ex:
        results = ex.run(jobs)
    from . import post
    n_jobs = len({j["job_id"] for j in jobs})
    print(f"{n_jobs} job(s): {n_jobs - ex.simulated_count} cached, {ex.simulated_count} simulated")
    for job, res in zip(jobs, results):
        print(f"{res.get('job_id', job['job_id'])}: {result_folder(res, job, args.out)}")
        print("  " + post.summary_line(res))
    if len(results) > 1:
        print(post.seed_statistics_text(results))


def _cmd_batch_table(args):
    import os
    from .executors.yade_batch import prepare_batch_table, shell_line
    jobs = _make_jobs(args)
    workers = args.workers or os.cpu_count() or 1
    rows, complete, refused, cmd = prepare_batch_table(jobs, args.out, args.table, workers)
    for msg in refused:
        print(f"left out (the rig refused it before): {msg}")
    if not rows:
        print(f"nothing to run: {len(complete)} job(s) complete, {len(refused)} refused; no table written")
        return
    print(f"wrote {args.table}: {len(rows)} job(s) (job folders under {args.out}/{jobs[0]['rig']}/"
          + (f"; {len(complete)} complete job(s) left out" if complete else "") + ")")
    print("run it from any folder with:\n  " + shell_line(cmd))
    print("each line's log goes to its job folder (yade.log); then `pycal run` (or ./run.sh calibrate) "
          "with the same jobs reads the results from there")


def _cmd_job(args):
    jobs = _make_jobs(args)
    if not args.write:
        print(json.dumps(jobs[0], indent=1, sort_keys=True))
        return
    import shlex
    from . import SCRIPT_DIR
    from .executors.jobdirs import cached_result, create_job_folder
    from .executors.yade_process import yade_command
    from .executors.yade_batch import shell_line
    for job in jobs:
        folder = create_job_folder(job, args.out)
        if cached_result(job, args.out) is not None:
            print(f"{job['job_id']}: complete ({folder}/result.json)")
            continue
        cmd = yade_command(SCRIPT_DIR / job["script"], folder / "job.json")
        print(f"{job['job_id']}: {folder}/job.json; run it with\n  "
              f"{shell_line(cmd)} 2>&1 | tee {shlex.quote(str(folder / 'yade.log'))}")


def _cmd_export(args):
    from .export.formats import export
    for path in export(args.calibrated, args.material, args.format, args.out):
        print(f"wrote {path}")


def _cmd_analyse(args):
    from .lab_analysis import cli_analyse
    cli_analyse(args)


def _cmd_impact(args):
    from .lab_analysis import cli_impact
    cli_impact(args)


def _cmd_results(args):
    from .results_page import main as results_main
    results_main(args.study, args.wall_time_s, args.update_readme)


def build_parser():
    from .executors import DEFAULT_RUNS_DIR, add_executor_args
    from .arguments import OneLineParser
    p = OneLineParser(prog="pycal", description="DEM calibration toolkit (YADE)")
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("validate", help="validate every config and lab-data file")
    s.set_defaults(func=_cmd_validate)

    def job_args(s):
        s.add_argument("rig", help="rig name (configs/rigs/<rig>.yaml)")
        s.add_argument("--material", required=True, help="material name (configs/materials/<name>.yaml) or "
                                                         "material set (configs/material_sets/<name>.yaml)")
        s.add_argument("--set", action="append", metavar="KEY=VALUE",
                       help="override a material key (e.g. particles.density_kg_m3=3100) or a rig key "
                            "(rig.procedure.lift_speed_m_s=0.01); repeatable")
        s.add_argument("--calibrated", metavar="STUDY_DIR",
                       help="take the calibrated values of a study (its output folder, e.g. runs/study/zinc_ore): "
                            "for a material set, each component's; --set still overrides them")
        s.add_argument("--seed", type=int, default=1, help="random seed of the fill (default 1)")
        s.add_argument("--seeds", type=int, default=1, help="run this many seeds: seed, seed+1, ...")
        s.add_argument("--out", default=str(DEFAULT_RUNS_DIR), help="runs directory (default runs/)")
        from .vtk_output import DEFAULT_INTERVAL_S
        s.add_argument("--vtk", nargs="?", type=float, const=DEFAULT_INTERVAL_S, default=None, metavar="INTERVAL_S",
                       help="also write VTK snapshots for ParaView into the job folder's vtk/, every INTERVAL_S "
                            f"of simulated time (default {DEFAULT_INTERVAL_S:g} s); part of the job")

    s = sub.add_parser("run", help="run one rig job (or several seeds) in YADE")
    job_args(s)
    add_executor_args(s)
    s.set_defaults(func=_cmd_run)

    s = sub.add_parser("job", help="print the resolved job file (no run); --write creates its job folder")
    job_args(s)
    s.add_argument("--write", action="store_true",
                   help="create runs/<rig>/<job_id>/job.json (each seed) and print the command that runs it "
                        "by hand; the rig writes result.json there, so pycal run finds it complete")
    s.set_defaults(func=_cmd_job)

    s = sub.add_parser("batch-table", help="write the job folders and a yade-batch table of the jobs, and "
                                           "print the yade-batch command that runs it")
    job_args(s)
    s.add_argument("--table", required=True, help="table file to write")
    s.add_argument("--workers", type=int, default=None,
                   help="parallel YADE processes in the printed command (default: cores)")
    s.set_defaults(func=_cmd_batch_table)

    s = sub.add_parser("export", help="write a calibrated material for another DEM code (conventions converted)")
    s.add_argument("--calibrated", required=True, metavar="STUDY_DIR", help="a study's output folder")
    s.add_argument("--material", required=True, help="a calibrated material of that study, or a material set "
                                                     "(configs/material_sets/) with its components' calibrated values")
    s.add_argument("--format", required=True, choices=["yaml", "liggghts", "rocky", "edem"])
    s.add_argument("--out", required=True, help="folder to write into")
    s.set_defaults(func=_cmd_export)

    s = sub.add_parser("analyse", help="lab analysis: moisture, densities, belt load, rolling "
                                       "resistance estimate, impact stress vs drop height")
    s.add_argument("--out", default="runs/lab_analysis", help="output folder for CSV and PNG")
    s.set_defaults(func=_cmd_analyse)

    s = sub.add_parser("impact", help="impact stress of a chute's stream at the receiving point")
    s.add_argument("--drop-height-m", type=float, required=True)
    s.add_argument("--belt-speed-m-s", type=float, required=True)
    s.add_argument("--flow-t-h", type=float, required=True)
    s.add_argument("--bulk-density-kg-m3", type=float, required=True)
    s.set_defaults(func=_cmd_impact)

    s = sub.add_parser("results", help="docs/results/<study>.json from a finished study run (the README's results "
                                       "tables); --update-readme rewrites the README's generated block")
    s.add_argument("study", help="the study's output folder, e.g. runs/study/zinc_ore")
    s.add_argument("--wall-time-s", type=float, default=None,
                   help="wall time of the whole run, measured around the command (default: the study's own)")
    s.add_argument("--update-readme", action="store_true", help="replace the README's generated results block")
    s.set_defaults(func=_cmd_results)

    from . import extra_commands
    extra_commands.register(sub)
    return p


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        from . import arguments
        arguments.check(args)
        args.func(args)
    except ConfigError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except RunError as exc:
        print(f"run failed: {exc}", file=sys.stderr)
        return 3
    except PycalError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted: complete jobs are kept; run the same command again to resume",
              file=sys.stderr)
        return 130
    return 0
