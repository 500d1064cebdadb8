"""A stage's targets read from the lab data (labresults/, or a stage's lab_dir).

Read once when the study starts, so a broken lab file stops the study before any run,
with the file, key and reason (never a silent stand-in value).
"""
import math
from dataclasses import dataclass

from .. import LAB_DIR, labdata
from ..configs import load_material
from ..errors import ConfigError


@dataclass(frozen=True)
class Target:
    value: float             # the response's unit
    band: float              # half width of the lab band (0: none given)
    standard_error: float    # of the target itself (0: taken as exact)
    source: str              # where the value comes from, for the report
    standard_error_seeds_count: int = 0   # values the standard error was estimated from (0: known)

    @property
    def standard_error_dof(self):
        """Degrees of freedom of the standard error: n - 1 for a mean of n values, inf when known."""
        n = self.standard_error_seeds_count
        return n - 1 if n >= 2 else math.inf


def lab_bulk_density(material, lab_dir=None):
    """Bulk density (kg/m3) of the material's lab sample (its `lab_sample:`)."""
    key = load_material(material).get("lab_sample")
    if not key:
        raise ConfigError(f"configs/materials/{material}.yaml", "lab_sample",
                          "missing: the density stage needs the lab sample's bulk density")
    return float(labdata.sample(key, lab_dir or LAB_DIR)["bulk_density_kg_m3"]), key


def resolve(spec, response, material, lab_dir=None):
    """The Target of a validated target spec (pycal.calibration.study_config) for `response`."""
    unit = response.unit
    if "value" in spec:
        value, source = float(spec["value"]), "value given in the study"
    elif "sample" in spec:
        value = float(labdata.aor_target_deg(spec["sample"], spec["test"], lab_dir or LAB_DIR))
        source = f"lab {spec['sample']} {spec['test']}"
    else:
        value, sample = lab_bulk_density(material, lab_dir)
        source = f"lab {sample} bulk density"
    band = float(spec.get(f"band_{unit}", abs(value) * float(spec.get("band_percent", 0.0)) / 100.0))
    return Target(value, band, float(spec.get(f"standard_error_{unit}", 0.0)), source,
                  int(spec.get("standard_error_seeds_count", 0)))
