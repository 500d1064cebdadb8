"""Post-processing of rig results: summaries, statistics over seeds.

Rig-specific modules: aor (pile angles), compression (spring curves), friction (tilt records).
"""
import math

SCALAR_SKIP = {"seed", "job_id", "rig", "material"}


def scalar_measurements(result):
    """{name: value} of the scalar numeric measurements of one result.json."""
    return {k: v for k, v in sorted(result.items())
            if k not in SCALAR_SKIP and isinstance(v, (int, float)) and not isinstance(v, bool)}


def summary_line(result):
    """One line of the scalar measurements of a result."""
    return ", ".join(f"{k}={v:.4g}" for k, v in scalar_measurements(result).items())


def mean_std(values):
    """(mean, sample standard deviation) of a list of numbers (std 0 for one value)."""
    n = len(values)
    mean = sum(values) / n
    if n < 2:
        return mean, 0.0
    return mean, math.sqrt(sum((v - mean) ** 2 for v in values) / (n - 1))


def seed_statistics(results):
    """{measurement: (mean, std, n)} over several results (seeds) of the same job."""
    keys = set.intersection(*(set(scalar_measurements(r)) for r in results))
    out = {}
    for k in sorted(keys):
        vals = [scalar_measurements(r)[k] for r in results]
        m, s = mean_std(vals)
        out[k] = (m, s, len(vals))
    return out


def seed_statistics_text(results):
    lines = [f"over {len(results)} seeds (mean +/- std):"]
    for k, (m, s, n) in seed_statistics(results).items():
        lines.append(f"  {k}: {m:.4g} +/- {s:.2g}")
    return "\n".join(lines)
