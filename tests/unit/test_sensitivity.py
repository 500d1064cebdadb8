"""`pycal sensitivity` (pycal.calibration.sensitivity) on fake physics with known effects
(tests/unit/fake_rigs.py: AoR = 20 + 40 x rolling resistance deg; the fake surcharge
angle here = 0.6 x AoR + 30 x particle friction, seed noise 0.5 deg)."""
import pytest

from fake_rigs import FakeRigs, aor_law
from pycal.calibration import sensitivity
from pycal.calibration.study import Study
from pycal.errors import ConfigError
from test_validation import STUDY


def surcharge(job, offset_per_seed=0.0):
    f = job["materials"]["M3-dry"]["interactions"]["M3-dry"]["friction_coefficient"]
    return {"surcharge_mean_deg": 0.6 * aor_law(job) + 30.0 * f + offset_per_seed * (job["seed"] - 2.5)}


def calibrated_study(tmp_path, offset_per_seed=0.0, noise=0.5):
    p = tmp_path / "val.yaml"
    p.write_text(STUDY)
    ex = FakeRigs(results={"surcharge": lambda job: surcharge(job, offset_per_seed)},
                  noise={"surcharge_mean_deg": noise})
    s = Study(p, ex, tmp_path / "out", log=lambda m: None)
    s.run()
    return s, ex


def expected_effects(s):
    rolling = s.overrides["M3-dry"]["interactions.M3-dry.rolling_resistance_coefficient"]
    from pycal.jobs import resolve_job
    f = resolve_job("surcharge", "M3-dry")["materials"]["M3-dry"]["interactions"]["M3-dry"]["friction_coefficient"]
    return 0.6 * 40 * 0.2 * rolling, 30.0 * 0.2 * f


def test_factors_are_the_calibrated_parameters_and_the_extra_keys(tmp_path):
    """The three keys the rolling stage sets to one value move together: one factor."""
    s, _ = calibrated_study(tmp_path)
    pred = s.cfg["validation"]["predictions"][1]
    from pycal.calibration.calibrated import run_overrides
    facs = sensitivity.factors(s, pred, run_overrides(s.overrides, pred))
    assert [sorted(f["keys"]) for f in facs] == [
        ["interactions.M3-dry.rolling_resistance_coefficient", "interactions.pvc.rolling_resistance_coefficient",
         "interactions.steel.rolling_resistance_coefficient"],
        ["interactions.M3-dry.friction_coefficient"]]


@pytest.mark.parametrize("design", ["screening", "one-at-a-time"])
def test_both_designs_find_the_known_effects(tmp_path, design):
    s, ex = calibrated_study(tmp_path)
    before = len(ex.asked)
    out = sensitivity.run(s, "fines_dry_surcharge", design=design)
    rolling, friction = expected_effects(s)
    eff = {f["keys"][0]: f for f in out["factors"]}
    assert eff["interactions.M3-dry.rolling_resistance_coefficient"]["effect"] == pytest.approx(rolling, abs=1.2)
    assert eff["interactions.M3-dry.friction_coefficient"]["effect"] == pytest.approx(friction, abs=1.2)
    assert [f["rank"] for f in out["factors"]] == [1, 2]
    new_runs = len(ex.asked) - before
    # screening: 8 design runs on 1 seed; one at a time: 2 factors x 2 seeds and the calibrated
    # values on those 2 seeds (in a real study those come from the cache of the validation)
    assert new_runs == (8 if design == "screening" else 6)
    assert (s.out / f"sensitivity-fines_dry_surcharge-{design}.csv").is_file()
    assert (s.out / "plots" / f"sensitivity-fines_dry_surcharge-{design}.png").is_file()


def test_screening_cancels_what_a_seed_carries_whatever_the_parameter(tmp_path):
    """A seed that piles 10 deg higher whatever the values: every design run is on the same
    seed, so the offset is in every row and cancels in every effect."""
    s, _ = calibrated_study(tmp_path, offset_per_seed=10.0, noise=0.01)
    out = sensitivity.run(s, "fines_dry_surcharge", design="screening", seeds_per_run=2)
    rolling, friction = expected_effects(s)
    eff = {f["keys"][0]: f["effect"] for f in out["factors"]}
    assert eff["interactions.M3-dry.rolling_resistance_coefficient"] == pytest.approx(rolling, abs=0.1)
    assert eff["interactions.M3-dry.friction_coefficient"] == pytest.approx(friction, abs=0.1)


def test_screening_ranks_as_well_as_one_at_a_time_with_a_third_of_the_runs():
    """Nine factors with known effects (8, 6, 4, 2, 1 deg and four at 0) and a run noise
    SD of 3 deg that no pairing cancels (a chaotic pile): a 12-run screening design on one
    seed puts the top three in order at least as often as one at a time with 3 paired
    seeds (27 moved runs + 3 base runs = 30, 2.5x as many; the old one-at-a-time run of the
    mixed dry pile moved each of its 13 keys alone, 39 runs)."""
    import numpy as np
    from pycal.stats import screening
    effects = np.array([8.0, 6.0, 4.0, 2.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    rng = np.random.default_rng(7)
    x = screening.plackett_burman(len(effects))
    right = {"screening": 0, "one-at-a-time": 0}
    trials = 400
    for _ in range(trials):
        y = x[:, :len(effects)] @ effects / 2 + rng.normal(0, 3.0, len(x))
        est = screening.main_effects(x, y)[:len(effects)]
        right["screening"] += list(np.argsort(-est)[:3]) == [0, 1, 2]
        base = rng.normal(0, 3.0, 3)
        oat = [np.mean(e + rng.normal(0, 3.0, 3) - base) for e in effects]
        right["one-at-a-time"] += list(np.argsort(-np.array(oat))[:3]) == [0, 1, 2]
    assert len(x) == 12
    assert right["screening"] >= right["one-at-a-time"]
    assert right["screening"] / trials > 0.3


def test_unknown_prediction_or_response_is_a_config_error(tmp_path):
    s, _ = calibrated_study(tmp_path)
    with pytest.raises(ConfigError, match="no prediction named 'pile'"):
        sensitivity.run(s, "pile")
    with pytest.raises(ConfigError, match="not a response of fines_dry_surcharge"):
        sensitivity.run(s, "fines_dry_surcharge", response="aor_left_deg")
