"""Practical equivalence of a cheaper setting (pure maths, no pycal imports).

A cheaper setting of a rig (a faster tilt, a softer contact) is measured on the same seeds as
the setting it would replace: the paired shift of the stage's response, its standard error
and degrees of freedom. It is taken when the whole 95 % interval of that shift lies within
+- `fraction` (20 %) of the stage's tolerance, converted into the response's units with the
stage's measured slope (d response / d parameter):

    margin = fraction x tolerance (parameter units) x |slope|        (response units)
    equivalent  <=>  -margin <= shift - t x SE  and  shift + t x SE <= margin

t: Student-t quantile with the shift's degrees of freedom (n - 1 for n paired seeds).
Not "within one standard error": that rule refuses a small bias measured precisely and
takes a large one measured badly.
"""
import math

from scipy import stats

FRACTION = 0.2
LEVEL = 0.95


def shift_interval(mean, se, dof, level=LEVEL):
    """(low, high) of the two-sided `level` interval of a shift measured as mean +- se."""
    if dof < 1 or not se >= 0:
        raise ValueError(f"need dof >= 1 and se >= 0 (got dof {dof}, se {se})")
    t = float(stats.t.ppf(0.5 + level / 2.0, dof))
    return mean - t * se, mean + t * se


def paired_shift(before, after):
    """(mean, se, dof) of the paired differences after - before (same seeds, n >= 2)."""
    d = [a - b for a, b in zip(after, before)]
    if len(d) != len(before) or len(d) != len(after) or len(d) < 2:
        raise ValueError("need two equal-length lists of at least two paired values")
    n = len(d)
    mean = sum(d) / n
    sd = math.sqrt(sum((x - mean) ** 2 for x in d) / (n - 1))
    return mean, sd / math.sqrt(n), n - 1


def margin(tolerance, slope, fraction=FRACTION):
    """The equivalence margin in the response's units: fraction x tolerance x |slope|."""
    return fraction * abs(tolerance) * abs(slope)


def judge(mean, se, dof, tolerance, slope, fraction=FRACTION, level=LEVEL):
    """{'shift', 'low', 'high', 'margin', 'equivalent', 'low_parameter', 'high_parameter'}: the
    shift's interval in the response's units and in the parameter's (divided by the slope),
    the margin, and whether the interval lies within +- margin."""
    low, high = shift_interval(mean, se, dof, level)
    m = margin(tolerance, slope, fraction)
    return {"shift": mean, "low": low, "high": high, "margin": m, "equivalent": -m <= low and high <= m,
            "low_parameter": low / abs(slope), "high_parameter": high / abs(slope)}
