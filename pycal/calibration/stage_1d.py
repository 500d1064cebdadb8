"""A one-parameter stage (density, rolling_resistance, cohesion, stiffness, friction).

1. the start point (seeds_count runs);
2. a second point: a Newton step when physics gives the slope (density: the bulk
   density is proportional to the particle density; a stated response_slope_estimate),
   else a quarter of the bounds towards the target;
3. then, until the stop rule (pycal.stats.stopping) says stop: fit the response model
   to every run so far, invert it for the target (estimate, 95 % interval), and run
   the point that most shrinks the interval (pycal.stats.sequential.step_1d).
A point the rig refuses becomes a limit: the bounds in use end halfway between it and
the nearest point that ran. When the target then lies beyond that limit (the stop rule
says so, or the estimate sits on the limit), the stage probes halfway between the limit
and the refused point (a probe that runs moves the limit out to it, one refused moves it
in), until the gap is below PROBE_GAP_U of the bounds; so does an interval that ends on
such a limit. A stage whose next point has already had REPEAT_RUNS_POINTS points' worth of
runs stops there (stopping.REPEATS): more runs at one value narrow its mean, not the interval.
The calibrated value is the estimate (4 significant digits).
"""
import math

import numpy as np

from ..errors import BudgetSpent, RunError
from ..post import responses as responses_mod
from ..stats import stopping
from ..stats.scales import Scale, round_significant
from ..stats.sequential import second_point_u, step_1d
from . import library_start, plots
from .names import unit_label

PROBE_GAP_U = 0.02     # bisection towards a refused point stops at this gap (fraction of the bounds)
REPEAT_RUNS_POINTS = 3  # a stage stops rather than run a point that has had this many points' worth of runs


def _slope_per_u(st, scale, x0, y0):
    """d response / d u at the start (u: the parameter on [0, 1]) when physics gives it, signed."""
    p = st["parameter"]
    span = (math.log(scale.hi) - math.log(scale.lo)) if scale.log else (scale.hi - scale.lo)
    if st["response_proportional"]:                         # e.g. bulk density proportional to particle density
        slope = y0 * span if scale.log else y0 / x0 * span
    elif p.get("slope"):
        slope = p["slope"] * (x0 * span if scale.log else span)
    else:
        return None
    return slope if p["increasing"] else -slope


def decide_step(p, scale, xs, ys, target, runs_left, runs_per_point, lo_u=0.0, hi_u=1.0, out_of_reach_factor=None):
    """The stage's decision after its runs (xs, ys): step_1d with the stage parameter p's
    tolerance, the Target's value, band and standard error and the stage's
    out_of_reach_factor (None: off) (also bench/stage_replay.py)."""
    return step_1d(scale, xs, ys, target.value, p["increasing"],
                   tolerance=None if p["tolerance_is_percent"] else p["tolerance"],
                   tolerance_percent=p["tolerance"] if p["tolerance_is_percent"] else None,
                   standard_error=target.standard_error, band=target.band, runs_left=runs_left,
                   runs_per_point=runs_per_point, lo_u=lo_u, hi_u=hi_u, standard_error_dof=target.standard_error_dof,
                   out_of_reach_factor=out_of_reach_factor)


class _Walk:
    """The points of one stage so far (xs, ys per run), the points the rig refused and the
    part [lo_u, hi_u] of the bounds in use (on the unit scale): what `run` decides from."""

    def __init__(self, study, material, st):
        self.study, self.material, self.st = study, material, st
        self.p = st["parameter"]
        self.target = study.targets[(material, st["label"])][0]
        self.response = responses_mod.get(st["response"])
        self.scale = Scale(*self.p["bounds"], log=self.p["scale"] == "log")
        self.lab_dir = study.lab_dir(st)
        self.n = len(study.seeds)
        self.runs_at_start = study.runs_requested
        self.xs, self.ys, self.refused = [], [], []
        self.lo_u, self.hi_u = 0.0, 1.0
        self.jr = study.stage_journal(material, st)
        self.from_library = 0                # runs taken from the library (library_start.py)

    def runs_left(self):
        return min(self.st["max_runs_count"] - (self.study.runs_requested - self.runs_at_start), self.study.runs_left())

    def extra(self, x):
        return {**self.st["rig_overrides"], **self.st["run_at"], **{k: x for k in self.p["keys"]}}

    def point(self, x, replay=False):
        """Run x; False when the rig refused it (then the bounds in use shrink)."""
        x = round_significant(x)
        if not replay:
            self.jr.record(x)
        try:
            vals = self.study.run_point(self.material, self.st["label"], self.st["rig"], self.extra(x), self.response,
                                        self.lab_dir)
        except RunError as exc:
            if not self.xs:
                raise                      # the start point itself: the stage cannot run
            u, ran = float(self.scale.to_unit(x)), self.scale.to_unit(np.array(self.xs))
            self.refused.append((x, str(exc)))
            self.study.log(f"  the rig refused {self.p['label']} = {x:.4g}: it becomes a limit")
            if u > np.median(ran):
                self.hi_u = min(self.hi_u, 0.5 * (u + float(np.max(ran[ran < u], initial=0.0))))
            else:
                self.lo_u = max(self.lo_u, 0.5 * (u + float(np.min(ran[ran > u], initial=1.0))))
            return False
        self.xs.extend([x] * len(vals))
        self.ys.extend(vals)
        u = float(self.scale.to_unit(x))
        self.lo_u, self.hi_u = min(self.lo_u, u), max(self.hi_u, u)   # a probe past a limit ran: the limit moves out
        return True

    def probe_past_limit(self, step):
        """The target lies beyond a limit set by a refused point (the stop rule says so, or
        the estimate sits on that limit: the model clips it there while the seed noise keeps
        the stop rule from calling it beyond): the point halfway between the limit and that
        refused point (bisection towards what the rig can run), or None when the gap is
        below PROBE_GAP_U or no refused point lies beyond that limit."""
        scale, lo_u, hi_u = self.scale, self.lo_u, self.hi_u
        side = {stopping.BEYOND_LOWER: -1, stopping.BEYOND_UPPER: 1}.get(step.stop)
        if side is None and not step.stop:
            u = float(scale.to_unit(step.estimate))
            side = -1 if u <= lo_u + 1e-9 else 1 if u >= hi_u - 1e-9 else None
            if side is None:
                # the interval, not the estimate, ends on the limit: what lies past it is unmeasured
                # (M3-dry rolling, 2026-12-03: 0.1296 [0.1025, 0.2534], the limit 0.1025 run 8 times)
                low_u, high_u = float(scale.to_unit(step.low)), float(scale.to_unit(step.high))
                side = -1 if low_u <= lo_u + 1e-9 else 1 if high_u >= hi_u - 1e-9 else None
        if side is None:
            return None
        limit = lo_u if side < 0 else hi_u
        beyond = [float(scale.to_unit(x)) for x, _ in self.refused]
        beyond = [u for u in beyond if (u - limit) * side > 0]
        if not beyond:
            return None
        nearest = min(beyond, key=lambda u: abs(u - limit))
        if abs(nearest - limit) < PROBE_GAP_U:
            return None
        return float(scale.from_unit(0.5 * (limit + nearest)))

    def decide(self, runs):
        return decide_step(self.p, self.scale, self.xs, self.ys, self.target, runs, self.n, self.lo_u, self.hi_u,
                           self.st["out_of_reach_factor"])

    def row(self, step):
        row = _row(self.study, self.material, self.st, self.p, self.scale, self.xs, self.ys, step, self.target,
                   self.response, self.refused, self.lo_u, self.hi_u, self.extra, self.lab_dir)
        row["runs_from_library"] = self.from_library
        return row

    def second_point(self, start):
        """Run points until two differ (the start's response and the physics' slope place the
        second); '' or why the stage has one point only."""
        p, scale, n = self.p, self.scale, self.n
        x0 = round_significant(start)
        y0 = float(np.mean([y for x, y in zip(self.xs, self.ys) if x == x0] or self.ys))
        u0 = float(scale.to_unit(x0))
        while len(set(self.xs)) < 2:
            if self.runs_left() < n:
                return "one point only"
            u1 = second_point_u(u0, y0, self.target.value, p["increasing"], _slope_per_u(self.st, scale, x0, y0),
                                self.lo_u, self.hi_u)
            if abs(u1 - u0) < 1e-6:
                u1 = 0.5 * (u0 + (self.hi_u if u0 < 0.5 else self.lo_u))
            try:
                self.point(float(scale.from_unit(u1)))
            except BudgetSpent:
                return "study run budget spent"
        return ""

    def walk(self):
        """Points where the model says until the stop rule stops (or a probe past a limit,
        repeats, the budget); the last step."""
        n = self.n
        while True:
            step = self.decide(self.runs_left())
            probe = self.probe_past_limit(step) if self.runs_left() >= n else None
            if step.stop and probe is None:
                return step
            if probe is not None:
                self.study.log(f"  the target lies past the limit a refused point set: probing {self.p['label']} = "
                               f"{probe:.4g}")
                step.next_x = probe
            elif self.xs.count(round_significant(step.next_x)) >= REPEAT_RUNS_POINTS * n:
                step.stop = stopping.REPEATS       # nothing left to learn there
                return step
            try:
                self.point(step.next_x)
            except BudgetSpent:
                step = self.decide(0)
                step.stop = stopping.STUDY_BUDGET
                return step


def run(study, material, st):
    """Run the stage; returns its row (parameters, responses, met, stop reason, plots)."""
    study.apply_set(material, st["set"])
    w = _Walk(study, material, st)
    for x, v in library_start.take(study, material, st, w.jr, w.extra, w.response, w.lab_dir):
        w.xs.append(x)                                     # runs already made at this stage's points
        w.ys.append(v)
    w.from_library = len(w.xs)
    while (x := w.jr.next_recorded()) is not None:        # a resumed study: the same points again
        w.point(x, replay=True)
    if w.jr.result and len(set(w.xs)) >= 2:
        step = w.decide(0)
        for k, v in w.jr.result.items():                    # the values carried before, exactly
            setattr(step, k, v)
        return w.row(step)
    start = study.first_value(material, st["parameter"])
    if not w.xs:
        w.point(start)
    budget_note = w.second_point(start)
    if len(set(w.xs)) < 2:
        return _one_point_row(study, st, w.target, w.response, w.xs, w.ys, budget_note)
    step = w.walk()
    step.estimate = round_significant(step.estimate)
    w.jr.finish({k: getattr(step, k) for k in ("estimate", "low", "high", "tolerance", "band_low", "band_high", "stop",
                                                "next_x")})
    return w.row(step)


def _row(study, material, st, p, scale, xs, ys, step, target, response, refused, lo_u, hi_u, extra, lab_dir):
    """The stage's row (and plots) from its runs and final step; carries the value on."""
    value = step.estimate
    study.set_value(material, p["keys"], value, (value, step.low, step.high))
    mean, var = step.model.mean_var(np.array([[float(scale.to_unit(value))]]))
    row = {
        "parameters": [{"label": p["label"], "keys": p["keys"], "unit": p["unit"], "scale": p["scale"],
                        "estimate": value, "low": step.low, "high": step.high, "tolerance": step.tolerance,
                        "band_low": step.band_low, "band_high": step.band_high}],
        "responses": [{"rig": st["rig"], "response": response.name, "unit": response.unit, "target": target.value,
                       "band": target.band, "standard_error": target.standard_error,
                       "target_source": target.source, "at_estimate": float(mean[0]),
                       "at_estimate_sd": float(math.sqrt(var[0])), "noise_sd": step.model.noise_sd,
                       "noise_dof": step.model.noise_dof}],
        "met": step.stop == stopping.WITHIN, "stop_reason": step.stop,
        "message": _message(step, p, scale, xs, ys, target, refused, lo_u, hi_u),
        "points_count": len(set(xs)),
    }
    row["plots"] = plots.stage_1d(study, material, st, row, scale, xs, ys, step, target, response)
    row["plots"] += plots.lab_curves(study, material, st["label"], st["rig"], extra(value), response, lab_dir)
    return row


def _message(step, p, scale, xs, ys, target, refused, lo_u, hi_u):
    half = max(step.estimate - step.low, step.high - step.estimate)
    unit = "" if unit_label(p["unit"]) == "-" else " " + unit_label(p["unit"])
    msg = f"95 % interval within +-{half:.3g}{unit} of the estimate; tolerance +-{step.tolerance:.3g}{unit}"
    if step.stop in (stopping.BEYOND_UPPER, stopping.BEYOND_LOWER):
        at = float(scale.from_unit(hi_u if step.stop == stopping.BEYOND_UPPER else lo_u))
        near = [y for x, y in zip(xs, ys) if abs(float(scale.to_unit(x)) - float(scale.to_unit(at))) < 0.01]
        msg = (f"the target {target.value:.4g} lies beyond what {p['label']} = {at:.4g} reaches "
               f"({np.mean(near):.4g} there, {len(near)} runs)")
    if step.stop == stopping.REPEATS and step.next_x is None:     # a journal written before next_x was kept
        msg += "; stopped: the next point had run at length already"
    elif step.stop == stopping.REPEATS:
        x = round_significant(step.next_x)
        msg += f"; stopped: the next point, {x:.4g}, had run {xs.count(x)} times already"
    if refused:
        msg += "; the rig refused " + ", ".join(f"{x:.4g}" for x, _ in refused) + f" ({refused[0][1][:160]})"
    return msg


def _one_point_row(study, st, target, response, xs, ys, note):
    p = st["parameter"]
    return {"parameters": [{"label": p["label"], "keys": p["keys"], "unit": p["unit"], "scale": p["scale"],
                            "estimate": math.nan, "low": math.nan, "high": math.nan,
                            "tolerance": math.nan if p["tolerance_is_percent"] else p["tolerance"],
                            "band_low": math.nan, "band_high": math.nan}],
            "responses": [{"rig": st["rig"], "response": response.name, "unit": response.unit,
                           "target": target.value, "band": target.band, "standard_error": target.standard_error,
                           "target_source": target.source, "at_estimate": float(np.mean(ys)) if ys else math.nan}],
            "met": False, "stop_reason": stopping.BUDGET,
            "message": f"{note}: a response model needs two points (start {xs[0] if xs else '-'} only)",
            "points_count": len(set(xs))}
