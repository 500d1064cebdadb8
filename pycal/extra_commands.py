"""Commands added by later stages of the pipeline (calibration, reports, rig studies).

Each stage adds a `register_<stage>(sub)` call here, so cli.py stays small.
"""


def register(sub):
    """Add the stage commands to the argparse sub-parsers."""
    try:
        from .calibration.cli import register as register_calibration
    except ImportError:
        return
    register_calibration(sub)
