"""Particle density from the cell fill (rig 1, method.md).

The 25 mm particle density of a material is adjusted until the simulated bulk
density of the struck cell fill (mean over several random fills) matches the lab
bulk density of the material's lab sample.

Update rule (physics first): at a fixed packing the bulk density is proportional to
the particle density, rho_bulk = phi x rho_p, so

    rho_p_new = rho_p x rho_bulk_lab / rho_bulk_sim_mean

Heavier particles with the same stiffness overlap a little more and may pack a little
differently, so phi is not exactly constant: the update is repeated (at most
max_iterations) until |misfit| <= tolerance. The same seeds are used at every
iteration (common random fills), so the seed noise largely cancels between
iterations; the seed spread is still reported with every point.

Every run goes through an executor (pycal.runner.LocalPool by default): runs are
cached by job hash, so nothing is simulated twice, and an interrupted calibration
started again with the same arguments replays the same iterations from the cache
(the densities are rounded to 0.1 kg/m3, so the sequence is deterministic).

Outputs in out_dir (default runs/density/<material>/):
  history.csv          iteration, particle density, bulk density mean/std, seeds, misfit
  result.yaml          calibrated particle density, solid fraction, particle count, ...
  bulk_density.png     bulk density (mean +/- std) per iteration with the lab target band
"""
import csv
import math
import os
import time
import warnings
from dataclasses import dataclass, field, asdict
from pathlib import Path

import yaml

from .. import CONFIG_DIR, REPO_ROOT
from ..configs import load_material
from ..errors import ConfigError
from ..jobs import resolve_job
from ..post import mean_std

DENSITY_KEY = "particles.density_kg_m3"
RIG = "fill"

# Lab bulk densities (kg/m3) of the lab samples, un-compacted (labresults/samples.yaml,
# lab-tests.md). Fallback only: pycal.labdata is the source once it is available.
LAB_BULK_DENSITY_FALLBACK = {
    "gravel_dry": 1603.0,   # M2
    "fines_dry": 1601.0,    # M3-dry
    "fines_wet": 1146.0,    # M3-wet
}


def lab_bulk_density(material_cfg):
    """Lab bulk density (kg/m3) of the material's lab sample (`lab_sample:` key)."""
    key = material_cfg.get("lab_sample")
    if not key:
        raise ConfigError(f"configs/materials/{material_cfg.get('name', '?')}.yaml", "lab_sample",
                          "missing: the density calibration needs the lab sample's bulk density")
    try:
        from .. import labdata
        sample = labdata.sample(key)
        value = sample.get("bulk_density_kg_m3") if isinstance(sample, dict) else \
            getattr(sample, "bulk_density_kg_m3", None)
        if value is not None:
            return float(value)
    except Exception:   # labdata missing or different API: use the fallback below
        pass
    if key not in LAB_BULK_DENSITY_FALLBACK:
        raise ConfigError("labresults/samples.yaml", f"samples.{key}.bulk_density_kg_m3",
                          "no lab bulk density for this sample")
    return LAB_BULK_DENSITY_FALLBACK[key]


@dataclass
class Iteration:
    iteration: int
    particle_density_kg_m3: float
    bulk_density_mean_kg_m3: float
    bulk_density_std_kg_m3: float
    n_seeds: int
    misfit_percent: float
    solid_fraction_mean: float
    n_particles_mean: float


@dataclass
class DensityFit:
    material: str
    lab_sample: str
    target_bulk_density_kg_m3: float
    tolerance_percent: float
    seeds: list
    tolerance_met: bool
    particle_density_kg_m3: float
    solid_fraction: float
    n_particles_mean: float
    bulk_density_mean_kg_m3: float
    bulk_density_std_kg_m3: float
    misfit_percent: float
    standard_error_percent: float
    iterations: int
    wall_time_s: float
    message: str = ""
    history: list = field(default_factory=list)


def update_density(rho_p, bulk_mean, target):
    """One proportional update: rho_p x target / bulk_mean (rounded to 0.1 kg/m3)."""
    if not (bulk_mean > 0 and math.isfinite(bulk_mean)):
        raise ValueError(f"simulated bulk density {bulk_mean!r} is not positive")
    return round(rho_p * target / bulk_mean, 1)


def fit_density(material, seeds=3, tolerance_percent=1.0, max_iterations=5, executor=None,
                out_dir=None, first_seed=1, start_density=None, overrides=None,
                config_dir=CONFIG_DIR, progress=print, target_bulk_density_kg_m3=None):
    """Calibrate the particle density of `material` on the cell fill. Returns DensityFit.

    executor: anything with run(jobs) -> list of result dicts (default LocalPool on runs/).
    overrides: other material/rig overrides kept fixed during the fit.
    target_bulk_density_kg_m3: the bulk density to match (default: the lab sample's).
    """
    t0 = time.time()
    if executor is None:
        from ..runner import LocalPool
        executor = LocalPool()
    if max_iterations < 1:
        raise ConfigError("--max-iterations", "", "must be >= 1")
    if seeds < 1:
        raise ConfigError("--seeds", "", "must be >= 1")
    mat_cfg = load_material(material, config_dir)
    target = (float(target_bulk_density_kg_m3) if target_bulk_density_kg_m3 is not None
              else lab_bulk_density(mat_cfg))
    tol = tolerance_percent / 100.0
    seed_list = list(range(first_seed, first_seed + seeds))
    rho = float(start_density if start_density is not None else mat_cfg["particles"]["density_kg_m3"])
    base = dict(overrides or {})
    history = []
    if progress:
        progress(f"fit-density {material}: lab sample {mat_cfg['lab_sample']}, target bulk density "
                 f"{target:.1f} kg/m3 +/- {tolerance_percent:g} %, seeds {seed_list}")
    for it in range(1, max_iterations + 1):
        ov = dict(base)
        ov[DENSITY_KEY] = rho
        jobs = [resolve_job(RIG, material, ov, seed=s, config_dir=config_dir) for s in seed_list]
        results = executor.run(jobs)
        bulk = [float(r["bulk_density_kg_m3"]) for r in results]
        m, s = mean_std(bulk)
        sf = mean_std([float(r.get("solid_fraction", r["bulk_density_kg_m3"] / rho)) for r in results])[0]
        npart = mean_std([float(r.get("n_particles", float("nan"))) for r in results])[0]
        misfit = (m - target) / target
        history.append(Iteration(it, rho, m, s, len(bulk), 100.0 * misfit, sf, npart))
        if progress:
            progress(f"  iteration {it}: particle density {rho:.1f} kg/m3 -> bulk density "
                     f"{m:.1f} +/- {s:.1f} kg/m3 (n={len(bulk)}), misfit {100 * misfit:+.2f} %")
        if abs(misfit) <= tol:
            break
        rho = update_density(rho, m, target)
    best = min(history, key=lambda h: abs(h.misfit_percent))
    # the iterations aim at the tolerance; the verdict is never tighter than the seed noise
    # (2 standard errors of the best point's mean), as for every other stage (root1d)
    best_error_percent = 100.0 * 2.0 * best.bulk_density_std_kg_m3 / math.sqrt(best.n_seeds) / target \
        if best.n_seeds > 1 else 0.0
    met = abs(best.misfit_percent) <= max(tolerance_percent, best_error_percent) + 1e-12
    msg = ""
    if met and abs(best.misfit_percent) > tolerance_percent:
        msg = (f"met within the seed noise: best misfit {best.misfit_percent:+.2f} % is inside 2 standard "
               f"errors ({best_error_percent:.1f} %) though outside the tolerance {tolerance_percent:g} %")
    elif not met:
        msg = (f"NOT CONVERGED: after {len(history)} iteration(s) the best misfit is {best.misfit_percent:+.2f} % "
               f"(tolerance {tolerance_percent:g} %, 2 standard errors {best_error_percent:.1f} %); the reported "
               f"density is the best point, not a calibrated value")
    fit = DensityFit(material=material, lab_sample=mat_cfg["lab_sample"], target_bulk_density_kg_m3=target,
                     tolerance_percent=tolerance_percent, seeds=seed_list, tolerance_met=met,
                     particle_density_kg_m3=best.particle_density_kg_m3,
                     solid_fraction=best.solid_fraction_mean, n_particles_mean=best.n_particles_mean,
                     bulk_density_mean_kg_m3=best.bulk_density_mean_kg_m3,
                     bulk_density_std_kg_m3=best.bulk_density_std_kg_m3,
                     misfit_percent=best.misfit_percent,
                     standard_error_percent=100.0 * best.bulk_density_std_kg_m3 / math.sqrt(best.n_seeds) / target,
                     iterations=len(history),
                     wall_time_s=round(time.time() - t0, 1), message=msg, history=history)
    if met and fit.standard_error_percent > tolerance_percent and progress:
        progress(f"note: the seed noise (standard error of the mean {fit.standard_error_percent:.1f} %) is larger "
                 f"than the tolerance: more seeds are needed for the match to be significant")
    if not met:
        warnings.warn(msg)
        if progress:
            progress("WARNING: " + msg)
    if out_dir is not None:
        write_outputs(fit, out_dir)
        if progress:
            progress(f"wrote {out_dir}/history.csv, result.yaml, bulk_density.png")
    return fit


HISTORY_COLUMNS = ["iteration", "particle_density_kg_m3", "bulk_density_mean_kg_m3",
                   "bulk_density_std_kg_m3", "n_seeds", "misfit_percent"]


def write_outputs(fit, out_dir):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "history.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(HISTORY_COLUMNS + ["solid_fraction_mean", "n_particles_mean"])
        for h in fit.history:
            w.writerow([h.iteration, f"{h.particle_density_kg_m3:.1f}", f"{h.bulk_density_mean_kg_m3:.2f}",
                        f"{h.bulk_density_std_kg_m3:.2f}", h.n_seeds, f"{h.misfit_percent:.3f}",
                        f"{h.solid_fraction_mean:.4f}", f"{h.n_particles_mean:.1f}"])
    res = {k: v for k, v in asdict(fit).items() if k != "history"}
    res["tolerance_met"] = "yes" if fit.tolerance_met else "no"
    res["calibrated_particle_density_kg_m3"] = res.pop("particle_density_kg_m3")
    res["rig"] = RIG
    res["update_rule"] = "rho_p_new = rho_p x rho_bulk_lab / rho_bulk_sim_mean"
    for k, v in list(res.items()):
        if isinstance(v, float):
            res[k] = round(v, 4)
    tmp = out / "result.yaml.part"
    tmp.write_text(yaml.safe_dump(res, sort_keys=False))
    os.replace(tmp, out / "result.yaml")
    plot_history(fit, out / "bulk_density.png")


def plot_history(fit, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    its = [h.iteration for h in fit.history]
    fig, ax = plt.subplots(figsize=(6, 4))
    t, tol = fit.target_bulk_density_kg_m3, fit.tolerance_percent / 100.0
    ax.axhspan(t * (1 - tol), t * (1 + tol), color="tab:green", alpha=0.25,
               label=f"lab {fit.lab_sample}: {t:.0f} kg/m3 +/- {fit.tolerance_percent:g} %")
    ax.axhline(t, color="tab:green", lw=1)
    ax.errorbar(its, [h.bulk_density_mean_kg_m3 for h in fit.history],
                yerr=[h.bulk_density_std_kg_m3 for h in fit.history], fmt="o-", capsize=4,
                label=f"simulated cell fill (mean +/- std, {len(fit.seeds)} seeds)")
    for h in fit.history:
        ax.annotate(f"{h.particle_density_kg_m3:.0f}", (h.iteration, h.bulk_density_mean_kg_m3),
                    textcoords="offset points", xytext=(6, -12), fontsize=8)
    ax.set_xlabel("iteration (label: particle density, kg/m3)")
    ax.set_ylabel("bulk density (kg/m3)")
    ax.set_xticks(its)
    status = "tolerance met" if fit.tolerance_met else "NOT CONVERGED"
    ax.set_title(f"{fit.material}: particle density calibration ({status})")
    ax.legend(fontsize=8, loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def default_out_dir(material, runs_dir=None):
    return Path(runs_dir or (REPO_ROOT / "runs")) / "density" / material
