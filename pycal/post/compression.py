"""Compression rigs (CCS, CCS expansion, UCS): spring curves, stiffness, misfits, plots.

Pure Python (never imports YADE); the rig scripts import it to compute the per-step
derived arrays and to write CSV + PNG into their job folder, and the same functions
work on any result.json afterwards:

    /usr/bin/python3 -m pycal.post.compression runs/ccs/<job_id>/result.json

Definitions (stated once, used by every rig):
- stress = upward force of the particles on the plate / reference area (CCS: cell
  cross-section, UCS: plate area), Pa;
- strain = (h0 - z_plate) / h0 with h0 = the plate's first-contact height (the top of
  the highest particle before loading);
- stiffness (secant, per step) = (stress_i - stress_{i-1}) / (strain_i - strain_{i-1});
  the first step of a branch starts from `origin` ((0, 0) for loading, the last
  loading point for unloading). It belongs to the stress of step i (the step reached).
  Where the strain does not change the stiffness is undefined (None);
- force balance error = (plate + weight - bottom - wall) / (plate + weight), wall =
  the downward friction force the particles put on the cell wall (weight of the step
  when `step_weight_n` is recorded).

Lab comparison: misfit of a simulated curve against a lab target curve
(labresults/curves/<rig>_<sample>.csv, pycal.labdata.target_curve) = RMS over the lab
stress steps of z = (sim - target) / (band half width on the side of sim), i.e.
(target_high - target) above the target, (target - target_low) below it: |z| <= 1
means inside the band. The simulated curve is interpolated linearly in log(stress)
to the lab steps; lab steps outside the simulated stress range (beyond
EXTRAPOLATE_RATIO) are left out and counted.
"""
import json
import math
import os
import sys

EXTRAPOLATE_RATIO = 0.05   # lab steps up to 5 % beyond the simulated stress range use the end segment

# columns of spring_curve.csv: (result.json key, CSV column with unit)
CURVE_COLUMNS = [
    ("branch", "branch"),
    ("target_stress_pa", "target_stress_pa"),
    ("stress_pa", "stress_pa"),
    ("strain", "strain_ratio"),
    ("plate_force_n", "plate_force_n"),
    ("plate_position_m", "plate_position_m"),
    ("plate_displacement_m", "plate_displacement_m"),
    ("bulk_density_kg_m3", "bulk_density_kg_m3"),
    ("solid_fraction", "solid_fraction"),
    ("stiffness_pa", "stiffness_pa"),
    ("bottom_force_n", "bottom_force_n"),
    ("wall_force_n", "wall_force_n"),
    ("force_balance_error", "force_balance_error_ratio"),
    ("plate_contacts_count", "plate_contacts_count"),
    ("step_time_s", "step_time_s"),
    ("max_overlap_ratio", "max_overlap_ratio"),
]


# ------------------------------------------------------------------ per-step math

def secant_stiffness(stress, strain, origin=(0.0, 0.0)):
    """[(s_i - s_{i-1}) / (e_i - e_{i-1})] with (s_{-1}, e_{-1}) = origin (Pa); None where
    the strain does not change."""
    out = []
    s_prev, e_prev = origin
    for s, e in zip(stress, strain):
        de = e - e_prev
        out.append((s - s_prev) / de if de != 0.0 else None)
        s_prev, e_prev = s, e
    return out


def branch_stiffness(stress, strain, branch):
    """Secant stiffness per step for a curve made of a loading branch followed by
    unloading (and possibly reloading) branches: each branch starts from the last point of
    the branch before ((0, 0) for the first)."""
    out = []
    origin = (0.0, 0.0)
    i = 0
    n = len(stress)
    while i < n:
        j = i
        while j < n and branch[j] == branch[i]:
            j += 1
        out.extend(secant_stiffness(stress[i:j], strain[i:j], origin))
        origin = (stress[j - 1], strain[j - 1])
        i = j
    return out


def force_balance_error(plate_force, weight, bottom_force, wall_force):
    """(plate + weight - bottom - wall) / (plate + weight) for one step (N in, ratio out)."""
    load = plate_force + weight
    return (load - bottom_force - wall_force) / load


def derived_arrays(result):
    """Fill in stiffness_pa, force_balance_error and plate_displacement_m of a result dict
    (from its stress_pa, strain, branch, plate/bottom/wall forces, weight). Returns it."""
    n = len(result["stress_pa"])
    branch = result.get("branch") or ["loading"] * n
    result["branch"] = branch
    result["stiffness_pa"] = branch_stiffness(result["stress_pa"], result["strain"], branch)
    # weight per step if recorded (particles may leave an open rig), else the final weight
    weights = result.get("step_weight_n") or [result["particle_weight_n"]] * n
    result["force_balance_error"] = [force_balance_error(p, w, b, s) for p, w, b, s in
                                     zip(result["plate_force_n"], weights, result["bottom_force_n"],
                                         result["wall_force_n"])]
    h0 = result["initial_height_m"]
    result["plate_displacement_m"] = [h0 - z for z in result["plate_position_m"]]
    unl = [k for k, b in zip(result["stiffness_pa"], branch) if b == "unloading"]
    if unl:
        result["unloading_stiffness_pa"] = unl
        result["unloading_stress_pa"] = [s for s, b in zip(result["stress_pa"], branch) if b == "unloading"]
    return result


# ------------------------------------------------------------------ lab comparison

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


# which simulated array is compared with which lab column, per rig:
# (name of the misfit, simulated key, lab quantity, factor applied to the lab values, branch)
COMPARISONS = {
    "ccs": [("bulk_stiffness", "stiffness_pa", "bulk_stiffness_pa", None, "loading"),
            ("solid_fraction", "solid_fraction", "solid_fraction", None, "loading"),
            ("bulk_density", "bulk_density_kg_m3", "solid_fraction", "lab_particle_density", "loading")],
    "ucs": [("bulk_stiffness", "stiffness_pa", "bulk_stiffness_pa", None, "loading"),
            ("bulk_density", "bulk_density_kg_m3", "bulk_density_kg_m3", None, "loading")],
    "ccs_expansion": [("unloading_stiffness", "stiffness_pa", "particle_stiffness_pa", None, "unloading"),
                      ("bulk_stiffness", "stiffness_pa", "bulk_stiffness_pa", None, "loading"),
                      ("solid_fraction", "solid_fraction", "solid_fraction", None, "loading")],
}


def lab_curve_name(rig, lab_sample):
    return f"{rig}_{lab_sample}"


def load_targets(rig, lab_sample, lab_dir=None):
    """{lab quantity: (stress, value, low, high)} of the lab curve for this rig and sample,
    plus '_particle_density' (kg/m3 of the lab material) and '_name'; {} if there is none.
    For ccs_expansion the loading-branch targets come from the ccs curve."""
    try:
        from .. import labdata
    except ImportError:      # pragma: no cover - labdata needs pandas
        return {}
    kw = {} if lab_dir is None else {"lab_dir": lab_dir}
    out = {}
    names = labdata.curve_names(**kw)
    for name in (lab_curve_name(rig, lab_sample),) + (
            (lab_curve_name("ccs", lab_sample),) if rig == "ccs_expansion" else ()):
        if name not in names:
            continue
        df = labdata.load_curve(name, **kw)
        for q in labdata.curve_quantities(df):
            if q in out:
                continue
            t = labdata.target_curve(name, q, **kw)
            out[q] = ([float(x) for x in t.stress_pa], [float(x) for x in t.value],
                      [float(x) for x in t.low], [float(x) for x in t.high])
        out.setdefault("_name", name)
    if out:
        out["_particle_density"] = float(labdata.load_samples(**kw)["material"]["particle_density_kg_m3"])
    return out


def compare(result, targets):
    """{misfit name: misfit dict + 'lab_curve', 'quantity'} of one result against targets
    from load_targets (an empty dict gives no misfits)."""
    out = {}
    if not targets:
        return out
    branch = result.get("branch") or ["loading"] * len(result["stress_pa"])
    for name, key, quantity, factor, br in COMPARISONS.get(result["rig"], []):
        if quantity not in targets or key not in result:
            continue
        stress, value, low, high = targets[quantity]
        if factor == "lab_particle_density":
            f = targets["_particle_density"]
            value, low, high = [v * f for v in value], [v * f for v in low], [v * f for v in high]
        idx = [i for i, b in enumerate(branch) if b == br]
        if not idx:
            continue
        m = misfit([result["stress_pa"][i] for i in idx], [result[key][i] for i in idx],
                   stress, value, low, high)
        m.update({"lab_curve": targets["_name"], "quantity": quantity, "lab_stress_pa": stress,
                  "lab_value": value, "lab_low": low, "lab_high": high})
        out[name] = m
    return out


# ------------------------------------------------------------------ outputs

def write_curve_csv(result, path):
    """spring_curve.csv: one row per load step, units in the column names."""
    import csv
    n = len(result["stress_pa"])
    cols = [(k, c) for k, c in CURVE_COLUMNS if k in result and len(result[k]) == n]
    tmp = path + ".part"
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["step_count"] + [c for _, c in cols])
        for i in range(n):
            w.writerow([i + 1] + ["" if result[k][i] is None else result[k][i] for k, _ in cols])
    os.replace(tmp, path)
    return path


def _savefig(fig, path):
    tmp = path + ".part.png"
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, path)


def write_plots(result, comparisons, out_dir):
    """spring_curve.png (force vs displacement, stress vs strain), stiffness.png (vs
    stress, with the lab band), bulk_density.png (vs stress, with the lab band)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    n = len(result["stress_pa"])
    branch = result.get("branch") or ["loading"] * n
    title = f"{result['rig']} {result['material']} seed {result.get('seed')}"
    colours = {"loading": "C0", "unloading": "C3"}
    paths = []

    def by_branch():
        seen = []
        for b in branch:
            if b not in seen:
                seen.append(b)
        for b in seen:
            yield b, [i for i in range(n) if branch[i] == b]

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    for b, idx in by_branch():
        # unloading starts at the last loading point
        if b == "unloading" and idx[0] > 0:
            idx = [idx[0] - 1] + idx
        a1.plot([result["plate_displacement_m"][i] * 1e3 for i in idx],
                [result["plate_force_n"][i] for i in idx], "o-", color=colours.get(b, "k"), label=b)
        a2.plot([result["strain"][i] for i in idx], [result["stress_pa"][i] / 1e3 for i in idx],
                "o-", color=colours.get(b, "k"), label=b)
    a1.set_xlabel("plate displacement (mm)")
    a1.set_ylabel("plate force (N)")
    a2.set_xlabel("strain (-)")
    a2.set_ylabel("stress (kPa)")
    for a in (a1, a2):
        a.grid(alpha=0.3)
        a.legend()
    fig.suptitle(f"spring curve: {title}")
    fig.tight_layout()
    p = os.path.join(out_dir, "spring_curve.png")
    _savefig(fig, p)
    plt.close(fig)
    paths.append(p)

    def band_plot(fname, ylabel, key, names, logy):
        fig, a = plt.subplots(figsize=(6, 4.2))
        for b, idx in by_branch():
            pts = [(result["stress_pa"][i], result[key][i]) for i in idx if result[key][i] is not None]
            if pts:
                a.plot([s / 1e3 for s, _ in pts], [v for _, v in pts], "o-", color=colours.get(b, "k"),
                       label=f"simulation ({b})")
        for nm, style in names:
            c = comparisons.get(nm)
            if not c:
                continue
            s = [x / 1e3 for x in c["lab_stress_pa"]]
            a.fill_between(s, c["lab_low"], c["lab_high"], color=style, alpha=0.2,
                           label=f"lab band ({c['lab_curve']}, {c['quantity']})")
            rms = "n/a" if c["rms_z"] is None else f"{c['rms_z']:.2f}"
            a.plot(s, c["lab_value"], "--", color=style, label=f"lab target (misfit {rms})")
        a.set_xscale("log")
        if logy:
            a.set_yscale("log")
        a.set_xlabel("stress (kPa)")
        a.set_ylabel(ylabel)
        a.grid(alpha=0.3, which="both")
        a.legend(fontsize=7)
        a.set_title(title, fontsize=9)
        fig.tight_layout()
        path = os.path.join(out_dir, fname)
        _savefig(fig, path)
        plt.close(fig)
        paths.append(path)

    band_plot("stiffness.png", "stiffness d stress / d strain (Pa)", "stiffness_pa",
              [("bulk_stiffness", "C2"), ("unloading_stiffness", "C1")], True)
    band_plot("bulk_density.png", "bulk density (kg/m3)", "bulk_density_kg_m3",
              [("bulk_density", "C2")], False)
    return paths


def lab_sample_of(result):
    mat = result["job"]["materials"][result["material"]] if "job" in result else {}
    return mat.get("lab_sample")


def write_outputs(result, out_dir=None, lab_dir=None, plots=True):
    """CSV + PNG of one compression result (dict or path to result.json) into out_dir
    (default: the folder of result.json). Returns {'files': [...], 'misfits': {...}}.
    The misfits are compact (no per-step arrays): {name: {'rms_z', 'n_points', ...}}."""
    if isinstance(result, (str, os.PathLike)):
        path = str(result)
        with open(path) as f:
            result = json.load(f)
        out_dir = out_dir or os.path.dirname(os.path.abspath(path))
    if out_dir is None:
        raise ValueError("write_outputs: out_dir is needed for a result given as a dict")
    sample = result.get("lab_sample") or lab_sample_of(result)
    targets = load_targets(result["rig"], sample, lab_dir) if sample else {}
    comps = compare(result, targets)
    files = [write_curve_csv(result, os.path.join(out_dir, "spring_curve.csv"))]
    if comps:
        files.append(write_comparison_csv(comps, os.path.join(out_dir, "lab_comparison.csv")))
    if plots:
        files.extend(write_plots(result, comps, out_dir))
    summary = {k: {"rms_z": c["rms_z"], "n_points": c["n_points"], "n_skipped": c["n_skipped"],
                   "inside_band_count": c["inside_band_count"], "lab_curve": c["lab_curve"],
                   "quantity": c["quantity"]} for k, c in comps.items()}
    return {"files": files, "misfits": summary}


def write_comparison_csv(comparisons, path):
    """lab_comparison.csv: per misfit and lab step the lab value, band and simulated value."""
    import csv
    tmp = path + ".part"
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["misfit", "lab_curve", "quantity", "stress_pa", "lab_value", "lab_low", "lab_high",
                    "sim_value", "z_ratio"])
        for name, c in comparisons.items():
            for i, s in enumerate(c["lab_stress_pa"]):
                sim, z = c["sim_at_lab"][i], c["z"][i]
                w.writerow([name, c["lab_curve"], c["quantity"], s, c["lab_value"][i], c["lab_low"][i],
                            c["lab_high"][i], "" if sim is None else sim, "" if z is None else z])
    os.replace(tmp, path)
    return path


def unloading_stiffness_log_ratio(result, min_stress_pa=10000.0, lab_dir=None):
    """log of the geometric mean of simulated / lab unloading stiffness over the lab's
    unloading steps at or above min_stress_pa (below it particles lose contact and the
    lab curve drops). 0 = on the lab curve; a calibration response that rises with E."""
    targets = load_targets(result["rig"], lab_sample_of(result), lab_dir)
    comp = compare(derived_arrays(dict(result)), targets).get("unloading_stiffness")
    if comp is None:
        raise ValueError(f"{result.get('job_id')}: no unloading stiffness to compare with a lab curve")
    logs = [math.log(s / v) for s, v, st in zip(comp["sim_at_lab"], comp["lab_value"], comp["lab_stress_pa"])
            if s is not None and v and s > 0 and st >= min_stress_pa]
    if not logs:
        raise ValueError(f"{result.get('job_id')}: no unloading step at or above {min_stress_pa} Pa")
    return sum(logs) / len(logs)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if not argv:
        print("usage: python3 -m pycal.post.compression RESULT.json [...]", file=sys.stderr)
        return 2
    for p in argv:
        out = write_outputs(p)
        print(p)
        for f in out["files"]:
            print("  wrote", f)
        for k, m in out["misfits"].items():
            rms = "n/a" if m["rms_z"] is None else f"{m['rms_z']:.3g}"
            print(f"  misfit {k} vs {m['lab_curve']}:{m['quantity']}: rms_z={rms} "
                  f"({m['inside_band_count']}/{m['n_points']} steps inside the band)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
