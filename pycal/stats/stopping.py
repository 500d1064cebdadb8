"""The stop rule of a stage, in the parameter's own units.

A stage stops when (checked in this order)
  1. "interval within tolerance": the whole 95 % interval lies within estimate +-
     tolerance, no more than 2.5 % of the draws point past either bound (else the
     interval's end is the bound, not a measured end), and at least MIN_POINTS distinct
     points have run (a line through two points cannot show its own bending: found on a
     response that jumps where the wet cell starts to hang on), and the interval is
     measured, not bridged: a point ran inside it on each side of the estimate. M2's
     rolling stage was called met at 0.295 [0.248, 0.341] from runs at 0.02 and 0.32 -
     0.37 only: the model's shape across the gap made the interval, and the joint pass
     then put the value at 0.174;
  2. "target beyond the upper/lower bound": at least 97.5 % of the draws point past
     that bound and a point has been run at it: what the bounds allow cannot reach
     the target;
  3. "tolerance out of reach in the run budget" (only where a stage asks for it, with a
     factor): the interval's half-width, shrunk as 1 / sqrt(runs) over the runs the
     budget leaves, would still be above factor x the tolerance (at least MIN_POINTS
     points run). A noisy response that hardly follows the parameter (the dry fines'
     internal-friction cell: half-width 2.2 x the tolerance after 9 of 15 runs, 1.6 x
     after 15) spends its budget without reaching it;
  4. "run budget spent": the next point would need more runs than the budget left.
Only the first counts as met. The 1-D driver adds "next point already run at length".
"""
import math

WITHIN = "interval within tolerance"
BUDGET = "run budget spent"
STUDY_BUDGET = "study run budget spent"      # the whole study's max_runs_count (said by the driver)
BEYOND_UPPER = "target beyond the upper bound"
BEYOND_LOWER = "target beyond the lower bound"
REPEATS = "next point already run at length"   # said by the driver (pycal.calibration.stage_1d)
OUT_OF_REACH = "tolerance out of reach in the run budget"
BOUND_SHARE = 0.025
MIN_POINTS = 3


def within_tolerance(estimate, low, high, tolerance):
    """True when [low, high] lies within estimate +- tolerance (parameter units)."""
    return max(estimate - low, high - estimate) <= tolerance


def unmeasured_side(estimate, low, high, points):
    """-1 when no point (parameter values that ran) lies in [low, estimate], +1 when none
    lies in [estimate, high], 0 when both sides of the interval have one. When neither
    side has one, the side the model bridges farther: the one whose nearest point lies
    farther from the estimate (the wet cohesion stage of 2026-12-03 ran its 3rd and 4th
    points just below an interval whose upper side was bridged to a point 0.06 away, and
    the interval moved up past each of them: 6 runs of 316 CPU s chasing it)."""
    lower = any(low <= x <= estimate for x in points)
    upper = any(estimate <= x <= high for x in points)
    if lower and upper:
        return 0
    if lower or upper:
        return 1 if lower else -1
    gap_below = min((estimate - x for x in points if x <= estimate), default=math.inf)
    gap_above = min((x - estimate for x in points if x >= estimate), default=math.inf)
    return 1 if gap_above > gap_below else -1


def projected_half_width(half_width, runs_done, runs_left):
    """The half-width after runs_left more runs if it shrinks as 1 / sqrt(runs): a point
    estimate's standard error does; an interval that still moves with the design can shrink
    faster (an optimistic bound early in a stage, hence a factor above 1 for the rule)."""
    return half_width * math.sqrt(runs_done / (runs_done + runs_left))


def stop_reason(estimate, low, high, tolerance, p_below=0.0, p_above=0.0, ran_at_lower=False,
                ran_at_upper=False, runs_left=None, runs_next=0, points_count=MIN_POINTS, points=None,
                runs_done=None, out_of_reach_factor=None):
    """The reason to stop now (one of the constants above), or None to go on. points: the
    distinct parameter values run (None: not checked); out_of_reach_factor (None: rule 3
    off) needs runs_done and runs_left."""
    measured = points is None or unmeasured_side(estimate, low, high, points) == 0
    if (p_below <= BOUND_SHARE and p_above <= BOUND_SHARE and points_count >= MIN_POINTS
            and within_tolerance(estimate, low, high, tolerance) and measured):
        return WITHIN
    if p_above >= 1 - BOUND_SHARE and ran_at_upper:
        return BEYOND_UPPER
    if p_below >= 1 - BOUND_SHARE and ran_at_lower:
        return BEYOND_LOWER
    if (out_of_reach_factor is not None and runs_left is not None and runs_done and points_count >= MIN_POINTS
            and projected_half_width(max(estimate - low, high - estimate), runs_done, runs_left)
            > out_of_reach_factor * tolerance):
        return OUT_OF_REACH
    if runs_left is not None and runs_left < runs_next:
        return BUDGET
    return None
