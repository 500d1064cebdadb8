"""Post-processing of rig results: summaries, statistics over seeds.

Rig-specific modules: aor and aor_mixed (pile angles), compression (spring curves),
friction (tilt records), transfer (the belt-stream rig's record); lab_curves (lab targets and misfits, shared), cli (the shared
command line of the modules).
"""
import math

SCALAR_SKIP = {"seed", "job_id", "rig", "material"}


def scalar_measurements(result):
    """{name: value} of the scalar numeric measurements of one result.json."""
    return {k: v for k, v in sorted(result.items())
            if k not in SCALAR_SKIP and isinstance(v, (int, float)) and not isinstance(v, bool)}


def summary_line(result):
    """One line of the scalar measurements of a result (keys with no value: '=none')."""
    parts = [f"{k}={v:.4g}" for k, v in scalar_measurements(result).items()]
    parts += [f"{k}=none" for k, v in sorted(result.items()) if v is None and k.endswith("_deg")]
    return ", ".join(parts)


def mean_std(values):
    """(mean, sample standard deviation) of a list of numbers (std 0 for one value)."""
    n = len(values)
    mean = sum(values) / n
    if n < 2:
        return mean, 0.0
    return mean, math.sqrt(sum((v - mean) ** 2 for v in values) / (n - 1))


def seed_statistics(results):
    """{measurement: (mean, std, n)} over several results (seeds) of the same job: per key
    the seeds that have a value (a null / NaN measurement, e.g. an AoR sector without an
    angle, is left out and n says so)."""
    per_seed = [scalar_measurements(r) for r in results]
    out = {}
    for k in sorted(set().union(*per_seed)):
        vals = [m[k] for m in per_seed if k in m and not math.isnan(m[k])]
        if vals:
            m, s = mean_std(vals)
            out[k] = (m, s, len(vals))
    return out


def seed_statistics_text(results):
    lines = [f"over {len(results)} seeds (mean +/- std):"]
    for k, (m, s, n) in seed_statistics(results).items():
        lines.append(f"  {k}: {m:.4g} +/- {s:.2g}" + (f"  ({n} of {len(results)} seeds have a value)"
                                                     if n < len(results) else ""))
    return "\n".join(lines)
