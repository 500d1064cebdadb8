"""The calibration study engine on a fake executor with known response laws (tests/unit/fake_rigs.py).

Fake physics: bulk density = 0.35 x particle density x (1 - 0.1 x rolling resistance);
angle of repose = 20 deg + 40 deg x rolling resistance + 8 deg x cohesion force fraction
(wet fines); seed noise 0.5 % and 0.5 deg. The engine must land on the values that
reproduce the lab targets, with 95 % intervals that contain them, carry them from stage
to stage, write loadable calibrated configs, and resume without new simulations.
"""
import json
import math

import numpy as np
import pytest
import yaml

from fake_rigs import FakeRigs, holds, stiffness_result, wall_result, YADE_VERSION
from pycal import labdata
from pycal.calibration.study import Study
from pycal.calibration.study_config import load_study
from pycal.stats import stopping
from pycal.configs import validate_material, material_names, load_boundaries
from pycal.errors import ConfigError, RunError
from pycal.report import write_report

STUDY = """
name: twin
seeds_count: 3
max_runs_count: 200
materials:
  M3-dry:
    - stage: density
      rig: fill
      target: {band_percent: 1.0}
      parameter: {bounds: [1500.0, 9000.0], tolerance_kg_m3: 30.0}
      max_runs_count: 24
    - stage: rolling_resistance
      rig: aor
      response: aor_mean_deg
      target: {sample: fines_dry, test: angle_of_repose, band_deg: 1.0}
      parameter:
        keys: [interactions.M3-dry.rolling_resistance_coefficient,
               interactions.steel.rolling_resistance_coefficient,
               interactions.pvc.rolling_resistance_coefficient]
        start: 0.35
        bounds: [0.05, 1.5]
        response_increases: true
        tolerance_coefficient: 0.02
      max_runs_count: 24
  M3-wet:
    - stage: inherit
      from: {material: M3-dry, stage: rolling_resistance}
      keys: [interactions.M3-wet.rolling_resistance_coefficient,
             interactions.steel.rolling_resistance_coefficient,
             interactions.pvc.rolling_resistance_coefficient]
    - stage: cohesion
      rig: aor
      response: aor_mean_deg
      target: {sample: fines_wet, test: angle_of_repose, band_deg: 1.0}
      parameter: {keys: [interactions.M3-wet.cohesion.force_fraction], start: 0.5, bounds: [0.0, 5.0],
                  response_increases: true, tolerance_fraction: 0.1}
      max_runs_count: 24
"""


def quiet(_):
    pass


@pytest.fixture
def study_file(tmp_path):
    p = tmp_path / "twin.yaml"
    p.write_text(STUDY)
    return p


def by_stage(rows):
    return {(r["material"], r["stage"]): r for r in rows}


def test_study_lands_on_known_parameters_with_intervals_that_hold_them(tmp_path, study_file):
    ex = FakeRigs()
    study = Study(study_file, ex, tmp_path / "out", log=quiet)
    rows = by_stage(study.run())
    dry_aor = labdata.aor_target_deg("fines_dry")
    eta_truth = (dry_aor - 20) / 40
    eta = rows[("M3-dry", "rolling_resistance")]["parameters"][0]
    assert holds(eta, eta_truth) and abs(eta["estimate"] - eta_truth) <= 0.02
    rho = rows[("M3-dry", "density")]["parameters"][0]
    # the density stage ran at the start rolling resistance 0.35 (fill = 0.35 rho (1 - 0.035))
    rho_truth = 1601 / (0.35 * (1 - 0.1 * 0.35))
    assert holds(rho, rho_truth) and abs(rho["estimate"] - rho_truth) <= 30
    f_truth = (labdata.aor_target_deg("fines_wet") - 20 - 40 * eta["estimate"]) / 8
    f = rows[("M3-wet", "cohesion")]["parameters"][0]
    assert holds(f, f_truth) and abs(f["estimate"] - f_truth) <= 0.1
    assert all(r["met"] and r["stop_reason"].endswith("interval within tolerance") for r in rows.values())
    # the inherited value carries the interval it came with
    inh = rows[("M3-wet", "inherit")]["parameters"][0]
    assert (inh["estimate"], inh["low"], inh["high"]) == (eta["estimate"], eta["low"], eta["high"])
    # calibrated configs load as configs, with the values carried
    partners = set(material_names()) | set(load_boundaries())
    for m in ("M3-dry", "M3-wet"):
        path = tmp_path / "out" / "twin" / "calibrated" / f"{m}.yaml"
        validate_material(yaml.safe_load(path.read_text()), path, partners)
    cal = yaml.safe_load((tmp_path / "out" / "twin" / "calibrated" / "M3-wet.yaml").read_text())
    assert cal["interactions"]["M3-wet"]["rolling_resistance_coefficient"] == eta["estimate"]
    # every run counted once, every run went through the executor once
    assert sum(r["runs_requested"] for r in rows.values()) == study.runs_requested == len(ex.asked)
    assert study.runs_requested <= 72


def test_outputs_give_estimate_interval_runs_and_stop_reason_per_parameter(tmp_path, study_file):
    study = Study(study_file, FakeRigs(), tmp_path / "out", log=quiet)
    study.run()
    out = tmp_path / "out" / "twin"
    import csv
    table = list(csv.DictReader(open(out / "stages.csv")))
    assert [t["parameter"] for t in table] == ["particle density", "rolling resistance (M3-dry, steel, PVC)",
                                               "rolling resistance (M3-wet, steel, PVC)",
                                               "pull-off weight fraction (M3-wet)"]
    for t in table:
        assert float(t["interval_low"]) <= float(t["estimate"]) <= float(t["interval_high"])
        assert t["stop_reason"] and int(t["runs_requested"]) >= 0 and t["parameter_unit"]
    summary = json.loads((out / "summary.json").read_text())       # strict JSON: no NaN
    assert summary["yade_versions"] == [YADE_VERSION]
    assert len(summary["runs"]) == study.runs_requested
    runs = list(csv.DictReader(open(out / "runs.csv")))
    assert len(runs) == study.runs_requested and {"seed", "value", "parameters"} <= set(runs[0])


def test_a_resumed_study_asks_for_the_same_jobs_and_simulates_none(tmp_path, study_file):
    cache = {}
    first = FakeRigs(cache=cache)
    rows1 = Study(study_file, first, tmp_path / "out", log=quiet).run()
    assert first.simulated_count > 0
    again = FakeRigs(cache=cache)            # the runner's cache: result.json files of the first study
    rows2 = Study(study_file, again, tmp_path / "out2", log=quiet).run()
    assert again.simulated_count == 0
    assert [j["job_id"] for j in again.asked] == [j["job_id"] for j in first.asked]
    assert [r["parameters"] for r in rows1] == [r["parameters"] for r in rows2]


def test_a_resumed_study_keeps_each_stages_simulated_runs_and_time(tmp_path, study_file):
    """Resumed in the same folder, every run comes from the cache: the stage rows still
    give the runs the first process simulated and its time, not zero."""
    cache = {}
    rows1 = by_stage(Study(study_file, FakeRigs(cache=cache), tmp_path / "out", log=quiet).run())
    again = FakeRigs(cache=cache)
    rows2 = by_stage(Study(study_file, again, tmp_path / "out", log=quiet).run())
    assert again.simulated_count == 0
    for name, r1 in rows1.items():
        assert rows2[name]["runs_simulated"] == r1["runs_simulated"]
        assert rows2[name]["elapsed_s"] >= r1["elapsed_s"]
    assert sum(r["runs_simulated"] for r in rows2.values()) > 0


def test_seed_base_moves_every_seed_and_gives_an_independent_calibration(tmp_path, study_file):
    a, b = FakeRigs(), FakeRigs()
    rows_a = by_stage(Study(study_file, a, tmp_path / "a", log=quiet, seed_base=1).run())
    rows_b = by_stage(Study(study_file, b, tmp_path / "b", log=quiet, seed_base=101).run())
    assert min(j["seed"] for j in a.asked) == 1 and min(j["seed"] for j in b.asked) == 101
    assert not {j["job_id"] for j in a.asked} & {j["job_id"] for j in b.asked}
    # a stage's interval is conditional on the values carried into it: the wet cohesion stage
    # inherits the rolling resistance (5 x its error shows in the cohesion, 40 vs 8 deg per
    # unit) and its two calibrations can differ by more than their conditional intervals
    # (found: 0.284 [0.237, ...] vs 0.195 [..., 0.223]); the stages that start from the
    # config's own values must overlap
    for key in [("M3-dry", "density"), ("M3-dry", "rolling_resistance")]:
        for pa, pb in zip(rows_a[key]["parameters"], rows_b[key]["parameters"]):
            assert pa["low"] <= pb["high"] and pb["low"] <= pa["high"], (key, pa, pb)    # intervals overlap


DENSITY_ONLY = """name: density_only
seeds_count: 3
materials:
  M2:
    - stage: density
      rig: fill
      target: {value: 1603.0, band_percent: 1.0}
      parameter: {bounds: [1500.0, 9000.0], tolerance_kg_m3: 1.0}
      max_runs_count: 18
"""


def test_each_point_runs_new_seeds_so_a_seeds_own_offset_does_not_pin_the_interval(tmp_path):
    """Each seed's pour holds 3.4 % more or fewer spheres at every density (measured on the
    fill cell), the run-to-run noise beyond it is 0.5 %. The truth is the population's:
    1603 / 0.35 / (1 - 0.1 x 0.35) = 4745 kg/m3. With the same 3 seeds at every point the
    18 runs know only 3 pours: the interval held the truth for 5 of these 12 seed bases
    (errors 2.2 % SD); with new seeds at every point for 10 of 12 (errors 1.1 % SD)."""
    cfg = tmp_path / "density.yaml"
    cfg.write_text(DENSITY_ONLY)
    truth = 1603.0 / 0.35 / (1 - 0.1 * 0.35)
    held = 0
    for k, base in enumerate(range(1, 1201, 100)):
        ex = FakeRigs(seed_offsets={"bulk_density_kg_m3": 0.034})
        (row,) = Study(cfg, ex, tmp_path / f"o{k}", log=quiet, seed_base=base).run()
        seeds = [j["seed"] for j in ex.asked]
        assert len(seeds) == len(set(seeds)) == row["runs_requested"]      # no seed twice in the stage
        p = row["parameters"][0]
        held += p["low"] <= truth <= p["high"]
    assert held >= 9, held


def test_run_seeds_gives_one_result_per_seed_and_replaces_a_refused_seed(tmp_path, study_file):
    log = []
    ex = FakeRigs(refuse=lambda job: "no rest" if job["seed"] == 2 else None)
    study = Study(study_file, ex, tmp_path / "out", log=log.append)
    results = study.run_seeds("aor", "M3-dry", {}, [1, 2])
    assert len(results) == 2 and study.last_seeds == [1, 3]      # seed 3: the next above those asked
    assert [j["seed"] for j in ex.asked] == [1, 2, 3] and study.runs_requested == 3
    assert any("replaced by seed 3" in line for line in log)
    with pytest.raises(RunError, match="run"):
        Study(study_file, FakeRigs(refuse=lambda job: "no rest"), tmp_path / "o2", log=quiet).run_seeds(
            "aor", "M3-dry", {}, [1, 2, 3])


def test_every_stage_runs_through_run_seeds(tmp_path, study_file, monkeypatch):
    """The density stage too: seed replacement and the run budget apply to every run."""
    calls = []
    original = Study.run_seeds

    def spy(self, rig, material, overrides, seeds, **kw):
        calls.append((rig, list(seeds)))
        return original(self, rig, material, overrides, seeds, **kw)
    monkeypatch.setattr(Study, "run_seeds", spy)
    ex = FakeRigs()
    Study(study_file, ex, tmp_path / "out", log=quiet).run()
    assert {rig for rig, _ in calls} == {"fill", "aor"}
    assert sum(len(s) for _, s in calls) == len(ex.asked)


def test_a_stage_whose_budget_ends_first_is_not_met_and_says_why(tmp_path, study_file):
    """Noise 6 deg and 6 runs: the interval cannot reach +-0.02; the report must not call it met."""
    cfg = tmp_path / "noisy.yaml"
    cfg.write_text(STUDY.replace("      max_runs_count: 24\n  M3-wet:", "      max_runs_count: 6\n  M3-wet:"))
    study = Study(cfg, FakeRigs(noise={"aor_mean_deg": 6.0}), tmp_path / "out", log=quiet)
    rows = by_stage(study.run())
    r = rows[("M3-dry", "rolling_resistance")]
    assert not r["met"] and r["stop_reason"] == "run budget spent" and r["runs_requested"] == 6
    p = r["parameters"][0]
    assert max(p["estimate"] - p["low"], p["high"] - p["estimate"]) > p["tolerance"]
    assert not rows[("M3-wet", "inherit")]["met"]          # carried, still marked not met
    html = write_report(tmp_path / "out" / "twin").read_text()
    # the cohesion stage (same 6 deg noise) cannot meet its tolerance either
    assert "1 of 3 calibrated stages are precise enough" in html
    assert "M3-dry rolling_resistance (run budget spent)" in html


def test_report_reads_on_a_laptop_and_names_parameter_groups(tmp_path, study_file):
    Study(study_file, FakeRigs(), tmp_path / "out", log=quiet).run()
    html = write_report(tmp_path / "out" / "twin").read_text()
    assert "3 of 3 calibrated stages are precise enough" in html
    assert "rolling resistance (M3-dry, steel, PVC)" in html
    assert "interactions.M3-dry.rolling_resistance_coefficient+" not in html     # no joined config keys
    assert f"YADE {YADE_VERSION}" in html and "unknown" not in html.split("Provenance")[1].split("git")[0]
    assert html.count("data:image/png;base64") == 3            # one calibration plot per calibrated stage
    assert "max-width:1180px" in html


def test_bad_study_configs_name_file_key_and_reason(tmp_path, study_file):
    cases = [
        ("start: 0.35", "start: 3.5", r"twin.yaml: materials.M3-dry\[1\].parameter.start: 3.5 outside"),
        ("stage: inherit", "stage: guess", r"materials.M3-wet\[0\].stage: must be one of"),
        ("tolerance_coefficient: 0.02", "tolerance_pa: 0.02",
         r"materials.M3-dry\[1\].parameter.tolerance_coefficient: give the stop rule's tolerance once"),
        ("        tolerance_coefficient: 0.02\n", "",
         r"materials.M3-dry\[1\].parameter.tolerance_coefficient: give the stop rule's tolerance once"),
        ("      max_runs_count: 24\n  M3-wet:", "      max_iterations_count: 6\n  M3-wet:",
         r"materials.M3-dry\[1\].max_iterations_count: replaced by max_runs_count"),
        ("band_deg: 1.0}\n      parameter:\n        keys", "band_mu: 1.0}\n      parameter:\n        keys",
         r"materials.M3-dry\[1\].target.band_mu: unknown key \(this response is in deg"),
        ("        response_increases: true\n", "", r"parameter.response_increases: must be true or false"),
        ("interactions.pvc.rolling_resistance_coefficient]\n        start",
         "interactions.pvc.rolling_resistance_coefficent]\n        start",
         r"parameter.keys: interactions.pvc.rolling_resistance_coefficent: no such key"),
        ("band_deg: 1.0}\n      parameter:\n        keys",
         "band_deg: 1.0, standard_error_seeds_count: 3}\n      parameter:\n        keys",
         r"target.standard_error_seeds_count: goes with standard_error_deg, which is missing"),
        ("band_deg: 1.0}\n      parameter:\n        keys",
         "band_deg: 1.0, standard_error_deg: 2.0, standard_error_seeds_count: 1}\n      parameter:\n        keys",
         r"target.standard_error_seeds_count: 1 must be a whole number >= 2"),
    ]
    for old, new, message in cases:
        assert old in STUDY, old
        study_file.write_text(STUDY.replace(old, new, 1))
        with pytest.raises(ConfigError, match=message):
            load_study(study_file)


def test_calibrate_cli_refuses_a_bad_config_with_exit_2_and_writes_nothing(tmp_path, study_file, capsys):
    from pycal.cli import main
    study_file.write_text(STUDY.replace("tolerance_fraction: 0.1", "tolerance_fraction: -0.1"))
    code = main(["calibrate", "--config", str(study_file), "--runs", str(tmp_path / "runs"),
                 "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and "twin.yaml: materials.M3-wet[1].parameter.tolerance_fraction: -0.1 must be > 0" in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists() and not (tmp_path / "runs").exists()


def test_a_broken_lab_samples_file_is_a_clear_error_before_any_run(tmp_path, study_file):
    import shutil
    from pycal import LAB_DIR
    lab = tmp_path / "lab"
    shutil.copytree(LAB_DIR, lab)
    text = (lab / "samples.yaml").read_text()
    (lab / "samples.yaml").write_text(text.replace("bulk_density_kg_m3: 1601", "bulk_density_kg_m3: dense", 1))
    study_file.write_text(STUDY.replace("      target: {band_percent: 1.0}", "      lab_dir: lab\n"
                                                                            "      target: {band_percent: 1.0}"))
    ex = FakeRigs()
    with pytest.raises(ConfigError, match=r"lab/samples.yaml: samples.fines_dry.bulk_density_kg_m3: 'dense' must be"):
        Study(study_file, ex, tmp_path / "out", log=quiet)
    assert ex.asked == [] and not (tmp_path / "out").exists()


def test_shipped_study_config_is_valid():
    from pycal.calibration.calibrate_cli import DEFAULT_STUDY
    cfg = load_study(DEFAULT_STUDY)
    assert set(cfg["materials"]) == {"M2", "M3-dry", "M3-wet"}
    kinds = {(m, st["label"]): st["kind"] for m, sts in cfg["materials"].items() for st in sts}
    # the wet cohesion from the wet internal-friction curve
    wet = next(st for st in cfg["materials"]["M3-wet"] if st["label"] == "cohesion")
    assert wet["rig"] == "internal_friction" and wet["response"] == "friction_angle_offset_deg"
    # the dry materials: rolling resistance on the (scaled) AoR, the density checked again last, at the
    # calibrated stiffness and friction; no stage moves the held particle friction of the fines
    for m in ("M2", "M3-dry"):
        labels = [st["label"] for st in cfg["materials"][m]]
        assert labels[-1] == "density_recheck" and kinds[(m, labels[-1])] == "density"
        assert labels.index("wall_friction") < labels.index("density_recheck")
        roll = next(st for st in cfg["materials"][m] if st["label"] == "rolling_resistance")
        assert roll["rig"] == "aor"
    for m, sts in cfg["materials"].items():
        for st in sts:
            keys = [k for p in st.get("parameters", [st.get("parameter") or {}]) for k in p.get("keys", [])]
            keys += st.get("keys", [])
            assert "interactions.M3-dry.friction_coefficient" not in keys, (m, st["label"])
            assert "interactions.M3-wet.friction_coefficient" not in keys, (m, st["label"])


@pytest.fixture
def fake_stiffness_key(monkeypatch):
    """The fake ccs_expansion (fake_rigs.stiffness_result) writes stiffness_log_ratio, a key
    the real rig does not: its descriptor lists it for these tests."""
    import dataclasses
    from pycal import rigs
    desc = rigs.get("ccs_expansion")
    monkeypatch.setitem(rigs._REGISTRY, "ccs_expansion",
                        dataclasses.replace(desc, result_keys=desc.result_keys + ("stiffness_log_ratio",)))


def test_stiffness_stage_works_in_log_e(tmp_path, fake_stiffness_key):
    """log(sim / lab) = log(0.17 E / 6e6): the lab is matched at E = 3.53e7 Pa."""
    cfg = tmp_path / "stiff.yaml"
    cfg.write_text("""
name: stiff
seeds_count: 2
materials:
  M2:
    - stage: stiffness
      rig: ccs_expansion
      response: stiffness_log_ratio
      target: {value: 0.0}
      parameter: {keys: [contact.youngs_modulus_pa], start: 6.0e6, bounds: [1.0e6, 1.0e9], response_increases: true,
                  tolerance_percent: 10.0}
      max_runs_count: 24
""")
    ex = FakeRigs(results={"ccs_expansion": stiffness_result(lambda e: math.log(0.17 * e / 6e6))},
                  noise={"stiffness_log_ratio": 0.03})
    (row,) = Study(cfg, ex, tmp_path / "out", log=quiet).run()
    p = row["parameters"][0]
    assert row["met"] and holds(p, 6e6 / 0.17)
    assert abs(p["estimate"] / (6e6 / 0.17) - 1) < 0.1 and p["estimate"] == float(f"{p['estimate']:.4g}")
    # the second point is a quarter of the log-bounds up (x ~5.6), not a quarter of 1e9 Pa
    es = [j["materials"]["M2"]["contact"]["youngs_modulus_pa"] for j in ex.asked]
    assert es[2] == pytest.approx(6e6 * (1e9 / 1e6) ** 0.25, rel=1e-3)


def test_a_point_the_rig_refuses_becomes_a_limit(tmp_path, fake_stiffness_key):
    """The servo cannot hold its load above 3e8 Pa (measured on M3-dry at 4.68e8): the
    stage must not ask again beyond halfway back, and still land on the root 2e8."""
    cfg = tmp_path / "stiff.yaml"
    cfg.write_text("""
name: stiff
seeds_count: 2
materials:
  M3-dry:
    - stage: stiffness
      rig: ccs_expansion
      response: stiffness_log_ratio
      target: {value: 0.0}
      parameter: {keys: [contact.youngs_modulus_pa], start: 6.0e6, bounds: [1.0e6, 1.0e9], response_increases: true,
                  response_slope_estimate: 1.0e-9, tolerance_percent: 10.0}
      max_runs_count: 30
""")
    ex = FakeRigs(results={"ccs_expansion": stiffness_result(lambda e: 0.38 * math.log(e / 2e8))},
                  noise={"stiffness_log_ratio": 0.02},
                  refuse=lambda j: "load to 3000 Pa: not reached at rest after 8 s"
                  if j["materials"]["M3-dry"]["contact"]["youngs_modulus_pa"] > 3e8 else None)
    (row,) = Study(cfg, ex, tmp_path / "out", log=quiet).run()
    es = [j["materials"]["M3-dry"]["contact"]["youngs_modulus_pa"] for j in ex.asked]
    refused = [e for e in es if e > 3e8]
    assert refused, "the Newton step should overshoot into the refused range"
    first = es.index(refused[0])
    assert all(e <= 3e8 for e in es[first + 4:])          # never beyond the limit again (4 = 1 seed + 3 replacements)
    p = row["parameters"][0]
    assert holds(p, 2e8) and "the rig refused" in row["message"]


def test_a_stage_whose_start_point_fails_is_not_met_and_the_study_goes_on(tmp_path, study_file):
    ex = FakeRigs(refuse=lambda j: "blow-up" if j["rig"] == "aor" and j["material"] == "M3-dry" else None)
    rows = by_stage(Study(study_file, ex, tmp_path / "out", log=quiet).run())
    assert rows[("M3-dry", "density")]["met"]
    rr = rows[("M3-dry", "rolling_resistance")]
    assert not rr["met"] and rr["stop_reason"] == "runs failed" and "blow-up" in rr["message"]
    assert rr["responses"][0]["target"] == pytest.approx(labdata.aor_target_deg("fines_dry"))
    inh = rows[("M3-wet", "inherit")]
    assert not inh["met"] and "found no value" in inh["message"]
    assert ("M3-wet", "cohesion") in rows


def test_inheriting_from_a_failed_stage_takes_the_sources_earlier_value(tmp_path):
    """Found in the shipped study: the dry fines' final pass failed at its start, and the wet
    fines kept their config rolling resistance (0.35) instead of the dry fines' calibrated
    one from the earlier rolling stage."""
    second = """    - stage: rolling_resistance
      name: rolling_again
      rig: aor
      rig_overrides: {rig.procedure.lift_speed_m_s: 0.05}
      response: aor_mean_deg
      target: {sample: fines_dry, test: angle_of_repose, band_deg: 1.0}
      parameter:
        keys: [interactions.M3-dry.rolling_resistance_coefficient]
        bounds: [0.05, 1.5]
        response_increases: true
        tolerance_coefficient: 0.02
      max_runs_count: 24
  M3-wet:
    - stage: inherit
      from: {material: M3-dry, stage: rolling_again, key: interactions.M3-dry.rolling_resistance_coefficient}
"""
    cfg = tmp_path / "s.yaml"
    cfg.write_text(STUDY.replace("  M3-wet:\n    - stage: inherit\n      from: {material: M3-dry, stage: rolling_resistance}\n",
                                 second))
    ex = FakeRigs(refuse=lambda j: "no angle" if j["rig_config"]["procedure"].get("lift_speed_m_s") == 0.05 else None)
    study = Study(cfg, ex, tmp_path / "out", log=quiet)
    rows = by_stage(study.run())
    assert rows[("M3-dry", "rolling_again")]["stop_reason"] == "runs failed"
    found = rows[("M3-dry", "rolling_resistance")]["parameters"][0]["estimate"]
    inh = rows[("M3-wet", "inherit")]
    assert inh["parameters"][0]["estimate"] == found != 0.35 and not inh["met"]
    assert study.overrides["M3-wet"]["interactions.M3-wet.rolling_resistance_coefficient"] == found


def test_a_target_beyond_the_bounds_is_reported_not_forced(tmp_path, study_file):
    cfg = tmp_path / "short.yaml"
    cfg.write_text(STUDY.replace("bounds: [0.05, 1.5]", "bounds: [0.05, 0.3]").replace("start: 0.35", "start: 0.2"))
    rows = by_stage(Study(cfg, FakeRigs(), tmp_path / "out", log=quiet).run())
    r = rows[("M3-dry", "rolling_resistance")]
    assert not r["met"] and r["stop_reason"] == "target beyond the upper bound"
    assert r["parameters"][0]["estimate"] == 0.3 and "beyond what" in r["message"]


def test_friction_stage_and_its_lab_curve_plot_chosen_by_response(tmp_path):
    """Fake wall friction mu = 0.9 x particle-steel friction + 0.05: the stage must land where
    the mean (sim - lab) over the steps >= 10 kPa is 0, reading the lab gravel curve."""
    cfg = tmp_path / "fric.yaml"
    cfg.write_text("""
name: fric
seeds_count: 2
materials:
  M2:
    - stage: friction
      rig: wall_friction
      response: friction_offset_mu_static
      target: {value: 0.0, band_mu: 0.03}
      parameter: {keys: [interactions.steel.friction_coefficient], start: 0.8, bounds: [0.05, 1.5],
                  response_increases: true, tolerance_coefficient: 0.02}
      max_runs_count: 24
""")
    ex = FakeRigs(results={"wall_friction": wall_result(lambda steel, s: 0.9 * steel["friction_coefficient"] + 0.05)})
    (row,) = Study(cfg, ex, tmp_path / "out", log=quiet).run()
    lab = labdata.target_curve("wall_friction_gravel_dry", "mu_static")
    at = {float(s): float(v) for s, v in zip(lab.stress_pa, lab.value)}
    truth = ((at[12000] + at[40000] + at[90000]) / 3 - 0.05) / 0.9
    p = row["parameters"][0]
    assert row["met"] and holds(p, truth) and abs(p["estimate"] - truth) <= 0.02
    assert row["plots"] == ["plots/M2-friction/calibration.png", "plots/M2-friction/wall_friction/friction_vs_stress.png"]
    report = write_report(tmp_path / "out" / "fric").read_text()
    assert report.count("data:image/png;base64") == 2


def test_the_calibration_plot_shows_every_run_the_fit_the_target_and_the_interval(tmp_path, study_file):
    import matplotlib
    matplotlib.use("Agg")
    from pycal.calibration import plots
    figures = []
    real = plots.save_png

    def keep(fig, path, dpi=110):
        figures.append(fig)
        return real(fig, path, dpi)
    plots.save_png = keep
    try:
        study = Study(study_file, FakeRigs(), tmp_path / "out", log=quiet)
        rows = by_stage(study.run())
    finally:
        plots.save_png = real
    ax = figures[1].axes[0]                                # rolling resistance
    row = rows[("M3-dry", "rolling_resistance")]
    runs = [r for r in study.runs if r["stage"] == "rolling_resistance"]
    points = next(line for line in ax.lines if line.get_marker() == "o")
    assert len(points.get_xdata()) == len(runs)             # every seed's run is drawn
    assert sorted(points.get_ydata()) == pytest.approx(sorted(r["value"] for r in runs))
    p = row["parameters"][0]
    verticals = [line for line in ax.lines if len(set(line.get_xdata())) == 1]
    assert any(line.get_xdata()[0] == pytest.approx(p["estimate"]) for line in verticals)
    target = labdata.aor_target_deg("fines_dry")
    assert any(list(line.get_ydata()) == [target, target] for line in ax.lines)
    spans = [patch.get_extents() for patch in ax.patches]
    assert len(spans) >= 2                                  # lab band and the 95 % interval
    assert "rolling resistance (M3-dry, steel, PVC)" in ax.get_xlabel()


def test_a_resumed_study_replays_its_journal_even_when_the_numbers_would_decide_otherwise(tmp_path, study_file,
                                                                                          monkeypatch):
    """GP and MCMC arithmetic is not bit-reproducible between processes (BLAS kernels depend
    on memory alignment): a resumed study must not rely on deciding the same again. Here
    the second invocation's design is deliberately different; the journal keeps the runs
    (and the values carried between stages) those of the first."""
    cache = {}
    first = FakeRigs(cache=cache)
    rows1 = Study(study_file, first, tmp_path / "out", log=quiet).run()
    from pycal.stats import design
    monkeypatch.setattr(design, "DISTANCE_SCALE_U", 0.01)          # another process, other choices
    again = FakeRigs(cache=cache)
    rows2 = Study(study_file, again, tmp_path / "out", log=quiet).run()
    assert again.simulated_count == 0
    assert [j["job_id"] for j in again.asked] == [j["job_id"] for j in first.asked]
    assert [r["parameters"] for r in rows1] == [r["parameters"] for r in rows2]
    # without the journal the same perturbation asks for other runs
    (tmp_path / "out" / "twin" / "journal.json").unlink()
    fresh = FakeRigs(cache=cache)
    Study(study_file, fresh, tmp_path / "out", log=quiet).run()
    assert fresh.simulated_count > 0


def test_a_killed_stage_resumes_its_recorded_points_then_decides_on(tmp_path, study_file):
    cache = {}

    class Killed(Exception):
        pass

    class DiesAfter(FakeRigs):
        def __init__(self, n, **kw):
            super().__init__(**kw)
            self.n = n

        def run(self, jobs, raise_on_error=True):
            if len(self.asked) >= self.n:
                raise Killed()
            return super().run(jobs, raise_on_error)
    with pytest.raises(Killed):
        Study(study_file, DiesAfter(15, cache=cache), tmp_path / "out", log=quiet).run()
    asked_before = len(cache)
    resumed = FakeRigs(cache=cache)
    rows = Study(study_file, resumed, tmp_path / "out", log=quiet).run()
    assert resumed.simulated_count == len(cache) - asked_before        # only runs beyond the kill are new
    assert all(r["met"] for r in rows)


def test_calibrate_and_fit_density_commands_run_on_a_fake_executor(tmp_path, study_file, capsys, monkeypatch):
    from pycal import runner
    from pycal.cli import main
    monkeypatch.setattr(runner, "make_executor", lambda name, **kw: FakeRigs())
    code = main(["calibrate", "--config", str(study_file), "--out", str(tmp_path / "out"), "--runs",
                 str(tmp_path / "runs"), "--seed-base", "5"])
    out = capsys.readouterr().out
    assert code == 0 and "seeds 5, 6, ..." in out and "3 of 3 calibrated stages met their tolerance" in out
    assert "rolling resistance (M3-dry, steel, PVC) = " in out and (tmp_path / "out" / "twin" / "report.html").is_file()
    monkeypatch.setattr(runner, "LocalPool", lambda **kw: FakeRigs())
    code = main(["fit-density", "--material", "M2", "--out", str(tmp_path / "dens"), "--runs", str(tmp_path / "runs")])
    out = capsys.readouterr().out
    rho_truth = 1603 / (0.35 * (1 - 0.1 * 0.35))
    import re
    estimate = float(re.search(r"^M2: particle density (\S+) kg/m3", out, re.M).group(1))
    assert code == 0 and abs(estimate - rho_truth) < 50 and "95 % interval" in out


def rolling_study(tmp_path, tolerance, max_runs, extra=""):
    """A one-stage study: the M3-dry rolling resistance on the dry fines' AoR, start 0.35
    (extra: more stage keys, one YAML line)."""
    cfg = tmp_path / "rolling.yaml"
    cfg.write_text(f"""
name: rolling
seeds_count: 3
materials:
  M3-dry:
    - stage: rolling_resistance
      rig: aor
      response: aor_mean_deg
      target: {{sample: fines_dry, test: angle_of_repose, band_deg: 2.0}}
      parameter:
        keys: [interactions.M3-dry.rolling_resistance_coefficient]
        start: 0.35
        bounds: [0.02, 1.5]
        response_increases: true
        tolerance_coefficient: {tolerance}
      max_runs_count: {max_runs}
      {extra}
""")
    return cfg


def test_a_pile_too_flat_for_an_angle_is_a_limit_not_a_crash(tmp_path):
    """Measured on the new law (M3-dry, rolling 0.02): the pile spreads to two layers and no
    sector has an angle, so aor_mean_deg is null on every seed. The stage must back off
    from such a point as from a refused one, and still land on the root (the lab's 38 deg
    at rolling 0.2 in this fake law); a single seed without an angle is left out."""
    cfg = rolling_study(tmp_path, tolerance=0.1, max_runs=45)

    def pile(job):
        eta = job["materials"]["M3-dry"]["interactions"]["M3-dry"]["rolling_resistance_coefficient"]
        if eta < 0.1 or (eta < 0.3 and job["seed"] % 3 == 0):
            return {"aor_mean_deg": None}
        return {"aor_mean_deg": 30 + 40 * eta}

    logged = []
    ex = FakeRigs(results={"aor": pile})
    (row,) = Study(cfg, ex, tmp_path / "out", log=logged.append).run()
    etas = [j["materials"]["M3-dry"]["interactions"]["M3-dry"]["rolling_resistance_coefficient"] for j in ex.asked]
    target = labdata.aor_target_deg("fines_dry")
    p = row["parameters"][0]
    assert min(etas) < 0.1, "the design should try the low end"
    assert holds(p, (target - 30) / 40)
    assert any("refused rolling resistance (M3-dry) = 0.02: it becomes a limit" in m for m in logged)
    assert any("has no value on seed(s)" in m and "left out" in m for m in logged)


def test_a_root_between_the_limit_and_a_refused_point_is_found_by_probing(tmp_path):
    """The M3-dry case of the shipped study on the new law: the lab angle needs rolling ~0.15,
    the pile has no angle at 0.02, and the first limit (halfway back to the start 0.35) is
    0.185 - above the root. The stage probes towards the refused point and lands on it."""
    cfg = rolling_study(tmp_path, tolerance=0.05, max_runs=60)
    target = labdata.aor_target_deg("fines_dry")
    root = 0.15

    def pile(job):
        eta = job["materials"]["M3-dry"]["interactions"]["M3-dry"]["rolling_resistance_coefficient"]
        return {"aor_mean_deg": None if eta < 0.08 else target + 40 * (eta - root)}

    logged = []
    ex = FakeRigs(results={"aor": pile})
    (row,) = Study(cfg, ex, tmp_path / "out", log=logged.append).run()
    p = row["parameters"][0]
    assert any("probing" in m for m in logged)
    assert row["met"] and holds(p, root), row["message"]


def test_an_estimate_clipped_at_a_refused_limit_probes_past_it(tmp_path):
    """Seen in the seed-base-101 study: the rig refused rolling 0.02, the limit became 0.185
    (halfway to 0.35), the root lay below it, and with AoR seed noise of ~5 deg the stop rule
    never called the target beyond: the stage ran 0.185 nine times. Fake AoR = 30 + 60 x
    rolling (root 0.133 for the lab's 38 deg), noise 8 deg, refused below 0.06: the stage
    must probe below 0.185 and bracket the root."""
    cfg = rolling_study(tmp_path, tolerance=0.05, max_runs=36)
    def aor(job):
        return {"aor_mean_deg": 30.0 + 60.0 * job["materials"]["M3-dry"]["interactions"]["M3-dry"][
            "rolling_resistance_coefficient"]}
    ex = FakeRigs(results={"aor": aor}, noise={"aor_mean_deg": 8.0},
                  refuse=lambda j: "no angle" if j["materials"]["M3-dry"]["interactions"]["M3-dry"][
                      "rolling_resistance_coefficient"] < 0.06 else None)
    (row,) = Study(cfg, ex, tmp_path / "out", log=quiet).run()
    xs = [j["materials"]["M3-dry"]["interactions"]["M3-dry"]["rolling_resistance_coefficient"] for j in ex.asked]
    assert 0.02 in xs                                              # refused: the limit
    assert any(0.06 <= x < 0.18 for x in xs)                       # a probe below the halfway limit ran
    p = row["parameters"][0]
    root = (labdata.aor_target_deg("fines_dry") - 30.0) / 60.0
    assert p["low"] < 0.18 and holds(p, root)


def test_a_stage_does_not_spend_its_budget_on_the_limit_it_cannot_pass(tmp_path):
    """The main job of 2026-12-03 (M3-dry rolling): 0.02 refused, the probe 0.1025 ran, the
    estimate 0.13 sat above the limit with the interval ending on it, and the stage ran
    0.1025 seven more times (24 of its 36 runs at one value). Fake AoR = 30 + 60 x rolling,
    noise 8 deg, refused below 0.095: the stage probes past the limit while the interval
    ends on it, and never runs one value more than three points' worth (9 runs)."""
    cfg = rolling_study(tmp_path, tolerance=0.05, max_runs=36)

    def eta(j):
        return j["materials"]["M3-dry"]["interactions"]["M3-dry"]["rolling_resistance_coefficient"]

    ex = FakeRigs(results={"aor": lambda j: {"aor_mean_deg": 30.0 + 60.0 * eta(j)}}, noise={"aor_mean_deg": 8.0},
                  refuse=lambda j: "no angle" if eta(j) < 0.095 else None)
    (row,) = Study(cfg, ex, tmp_path / "out", log=quiet).run()
    xs = [eta(j) for j in ex.asked]
    assert max(xs.count(x) for x in set(xs)) <= 9, sorted(xs)
    assert any(x < 0.1025 for x in xs if x != 0.02)        # probed past the limit 0.1025 (refused or not)


def test_a_stage_that_cannot_reach_its_tolerance_stops_early_when_its_config_says_so(tmp_path):
    """A pile that hardly follows the rolling resistance (AoR = 30 + 20 x rolling, seed noise
    10 deg, tolerance 0.05): a root found from n runs has a half-width of about
    1.96 x 10 / (20 sqrt(n)) = 0.16 at the budget's 36 runs, 3 x the tolerance. With
    out_of_reach_factor 1.5 the stage stops, not met, before its budget; without it, it
    spends the budget."""
    def eta(j):
        return j["materials"]["M3-dry"]["interactions"]["M3-dry"]["rolling_resistance_coefficient"]

    rows = {}
    for name, extra in (("on", "out_of_reach_factor: 1.5"), ("off", "")):
        (tmp_path / name).mkdir()
        ex = FakeRigs(results={"aor": lambda j: {"aor_mean_deg": 30.0 + 20.0 * eta(j)}}, noise={"aor_mean_deg": 10.0})
        (row,) = Study(rolling_study(tmp_path / name, 0.05, 36, extra), ex, tmp_path / name / "out", log=quiet).run()
        rows[name] = (row, len(ex.asked))
    (on, runs_on), (off, runs_off) = rows["on"], rows["off"]
    assert on["stop_reason"] == stopping.OUT_OF_REACH and not on["met"] and runs_on < 36
    assert off["stop_reason"] != stopping.OUT_OF_REACH and runs_off > runs_on


def test_report_shows_pictures_held_values_both_verdicts_and_provenance(tmp_path, study_file):
    """Every calibrated stage of the report: a gallery of its rig's pictures (the AoR stages:
    the pile at the estimate and at the lowest and highest value run), the values it held
    (the rolling stage holds the density found before it), both verdicts; and the
    provenance block (host, command, libraries, lab and config fingerprints)."""
    rows = by_stage(Study(study_file, FakeRigs(runs_dir=tmp_path / "runs"), tmp_path / "out", log=quiet).run())
    rolling = rows[("M3-dry", "rolling_resistance")]
    held = {h["key"]: h for h in rolling["held"]}
    density = rows[("M3-dry", "density")]["parameters"][0]
    assert held["particles.density_kg_m3"]["value"] == density["estimate"]
    assert held["particles.density_kg_m3"]["source"] == "calibrated: M3-dry/density"
    assert rolling["matches_lab"] is True and rolling["met"] is True
    captions = [g["caption"] for g in rolling["gallery"]]
    assert len(captions) == 3 and "at the estimate" in captions[0] and "pile_side.png" in captions[0]
    assert "lowest value run" in captions[1] and "highest value run" in captions[2]
    cohesion = rows[("M3-wet", "cohesion")]
    held = {h["key"]: h["source"] for h in cohesion["held"]}
    assert held["interactions.M3-wet.rolling_resistance_coefficient"] == "calibrated: M3-wet/inherit"
    seeds = rolling["aor_seeds"]
    assert [x["seed"] for x in seeds["seeds"]] and seeds["lab"]["sample"] == "fines_dry"
    html = write_report(tmp_path / "out" / "twin").read_text()
    assert "<th>matches the lab</th><th>precise enough</th>" in html
    assert html.count("as the lab reads it") == 2          # the two AoR stages
    assert html.count("held values (not fitted in this stage)") == 3 and html.count("points run (in order)") == 3
    assert html.count("<figure") == 6                       # 3 per AoR stage; the fill writes no picture
    prov = html.split("<h2>Provenance</h2>")[1]
    for field in ("host:", "command:", "libraries:", "python 3", "sklearn", "emcee", "lab files:", "SHA-256",
                  "study config:"):
        assert field in prov, field


def test_calibrated_files_say_which_values_were_calibrated_with_intervals_and_which_are_start_values(
        tmp_path, study_file):
    cfg = tmp_path / "noisy.yaml"       # the wet cohesion stage refuses every run: its key keeps its start value
    cfg.write_text(STUDY)
    ex = FakeRigs(refuse=lambda job: "no rest" if job["material"] == "M3-wet" and job["rig"] == "aor" else None)
    study = Study(cfg, ex, tmp_path / "out", log=quiet)
    study.run()
    rec = yaml.safe_load((study.out / "calibrated" / "M3-dry.calibration.yaml").read_text())
    rr = rec["calibrated"]["interactions.M3-dry.rolling_resistance_coefficient"]
    assert rr["stage"] == "M3-dry/rolling_resistance" and rr["start_value"] == 0.35
    assert rr["interval_95"][0] <= rr["value"] <= rr["interval_95"][1]
    assert rec["git_commit"] and rec["started_utc"]
    assert rec["rig_scales"]["rolling_resistance"] == {"aor": 1.5}     # the shipped cylinder (configs/rigs/aor.yaml)
    wet = yaml.safe_load((study.out / "calibrated" / "M3-wet.calibration.yaml").read_text())
    assert "interactions.M3-wet.cohesion.force_fraction" in wet["start_values"]
    assert wet["calibrated"]["interactions.M3-wet.rolling_resistance_coefficient"]["stage"] == "M3-wet/inherit"


def test_eta_is_an_upper_bound_from_the_cpu_per_run_so_far():
    from pycal.calibration.eta import Eta, text
    e = Eta(workers=2)
    e.add("M2", "aor", [{"provenance": {"cpu_time_s": 10.0}}, {"provenance": {"cpu_time_s": 14.0}}, None])
    seconds, unknown = e.bound_s([("M2", "aor", 6), ("M2", "wall_friction", 9)])
    assert seconds == pytest.approx(6 * 12.0 / 2) and unknown == ["wall_friction"]
    assert text(seconds, unknown) == "~36 s + ?" and text(600, []) == "~10 min"


def test_eta_keeps_each_material_s_cost_on_a_rig_and_counts_only_the_cores():
    """The main job's wet cohesion stage: the dry fines' internal-friction runs cost 110 s,
    the wet ones 570 s; 15 wet runs left on 3 workers and 2 cores are ~71 min, not the 9
    min that a rig-wide median over 3 workers gave. A material not run yet on a rig takes
    the costliest material's cost there."""
    from pycal.calibration.eta import Eta
    e = Eta(workers=3, cores=2)
    e.add("M3-dry", "internal_friction", [{"provenance": {"cpu_time_s": 110.0}}] * 15)
    e.add("M3-wet", "internal_friction", [{"provenance": {"cpu_time_s": c}} for c in (517.0, 571.0, 644.0)])
    seconds, _ = e.bound_s([("M3-wet", "internal_friction", 15)])
    assert seconds == pytest.approx(15 * 571.0 / 2)
    seconds, _ = e.bound_s([("M9", "internal_friction", 2)])
    assert seconds == pytest.approx(2 * 571.0 / 2)
    assert Eta(workers=3).workers == 3 and Eta(workers=3, cores=8).workers == 3


def test_the_console_shows_stage_runs_and_time_left(tmp_path, study_file):
    log = []
    Study(study_file, FakeRigs(), tmp_path / "out", log=log.append).run()
    points = [line for line in log if " -> aor_mean_deg " in line]
    assert points and all(" runs; left <= " in line for line in points)
    assert all(len(line) <= 125 for line in points), max(points, key=len)


def test_a_resumed_stage_that_stopped_on_a_repeated_point_says_which(tmp_path, study_file):
    """A 1-D stage that stopped because its next point had run at length (stopping.REPEATS)
    resumes from its journal with the same message; a journal written before the next point
    was kept resumes too (it crashed on the missing point: seed base 101's dry rolling stage)."""
    cache = {}
    Study(study_file, FakeRigs(cache=cache), tmp_path / "out", log=quiet).run()
    path = tmp_path / "out" / "twin" / "journal.json"
    journal = json.loads(path.read_text())
    key = next(k for k in journal if "rolling_resistance" in k and "M3-dry" in k)
    x = journal[key]["points"][-1]
    journal[key]["result"].update(stop=stopping.REPEATS, next_x=x)
    path.write_text(json.dumps(journal))
    rows = by_stage(Study(study_file, FakeRigs(cache=cache), tmp_path / "out", log=quiet).run())
    msg = rows[("M3-dry", "rolling_resistance")]["message"]
    assert f"stopped: the next point, {x:.4g}, had run" in msg
    del journal[key]["result"]["next_x"]
    path.write_text(json.dumps(journal))
    rows = by_stage(Study(study_file, FakeRigs(cache=cache), tmp_path / "out", log=quiet).run())
    assert "stopped: the next point had run at length already" in rows[("M3-dry", "rolling_resistance")]["message"]
