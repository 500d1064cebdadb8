"""The calibration responses: what a stage reads from one result.json, beside the
post-processing it uses.

Each response has a name (what a study config's `response:` says), a unit (the suffix
of its target keys: band_<unit>, standard_error_<unit>), whether it is one number or
a vector (one value per lab step), how to compute it from one result (and the lab
folder), and which lab-curve plots show a stage's chosen point (by response, not by
rig name). A name that is not listed here is read as a scalar key of result.json
(e.g. aor_mean_deg); its unit is its name's unit suffix.
"""
import math
from dataclasses import dataclass
from typing import Callable, Optional

from ..configs import DIMENSIONLESS_SUFFIXES, UNIT_SUFFIXES

UNIT_LABELS = {"deg": "deg", "kg_m3": "kg/m3", "pa": "Pa", "log_ratio": "ln(sim/lab)", "mu": "-", "z": "z",
               "ratio": "-", "fraction": "-", "coefficient": "-", "percent": "%", "m": "m", "s": "s"}


@dataclass(frozen=True)
class Response:
    name: str
    unit: str                      # suffix of the target keys: band_<unit>, standard_error_<unit>
    vector: bool
    value: Callable                # (result, lab_dir) -> float, or list (vector: None where not reached)
    lab_plots: Optional[Callable] = None   # (results of one point, out_dir, lab_dir) -> list of files
    description: str = ""

    @property
    def unit_label(self):
        return UNIT_LABELS.get(self.unit, self.unit)


def _scalar(key):
    """A scalar result key as float; NaN where the result has no value (`null`, e.g. a
    pile too flat for any sector to have an angle)."""
    def f(result, lab_dir):
        v = result[key]
        return math.nan if v is None else float(v)
    return f


def _friction_targets(result, lab_dir):
    from . import friction
    return friction.load_targets(result["rig"], friction.lab_sample_of(result), lab_dir)


def _friction_plots(results, out_dir, lab_dir):
    from . import friction
    return friction.write_outputs(results, str(out_dir), lab_dir=lab_dir)["files"]


def _compression_plots(results, out_dir, lab_dir):
    from . import compression
    out_dir.mkdir(parents=True, exist_ok=True)
    return compression.write_outputs(results[0], str(out_dir), lab_dir=lab_dir)["files"]   # first seed


def _offset(quantity):
    def f(result, lab_dir):
        from .friction import friction_offset
        return friction_offset(result, quantity, targets=_friction_targets(result, lab_dir))
    return f


def _band_z(quantity):
    def f(result, lab_dir):
        from .friction import friction_band_z
        return friction_band_z(result, quantity, targets=_friction_targets(result, lab_dir))
    return f


def _angle_offset(result, lab_dir):
    from .friction import friction_angle_offset_deg
    return friction_angle_offset_deg(result, "mu_static", targets=_friction_targets(result, lab_dir))


def _log_ratio(result, lab_dir):
    from .compression import unloading_stiffness_log_ratio
    return unloading_stiffness_log_ratio(result, lab_dir=lab_dir)


RESPONSES = {r.name: r for r in [
    Response("bulk_density_kg_m3", "kg_m3", False, _scalar("bulk_density_kg_m3"),
             description="bulk density of the struck cell fill"),
    Response("aor_mean_deg", "deg", False, _scalar("aor_mean_deg"),
             description="angle of repose, mean over the pile's sectors"),
    Response("pile_footprint_fraction", "fraction", False, _scalar("pile_footprint_fraction"),
             description="share of the pile's volume inside the lifted cylinder's footprint"),
    Response("unloading_stiffness_log_ratio", "log_ratio", False, _log_ratio, _compression_plots,
             "ln(simulated / lab unloading stiffness), mean over the lab steps >= 10 kPa"),
    Response("friction_offset_mu_static", "mu", False, _offset("mu_static"), _friction_plots,
             "mean (simulated - lab) static friction over the steps >= 10 kPa"),
    Response("friction_offset_mu_dynamic", "mu", False, _offset("mu_dynamic"), _friction_plots,
             "mean (simulated - lab) dynamic friction over the steps >= 10 kPa"),
    Response("friction_angle_offset_deg", "deg", False, _angle_offset, _friction_plots,
             "mean (simulated - lab) tilt angle atan(mu_static) over the steps >= 10 kPa, a cell that "
             "hangs on counted as 90 deg"),
    Response("friction_band_z_mu_static", "z", True, _band_z("mu_static"), _friction_plots,
             "per lab step >= 10 kPa: (simulated - lab) static friction / half band"),
    Response("friction_band_z_mu_dynamic", "z", True, _band_z("mu_dynamic"), _friction_plots,
             "per lab step >= 10 kPa: (simulated - lab) dynamic friction / half band"),
]}


def unit_of_name(name):
    """The unit suffix of a result key (e.g. 'deg' of aor_mean_deg), or None."""
    for suffix in sorted(UNIT_SUFFIXES + DIMENSIONLESS_SUFFIXES, key=len, reverse=True):
        if name.endswith(suffix):
            return suffix[1:]
    return None


def get(name):
    """The Response called `name`: listed above, or a scalar result key with a unit
    suffix; None when neither."""
    if name in RESPONSES:
        return RESPONSES[name]
    unit = unit_of_name(name)
    if unit is None:
        return None
    return Response(name, unit, False, _scalar(name), description=f"result key {name}")
