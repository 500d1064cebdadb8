"""Commands of the later pipeline stages (calibration, study), kept out of cli.py."""


def register(sub):
    """Add the stage commands to the argparse sub-parsers."""
    from .calibration.cli import register as register_fit_density
    from .calibration.calibrate_cli import register as register_calibrate
    register_fit_density(sub)
    register_calibrate(sub)
