"""Tilt-table friction rigs (wall_friction, internal_friction): friction vs consolidation
stress over seeds, against the lab curves and bands; CSV, PNG and a misfit per curve.

Pure Python (never imports YADE); works on result.json files:

    /usr/bin/python3 -m pycal.post.friction runs/wall_friction/<job_id>/result.json [...] [--out DIR]

Several results (seeds of one job) are pooled per consolidation stress: mean and sample
standard deviation of mu_static and mu_dynamic over the seeds where the cell slid, and
the share of seeds in which it stuck.

Lab comparison (labresults/curves/<rig>_<lab_sample>.csv through pycal.post.lab_curves,
or plain arrays given to `compare`): per quantity (mu_static, mu_dynamic) the misfit of
pycal.post.lab_curves.misfit: RMS over the lab steps where the lab cell slides of
z = (sim - lab) / (half band width on the side of sim), the simulated mean curve
interpolated in log(stress); |z| <= 1 is inside the band. Lab steps where the cell
sticks are compared as outcomes: `outcome_mismatch_count` counts lab steps whose
outcome (slides / sticks) differs from the simulated majority at the nearest simulated
stress (within 5 %; farther steps are skipped).
"""
import math
import os

from ..files import write_csv
from . import lab_curves, mean_std
from .lab_curves import (EXTRAPOLATE_RATIO, band_z, interp_log_stress, lab_sample_of,  # noqa: F401 (API)
                         misfit, sliding_steps, targets_from_arrays, write_comparison_csv)

QUANTITIES = ("mu_static", "mu_dynamic")
# mu_dynamic = tan t - a / (g cos t) loses mu as cos t -> 0 (at 90 deg a = g whatever mu is):
# a travel timed at a held angle above this gives no dynamic friction (the rig reports
# mu_dynamic None there, and older results are read the same way)
DYNAMIC_MAX_ANGLE_DEG = 85.0


def dynamic_value(result, k):
    """mu_dynamic of step k, None where the travel was timed above DYNAMIC_MAX_ANGLE_DEG."""
    a = (result.get("dynamic_angle_deg") or [None] * (k + 1))[k]
    v = result["mu_dynamic"][k]
    return None if v is None or (a is not None and a > DYNAMIC_MAX_ANGLE_DEG) else v
def friction_rigs():
    """The tilt-table rigs (post: friction in their descriptors, pycal/rigs/)."""
    from .. import rigs
    return tuple(n for n in rigs.names() if rigs.get(n).post == "friction")


# ------------------------------------------------------------------ statistics

def seed_summary(results):
    """Pool results (dicts) of one job over seeds, per consolidation stress.

    Returns {'stress_pa': [...], 'n_seeds': [...], 'sticks_ratio': [...],
    'mu_static_mean', 'mu_static_std', 'mu_static_n', same for mu_dynamic,
    'max_tilt_deg_max'}; a mean is None where no seed slid."""
    if not results:
        raise ValueError("seed_summary: no results")
    stresses = sorted({s for r in results for s in r["stress_pa"]})
    out = {"stress_pa": stresses, "n_seeds": [], "sticks_ratio": [], "max_tilt_deg_max": []}
    for q in QUANTITIES:
        for suffix in ("mean", "std", "n"):
            out[f"{q}_{suffix}"] = []
    for s in stresses:
        rows = []
        for r in results:
            if s in r["stress_pa"]:
                i = r["stress_pa"].index(s)
                row = {k: r[k][i] for k in QUANTITIES + ("sticks", "max_tilt_deg") if k in r}
                if "mu_dynamic" in r:
                    row["mu_dynamic"] = dynamic_value(r, i)
                rows.append(row)
        out["n_seeds"].append(len(rows))
        out["sticks_ratio"].append(sum(1 for x in rows if x.get("sticks")) / len(rows))
        tilts = [x["max_tilt_deg"] for x in rows if x.get("max_tilt_deg") is not None]
        out["max_tilt_deg_max"].append(max(tilts) if tilts else None)
        for q in QUANTITIES:
            vals = [x[q] for x in rows if x.get(q) is not None]
            m, sd = mean_std(vals) if vals else (None, None)
            out[f"{q}_mean"].append(m)
            out[f"{q}_std"].append(sd)
            out[f"{q}_n"].append(len(vals))
    return out


# ------------------------------------------------------------------ lab targets

def load_targets(rig, lab_sample, lab_dir=None):
    """Targets (pycal.post.lab_curves form) of the lab curve <rig>_<lab_sample>
    (value None where the lab cell sticks); {} when there is no such curve."""
    return lab_curves.load_targets([f"{rig}_{lab_sample}"], lab_dir)


def _nearest(stresses, s):
    """Index of the simulated stress within EXTRAPOLATE_RATIO of s, or None."""
    best = min(range(len(stresses)), key=lambda i: abs(math.log(stresses[i] / s)))
    return best if abs(math.log(stresses[best] / s)) <= math.log1p(EXTRAPOLATE_RATIO) else None


def compare(summary, targets):
    """{quantity: misfit dict + outcome counts + lab arrays} of a seed summary against
    targets ({quantity: target} as load_targets gives; '_name' optional)."""
    out = {}
    for q in QUANTITIES:
        t = targets.get(q)
        if not t:
            continue
        lab_s, lab_v, lab_lo, lab_hi = sliding_steps(t)
        m = misfit(summary["stress_pa"], summary[f"{q}_mean"], lab_s, lab_v, lab_lo, lab_hi)
        mismatch, compared = 0, 0
        for i, s in enumerate(t["stress_pa"]):
            k = _nearest(summary["stress_pa"], s)
            if k is None:
                continue
            compared += 1
            sim_sticks = summary["sticks_ratio"][k] > 0.5
            if sim_sticks != (t["outcome"][i] == "sticks"):
                mismatch += 1
        m.update({"lab_curve": targets.get("_name", "arrays"), "quantity": q,
                  "outcome_mismatch_count": mismatch, "outcome_compared_count": compared,
                  "lab_stress_pa": lab_s, "lab_value": lab_v, "lab_low": lab_lo, "lab_high": lab_hi,
                  "lab_all": t})
        out[q] = m
    return out


# ------------------------------------------------------------------ calibration response

STICKS_MU = 2.0   # a simulated step where the cell did not slide even at max tilt counts as
                  # this friction coefficient (tan 63 deg: above every lab value here)


def _lab_target(result, quantity, targets):
    """The lab target of `quantity` for this result (targets default: its lab curve)."""
    if targets is None:
        targets = load_targets(result["rig"], lab_sample_of(result))
    t = targets.get(quantity)
    if not t:
        raise ValueError(f"{result.get('job_id', result.get('rig'))}: no lab curve of {quantity} to compare with")
    return t


def compared_values(result, quantity):
    """Per simulated step the value a calibration compares with the lab: STICKS_MU where
    the cell stuck or gave no value (mu_dynamic above DYNAMIC_MAX_ANGLE_DEG included)."""
    out = []
    for k, stuck in enumerate(result["sticks"]):
        v = dynamic_value(result, k) if quantity == "mu_dynamic" else result[quantity][k]
        out.append(STICKS_MU if stuck or v is None else v)
    return out


def friction_offset(result, quantity="mu_static", min_stress_pa=10000.0, targets=None):
    """Mean over the simulated steps at or above min_stress_pa of (simulated - lab)
    `quantity`, the lab curve interpolated in log(stress) at the simulated stress; lab
    steps where the cell sticks and simulated stresses outside the lab range are left
    out; a simulated step that sticks counts as STICKS_MU. 0 = on the lab curve; rises
    with the particle friction coefficient (the response of the calibration's friction
    stages). Below ~10 kPa a loose bed shears inside itself first (measured), so those
    steps say little about the contact friction.
    targets: as load_targets (default: the lab curve of the rig and the material)."""
    t = _lab_target(result, quantity, targets)
    sim = compared_values(result, quantity)
    lab_s, lab_v, _, _ = sliding_steps(t)
    diffs = [sim[k] - lab for k, lab in _lab_at_simulated_steps(result, lab_s, lab_v, min_stress_pa)]
    if not diffs:
        raise ValueError(f"{result.get('job_id', result.get('rig'))}: no simulated step at or above "
                         f"{min_stress_pa:g} Pa where the lab cell slides")
    return sum(diffs) / len(diffs)


def _lab_at_simulated_steps(result, lab_s, lab_v, min_stress_pa):
    """[(simulated step index, lab value interpolated in log(stress) at its stress)] for the
    simulated steps at or above min_stress_pa inside the lab curve's stress range."""
    out = []
    for k, s in enumerate(result["stress_pa"]):
        if s < min_stress_pa:
            continue
        lab = interp_log_stress(lab_s, lab_v, s, extrapolate_ratio=0.0)
        if lab is not None:
            out.append((k, lab))
    return out


STICKS_ANGLE_DEG = 90.0   # a cell that does not slide up to the max tilt (lab or simulation)


def friction_angle_offset_deg(result, quantity="mu_static", min_stress_pa=10000.0, targets=None):
    """Mean over the simulated steps at or above min_stress_pa of (simulated - lab) tilt
    angle atan(mu) in deg, where a step that sticks (lab or simulation) counts as 90 deg:
    continuous through the lab cell's hang-on (the wet fines from ~60 kPa), rises with
    cohesion. The lab angles are interpolated in log(stress) (sticking steps included)
    at the simulated stress; simulated stresses outside the lab range are left out."""
    t = _lab_target(result, quantity, targets)
    sim = compared_values(result, quantity)
    lab_s, lab_a = [], []
    for i, s in enumerate(t["stress_pa"]):
        v = t["value"][i]
        if t["outcome"][i] == "sticks":
            lab_s.append(s)
            lab_a.append(STICKS_ANGLE_DEG)
        elif v is not None:
            lab_s.append(s)
            lab_a.append(math.degrees(math.atan(v)))
    diffs = []
    for k, lab in _lab_at_simulated_steps(result, lab_s, lab_a, min_stress_pa):
        stuck = result["sticks"][k] or sim[k] >= STICKS_MU
        diffs.append((STICKS_ANGLE_DEG if stuck else math.degrees(math.atan(sim[k]))) - lab)
    if not diffs:
        raise ValueError(f"{result.get('job_id', result.get('rig'))}: no simulated step at or above "
                         f"{min_stress_pa:g} Pa inside the lab curve's stress range")
    return sum(diffs) / len(diffs)


def friction_band_z(result, quantity="mu_static", min_stress_pa=10000.0, targets=None):
    """Per lab step at or above min_stress_pa where the lab cell slides: z = (simulated -
    lab) / (half band width on the side of the simulation), the simulated curve
    interpolated in log(stress) (None where it does not reach that step; a simulated
    step that sticks counts as STICKS_MU). |z| <= 1 is inside the band: the residual
    vector of the calibration's joint stages."""
    t = _lab_target(result, quantity, targets)
    sim = compared_values(result, quantity)
    out = []
    for i, s in enumerate(t["stress_pa"]):
        if s < min_stress_pa or t["outcome"][i] != "slides" or t["value"][i] is None:
            continue
        v = interp_log_stress(result["stress_pa"], sim, s)
        out.append(None if v is None else band_z(v, t["value"][i], t["low"][i], t["high"][i]))
    return out


# ------------------------------------------------------------------ outputs

def write_summary_csv(summary, comparisons, path):
    """friction_vs_stress.csv: per stress the seed statistics and the lab value and band
    at that stress (blank where the lab has no step there)."""
    cols = ["stress_pa", "n_seeds", "sticks_ratio", "max_tilt_deg_max"]
    for q in QUANTITIES:
        cols += [f"{q}_mean", f"{q}_std", f"{q}_n"]
    lab_cols = []
    for q in QUANTITIES:
        if q in comparisons:
            lab_cols += [f"lab_{q}", f"lab_{q}_low", f"lab_{q}_high", f"lab_{q}_outcome"]
    rows = []
    for i, s in enumerate(summary["stress_pa"]):
        row = [summary[c][i] for c in cols]
        for q in QUANTITIES:
            if q not in comparisons:
                continue
            t = comparisons[q]["lab_all"]
            j = next((j for j, ls in enumerate(t["stress_pa"]) if abs(ls - s) <= 1e-6 * s), None)
            if j is None:
                row += [None] * 4
            else:
                row += [t[k][j] for k in ("value", "low", "high")] + [t["outcome"][j]]
        rows.append(row)
    return write_csv(path, cols + lab_cols, rows)


def write_plot(summary, comparisons, path, title):
    """friction_vs_stress.png: mean +/- std of mu_static and mu_dynamic vs stress (kPa),
    the lab curves with their bands, sticking steps marked (x at the top)."""
    from ..plotting import new_figure, save_png
    fig, ax = new_figure(figsize=(7, 4.5))
    colours = {"mu_static": "C0", "mu_dynamic": "C3"}
    s_kpa = [s / 1e3 for s in summary["stress_pa"]]
    for q in QUANTITIES:
        pts = [(s, m, sd) for s, m, sd in zip(s_kpa, summary[f"{q}_mean"], summary[f"{q}_std"]) if m is not None]
        if pts:
            ax.errorbar([p[0] for p in pts], [p[1] for p in pts], yerr=[p[2] for p in pts], fmt="o-",
                        color=colours[q], capsize=3, label=f"simulation {q}")
        c = comparisons.get(q)
        if c and c["lab_stress_pa"]:
            ls = [s / 1e3 for s in c["lab_stress_pa"]]
            ax.fill_between(ls, c["lab_low"], c["lab_high"], color=colours[q], alpha=0.15)
            rms = "n/a" if c["rms_z"] is None else f"{c['rms_z']:.2f}"
            ax.plot(ls, c["lab_value"], "--", color=colours[q], label=f"lab {q} (misfit {rms})")
    ymax = ax.get_ylim()[1]
    stuck = [s for s, r in zip(s_kpa, summary["sticks_ratio"]) if r > 0.5]
    if stuck:
        ax.plot(stuck, [ymax] * len(stuck), "kx", ms=9, label="simulated cell sticks")
    for q in QUANTITIES:
        c = comparisons.get(q)
        if c:
            t = c["lab_all"]
            lab_stuck = [s / 1e3 for s, o in zip(t["stress_pa"], t["outcome"]) if o == "sticks"]
            if lab_stuck:
                ax.plot(lab_stuck, [ymax * 0.97] * len(lab_stuck), "s", mfc="none", color="k",
                        label="lab cell sticks")
            break
    ax.set_xlabel("consolidation stress (kPa)")
    ax.set_ylabel("friction coefficient (-)")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return save_png(fig, path)


def write_tilt_trace(record_csv, path, onset_m=None, stresses_pa=()):
    """tilt_trace.png from a run's tilt_record.csv: the mobile cell's slide (mm) against the
    tilt angle (deg), one line per consolidation step (its stress, Pa, from stresses_pa), the
    onset distance dashed. Returns
    the path, or None when the record has no rows."""
    import csv
    from ..plotting import new_figure, save_png
    steps = {}
    with open(record_csv, newline="") as f:
        for row in csv.DictReader(f):
            steps.setdefault(int(row["step_index_count"]), []).append(
                (float(row["tilt_deg"]), 1e3 * float(row["slide_displacement_m"])))
    if not steps:
        return None
    fig, ax = new_figure(figsize=(5, 3.4))
    for k, pts in sorted(steps.items()):
        at = f" ({stresses_pa[k] / 1e3:g} kPa)" if k < len(stresses_pa) else ""
        ax.plot([p[0] for p in pts], [p[1] for p in pts], lw=1, label=f"step {k + 1}{at}")
    if onset_m:
        ax.axhline(1e3 * onset_m, ls="--", color="k", lw=0.8, label="onset distance")
    ax.set_xlabel("tilt (deg)")
    ax.set_ylabel("slide of the mobile cell (mm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return save_png(fig, path)


def trace_picture(folder, job, path):
    """The report's picture of one tilt run (pycal.calibration.gallery): its tilt_record.csv
    as write_tilt_trace draws it; None without a record."""
    record = os.path.join(folder, "tilt_record.csv")
    if not os.path.isfile(record):
        return None
    p = job["rig_config"]["procedure"]
    return write_tilt_trace(record, path, p.get("slide_onset_displacement_m"), p.get("consolidation_stresses_pa", ()))


def write_outputs(results, out_dir, lab_dir=None, targets=None, plots=True):
    """CSV + PNG for one or several results (dicts or paths to result.json) of one job
    (seeds). targets: as load_targets (default: the lab curve of the rig and the
    material's lab_sample). Returns {'files', 'summary', 'misfits'} with compact misfits
    {quantity: {'rms_z', 'n_points', 'inside_band_count', 'outcome_mismatch_count', ...}}."""
    from .cli import read_result
    loaded = [read_result(r) if isinstance(r, (str, os.PathLike)) else r
              for r in (results if isinstance(results, (list, tuple)) else [results])]
    rigs = {r["rig"] for r in loaded}
    if len(rigs) != 1 or not rigs <= set(friction_rigs()):
        raise ValueError(f"write_outputs: results of one friction rig expected, got {sorted(rigs)}")
    rig = rigs.pop()
    summary = seed_summary(loaded)
    if targets is None:
        sample = lab_sample_of(loaded[0])
        targets = load_targets(rig, sample, lab_dir) if sample else {}
    comps = compare(summary, targets)
    os.makedirs(out_dir, exist_ok=True)
    files = [write_summary_csv(summary, comps, os.path.join(out_dir, "friction_vs_stress.csv"))]
    if comps:
        files.append(write_comparison_csv(comps, os.path.join(out_dir, "lab_comparison.csv")))
    if plots:
        title = f"{rig} {loaded[0]['material']} ({len(loaded)} seed{'s' if len(loaded) > 1 else ''})"
        files.append(write_plot(summary, comps, os.path.join(out_dir, "friction_vs_stress.png"), title))
    misfits = {q: {k: c[k] for k in ("rms_z", "n_points", "n_skipped", "inside_band_count",
                                     "outcome_mismatch_count", "outcome_compared_count", "lab_curve")}
               for q, c in comps.items()}
    return {"files": files, "summary": summary, "misfits": misfits}


def _cli_handle(loaded, out_dir):
    from ..errors import ConfigError
    rigs = {r["rig"] for _, r in loaded}
    if len(rigs) != 1 or not rigs <= set(friction_rigs()):
        raise ConfigError(loaded[0][0], "rig", f"results of one friction rig ({', '.join(friction_rigs())}) expected, "
                                               f"got {', '.join(sorted(rigs))}")
    res = write_outputs([r for _, r in loaded], out_dir or os.path.dirname(os.path.abspath(loaded[0][0])))
    for f in res["files"]:
        print("wrote", f)
    s = res["summary"]
    for i, st in enumerate(s["stress_pa"]):
        parts = [f"{st / 1e3:6.1f} kPa"]
        for q in QUANTITIES:
            m, sd = s[f"{q}_mean"][i], s[f"{q}_std"][i]
            parts.append(f"{q} " + ("  n/a " if m is None else f"{m:.3f} +/- {sd:.3f}"))
        parts.append(f"sticks {s['sticks_ratio'][i]:.2f}")
        print("  ".join(parts))
    for q, m in res["misfits"].items():
        rms = "n/a" if m["rms_z"] is None else f"{m['rms_z']:.3g}"
        print(f"misfit {q} vs {m['lab_curve']}: rms_z={rms} ({m['inside_band_count']}/{m['n_points']} inside "
              f"the band; outcome mismatches {m['outcome_mismatch_count']}/{m['outcome_compared_count']})")


def main(argv=None):
    """python3 -m pycal.post.friction RESULT.json [...] [--out DIR]: the seeds of one job pooled."""
    from .cli import run
    return run(argv, "pycal.post.friction", "friction vs consolidation stress of the seeds of one "
               "friction job against the lab curve (CSV + PNG)", _cli_handle)


if __name__ == "__main__":
    raise SystemExit(main())
