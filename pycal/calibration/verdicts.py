"""A stage's two verdicts, kept apart (the report shows both):

- matches the lab: at the estimate, the fitted response lies within the lab band of its
  target (each response of the stage; where no band is given, within 1.96 standard
  errors of the target's own uncertainty); None when nothing tells;
- precise enough: the 95 % interval of every parameter lies within its tolerance of the
  estimate (the stage's `met`, pycal.stats.stopping).
"""
import math


def matches_lab(row):
    """True / False / None (see the module doc) for a stage row with `responses`."""
    verdicts = []
    for r in row.get("responses") or []:
        at, target = r.get("at_estimate"), r.get("target")
        if not _finite(at) or not _finite(target):
            continue
        if _finite(r.get("band")) and r["band"] > 0:
            half = r["band"]
        elif _finite(r.get("standard_error")) and r["standard_error"] > 0:
            half = 1.96 * r["standard_error"]
        else:
            continue
        verdicts.append(abs(at - target) <= half)
    return all(verdicts) if verdicts else None


def _finite(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
