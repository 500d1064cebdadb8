"""The study report: one self-contained HTML page (plots embedded) from a study folder.

Reads <study>/summary.json (pycal.calibration.outputs) and the stage plots. Laid out
for a laptop screen: per material a table with one row per calibrated parameter group
(named, e.g. "rolling resistance (M2, steel, PVC)"): estimate, 95 % interval,
tolerance, runs and the stop reason; then per stage its calibration plot and lab
curves. The headline counts a stage as met only when its 95 % interval lies within its
tolerance. Provenance closes the page: git commit, the YADE versions that ran, seeds.
"""
import base64
import html
import json
import math
from pathlib import Path

from .calibration.names import fmt3, format_params, unit_label
from .calibration.stages import calibrates
from .calibration.study import cost_per_material
from .files import write_text

CSS = """
body{font-family:system-ui,sans-serif;max-width:1180px;margin:0 auto;padding:0 16px;color:#222;line-height:1.35}
h1{font-size:22px}h2{font-size:18px;margin-top:28px;border-bottom:1px solid #ccc}h3{font-size:15px;margin-bottom:4px}
table{border-collapse:collapse;width:100%;margin:6px 0 12px}
td,th{border:1px solid #ccc;padding:3px 6px;font-size:13px;text-align:left;vertical-align:top}
th{background:#f2f2f2}td.num{text-align:right;white-space:nowrap}tr.mat td{background:#e8eef6;font-weight:bold}
.no{color:#b00;font-weight:bold}.yes{color:#070;font-weight:bold}.muted{color:#666;font-size:12px}
img{max-width:100%;height:auto;border:1px solid #eee}details{margin:8px 0}pre{font-size:11px;overflow-x:auto}
"""


def _num(v, unit=""):
    """A number for a table: 3 significant digits (no exponent between 1e-3 and 1e6), its
    unit after it."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return _esc(v)
    text = fmt3(v)
    u = unit_label(unit) if unit else ""
    return text + (f" {u}" if u and u != "-" else "")


def _esc(v):
    return html.escape(str(v))


def _img(study_dir, rel):
    data = base64.b64encode((study_dir / rel).read_bytes()).decode()
    return f"<img alt='{_esc(rel)}' src='data:image/png;base64,{data}'>"


def headline(stages):
    """'3 of 5 calibrated stages met ...' and the stages not met (inherited values apart)."""
    calibrated = [s for s in stages if calibrates(s["kind"])]
    met = [s for s in calibrated if s["met"]]
    lab = [s for s in calibrated if s.get("matches_lab")]
    text = (f"{len(met)} of {len(calibrated)} calibrated stages are precise enough (the whole 95 % interval "
            f"within ± tolerance of the estimate); {len(lab)} match the lab (the fitted response at the "
            f"estimate within the lab band).")
    inherited = [s for s in stages if not calibrates(s["kind"])]
    if inherited:
        text += f" {len(inherited)} value{'s' if len(inherited) > 1 else ''} inherited from other materials."
    return text, [s for s in calibrated if not s["met"]]


def _stage_table(stages):
    head = ("<table><tr><th>stage</th><th>parameter</th><th>estimate</th><th>95 % interval</th>"
            "<th>tolerance</th><th>runs</th><th>matches the lab</th><th>precise enough</th></tr>")
    rows, material = [head], None
    for s in stages:
        if s["material"] != material:
            material = s["material"]
            rows.append(f"<tr class='mat'><td colspan='8'>{_esc(material)}</td></tr>")
        lab = s.get("matches_lab")
        matches = ("<span class='muted'>no band</span>" if lab is None else
                   f"<span class='{'yes' if lab else 'no'}'>{'yes' if lab else 'no'}</span>")
        verdict = (f"<span class='{'yes' if s['met'] else 'no'}'>{'yes' if s['met'] else 'no'}</span>"
                   f"<br><span class='muted'>{_esc(s['stop_reason'])}</span>")
        params = s["parameters"] or [None]
        for i, p in enumerate(params):
            cells = [_esc(s["stage"]) if i == 0 else ""]
            if p is None:
                cells += [f"<span class='muted'>{_esc(s.get('message', ''))}</span>", "-", "-", "-"]
            else:
                cells += [_esc(p["label"]), _num(p["estimate"], p["unit"]),
                          f"{_num(p['low'])} - {_num(p['high'], p['unit'])}", "± " + _num(p["tolerance"], p["unit"])]
            cells += [str(s.get("runs_requested", "")) if i == 0 else "", matches if i == 0 else "",
                      verdict if i == 0 else ""]
            rows.append("<tr>" + "".join(f"<td{' class=num' if k in (2, 3, 4, 5) else ''}>{c}</td>"
                                         for k, c in enumerate(cells)) + "</tr>")
    rows.append("</table>")
    return "\n".join(rows)


def _points_table(points):
    """The stage's points: parameter values, seeds, mean and seed SD of the response."""
    if not points:
        return ""
    rows = "".join(
        f"<tr><td>{_esc(format_params(p['parameters']))}</td><td>{_esc(p['rig'])}</td>"
        f"<td class=num>{', '.join(str(x) for x in p.get('seeds') or [])}</td>"
        f"<td class=num>{_num(p['mean'])}</td><td class=num>{_num(p['std'])}</td></tr>" for p in points)
    return ("<details><summary>points run (in order)</summary><table><tr><th>point</th><th>rig</th><th>seeds</th>"
            f"<th>mean response</th><th>seed SD</th></tr>{rows}</table></details>")


def _stage_detail(study_dir, s, history=()):
    on_set = f" (runs on the material set {_esc(s['material_set'])})" if s.get("material_set") else ""
    parts = [f"<h3>{_esc(s['material'])}: {_esc(s['stage'])}{on_set}</h3>"]
    lines = []
    for r in s.get("responses") or []:
        if "at_estimate" not in r:
            continue
        unit = r.get("unit", "")
        band = f", lab band ± {_num(r['band'], unit)}" if r.get("band") else ""
        se = f", its standard error {_num(r['standard_error'], unit)}" if r.get("standard_error") else ""
        lines.append(f"{_esc(r['response'])}: fitted mean at the estimate {_num(r['at_estimate'])} ± "
                     f"{_num(1.96 * (r.get('at_estimate_sd') or 0), unit)} (95 %); target {_num(r['target'], unit)}"
                     f"{band}{se} ({_esc(r.get('target_source', ''))}); seed noise sd {_num(r.get('noise_sd'), unit)}")
    if s.get("correlation") and len(s["parameters"]) > 1:
        names = [p["label"] for p in s["parameters"]]
        pairs = [f"{names[i]} / {names[j]}: {s['correlation'][i][j]:+.2f}"
                 for i in range(len(names)) for j in range(i + 1, len(names))]
        lines.append("posterior correlation: " + "; ".join(_esc(p) for p in pairs))
    lines.append(f"{s.get('points_count', 0)} points, {s.get('runs_requested', 0)} runs requested "
                 f"({s.get('runs_simulated', 0)} simulated), {s.get('elapsed_s', 0):.0f} s; "
                 f"{_esc(s['stop_reason'])}: {_esc(s.get('message', ''))}")
    parts.append("<ul>" + "".join(f"<li>{line}</li>" for line in lines) + "</ul>")
    parts.append(_held_table(s.get("held")))
    parts.append(_gallery(study_dir, s.get("gallery")))
    parts.append(_aor_seeds(s.get("aor_seeds")))
    for f in s.get("plots") or []:
        if not (study_dir / f).is_file():
            raise FileNotFoundError(f"{study_dir / f}: a plot named in summary.json is missing")
        parts.append(_img(study_dir, f))
    parts.append(_points_table([p for p in history if p["material"] == s["material"] and p["stage"] == s["stage"]]))
    return "\n".join(parts)


def _held_table(held):
    """The values the stage held while it fitted its own, with where they came from."""
    if not held:
        return "<p class='muted'>held values: none (no other calibrated value of this material)</p>"
    rows = "".join(f"<tr><td>{_esc(h['key'])}</td><td class=num>"
                   f"{_num(h['value']) if isinstance(h['value'], (int, float)) else _esc(h['value'])}</td>"
                   f"<td>{_esc(h['source'])}</td></tr>" for h in held)
    return ("<details open><summary>held values (not fitted in this stage)</summary><table><tr><th>key</th>"
            f"<th>value</th><th>from</th></tr>{rows}</table></details>")


def _gallery(study_dir, pictures):
    """The stage's simulated samples (pycal.calibration.gallery), small, with captions."""
    if not pictures:
        return ""
    cells = "".join(f"<figure style='display:inline-block;width:32%;margin:0 1% 8px 0;vertical-align:top'>"
                    f"{_img(study_dir, p['file'])}<figcaption class='muted'>{_esc(p['caption'])}</figcaption>"
                    "</figure>" for p in pictures if (study_dir / p["file"]).is_file())
    return f"<details open><summary>simulated samples</summary>{cells}</details>"


def _angle_cell(x, key):
    """A seed's value of `key` for a table (3 significant digits, deg for a *_deg key),
    with '?' when the run flagged that side's flank fit as doubtful (x['flank_flags'],
    pycal/post/aor.py)."""
    flag = (x.get("flank_flags") or {}).get(key.replace("aor_", "").replace("_deg", ""))
    return _num(x.get(key), "deg" if key.endswith("_deg") else "") + ("?" if flag else "")


def _flags_cell(x):
    """A seed's doubtful flank fits as text, '-' for none."""
    return _esc("; ".join(f"{k}: {v}" for k, v in (x.get("flank_flags") or {}).items()) or "-")


def _aor_seeds(a):
    """The pile as the lab reads it: per seed left / right / front / back at the point nearest
    the estimate, and the lab's left / right."""
    if not a or not a.get("seeds"):
        return ""
    head = ("<table><tr><th>seed</th><th>left</th><th>right</th><th>front</th><th>back</th><th>mean of the sides "
            "with an angle</th><th>sides</th><th>doubtful flank fits (kept in the mean)</th></tr>")
    rows = "".join("<tr>" + "".join(f"<td class=num>{c}</td>" for c in (
        x["seed"], *(_angle_cell(x, f"aor_{side}_deg") for side in ("left", "right", "front", "back")),
        _num(x["aor_mean_deg"], "deg"), x.get("aor_sectors_count", "-"))) + f"<td>{_flags_cell(x)}</td></tr>"
                   for x in a["seeds"])
    lab = a.get("lab")
    if lab:
        rows += (f"<tr><td>lab ({_esc(lab['sample'])})</td><td class=num>{_num(lab['left_deg'], 'deg')}</td>"
                 f"<td class=num>{_num(lab['right_deg'], 'deg')}</td><td>-</td><td>-</td><td>-</td><td>-</td><td>-</td></tr>")
    at = a["point"]
    return (f"<details open><summary>the pile per seed at the point nearest the estimate ({_esc(at)}), "
            f"as the lab reads it</summary>{head}{rows}</table></details>")


def _provenance_items(summary):
    """<li> lines of the provenance block (pycal.calibration.provenance)."""
    p = summary.get("provenance") or {}
    libs = ", ".join(f"{k} {v}" for k, v in (p.get("libraries") or {}).items())
    dirty = p.get("git_dirty")
    return "".join(f"<li>{_esc(k)}: {_esc(v)}</li>" for k, v in [
        ("started", p.get("started_utc", "not recorded")), ("host", p.get("host", "not recorded")),
        ("command", p.get("command", "not recorded")),
        ("git commit", f"{summary.get('git_commit', 'unknown')}"
                       + ("" if dirty is None else " (uncommitted changes)" if dirty else " (clean)")),
        ("YADE of the runs", ", ".join(summary.get("yade_versions") or []) or "not recorded"),
        ("libraries", libs or "not recorded"),
        ("lab files", f"{p.get('lab_files_count', '?')} files, SHA-256 {p.get('lab_files_sha256', '?')}"),
        ("study config", f"{summary.get('config_file', '')}, SHA-256 {p.get('study_config_sha256', '?')}")])


def _validation(study_dir, rows):
    """The 'predicted' section: tests the calibration never saw, run with the calibrated values."""
    if not rows:
        return []
    parts = ["<h2>Predicted (validation: nothing fitted to these tests)</h2>",
             "<table><tr><th>prediction</th><th>response</th><th>predicted (mean +- SD, n)</th><th>lab +- band</th>"
             "<th>z</th><th>verdict</th></tr>"]
    for r in rows:
        if r.get("error"):
            parts.append(f"<tr><td>{_esc(r['prediction'])}</td><td colspan=5>runs failed: {_esc(r['error'])}</td></tr>")
            continue
        for c in r["comparisons"]:
            lab = "-" if c["lab"] is None else f"{_num(c['lab'])} +- {_num(c['band'])}"
            parts.append(f"<tr><td>{_esc(r['prediction'])} ({_esc(r['material'])}, {_esc(r['rig'])})</td>"
                         f"<td>{_esc(c['response'])}</td><td class=num>{_num(c['sim_mean'])} +- {_num(c['sim_sd'])} "
                         f"({c['n']})</td><td class=num>{lab}</td><td class=num>{_num(c['z'])}</td>"
                         f"<td>{'inside the lab band' if c['inside'] else 'missed'}</td></tr>")
    parts.append("</table>")
    for r in rows:
        parts += _sensitivity_section(study_dir, r)
        if r.get("plot") and (study_dir / r["plot"]).is_file():
            parts.append(_img(study_dir, r["plot"]))
        parts.append(_seed_values(r))
        parts.append(_gallery(study_dir, r.get("gallery")))
    return parts


def _seed_values(r):
    """A prediction's compared responses per seed beside the lab's values (a '?' marks a
    doubtful flank fit, pycal/post/aor.py)."""
    seeds = r.get("seed_values") or []
    responses = [c["response"] for c in r.get("comparisons") or [] if any(c["response"] in x for x in seeds)]
    if not seeds or not responses:
        return ""
    labs = {c["response"]: c["lab"] for c in r["comparisons"]}
    head = "".join(f"<th>{_esc(k)}</th>" for k in responses)
    rows = "".join(f"<tr><td>{x['seed']}</td>" + "".join(f"<td class=num>{_angle_cell(x, k)}</td>" for k in responses)
                   + f"<td>{_flags_cell(x)}</td></tr>" for x in seeds)
    rows += "<tr><td>lab</td>" + "".join(f"<td class=num>{_num(labs.get(k))}</td>" for k in responses) + "<td>-</td></tr>"
    return (f"<details><summary>{_esc(r['prediction'])} per seed</summary><table><tr><th>seed</th>{head}"
            f"<th>doubtful flank fits</th></tr>{rows}</table></details>")


def _run_at_checks(rows):
    """Stages that ran at other material values (run_at), checked at the calibrated ones."""
    if not rows:
        return []
    parts = ["<h2>Stages run at other values, checked with the calibrated set</h2>",
             "<p>These stages ran at the values in <code>run_at</code> (a cheaper stiffness the response was "
             "measured not to depend on); here their response with the final calibrated set at the calibrated "
             "values, beside the stage's model at its estimate and the target.</p>",
             "<table><tr><th>material / stage</th><th>response</th><th>ran at</th><th>checked at</th>"
             "<th>check: mean +- SD (n)</th><th>stage model at the estimate</th><th>target +- band</th></tr>"]
    for r in rows:
        fmt = lambda d: ", ".join(f"{k.split('.')[-1]} {_num(v)}" for k, v in d.items())   # noqa: E731
        check = f"{_num(r['value_mean'])} +- {_num(r['value_sd'])} ({r['n']})" if r["n"] else \
            f"no value ({_esc(r.get('error') or '')})"
        parts.append(f"<tr><td>{_esc(r['material'])} / {_esc(r['stage'])}</td><td>{_esc(r['response'])}</td>"
                     f"<td>{_esc(fmt(r['run_at']))}</td><td>{_esc(fmt(r['calibrated_at']))}</td>"
                     f"<td class=num>{check}</td><td class=num>{_num(r['stage_at_estimate'])}</td>"
                     f"<td class=num>{_num(r['target'])} +- {_num(r['band'])}</td></tr>")
    return parts + ["</table>"]


def _application(study_dir, rows):
    """The 'application' section: design runs with the calibrated values (no lab test)."""
    if not rows:
        return []
    parts = ["<h2>Application (design runs with the calibrated values; no lab test behind them)</h2>",
             "<table><tr><th>run</th><th>response</th><th>seed mean +- SD (n)</th></tr>"]
    for r in rows:
        head = f"{_esc(r['name'])} ({_esc(r['material'])}, {_esc(r['rig'])})"
        if r.get("error"):
            parts.append(f"<tr><td>{head}</td><td colspan=2>runs failed: {_esc(r['error'])}</td></tr>")
            continue
        for s in r["responses"]:
            value = (f"{s['true_count']} of {s['n']} seeds" if s["kind"] == "flag"
                     else f"{_num(s['mean'])} +- {_num(s['sd'])} ({s['n']})")
            parts.append(f"<tr><td>{head}</td><td>{_esc(s['response'])}</td><td class=num>{value}</td></tr>")
    parts.append("</table>")
    plots = sorted({r["plot"] for r in rows if r.get("plot")})
    parts += [_img(study_dir, p) for p in plots if (study_dir / p).is_file()]
    return parts


def write_report(study_dir):
    """Write <study_dir>/report.html from summary.json and the plots; returns its path."""
    study_dir = Path(study_dir)
    summary = json.loads((study_dir / "summary.json").read_text())
    stages, cfg = summary["stages"], summary["study"]
    text, not_met = headline(stages)
    versions = ", ".join(summary.get("yade_versions") or []) or "not recorded in the results read"
    parts = ["<!doctype html><html><head><meta charset='utf-8'>"
             "<meta name='viewport' content='width=device-width, initial-scale=1'>"
             f"<title>Calibration {_esc(cfg['name'])}</title><style>{CSS}</style></head><body>",
             f"<h1>DEM calibration: {_esc(cfg['name'])}</h1>",
             f"<p>{_esc(cfg.get('description', ''))}</p>",
             f"<p><b>{_esc(text)}</b></p>"]
    if not_met:
        parts.append("<p>Not met: " + "; ".join(f"{_esc(s['material'])} {_esc(s['stage'])} "
                                                 f"({_esc(s['stop_reason'])})" for s in not_met) + ".</p>")
    parts.append(f"<p class='muted'>{summary['runs_requested']} runs requested (cached runs are not simulated "
                 f"again), {summary['elapsed_s']:.0f} s; seeds from {summary['seed_base']}, "
                 f"{len(summary['seeds'])} per point, none used twice in a stage; YADE {_esc(versions)}.</p>")
    parts += ["<h2>Calibrated parameters</h2>", _stage_table(stages)]
    parts.append("<h2>Cost per material</h2><table><tr><th>material</th><th>runs requested</th>"
                 "<th>runs simulated</th><th>wall time s</th></tr>")
    for mat, c in cost_per_material(stages).items():
        parts.append(f"<tr><td>{_esc(mat)}</td><td class=num>{c['runs_requested']}</td>"
                     f"<td class=num>{c['runs_simulated']}</td><td class=num>{c['elapsed_s']:.0f}</td></tr>")
    parts.append("</table><h2>Stages</h2>")
    parts += [_stage_detail(study_dir, s, summary.get("history") or []) for s in stages if calibrates(s["kind"])]
    parts += _run_at_checks(summary.get("run_at_checks") or [])
    parts += _validation(study_dir, summary.get("predicted") or [])
    parts += _application(study_dir, summary.get("applied") or [])
    parts.append("<h2>Calibrated material files</h2>")
    for mat, ov in summary["overrides"].items():
        iv = summary.get("intervals", {}).get(mat, {})
        src = (summary.get("value_sources") or {}).get(mat, {})
        parts.append(f"<h3>{_esc(mat)}</h3><p class='muted'>calibrated/{_esc(mat)}.yaml (loads as a material "
                     f"config); calibrated/{_esc(mat)}.calibration.yaml: intervals, stages, start values, commit</p>"
                     "<table><tr><th>config key</th><th>value</th><th>95 % interval</th><th>stage</th></tr>")
        for k, v in ov.items():
            rng = iv.get(k)
            shown = f"{_num(rng[1])} - {_num(rng[2])}" if rng else ""
            if isinstance(v, dict):       # a law with its settings (a cohesion model): one line each, it wraps
                cell = "<td>" + "<br>".join(f"{_esc(a)}: {_esc(b)}" for a, b in v.items()) + "</td>"
            else:
                cell = f"<td class=num>{_num(v) if isinstance(v, (int, float)) else _esc(v)}</td>"
            parts.append(f"<tr><td>{_esc(k)}</td>{cell}<td class=num>{shown}</td><td>{_esc(src.get(k, ''))}</td></tr>")
        parts.append("</table>")
    parts.append("<h2>Provenance</h2><ul>" + _provenance_items(summary)
                 + f"<li>seeds {summary['seed_base']}, "
                 f"{summary['seed_base'] + 1}, ... (--seed-base)</li>"
                 "<li>every run's result.json (under the runs directory) holds its job, seed, YADE version and git "
                 "commit; runs.csv lists every run of the study</li></ul>"
                 f"<details><summary>study config</summary><pre>{_esc(json.dumps(cfg, indent=1))}</pre></details>"
                 "</body></html>")
    return write_text(study_dir / "report.html", "\n".join(parts))


def _sensitivity_section(study_dir, r):
    """What drives a prediction's miss: the latest `pycal sensitivity` output of it, if
    any (screening first), else the command that finds it."""
    for design in ("screening", "one-at-a-time"):
        path = study_dir / f"sensitivity-{r['prediction']}-{design}.json"
        if path.is_file():
            data = json.loads(path.read_text())
            parts = [f"<p>{_esc(r['prediction'])}: what drives {_esc(data['response'])} ({_esc(design)} design, "
                     f"each value x{1 + data['relative_step_fraction']:g}, +- its standard error; "
                     f"<code>{_esc(path.name)}</code>):</p><ul>"]
            for x in data["factors"][:6]:
                eff = "no result" if x.get("effect") is None else f"{x['effect']:+.3g}"
                if x.get("effect") is not None and x.get("effect_se") is not None:
                    eff += f" +- {x['effect_se']:.2g}"
                    if abs(x["effect"]) < 2 * x["effect_se"]:
                        eff += " (within 2 standard errors of 0: seed noise)"
                parts.append(f"<li>{_esc(x['label'])} {_num(x['value'])} -> {_num(x['moved_to'])}: {eff}</li>")
            parts.append("</ul>")
            plot = Path("plots") / f"sensitivity-{r['prediction']}-{design}.png"
            if (study_dir / plot).is_file():
                parts.append(_img(study_dir, str(plot)))
            return parts
    if r.get("sensitivity_command"):
        return [f"<p>{_esc(r['prediction'])} missed; what drives the miss: <code>{_esc(r['sensitivity_command'])}"
                f"</code> (not part of the main job)</p>"]
    return []
