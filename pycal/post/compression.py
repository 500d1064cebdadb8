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

Lab comparison: the misfit of pycal.post.lab_curves (RMS of the band z over the lab
steps of labresults/curves/<rig>_<sample>.csv, the simulated curve interpolated in
log stress).
"""
import math
import os

from ..files import write_csv
from .lab_curves import (EXTRAPOLATE_RATIO, band_z, interp_log_stress, lab_sample_of,  # noqa: F401 (API)
                         misfit, write_comparison_csv)
from . import lab_curves

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

def lab_curve_name(rig, lab_sample):
    return f"{rig}_{lab_sample}"


def load_targets(rig, lab_sample, lab_dir=None):
    """Targets (pycal.post.lab_curves form) of the lab curve <rig>_<lab_sample>, plus
    '_particle_density' (kg/m3, labresults/samples.yaml: lab solid fractions become bulk
    densities); the curves are those the rig's descriptor names (pycal/rigs/<rig>.py:
    ccs_expansion's loading branch is the sample's ccs curve). {} when there is none."""
    from .. import labdata
    from .. import rigs
    names = [lab_curve_name(r, lab_sample) for r in rigs.get(rig).lab_curves]
    out = lab_curves.load_targets(names, lab_dir)
    if out:
        kw = {} if lab_dir is None else {"lab_dir": lab_dir}
        out["_particle_density"] = float(labdata.load_samples(**kw)["material"]["particle_density_kg_m3"])
    return out


def compare(result, targets):
    """{misfit name: misfit dict + 'lab_curve', 'quantity'} of one result against targets
    from load_targets (an empty dict gives no misfits)."""
    out = {}
    if not targets:
        return out
    branch = result.get("branch") or ["loading"] * len(result["stress_pa"])
    from .. import rigs
    for name, key, quantity, factor, br in rigs.get(result["rig"]).comparisons:
        if quantity not in targets or key not in result:
            continue
        t = targets[quantity]
        stress, value, low, high = t["stress_pa"], t["value"], t["low"], t["high"]
        if factor == "lab_particle_density":
            f = targets["_particle_density"]
            value, low, high = ([None if v is None else v * f for v in a] for a in (value, low, high))
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
    n = len(result["stress_pa"])
    cols = [(k, c) for k, c in CURVE_COLUMNS if k in result and len(result[k]) == n]
    rows = [[i + 1] + [result[k][i] for k, _ in cols] for i in range(n)]
    return write_csv(path, ["step_count"] + [c for _, c in cols], rows)


def write_plots(result, comparisons, out_dir):
    """spring_curve.png (force vs displacement, stress vs strain), stiffness.png (vs
    stress, with the lab band), bulk_density.png (vs stress, with the lab band)."""
    from ..plotting import new_figure, save_png
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

    fig, (a1, a2) = new_figure(1, 2, figsize=(10, 4))
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
    paths.append(save_png(fig, os.path.join(out_dir, "spring_curve.png")))

    def band_plot(fname, ylabel, key, names, logy):
        fig, a = new_figure(figsize=(6, 4.2))
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
        paths.append(save_png(fig, os.path.join(out_dir, fname)))

    band_plot("stiffness.png", "stiffness d stress / d strain (Pa)", "stiffness_pa",
              [("bulk_stiffness", "C2"), ("unloading_stiffness", "C1")], True)
    band_plot("bulk_density.png", "bulk density (kg/m3)", "bulk_density_kg_m3",
              [("bulk_density", "C2")], False)
    return paths


def write_outputs(result, out_dir=None, lab_dir=None, plots=True):
    """CSV + PNG of one compression result (dict or path to result.json) into out_dir
    (default: the folder of result.json). Returns {'files': [...], 'misfits': {...}}.
    The misfits are compact (no per-step arrays): {name: {'rms_z', 'n_points', ...}}."""
    if isinstance(result, (str, os.PathLike)):
        from .cli import read_result
        path = str(result)
        result = read_result(path)
        out_dir = out_dir or os.path.dirname(os.path.abspath(path))
    if out_dir is None:
        raise ValueError("write_outputs: out_dir is needed for a result given as a dict")
    sample = lab_sample_of(result)
    targets = load_targets(result["rig"], sample, lab_dir) if sample else {}
    comps = compare(result, targets)
    os.makedirs(out_dir, exist_ok=True)
    files = [write_curve_csv(result, os.path.join(out_dir, "spring_curve.csv"))]
    if comps:
        files.append(write_comparison_csv(comps, os.path.join(out_dir, "lab_comparison.csv")))
    if plots:
        files.extend(write_plots(result, comps, out_dir))
    summary = {k: {"rms_z": c["rms_z"], "n_points": c["n_points"], "n_skipped": c["n_skipped"],
                   "inside_band_count": c["inside_band_count"], "lab_curve": c["lab_curve"],
                   "quantity": c["quantity"]} for k, c in comps.items()}
    return {"files": files, "misfits": summary}


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


def _cli_handle(loaded, out_dir):
    for path, result in loaded:
        out = write_outputs(result, out_dir or os.path.dirname(os.path.abspath(path)))
        print(path)
        for f in out["files"]:
            print("  wrote", f)
        for k, m in out["misfits"].items():
            rms = "n/a" if m["rms_z"] is None else f"{m['rms_z']:.3g}"
            print(f"  misfit {k} vs {m['lab_curve']}:{m['quantity']}: rms_z={rms} "
                  f"({m['inside_band_count']}/{m['n_points']} steps inside the band)")


def main(argv=None):
    """python3 -m pycal.post.compression RESULT.json [...] [--out DIR]: CSV + PNG per result."""
    from .cli import run
    return run(argv, "pycal.post.compression", "spring curves, stiffness and lab comparison of "
               "compression results (CSV + PNG next to each result.json)", _cli_handle)


if __name__ == "__main__":
    raise SystemExit(main())
