"""The study report: one self-contained HTML page (plots embedded) from a study folder.

Reads <study>/summary.json (written by pycal.calibration.study) and draws, per stage,
the response of every evaluated point against its lab target and tolerance band, and
the parameter history. Calibrated values are tabulated per material with the spread
over seeds; provenance (config, seeds, YADE version, git commit) closes the page.
"""
import base64
import html
import io
import json
import math
import os
import subprocess
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from . import REPO_ROOT  # noqa: E402
from .calibration.study import row_values, cost_per_material  # noqa: E402


def _png_b64(fig):
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode()


def stage_figure(stage, history):
    """Response per evaluation with the target band, and the parameter per evaluation."""
    pts = [h for h in history if h["material"] == stage["material"] and h["stage"] == stage["stage"]]
    if not pts:
        return None
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.2))
    it = list(range(1, len(pts) + 1))
    ax1.errorbar(it, [p["mean"] for p in pts], yerr=[p["std"] for p in pts], fmt="o-", capsize=3,
                 label="simulation (mean +/- std over seeds)")
    tgt, tol = stage.get("target"), stage.get("tolerance")
    if isinstance(tgt, (int, float)) and not math.isnan(tgt):
        ax1.axhline(tgt, color="k", lw=1, label="lab target")
        if isinstance(tol, (int, float)) and not math.isnan(tol):
            ax1.axhspan(tgt - tol, tgt + tol, color="0.85", label="tolerance")
    ax1.set_xlabel("evaluation")
    ax1.set_ylabel(stage.get("response") or "response")
    ax1.set_title(f"{stage['material']}: {stage['stage']}")
    ax1.legend(fontsize=7)
    for key in sorted({k for p in pts for k in p["parameters"] if not k.startswith("rig.")}):
        label = key.replace("interactions.", "").replace("_coefficient", "")
        ax2.plot(it, [p["parameters"].get(key, math.nan) for p in pts], "s-", label=label)
    ax2.set_xlabel("evaluation")
    ax2.set_ylabel("parameter value")
    ax2.legend(fontsize=7)
    fig.tight_layout()
    return _png_b64(fig)


def _git_commit():
    try:
        return subprocess.run(["git", "-C", str(REPO_ROOT), "rev-parse", "HEAD"], capture_output=True,
                              text=True, timeout=10).stdout.strip() or "unknown"
    except Exception:
        return "unknown"


def _fmt(v):
    if isinstance(v, float):
        return "" if math.isnan(v) else f"{v:.4g}"
    return html.escape(str(v))


def write_report(study_dir, yade_version="unknown"):
    """Write <study_dir>/report.html; returns its path."""
    study_dir = Path(study_dir)
    summary = json.loads((study_dir / "summary.json").read_text())
    stages, history = summary["stages"], summary["history"]
    cfg = summary["study"]
    met = sum(1 for s in stages if s["met"])
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>Calibration {html.escape(cfg['name'])}"
             "</title><style>body{font-family:sans-serif;max-width:1000px;margin:auto}"
             "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:3px 7px;font-size:13px}"
             ".no{color:#b00;font-weight:bold}.yes{color:#070}</style></head><body>",
             f"<h1>DEM calibration: {html.escape(cfg['name'])}</h1>",
             f"<p>{html.escape(cfg.get('description', ''))}</p>",
             f"<p><b>{met} of {len(stages)} stage targets met.</b> Runs requested: "
             f"{summary['runs_requested']} (cached runs are not simulated again); "
             f"elapsed {summary['elapsed_s']:.0f} s; {cfg['seeds_count']} seeds per point.</p>",
             "<h2>Stages</h2><table><tr><th>material</th><th>stage</th><th>parameter</th><th>value</th>"
             "<th>response</th><th>simulated (mean +/- std)</th><th>lab target</th><th>tolerance</th>"
             "<th>met</th><th>note</th></tr>"]
    for s in stages:
        shown = dict(s, value="; ".join(f"{k} = {v:.4g}" for k, v in row_values(s).items())) if s.get("values") else s
        parts.append("<tr>" + "".join(f"<td>{_fmt(shown.get(k, ''))}</td>" for k in
                                      ("material", "stage", "parameter", "value", "response")) +
                     f"<td>{_fmt(s['response_mean'])} +/- {_fmt(s['response_std'])}</td>"
                     f"<td>{_fmt(s['target'])}</td><td>{_fmt(s['tolerance'])}</td>"
                     f"<td class='{'yes' if s['met'] else 'no'}'>{'yes' if s['met'] else 'NO'}</td>"
                     f"<td>{_fmt(s.get('message', ''))}</td></tr>")
    parts.append("</table><h2>Cost per material</h2><p>Runs requested (cached ones included), runs simulated "
                 "by YADE and wall time in the invocation that wrote this report.</p><table><tr><th>material</th>"
                 "<th>runs requested</th><th>runs simulated</th><th>wall time s</th></tr>")
    for mat, c in cost_per_material(stages).items():
        parts.append(f"<tr><td>{html.escape(mat)}</td><td>{c['runs_requested']}</td>"
                     f"<td>{c['runs_simulated']}</td><td>{c['elapsed_s']:.0f}</td></tr>")
    parts.append("</table><h2>Calibrated materials</h2>")
    for mat, ov in summary["overrides"].items():
        parts.append(f"<h3>{html.escape(mat)}</h3><p>file: calibrated/{html.escape(mat)}.yaml</p>"
                     "<table><tr><th>config key</th><th>calibrated value</th></tr>")
        for k, v in ov.items():
            parts.append(f"<tr><td>{html.escape(k)}</td><td>{_fmt(v)}</td></tr>")
        parts.append("</table>")
    parts.append("<h2>Lab vs simulation per stage</h2>")
    for s in stages:
        img = stage_figure(s, history)
        if img:
            parts.append(f"<img alt='{html.escape(s['material'] + ' ' + s['stage'])}' "
                         f"src='data:image/png;base64,{img}'>")
    curves = [(s, f) for s in stages for f in s.get("plots") or [] if (study_dir / f).is_file()]
    if curves:
        parts.append("<h2>Lab curves vs simulation at the calibrated values</h2>")
        for s, f in curves:
            img = base64.b64encode((study_dir / f).read_bytes()).decode()
            parts.append(f"<h4>{html.escape(s['material'] + ': ' + s['stage'])} ({html.escape(f)})</h4>"
                         f"<img alt='{html.escape(f)}' style='max-width:100%' src='data:image/png;base64,{img}'>")
    parts.append("<h2>Provenance</h2><ul>"
                 f"<li>study config: <pre>{html.escape(json.dumps(cfg, indent=1))}</pre></li>"
                 f"<li>git commit: {html.escape(_git_commit())}</li>"
                 f"<li>YADE version: {html.escape(yade_version)}</li>"
                 "<li>every run's result.json (under the runs directory) holds its job, seed, YADE "
                 "version and git commit</li></ul></body></html>")
    path = study_dir / "report.html"
    tmp = Path(str(path) + ".part")
    tmp.write_text("\n".join(parts))
    os.replace(tmp, path)
    return path
