"""Lab target curves and how a simulated curve is compared with them (pure Python).

One form of the targets for every rig (compression and friction):

    {"_name": curve name,
     quantity: {"stress_pa": [...], "value": [...], "low": [...], "high": [...],
                "outcome": ["slides" | "sticks", ...]}, ...}

value/low/high are in the quantity's unit, None where the lab cell sticks (no value).

Misfit of a simulated curve against a lab curve = RMS over the lab stress steps of
z = (sim - target) / (band half width on the side of sim), i.e. (high - target) above
the target and (target - low) below it: |z| <= 1 is inside the band. The simulated
curve is interpolated linearly in log(stress) to the lab steps; lab steps farther
than EXTRAPOLATE_RATIO outside the simulated stress range are left out and counted.
"""
import math

from ..files import write_csv

EXTRAPOLATE_RATIO = 0.05   # lab steps up to 5 % beyond the simulated stress range use the end segment


def _clean(values):
    """Floats, with None for blanks (None or NaN)."""
    return [None if (x is None or (isinstance(x, float) and math.isnan(x))) else float(x) for x in values]


def lab_sample_of(result):
    """Lab sample a result is compared with: result['lab_sample'] if the rig wrote it,
    else `lab_sample` of the job's material (or of its material set); None if neither."""
    if result.get("lab_sample"):
        return result["lab_sample"]
    job = result.get("job") or {}
    material = job.get("materials", {}).get(result.get("material")) or job.get("material_set") or {}
    return material.get("lab_sample")


def targets_from_arrays(stress_pa, value, low, high, outcome=None):
    """One quantity's target from plain arrays (None/NaN value = the lab cell sticks)."""
    value = _clean(value)
    if outcome is None:
        outcome = ["sticks" if v is None else "slides" for v in value]
    return {"stress_pa": [float(s) for s in stress_pa], "value": value, "low": _clean(low),
            "high": _clean(high), "outcome": [str(o) for o in outcome]}


def load_targets(curve_names, lab_dir=None):
    """Targets (module doc) of the first of `curve_names` that exists in lab_dir
    (default labresults/); quantities missing there are taken from the next curves of the
    list. {} when none exists."""
    from .. import labdata
    kw = {} if lab_dir is None else {"lab_dir": lab_dir}
    known = labdata.curve_names(**kw)
    out = {}
    for name in curve_names:
        if name not in known:
            continue
        for q in labdata.curve_quantities(labdata.load_curve(name, **kw)):
            if q not in out:
                t = labdata.target_curve(name, q, **kw)
                out[q] = targets_from_arrays(t.stress_pa, t.value, t.low, t.high, t.outcome)
        out.setdefault("_name", name)
    return out


def sliding_steps(target):
    """(stress, value, low, high) of the lab steps where the cell slides and a value exists."""
    idx = [i for i, o in enumerate(target["outcome"]) if o == "slides" and target["value"][i] is not None]
    return tuple([target[k][i] for i in idx] for k in ("stress_pa", "value", "low", "high"))


# ------------------------------------------------------------------ comparison maths

def interp_log_stress(stress, values, at, extrapolate_ratio=EXTRAPOLATE_RATIO):
    """Value of the piecewise-linear curve (log stress, value) at stress `at`; None when
    `at` is farther than extrapolate_ratio outside the range or no usable point exists.
    Points with value None are skipped; stresses must be > 0."""
    pts = sorted((math.log(s), v) for s, v in zip(stress, values) if v is not None and s > 0)
    if not pts or at <= 0:
        return None
    x = math.log(at)
    if len(pts) == 1:
        return pts[0][1] if abs(x - pts[0][0]) <= math.log1p(extrapolate_ratio) else None
    lo, hi = pts[0][0], pts[-1][0]
    if x < lo - math.log1p(extrapolate_ratio) or x > hi + math.log1p(extrapolate_ratio):
        return None
    for k in range(len(pts) - 1):
        (x0, y0), (x1, y1) = pts[k], pts[k + 1]
        if x <= x1 or k == len(pts) - 2:
            if x1 == x0:
                return 0.5 * (y0 + y1)
            return y0 + (y1 - y0) * (x - x0) / (x1 - x0)
    return None  # pragma: no cover


def band_z(sim, value, low, high):
    """(sim - value) / half width of the band on the side of sim (|z| <= 1: inside)."""
    if sim >= value:
        w = high - value
    else:
        w = value - low
    if w <= 0:
        w = max(abs(value) * 1e-6, 1e-300)
    return (sim - value) / w


def misfit(sim_stress, sim_values, lab_stress, lab_value, lab_low, lab_high,
           extrapolate_ratio=EXTRAPOLATE_RATIO):
    """Scalar misfit of a simulated curve against a lab curve with band.

    Returns {'rms_z', 'z', 'sim_at_lab', 'n_points', 'n_skipped', 'inside_band_count'}:
    z per lab step (None where skipped), RMS of the usable z (None if none)."""
    zs, sims = [], []
    for s, v, lo, hi in zip(lab_stress, lab_value, lab_low, lab_high):
        if v is None or (isinstance(v, float) and math.isnan(v)):
            zs.append(None)
            sims.append(None)
            continue
        sim = interp_log_stress(sim_stress, sim_values, s, extrapolate_ratio)
        sims.append(sim)
        zs.append(None if sim is None else band_z(sim, float(v), float(lo), float(hi)))
    used = [z for z in zs if z is not None]
    return {"rms_z": math.sqrt(sum(z * z for z in used) / len(used)) if used else None,
            "z": zs, "sim_at_lab": sims, "n_points": len(used),
            "n_skipped": len(zs) - len(used),
            "inside_band_count": sum(1 for z in used if abs(z) <= 1.0)}


COMPARISON_COLUMNS = ["misfit", "lab_curve", "quantity", "stress_pa", "lab_value", "lab_low", "lab_high",
                      "sim_value", "z_ratio"]


def write_comparison_csv(comparisons, path):
    """lab_comparison.csv: per misfit and lab step the lab value, its band, the simulated
    value there and z (blank where the simulation does not reach the step). comparisons:
    {misfit name: misfit() dict + 'lab_curve', 'quantity', 'lab_stress_pa', 'lab_value',
    'lab_low', 'lab_high'}."""
    rows = []
    for name, c in comparisons.items():
        for i, s in enumerate(c["lab_stress_pa"]):
            rows.append([name, c["lab_curve"], c["quantity"], s, c["lab_value"][i], c["lab_low"][i],
                         c["lab_high"][i], c["sim_at_lab"][i], c["z"][i]])
    return write_csv(path, COMPARISON_COLUMNS, rows)
