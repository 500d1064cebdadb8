"""pycal.calibration.joint: the scipy least-squares joint fit, and the study's joint stage."""
import math

import pytest

from pycal.calibration.joint import solve_joint, rms, MISSING_Z
from pycal.calibration.study import Study


def line_residuals(truth_a, truth_b, stresses=(12e3, 24e3, 40e3, 60e3, 86e3), half_band=0.05):
    """z of a straight friction line a + b x stress against the truth (band +-0.05)."""
    def f(x):
        a, b = x
        return [((a + b * s) - (truth_a + truth_b * s)) / half_band for s in stresses]
    return f


def test_joint_fit_finds_both_coupled_parameters():
    sol = solve_joint(line_residuals(0.40, 3.5e-6), [0.5, 1e-6], [0.05, 0.0], [1.2, 2e-5], 0.1,
                      max_evaluations=30)
    assert sol.met and sol.rms <= 0.1
    assert sol.x[0] == pytest.approx(0.40, abs=0.01)
    assert sol.x[1] == pytest.approx(3.5e-6, rel=0.1)
    assert len(sol.history) <= 30


def test_joint_fit_stops_at_the_budget_with_the_best_point():
    sol = solve_joint(line_residuals(0.40, 3.5e-6), [1.1, 1.9e-5], [0.05, 0.0], [1.2, 2e-5], 1e-9,
                      max_evaluations=4)
    assert not sol.met and len(sol.history) == 4
    assert sol.rms == min(h[2] for h in sol.history)
    assert "4 evaluations" in sol.message


def test_joint_fit_rejects_a_start_outside_the_bounds():
    with pytest.raises(ValueError, match="within bounds"):
        solve_joint(line_residuals(0.4, 0.0), [2.0, 0.0], [0.05, 0.0], [1.2, 1.0], 0.1)


def test_missing_steps_count_as_large_residuals():
    assert rms([None, 0.0]) == pytest.approx(MISSING_Z / math.sqrt(2))


def test_joint_stage_fits_the_wet_wall_curve(tmp_path):
    """Fake wet wall friction: mu = steel friction + 3e-4 x pressure_fraction x stress (Pa).
    The wet-fines lab curve is 0.40 + 3.5e-6 / Pa x stress, so the truth is steel friction
    0.40 and pressure_fraction 0.0117; the stage starts from the config's 0.5 (no start
    given) after switching the pair to the hysteretic law (set)."""
    cfg = tmp_path / "wet.yaml"
    cfg.write_text("""
name: wet
seeds_count: 2
materials:
  M3-wet:
    - stage: joint
      name: wet_wall
      rig: wall_friction
      response: friction_band_z_mu_static
      tolerance_rms_z: 0.1
      set:
        interactions.steel.cohesion: {model: hysteretic, force_fraction: 0.0, pressure_fraction: 0.0, update_interval_s: 0.01}
      parameters:
        - {keys: [interactions.steel.friction_coefficient], bounds: [0.05, 1.2]}
        - {keys: [interactions.steel.cohesion.pressure_fraction], start: 0.005, bounds: [0.0, 0.1]}
      max_iterations_count: 30
""")
    stress = [3000, 6000, 12000, 24000, 40000, 60000, 86000]

    class Wet:
        def run(self, jobs, raise_on_error=True):
            out = []
            for j in jobs:
                steel = j["materials"]["M3-wet"]["interactions"]["steel"]
                assert steel["cohesion"]["model"] == "hysteretic"
                mu = [steel["friction_coefficient"] + 3e-4 * steel["cohesion"]["pressure_fraction"] * s
                      for s in stress]
                out.append({"rig": "wall_friction", "material": "M3-wet", "job": j, "stress_pa": stress,
                            "mu_static": mu, "mu_dynamic": mu, "sticks": [False] * 7})
            return out
    (row,) = Study(cfg, Wet(), tmp_path / "out", log=lambda m: None).run()
    assert row["met"], row["message"]
    v = row["values"]
    assert v["interactions.steel.friction_coefficient"] == pytest.approx(0.40, abs=0.02)
    assert v["interactions.steel.cohesion.pressure_fraction"] == pytest.approx(0.0117, rel=0.15)
    assert row["plots"] == ["plots/M3-wet-wet_wall/friction_vs_stress.png"]
    cal = (tmp_path / "out" / "wet" / "calibrated" / "M3-wet.yaml").read_text()
    assert "hysteretic" in cal


@pytest.mark.parametrize("change, field", [
    ("response: friction_band_z_mu_static", "response: aor_mean_deg"),
    ("        - {keys: [interactions.steel.cohesion.pressure_fraction], start: 0.005, bounds: [0.0, 0.1]}\n", ""),
    ("start: 0.005, bounds: [0.0, 0.1]", "start: 0.5, bounds: [0.0, 0.1]"),
])
def test_bad_joint_stage_names_the_field(tmp_path, change, field):
    from pycal.calibration.study import load_study
    from pycal.errors import ConfigError
    text = """
name: wet
seeds_count: 2
materials:
  M3-wet:
    - stage: joint
      rig: wall_friction
      response: friction_band_z_mu_static
      tolerance_rms_z: 0.25
      parameters:
        - {keys: [interactions.steel.friction_coefficient], bounds: [0.05, 1.2]}
        - {keys: [interactions.steel.cohesion.pressure_fraction], start: 0.005, bounds: [0.0, 0.1]}
"""
    assert change in text
    p = tmp_path / "bad.yaml"
    p.write_text(text.replace(change, field))
    with pytest.raises(ConfigError) as exc:
        load_study(p)
    assert "bad.yaml" in str(exc.value) and "materials.M3-wet[0]" in str(exc.value)


def test_joint_fit_step_is_a_share_of_the_range_even_at_a_start_near_a_bound():
    """The forward-difference step must move a parameter that starts near its lower
    bound by several % of its range (scipy's step is relative to the variable)."""
    seen = []

    def f(x):
        seen.append(list(x))
        return [(x[0] - 0.4) / 0.05, (x[1] - 0.02) / 0.005]
    solve_joint(f, [0.5, 0.001], [0.05, 0.0], [1.2, 0.05], 1e-9, max_evaluations=3)
    steps = [abs(b - a) for a, b in zip(seen[0], seen[1]) if b != a] + \
            [abs(b - a) for a, b in zip(seen[0], seen[2]) if b != a]
    assert len(steps) == 2
    assert steps[0] >= 0.04 * 1.15 and steps[1] >= 0.04 * 0.05


def test_a_failed_point_is_a_bad_point_and_the_fit_goes_on(tmp_path):
    from pycal.errors import RunError
    cfg = tmp_path / "wet.yaml"
    cfg.write_text("""
name: wet
seeds_count: 1
materials:
  M3-wet:
    - stage: joint
      rig: wall_friction
      response: friction_band_z_mu_static
      tolerance_rms_z: 0.01
      parameters:
        - {keys: [interactions.steel.friction_coefficient], bounds: [0.05, 1.2]}
        - {keys: [interactions.steel.rolling_resistance_coefficient], start: 0.35, bounds: [0.0, 1.0]}
      max_iterations_count: 6
""")
    stress = [12000, 24000, 40000, 60000, 86000]

    class Flaky:
        def run(self, jobs, raise_on_error=True):
            steel = jobs[0]["materials"]["M3-wet"]["interactions"]["steel"]
            if steel["rolling_resistance_coefficient"] > 0.36:     # the rig blows up up there
                raise RunError("wall_friction: RIG FAILED: blow-up")
            mu = [steel["friction_coefficient"] - 0.2 + 4e-6 * s for s in stress]
            return [{"rig": "wall_friction", "material": "M3-wet", "job": j, "stress_pa": stress,
                     "mu_static": mu, "mu_dynamic": mu, "sticks": [False] * 5} for j in jobs]
    study = Study(cfg, Flaky(), tmp_path / "out", log=lambda m: None)
    (row,) = study.run()
    failed = [h for h in study.history if h["n"] == 0]
    assert failed, "the fit should have tried a point where the rig fails"
    assert row["evaluations"] > len(failed) and math.isfinite(row["response_mean"])
