"""One plot per stage, into <study>/plots/<material>-<stage>/ (paths relative to the study folder).

1-D stage (calibration.png): every run's response against the parameter, the fitted
mean response with its 95 % band, the lab target with its band, and the chosen value
with its 95 % interval. Joint stage: per parameter, every run's outputs as
(response - target) / lab band against it, the fitted curves through the estimate of
the others, the band |z| <= 1; and the parameter plane with the posterior samples,
the points run and the estimate with its intervals. Lab-curve plots (friction or
compression curves at the run point nearest the estimate) come from the response's
own post-processing (pycal.post.responses), whatever the rig is called.
"""
from pathlib import Path

import numpy as np

from ..plotting import pyplot, save_png
from ..stats.inversion import target_factor_95
from .names import fmt3, unit_label


def _plt():
    return pyplot()


def _folder(study, material, label):
    return study.out / "plots" / f"{material}-{label}"


def _rel(study, path):
    return str(Path(path).relative_to(study.out))


def response_axis_label(response):
    """'angle of repose, mean over the pile's sectors (deg)': the response's description
    (pycal.post.responses) and its unit; its name when it has none."""
    text = response.description if response.description and not response.description.startswith("result key") \
        else response.name
    return f"{text} ({response.unit_label})"


def _x_axis(ax, scale, xs):
    """A log axis only where the plotted range spans a decade or more (else linear: a log
    axis over a factor 2 shows two ticks)."""
    from matplotlib.ticker import LogLocator, ScalarFormatter
    lo, hi = float(np.min(xs)), float(np.max(xs))
    if scale.log and lo > 0 and hi / lo >= 10:
        ax.set_xscale("log")
        ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(ScalarFormatter())


def stage_1d(study, material, st, row, scale, xs, ys, step, target, response):
    """calibration.png of a one-parameter stage; returns [its path relative to the study]."""
    plt = _plt()
    p = row["parameters"][0]
    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    u = scale.to_unit(np.r_[xs, p["low"], p["high"]])
    lo_u, hi_u = max(0.0, float(np.min(u)) - 0.05), min(1.0, float(np.max(u)) + 0.05)
    grid_u = np.linspace(lo_u, hi_u, 200)
    mean, var = step.model.mean_var(grid_u[:, None])
    grid_x = scale.from_unit(grid_u)
    fig, ax = plt.subplots(figsize=(7.5, 4.4))
    if target.band > 0:
        ax.axhspan(target.value - target.band, target.value + target.band, color="tab:green", alpha=0.18,
                   label=f"lab target {fmt3(target.value)} +- {fmt3(target.band)}")
    ax.axhline(target.value, color="tab:green", lw=1.2, label=None if target.band > 0 else f"target {fmt3(target.value)}")
    if target.standard_error > 0:        # the target is itself a mean (a twin's): its own 95 % range
        half = target.standard_error * target_factor_95(target.standard_error_dof)
        n = target.standard_error_seeds_count
        ax.axhline(target.value - half, color="tab:green", lw=0.9, ls="--",
                   label=f"target's own 95 % range +- {half:.3g}" + (f" (mean of {n} seeds)" if n else ""))
        ax.axhline(target.value + half, color="tab:green", lw=0.9, ls="--")
    ax.fill_between(grid_x, mean - 1.96 * np.sqrt(var), mean + 1.96 * np.sqrt(var), color="tab:blue", alpha=0.2,
                    label="fitted mean response, 95 % band")
    ax.plot(grid_x, mean, color="tab:blue", lw=1.5)
    ax.plot(xs, ys, "o", ms=4, color="k", alpha=0.6,
            label=f"runs ({len(ys)}: every seed; seed noise sd {fmt3(step.model.noise_sd)})")
    ax.axvspan(p["low"], p["high"], color="tab:red", alpha=0.15, label=f"95 % interval [{fmt3(p['low'])}, {fmt3(p['high'])}]")
    ax.axvline(p["estimate"], color="tab:red", lw=1.5, label=f"chosen {fmt3(p['estimate'])}")
    _x_axis(ax, scale, grid_x)
    ax.set_xlabel(f"{p['label']} ({unit_label(p['unit'])})")
    ax.set_ylabel(response_axis_label(response))
    verdict = "met" if row["met"] else "NOT met"
    ax.set_title(f"{material} {st['label']}: {verdict} - {row['stop_reason']}", fontsize=10)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    path = save_png(fig, _folder(study, material, st["label"]) / "calibration.png")
    plt.close(fig)
    return [_rel(study, path)]


def stage_joint(study, material, st, row, scales, X, Y, step, tgts, widths, resp):
    """calibration.png of a joint stage; returns [its path relative to the study]."""
    plt = _plt()
    params = row["parameters"]
    d = len(params)
    # every output as (value - target) / scale: its lab band, else its seed noise
    names, t_out, s_out = [], [], []
    for t, w, r in zip(tgts, widths, resp):
        for e in range(w):
            names.append(r.name + (f"[{e}]" if r.vector else ""))
            t_out.append(t.value)
            s_out.append(t.band)
    for k, m in enumerate(step.models):
        if not s_out[k] > 0:
            s_out[k] = m.noise_sd or 1.0
    est_u = np.array([float(s.to_unit(p["estimate"])) for s, p in zip(scales, params)])
    fig, axes = plt.subplots(1, d + 1, figsize=(4.2 * (d + 1), 4.0))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for j, (ax, p, s) in enumerate(zip(axes, params, scales)):
        ax.axhspan(-1, 1, color="tab:green", alpha=0.15, label="lab band")
        ax.axhline(0, color="tab:green", lw=1)
        u_runs = s.to_unit(X[:, j])
        grid_u = np.linspace(max(0.0, u_runs.min() - 0.05), min(1.0, u_runs.max() + 0.05), 120)
        U = np.repeat(est_u[None, :], len(grid_u), axis=0)
        U[:, j] = grid_u
        for k, m in enumerate(step.models):
            c = colors[k % len(colors)]
            ax.plot(X[:, j], (Y[:, k] - t_out[k]) / s_out[k], "o", ms=3, color=c, alpha=0.5)
            mean, var = m.mean_var(U)
            z, dz = (mean - t_out[k]) / s_out[k], 1.96 * np.sqrt(var) / s_out[k]
            ax.plot(s.from_unit(grid_u), z, color=c, lw=1.3, label=names[k])
            ax.fill_between(s.from_unit(grid_u), z - dz, z + dz, color=c, alpha=0.12)
        ax.axvspan(p["low"], p["high"], color="tab:red", alpha=0.12)
        ax.axvline(p["estimate"], color="tab:red", lw=1.3)
        if s.log:
            ax.set_xscale("log")
        ax.set_xlabel(f"{p['label']} ({unit_label(p['unit'])})", fontsize=8)
        ax.set_ylabel("(response - target) / lab band" if j == 0 else "")
        ax.set_title(f"{fmt3(p['estimate'])} [{fmt3(p['low'])}, {fmt3(p['high'])}]", fontsize=9)
        if j == 0:
            ax.legend(fontsize=6, loc="best")
    ax = axes[-1]
    S = step.samples
    ax.plot(S[:, 0], S[:, 1], ".", ms=1, color="tab:blue", alpha=0.3, label="posterior samples")
    ax.plot(X[:, 0], X[:, 1], "kx", ms=6, label="points run")
    ax.errorbar([params[0]["estimate"]], [params[1]["estimate"]],
                xerr=[[params[0]["estimate"] - params[0]["low"]], [params[0]["high"] - params[0]["estimate"]]],
                yerr=[[params[1]["estimate"] - params[1]["low"]], [params[1]["high"] - params[1]["estimate"]]],
                fmt="o", color="tab:red", capsize=4, label="estimate, 95 % intervals")
    if scales[0].log:
        ax.set_xscale("log")
    if scales[1].log:
        ax.set_yscale("log")
    ax.set_xlabel(params[0]["label"], fontsize=8)
    ax.set_ylabel(params[1]["label"], fontsize=8)
    ax.set_title(f"correlation {step.correlation[0][1]:+.2f}", fontsize=9)
    ax.legend(fontsize=6, loc="best")
    fig.suptitle(f"{material} {st['label']}: {'met' if row['met'] else 'NOT met'} - {row['stop_reason']}",
                 fontsize=10)
    fig.tight_layout()
    path = save_png(fig, _folder(study, material, st["label"]) / "calibration.png")
    plt.close(fig)
    return [_rel(study, path)]


def lab_curves(study, material, label, rig, extra, response, lab_dir):
    """The response's lab-curve plots at the point run nearest the chosen value
    (its own post-processing); [] when the response has none."""
    if response.lab_plots is None:
        return []
    results, _ = study.nearest_point_results(material, label, rig, extra)
    if not results:
        return []
    out = _folder(study, material, label) / rig
    files = response.lab_plots(results, out, lab_dir)
    return [_rel(study, f) for f in files if str(f).endswith(".png")]
