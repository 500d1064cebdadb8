"""Commands of the later pipeline stages (calibration, study, the runs table, the library), kept out of cli.py."""


def register(sub):
    """Add the stage commands to the argparse sub-parsers."""
    from .calibration.cli import register as register_fit_density
    from .calibration.calibrate_cli import register as register_calibrate
    register_fit_density(sub)
    register_calibrate(sub)
    register_runs(sub)
    from .library import register as register_library
    register_library(sub)


def register_runs(sub):
    """`pycal runs`: the runs folder as a table (pycal/runs_index.py)."""
    from .executors import DEFAULT_RUNS_DIR
    from .runs_index import cli
    s = sub.add_parser("runs", help="the runs folder as a table: one row per seed run (status, CPU, parameters, "
                                    "responses, the study stage that asked for it); --csv writes every column")
    s.add_argument("runs", nargs="?", default=str(DEFAULT_RUNS_DIR), help="runs folder (default runs/)")
    s.add_argument("--study", default=None, metavar="STUDY_DIR",
                   help="a study's output folder (runs/study/<name>): add the stage that asked for each run")
    s.add_argument("--rig", default=None, help="only this rig")
    s.add_argument("--material", default=None, help="only this material (or material set)")
    s.add_argument("--status", default=None, choices=["ok", "refused", "failed", "pending", "missing"],
                   help="only this status")
    s.add_argument("--csv", default=None, metavar="FILE", help="write the whole table (every column) to FILE")
    s.set_defaults(func=cli)

