"""What a stage kind is (one StageKind per kind, registered by pycal/calibration/stages/)."""
from dataclasses import dataclass
from typing import Callable, Optional


@dataclass(frozen=True)
class StageKind:
    name: str
    normalise: Callable                  # (checker, stage cfg, key, material, material cfg, seeds, done) -> stage dict
    run: Callable                        # (study, material, stage dict) -> stage row
    calibrates: bool = True              # False: copies values found elsewhere (no runs, no pictures, no verdict)
    default_keys: tuple = ()             # the parameter's keys when the config gives none
    default_response: Optional[str] = None   # the response when the config gives none
    log_scale: bool = False              # the parameter's default scale: log (spans ratios) or linear
    response_increases: Optional[bool] = None   # the response's direction when the config gives none
    proportional: bool = False           # the response is proportional to the parameter (slope known at the start)
