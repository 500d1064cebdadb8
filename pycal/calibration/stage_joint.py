"""A joint stage: 2-3 coupled parameter groups against one or more responses.

E.g. the wet wall friction (fines-steel friction sets the curve's level, the adhesion
its rise with consolidation: one vector response, a band z per lab step), or the final
pass over rolling resistance and particle density (AoR and bulk density: two rigs).

1. the start point and one step per parameter (a tenth of its bounds, inwards): d + 1
   points, each running every response's rig with seeds_count seeds;
2. then, until the stop rule: a response model per output over all runs, the posterior
   over the parameters sampled with emcee, and the point (drawn from the posterior)
   that most shrinks the outputs' uncertainty where the posterior lies
   (pycal.stats.sequential.step_nd).
Reported per parameter: estimate (posterior median), 95 % interval, and the
correlation matrix. A point the rig refuses is not asked again, nor anything closer to
it than half its distance to the nearest point that ran (in u); a refused first step
is tried the other way once. A refused start point (e.g. the final pass starts where the
pile is too flat for an angle, after a friction stage lowered the friction) does not end
the stage: its first steps go on, and the stage fails only when none of them runs.
"""
import json
import math

import numpy as np

from ..errors import BudgetSpent, RunError
from ..post import responses as responses_mod
from ..stats import stopping
from ..stats.scales import Scale, round_significant
from ..stats.sequential import step_nd
from . import plots
from .names import unit_label

FIRST_STEP_U = 0.1      # a tenth of the bounds: a second pass starts from values already close


def shared_runs(responses, extras):
    """Groups of response indices read from the same runs: responses on one rig with the
    same overrides (e.g. aor_mean_deg and surcharge_mean_deg, the pile before and after
    the vibration of one surcharge run), in the order of their first member."""
    groups = {}
    for j, (r, e) in enumerate(zip(responses, extras)):
        groups.setdefault((r["rig"], json.dumps(e, sort_keys=True)), []).append(j)
    return list(groups.values())


class _Design:
    """The points of one joint stage so far (X: parameter values per run, Y: every output per
    run), the points the rig refused and each response's width (outputs per response)."""

    def __init__(self, study, material, st):
        self.study, self.material, self.st = study, material, st
        self.params = st["parameters"]
        self.tgts = study.targets[(material, st["label"])]
        self.resp = [responses_mod.get(r["response"]) for r in st["responses"]]
        self.scales = [Scale(*p["bounds"], log=p["scale"] == "log") for p in self.params]
        self.lab_dir = study.lab_dir(st)
        self.per_point = len(study.seeds) * len(self.resp)
        self.runs_at_start = study.runs_requested
        self.X, self.Y, self.refused = [], [], []
        self.widths = [None] * len(self.resp)          # outputs per response (a vector's length)
        self.jr = study.stage_journal(material, st)

    def runs_left(self):
        return min(self.st["max_runs_count"] - (self.study.runs_requested - self.runs_at_start), self.study.runs_left())

    def extra(self, xs, r):
        e = dict(r["rig_overrides"], **self.st["run_at"])
        for p, x in zip(self.params, xs):
            e.update({k: x for k in p["keys"]})
        return e

    def point(self, xs, replay=False):
        """Run xs; False when the rig refused it."""
        study, st, label, resp, widths = self.study, self.st, self.st["label"], self.resp, self.widths
        xs = [round_significant(x) for x in xs]
        if not replay:
            self.jr.record(xs)
        try:
            cols = [None] * len(resp)
            for group in shared_runs(st["responses"], [self.extra(xs, r) for r in st["responses"]]):
                r0 = st["responses"][group[0]]
                if len(group) == 1:                       # a seed without a value is left out
                    vals_of = [study.run_point(self.material, label, r0["rig"], self.extra(xs, r0), resp[group[0]],
                                               self.lab_dir)]
                else:                                     # a seed without one value keeps the others (NaN there)
                    vals_of = study.run_point_responses(self.material, label, r0["rig"], self.extra(xs, r0),
                                                        [resp[j] for j in group], self.lab_dir)
                for j, vals in zip(group, vals_of):
                    vals = [v if isinstance(v, list) else [v] for v in vals]
                    widths[j] = widths[j] or len(vals[0])
                    cols[j] = [[math.nan if v is None else float(v) for v in row] for row in vals]
        except RunError as exc:
            self.refused.append((xs, str(exc)))
            study.log(f"  the rig refused {xs}: no point near it is asked again")
            return False
        # a seed without a value (e.g. a pile too flat for an angle, left out by run_point, or
        # NaN beside a value of the same run) is a NaN row of that response: each output's
        # model uses its own finite rows
        rows = max(len(c) for c in cols)
        for i in range(rows):
            self.X.append(xs)
            self.Y.append([v for c, w in zip(cols, widths) for v in (c[i] if i < len(c) else [math.nan] * w)])
        return True

    def decide(self, runs):
        # one target per output (a vector response has several), known once a point ran
        tgts, widths = self.tgts, self.widths
        targets = [t.value for t, w in zip(tgts, widths) for _ in range(w)]
        ses = [t.standard_error for t, w in zip(tgts, widths) for _ in range(w)]
        dofs = [t.standard_error_dof for t, w in zip(tgts, widths) for _ in range(w)]
        tols = [(p["tolerance"], p["tolerance_is_percent"]) for p in self.params]
        return step_nd(self.scales, self.X, self.Y, targets, ses, tols, runs_left=runs, runs_per_point=self.per_point,
                       avoid_x=[x for x, _ in self.refused], standard_error_dofs=dofs)

    def first_steps(self, base):
        """One step per parameter from base (a tenth of the bounds, inwards; a refused
        step is tried the other way once)."""
        scales = self.scales
        u0 = [float(s.to_unit(x)) for s, x in zip(scales, base)]
        for j in range(len(self.params)):
            for sign in ((1, -1) if u0[j] <= 0.5 else (-1, 1)):
                u = list(u0)
                u[j] = min(1.0, max(0.0, u[j] + sign * FIRST_STEP_U))
                xs = [round_significant(float(s.from_unit(v))) for s, v in zip(scales, u)]
                if xs in self.X:                          # run already (replayed)
                    break
                if any(xs == r for r, _ in self.refused):  # refused already: the other way
                    continue
                if self.point(xs):
                    break

    def walk(self, x0):
        """The first design around x0, then points where the model says until the stop rule
        (or the budget) stops; the last step, its estimate rounded and journalled."""
        try:
            self.first_steps(x0)
            if not self.X:
                raise RunError(f"no point of the first design ran: {self.refused[0][1]}")
            if len({tuple(x) for x in self.X}) < 2:       # the start was refused: steps from what ran
                self.first_steps(self.X[0])
            while True:
                step = self.decide(self.runs_left())
                if step.stop:
                    break
                self.point(step.next_x)
        except BudgetSpent:
            if len({tuple(x) for x in self.X}) < 2:
                raise
            step = self.decide(0)
            step.stop = stopping.STUDY_BUDGET
        step.estimate = [round_significant(v) for v in step.estimate]
        self.jr.finish({k: getattr(step, k) for k in ("estimate", "low", "high", "tolerance", "correlation", "stop")})
        return step

    def responses_at(self, step, values):
        """Each output's model at the estimate, beside its target (the stage row's responses)."""
        u_est = np.array([[float(s.to_unit(v)) for s, v in zip(self.scales, values)]])
        out_resp, k = [], 0
        for r, response, t, w in zip(self.st["responses"], self.resp, self.tgts, self.widths):
            for e in range(w):
                m = step.models[k] if k < len(step.models) else None
                mean, var = m.mean_var(u_est) if m else (np.array([math.nan]), np.array([math.nan]))
                out_resp.append({"rig": r["rig"], "response": response.name + (f"[{e}]" if response.vector else ""),
                                 "unit": response.unit, "target": t.value, "band": t.band,
                                 "standard_error": t.standard_error, "target_source": t.source,
                                 "at_estimate": float(mean[0]), "at_estimate_sd": float(math.sqrt(var[0])),
                                 "noise_sd": m.noise_sd if m else math.nan, "noise_dof": m.noise_dof if m else 0})
                k += 1
        return out_resp


def run(study, material, st):
    """Run the stage; returns its row."""
    params = st["parameters"]
    study.apply_set(material, st["set"])
    d = _Design(study, material, st)
    while (xs := d.jr.next_recorded()) is not None:        # a resumed study: the same points again
        d.point(xs, replay=True)
    x0 = [study.first_value(material, p) for p in params]
    if not d.X and not d.refused:
        d.point(x0)
    if d.jr.result:
        step = d.decide(0)
        for k, v in d.jr.result.items():                    # the values carried before, exactly
            setattr(step, k, v)
    else:
        step = d.walk(x0)
    values = list(step.estimate)
    for p, v, lo, hi in zip(params, values, step.low, step.high):
        study.set_value(material, p["keys"], v, (v, lo, hi))
    row = {"parameters": [{"label": p["label"], "keys": p["keys"], "unit": p["unit"], "scale": p["scale"],
                           "estimate": v, "low": lo, "high": hi, "tolerance": tol,
                           "band_low": math.nan, "band_high": math.nan}
                          for p, v, lo, hi, tol in zip(params, values, step.low, step.high, step.tolerance)],
           "responses": d.responses_at(step, values), "correlation": step.correlation,
           "met": step.stop == stopping.WITHIN, "stop_reason": step.stop, "points_count": len({tuple(x) for x in d.X}),
           "message": "; ".join(f"{p['label']}: 95 % interval within +-{max(v - lo, hi - v):.3g} "
                                f"{unit_label(p['unit'])} (tolerance +-{tol:.3g})"
                                for p, v, lo, hi, tol in zip(params, values, step.low, step.high, step.tolerance))
           + (("; the rig refused " + ", ".join(str(x) for x, _ in d.refused)) if d.refused else "")}
    row["plots"] = plots.stage_joint(study, material, st, row, d.scales, np.array(d.X), np.array(d.Y), step, d.tgts,
                                     d.widths, d.resp)
    for r, response in zip(st["responses"], d.resp):
        row["plots"] += plots.lab_curves(study, material, st["label"], r["rig"], d.extra(values, r), response,
                                         d.lab_dir)
    return row
