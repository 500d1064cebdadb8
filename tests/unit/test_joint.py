"""Joint stages: 2-3 coupled parameters, a posterior over them (GP surrogate + emcee), on
fake rigs with known answers."""
import json
import math

import pytest

from fake_rigs import FakeRigs, holds, wall_result
from pycal import labdata
from pycal.calibration.study import Study
from pycal.calibration.study_config import load_study
from pycal.errors import ConfigError

WET = """
name: wet
seeds_count: 3
materials:
  M3-wet:
    - stage: joint
      name: wet_wall
      responses:
        - {rig: wall_friction, response: friction_band_z_mu_static}
      set:
        interactions.steel.cohesion: {model: hysteretic, force_fraction: 0.0, pressure_fraction: 0.0, update_interval_s: 0.01}
      parameters:
        - {keys: [interactions.steel.friction_coefficient], bounds: [0.05, 1.2], tolerance_coefficient: 0.05}
        - {keys: [interactions.steel.cohesion.pressure_fraction], start: 0.005, bounds: [0.0, 0.05],
           tolerance_fraction: 0.004}
      max_runs_count: 60
    - stage: inherit
      name: steel_friction_copy
      from: {material: M3-wet, stage: wet_wall, key: interactions.steel.friction_coefficient}
      keys: [interactions.pvc.friction_coefficient]
"""


def quiet(_):
    pass


def wet_wall_rig():
    """mu = steel friction + 3e-4 x pressure_fraction x stress (Pa), seed noise 0.01: the
    wet-fines lab curve (0.40 + 3.5e-6 / Pa x stress) is met at friction 0.40, pressure
    fraction 0.0117. The fake rig reports every lab step (no interpolation between steps)."""
    def mu(steel, s):
        assert steel["cohesion"]["model"] == "hysteretic"      # the stage's `set` reached the job
        return steel["friction_coefficient"] + 3e-4 * steel["cohesion"]["pressure_fraction"] * s
    return FakeRigs(results={"wall_friction": wall_result(mu, stresses=(12000, 24000, 40000, 60000, 86000))})


def test_wet_wall_joint_stage_recovers_both_parameters_with_their_trade_off(tmp_path):
    cfg = tmp_path / "wet.yaml"
    cfg.write_text(WET)
    study = Study(cfg, wet_wall_rig(), tmp_path / "out", log=quiet)
    rows = study.run()
    row = rows[0]
    fric, press = row["parameters"]
    assert fric["label"] == "friction (steel)" and press["label"] == "pull-off pressure fraction (steel)"
    assert holds(fric, 0.40) and abs(fric["estimate"] - 0.40) < 0.03
    assert holds(press, 0.0117) and abs(press["estimate"] - 0.0117) < 0.003
    # raising the friction lifts the whole curve; less adhesion must make up for it
    assert row["correlation"][0][1] < -0.3
    assert row["met"] and row["stop_reason"] == "interval within tolerance"
    assert row["runs_requested"] <= 60
    assert row["plots"][0] == "plots/M3-wet-wet_wall/calibration.png"
    assert "friction_vs_stress.png" in row["plots"][1]
    cal = (tmp_path / "out" / "wet" / "calibrated" / "M3-wet.yaml").read_text()
    assert "hysteretic" in cal
    # an inherit stage can take one parameter of a joint stage
    copy = rows[1]["parameters"][0]
    assert copy["estimate"] == fric["estimate"] and copy["label"] == "friction (PVC)"
    assert study.overrides["M3-wet"]["interactions.pvc.friction_coefficient"] == fric["estimate"]


ROLLING_DENSITY = """
name: final
seeds_count: 3
materials:
  M2:
    - stage: joint
      name: rolling_density_final
      responses:
        - {rig: aor, response: aor_mean_deg, target: {sample: gravel_dry, test: angle_of_repose, band_deg: 2.0}}
        - {rig: fill, response: bulk_density_kg_m3, target: {band_percent: 1.0}}
      parameters:
        - keys: [interactions.M2.rolling_resistance_coefficient, interactions.steel.rolling_resistance_coefficient,
                 interactions.pvc.rolling_resistance_coefficient]
          bounds: [0.02, 1.5]
          tolerance_coefficient: 0.03
        - {keys: [particles.density_kg_m3], bounds: [1500.0, 9000.0], scale: log, tolerance_kg_m3: 40.0}
      max_runs_count: 72
"""


def test_joint_stage_over_two_rigs_rolling_resistance_and_density(tmp_path):
    """The final pass: AoR = 20 + 40 eta (deg), bulk = 0.35 rho (1 - 0.1 eta) (kg/m3)."""
    cfg = tmp_path / "final.yaml"
    cfg.write_text(ROLLING_DENSITY)
    ex = FakeRigs()
    (row,) = Study(cfg, ex, tmp_path / "out", log=quiet).run()
    eta_truth = (labdata.aor_target_deg("gravel_dry") - 20) / 40
    rho_truth = 1603 / (0.35 * (1 - 0.1 * eta_truth))
    eta, rho = row["parameters"]
    assert holds(eta, eta_truth) and abs(eta["estimate"] - eta_truth) < 0.03
    assert holds(rho, rho_truth) and abs(rho["estimate"] - rho_truth) < 40
    assert {j["rig"] for j in ex.asked} == {"aor", "fill"}
    # each point runs both rigs with the same seeds; the start is the config's values
    assert [j["seed"] for j in ex.asked[:6]] == [1, 2, 3, 1, 2, 3]
    assert row["responses"][0]["target_source"] == "lab gravel_dry angle_of_repose"
    assert row["responses"][1]["target_source"] == "lab gravel_dry bulk density"


def test_a_start_point_without_a_response_does_not_end_the_stage(tmp_path):
    """Found in the shipped study: after the friction stage lowered the fines' friction to
    0.11, the final pass's start (rolling 0.10) gave piles too flat for an angle on every
    seed and the stage ended there. Fake: no angle below rolling 0.15; the truth lies above."""
    cfg = tmp_path / "final.yaml"
    cfg.write_text(ROLLING_DENSITY.replace("          bounds: [0.02, 1.5]", "          start: 0.1\n          bounds: [0.02, 1.5]"))
    from fake_rigs import aor_law
    def aor(j):      # no angle below rolling 0.15; between 0.15 and 0.3, none on seed 2 (one seed left out)
        eta = j["materials"]["M2"]["interactions"]["M2"]["rolling_resistance_coefficient"]
        flat = eta < 0.15 or (eta < 0.3 and j["seed"] == 2)
        return {"aor_mean_deg": float("nan") if flat else aor_law(j)}
    ex = FakeRigs(results={"aor": aor})
    (row,) = Study(cfg, ex, tmp_path / "out", log=quiet).run()
    eta_truth = (labdata.aor_target_deg("gravel_dry") - 20) / 40
    eta, rho = row["parameters"]
    assert "the rig refused" in row["message"] and eta_truth > 0.15
    assert holds(eta, eta_truth) and abs(eta["estimate"] - eta_truth) < 0.05


def test_a_refused_point_is_not_asked_again_and_the_fit_goes_on(tmp_path):
    """The rig blows up above fines-steel friction 0.6: the first step of the design goes
    there (0.5 + a fifth of the bounds); the stage must carry on without it."""
    cfg = tmp_path / "wet.yaml"
    cfg.write_text(WET)
    rig = wet_wall_rig()
    rig.refuse = (lambda job: "blow-up"
                  if job["materials"]["M3-wet"]["interactions"]["steel"]["friction_coefficient"] > 0.6 else None)
    row = Study(cfg, rig, tmp_path / "out", log=quiet).run()[0]
    refused = [j for j in rig.asked if j["materials"]["M3-wet"]["interactions"]["steel"]["friction_coefficient"] > 0.6]
    assert len(refused) == 3 and "the rig refused" in row["message"]      # one point, its 3 seeds, once
    fric, press = row["parameters"]
    assert holds(fric, 0.40) and holds(press, 0.0117)


@pytest.mark.parametrize("old, new, message", [
    ("response: friction_band_z_mu_static}", "response: aor_mean_deg}",
     r"materials.M3-wet\[0\].responses\[0\].response: rig wall_friction does not give aor_mean_deg"),
    ("        - {keys: [interactions.steel.cohesion.pressure_fraction], start: 0.005, bounds: [0.0, 0.05],\n"
     "           tolerance_fraction: 0.004}\n", "",
     r"materials.M3-wet\[0\].parameters: a joint stage moves a list of 2 or 3 parameter groups"),
    ("start: 0.005, bounds: [0.0, 0.05]", "start: 0.5, bounds: [0.0, 0.05]",
     r"materials.M3-wet\[0\].parameters\[1\].start: 0.5 outside bounds"),
    ("      set:\n        interactions.steel.cohesion: {model: hysteretic, force_fraction: 0.0, pressure_fraction: 0.0, "
     "update_interval_s: 0.01}\n", "",
     r"parameters\[1\].keys: interactions.steel.cohesion.pressure_fraction: no such key"),
    ("tolerance_rms_z", "tolerance_rms_z", None),
])
def test_bad_joint_stage_names_the_field(tmp_path, old, new, message):
    text = WET.replace("    - stage: joint\n      name: wet_wall\n", "    - stage: joint\n      name: wet_wall\n"
                       "      tolerance_rms_z: 1.0\n") if message is None else WET
    if message is None:
        message = r"materials.M3-wet\[0\].tolerance_rms_z: joint stages: responses\[\].target.band_z"
    else:
        assert old in text, old
        text = text.replace(old, new)
    p = tmp_path / "bad.yaml"
    p.write_text(text)
    with pytest.raises(ConfigError, match=message) as exc:
        load_study(p)
    assert "bad.yaml" in str(exc.value)


SURCHARGE_JOINT = """
name: surcharge_joint
seeds_count: 2
materials:
  M3-dry:
    - stage: joint
      name: friction_rolling
      responses:
        - {rig: surcharge, response: aor_mean_deg, target: {sample: fines_dry, test: angle_of_repose, band_deg: 2.0}}
        - {rig: surcharge, response: surcharge_mean_deg, target: {sample: fines_dry, test: surcharge, band_deg: 2.0}}
      parameters:
        - {keys: [interactions.M3-dry.friction_coefficient], start: 0.5, bounds: [0.05, 1.2], tolerance_coefficient: 0.05}
        - keys: [interactions.M3-dry.rolling_resistance_coefficient]
          start: 0.3
          bounds: [0.02, 1.5]
          tolerance_coefficient: 0.05
      max_runs_count: 80
"""


def test_two_responses_of_one_rig_are_read_from_the_same_runs(tmp_path):
    """The pile before and after the vibration come from one surcharge run: a joint stage over
    particle friction mu and rolling resistance eta reads both from the same runs (one job per
    seed and point, not two). Fake laws: AoR = 20 + 30 eta + 10 mu, surcharge = 10 eta + 40 mu
    (deg); the lab's fines_dry (38 / 28 deg) is met at mu = 0.6, eta = 0.4."""
    def surcharge(j):
        pair = j["materials"]["M3-dry"]["interactions"]["M3-dry"]
        mu, eta = pair["friction_coefficient"], pair["rolling_resistance_coefficient"]
        return {"aor_mean_deg": 20 + 30 * eta + 10 * mu, "surcharge_mean_deg": 10 * eta + 40 * mu}
    cfg = tmp_path / "s.yaml"
    cfg.write_text(SURCHARGE_JOINT)
    ex = FakeRigs(results={"surcharge": surcharge}, noise={"surcharge_mean_deg": 0.5})
    study = Study(cfg, ex, tmp_path / "out", log=quiet)
    (row,) = study.run()
    mu, eta = row["parameters"]
    assert labdata.aor_target_deg("fines_dry") == 38.0 and labdata.aor_target_deg("fines_dry", "surcharge") == 28.0
    assert holds(mu, 0.6) and holds(eta, 0.4)
    # one job per seed and point: the two responses share them
    assert len({j["job_id"] for j in ex.asked}) == len(ex.asked) == row["runs_requested"]
    per_response = {r["response"]: [(json.dumps(r["parameters"], sort_keys=True), r["seed"]) for r in study.runs]
                    for r in study.runs}
    assert set(per_response) == {"aor_mean_deg", "surcharge_mean_deg"}
    rows = {name: [(json.dumps(r["parameters"], sort_keys=True), r["seed"]) for r in study.runs if r["response"] == name]
            for name in per_response}
    assert rows["aor_mean_deg"] == rows["surcharge_mean_deg"]
