"""The calibration study engine on a fake executor with known response laws.

Fake physics: bulk density = 0.35 x particle density; angle of repose =
20 deg + 40 deg x rolling resistance + 8 deg x cohesion force fraction. The engine must
find the values that reproduce the lab targets, carry them from stage to stage, write
loadable calibrated configs and resume without new runs.
"""
import math

import pytest
import yaml

from pycal import labdata
from pycal.calibration.study import Study, load_study
from pycal.configs import validate_material, material_names, load_boundaries
from pycal.errors import ConfigError
from pycal.report import write_report

STUDY = """
name: twin
seeds_count: 2
max_runs_count: 200
materials:
  M3-dry:
    - {stage: density, rig: fill, tolerance_percent: 1.0}
    - stage: rolling_resistance
      rig: aor
      response: aor_mean_deg
      target: {sample: fines_dry, test: angle_of_repose}
      tolerance_deg: 0.5
      parameter:
        keys: [interactions.M3-dry.rolling_resistance_coefficient,
               interactions.steel.rolling_resistance_coefficient,
               interactions.pvc.rolling_resistance_coefficient]
        start: 0.35
        bounds: [0.05, 1.5]
  M3-wet:
    - stage: inherit
      from: {material: M3-dry, stage: rolling_resistance}
      keys: [interactions.M3-wet.rolling_resistance_coefficient,
             interactions.steel.rolling_resistance_coefficient,
             interactions.pvc.rolling_resistance_coefficient]
    - stage: cohesion
      rig: aor
      response: aor_mean_deg
      target: {sample: fines_wet, test: angle_of_repose}
      tolerance_deg: 0.5
      parameter: {keys: [interactions.M3-wet.cohesion.force_fraction], start: 0.5, bounds: [0.0, 5.0]}
"""


class FakeExecutor:
    def __init__(self):
        self.simulated = set()

    def run(self, jobs, raise_on_error=True):
        out = []
        for job in jobs:
            self.simulated.add(job["job_id"])
            mat = job["materials"][job["material"]]
            name = job["material"]
            rho = mat["particles"]["density_kg_m3"]
            eta = mat["interactions"][name]["rolling_resistance_coefficient"]
            coh = mat["interactions"][name]["cohesion"]
            f = coh.get("force_fraction", 0.0) if name == "M3-wet" else 0.0
            noise = 0.1 * math.sin(job["seed"])
            out.append({"bulk_density_kg_m3": 0.35 * rho * (1 + 0.001 * noise),
                        "aor_mean_deg": 20 + 40 * eta + 8 * f + noise})
        return out


@pytest.fixture
def study_file(tmp_path):
    p = tmp_path / "twin.yaml"
    p.write_text(STUDY)
    return p


def test_study_recovers_known_parameters(tmp_path, study_file):
    ex = FakeExecutor()
    study = Study(study_file, ex, tmp_path / "out", log=lambda m: None)
    rows = study.run()
    assert all(r["met"] for r in rows), rows
    by = {(r["material"], r["stage"]): r for r in rows}
    assert by[("M3-dry", "density")]["value"] == pytest.approx(1601 / 0.35, rel=0.01)
    dry_target = labdata.aor_target_deg("fines_dry")
    eta = by[("M3-dry", "rolling_resistance")]["value"]
    assert 20 + 40 * eta == pytest.approx(dry_target, abs=0.5)
    assert by[("M3-wet", "inherit")]["value"] == eta
    f = by[("M3-wet", "cohesion")]["value"]
    assert 20 + 40 * eta + 8 * f == pytest.approx(labdata.aor_target_deg("fines_wet"), abs=0.5)
    # calibrated configs load as configs
    partners = set(material_names()) | set(load_boundaries())
    for m in ("M3-dry", "M3-wet"):
        path = tmp_path / "out" / "twin" / "calibrated" / f"{m}.yaml"
        cal = yaml.safe_load(path.read_text())
        validate_material(cal, path.with_name(f"{m}.yaml"), partners)
    cal = yaml.safe_load((tmp_path / "out" / "twin" / "calibrated" / "M3-wet.yaml").read_text())
    assert cal["interactions"]["M3-wet"]["rolling_resistance_coefficient"] == eta
    # report
    html = write_report(tmp_path / "out" / "twin").read_text()
    assert "4 of 4 stage targets met" in html and "data:image/png;base64" in html
    # cost per stage and per material: every run of the study is counted once
    assert sum(r["runs_requested"] for r in rows) == study.runs_requested > 0
    assert "Cost per material" in html and "runs_simulated" in (tmp_path / "out" / "twin" / "stages.csv").read_text()


def test_rerun_simulates_nothing_new(tmp_path, study_file):
    ex = FakeExecutor()
    Study(study_file, ex, tmp_path / "out", log=lambda m: None).run()
    first = set(ex.simulated)
    ex2 = FakeExecutor()
    Study(study_file, ex2, tmp_path / "out", log=lambda m: None).run()
    assert ex2.simulated == first      # same jobs asked again: a caching executor runs none of them


def test_bad_study_config_names_field(tmp_path, study_file):
    study_file.write_text(STUDY.replace("start: 0.35", "start: 3.5"))
    with pytest.raises(ConfigError, match=r"twin.yaml: materials.M3-dry\[1\].parameter.start: 3.5 outside"):
        load_study(study_file)
    study_file.write_text(STUDY.replace("stage: inherit", "stage: guess"))
    with pytest.raises(ConfigError, match=r"materials.M3-wet\[0\].stage: must be one of"):
        load_study(study_file)


def test_shipped_study_config_is_valid():
    from pycal.calibration.calibrate_cli import DEFAULT_STUDY
    cfg = load_study(DEFAULT_STUDY)
    assert set(cfg["materials"]) == {"M2", "M3-dry", "M3-wet"}


def test_noisy_points_get_more_seeds(tmp_path):
    cfg = tmp_path / "noisy.yaml"
    cfg.write_text(STUDY.replace("seeds_count: 2", "seeds_count: 2\nmax_seeds_count: 8"))

    class Noisy(FakeExecutor):
        def run(self, jobs, raise_on_error=True):
            out = super().run(jobs)
            for job, r in zip(jobs, out):   # +-10 deg seed noise on the angle
                r["aor_mean_deg"] += 10.0 * (1 if job["seed"] % 2 else -1)
            return out
    ex = Noisy()
    study = Study(cfg, ex, tmp_path / "out", log=lambda m: None)
    m, s, n = study.evaluate("aor", "M3-dry", {}, "aor_mean_deg", "rolling_resistance", tolerance=2.0)
    assert n == 8                                   # 2 -> 4 -> 8 seeds: the noise stays above tolerance
    m, s, n = study.evaluate("aor", "M3-dry", {}, "aor_mean_deg", "rolling_resistance", tolerance=50.0)
    assert n == 2                                   # quiet enough for a loose tolerance
    # a point whose whole +-2 standard errors lie off the target's tolerance band is not
    # in doubt: its 2 seeds already say which way to go
    m, s, n = study.evaluate("aor", "M3-dry", {}, "aor_mean_deg", "rolling_resistance", tolerance=2.0,
                             target=m + 30.0)
    assert n == 2
    m, s, n = study.evaluate("aor", "M3-dry", {}, "aor_mean_deg", "rolling_resistance", tolerance=2.0,
                             target=m + 3.0)
    assert n == 8                                   # in doubt: more seeds


def test_stiffness_stage_solves_in_log_space(tmp_path):
    """Fake bulk unloading stiffness = 0.17 x E: log(sim / lab) = log(0.17 E / 6e6);
    the stage must find E = 6e6 / 0.17 = 3.53e7 within +-28 % (tolerance 0.25 in log)."""
    cfg = tmp_path / "stiff.yaml"
    cfg.write_text("""
name: stiff
seeds_count: 2
materials:
  M2:
    - stage: stiffness
      rig: ccs_expansion
      response: fake_log_ratio
      target: {value: 0.0}
      tolerance_log_ratio: 0.25
      parameter: {keys: [contact.youngs_modulus_pa], start: 6.0e6, bounds: [1.0e6, 1.0e9], response_increases: true}
""")

    class Stiff(FakeExecutor):
        def run(self, jobs, raise_on_error=True):
            return [{"fake_log_ratio": math.log(0.17 * j["materials"]["M2"]["contact"]["youngs_modulus_pa"] / 6e6)}
                    for j in jobs]
    (row,) = Study(cfg, Stiff(), tmp_path / "out", log=lambda m: None).run()
    assert row["met"] and abs(math.log(row["value"] / 3.53e7)) <= 0.25
    assert row["value"] == float(f"{row['value']:.3g}")


def test_a_stage_whose_runs_fail_is_not_met_and_the_study_goes_on(tmp_path, study_file):
    from pycal.errors import RunError

    class FailingAor(FakeExecutor):
        def run(self, jobs, raise_on_error=True):
            if jobs[0]["rig"] == "aor" and jobs[0]["material"] == "M3-dry":
                raise RunError("aor-M3-dry: no result (RIG FAILED: blow-up)")
            return super().run(jobs)
    rows = Study(study_file, FailingAor(), tmp_path / "out", log=lambda m: None).run()
    by = {(r["material"], r["stage"]): r for r in rows}
    assert by[("M3-dry", "density")]["met"]
    assert not by[("M3-dry", "rolling_resistance")]["met"]
    assert "blow-up" in by[("M3-dry", "rolling_resistance")]["message"]
    assert by[("M3-dry", "rolling_resistance")]["tolerance"] == 0.5       # the table still names the target
    assert math.isfinite(by[("M3-dry", "rolling_resistance")]["target"])
    assert not by[("M3-wet", "inherit")]["met"] and "found no value" in by[("M3-wet", "inherit")]["message"]
    assert ("M3-wet", "cohesion") in by          # the study went on


def test_a_failed_seed_is_replaced_by_the_next_one(tmp_path, study_file):
    """One packing that does not come to rest must not cost a stage: seed 2 fails, seed
    3 stands in; a point where most seeds fail is a point the rig cannot run."""
    from pycal.errors import RunError

    class Refuses(FakeExecutor):
        def __init__(self, bad_seeds):
            super().__init__()
            self.bad_seeds, self.last_errors, self.seeds_run = bad_seeds, [], []

        def run(self, jobs, raise_on_error=True):
            out = super().run(jobs)
            self.seeds_run += [j["seed"] for j in jobs]
            self.last_errors = [f"{j['job_id']}: no result (RIG FAILED: no rest)" for j in jobs
                                if j["seed"] in self.bad_seeds]
            return [None if j["seed"] in self.bad_seeds else r for j, r in zip(jobs, out)]
    log = []
    ex = Refuses({2})
    study = Study(study_file, ex, tmp_path / "out", log=log.append)
    m, s, n = study.evaluate("aor", "M3-dry", {}, "aor_mean_deg", "rolling_resistance")
    assert n == 2 and ex.seeds_run == [1, 2, 3]
    assert any("WARNING" in line and "replaced by seed 3" in line for line in log)
    with pytest.raises(RunError, match="2 of 2 run"):
        Study(study_file, Refuses({1, 2, 3}), tmp_path / "out2", log=log.append).evaluate(
            "aor", "M3-dry", {}, "aor_mean_deg", "rolling_resistance")


def test_a_value_not_met_is_still_inherited_and_marked(tmp_path, study_file):
    """The dry stage's closest value beats the config's start for the wet stages; the
    inherit row stays 'not met' so nobody mistakes it for a calibrated value."""
    cfg = tmp_path / "strict.yaml"
    cfg.write_text(STUDY.replace("tolerance_deg: 0.5", "tolerance_deg: 0.0001", 1).replace(
        "bounds: [0.05, 1.5]", "bounds: [0.05, 1.5]\n      max_iterations_count: 2", 1))
    study = Study(cfg, FakeExecutor(), tmp_path / "out", log=lambda m: None)
    rows = study.run()
    by = {(r["material"], r["stage"]): r for r in rows}
    dry = by[("M3-dry", "rolling_resistance")]
    assert not dry["met"] and not math.isnan(dry["value"])
    inh = by[("M3-wet", "inherit")]
    assert not inh["met"] and inh["value"] == dry["value"] and "did not meet" in inh["message"]
    assert study.overrides["M3-wet"]["interactions.M3-wet.rolling_resistance_coefficient"] == dry["value"]


def test_friction_stage_matches_the_wall_friction_curve(tmp_path):
    """Fake wall friction: mu_static = 0.9 x particle-steel friction + 0.05 at every step
    (a plateau). The lab gravel curve rises to 0.50 at 30 kPa; the offset response is the
    mean (sim - lab) over the steps >= 10 kPa, so the stage must move the particle-steel
    friction until that mean is within tolerance_mu, reading the lab curve itself."""
    cfg = tmp_path / "fric.yaml"
    cfg.write_text("""
name: fric
seeds_count: 2
materials:
  M2:
    - stage: friction
      rig: wall_friction
      response: friction_offset_mu_static
      target: {value: 0.0}
      tolerance_mu: 0.01
      parameter: {keys: [interactions.steel.friction_coefficient], start: 0.8, bounds: [0.05, 1.5], response_increases: true}
""")
    stress = [3000, 12000, 40000, 90000]

    class Wall(FakeExecutor):
        def run(self, jobs, raise_on_error=True):
            out = []
            for j in jobs:
                mu = 0.9 * j["materials"]["M2"]["interactions"]["steel"]["friction_coefficient"] + 0.05
                out.append({"rig": "wall_friction", "material": "M2", "job": j, "stress_pa": stress,
                            "mu_static": [mu] * 4, "mu_dynamic": [mu] * 4, "sticks": [False] * 4})
            return out
    study = Study(cfg, Wall(), tmp_path / "out", log=lambda m: None)
    (row,) = study.run()
    # the chosen point's friction curve against the lab band, pooled over seeds, in the report
    assert row["plots"] == ["plots/M2-friction/friction_vs_stress.png"]
    assert (tmp_path / "out" / "fric" / row["plots"][0]).stat().st_size > 1000
    report = write_report(tmp_path / "out" / "fric").read_text()
    assert "Lab curves vs simulation" in report and "friction_vs_stress.png" in report
    lab = labdata.target_curve("wall_friction_gravel_dry", "mu_static")
    at = {float(s): float(v) for s, v in zip(lab.stress_pa, lab.value)}
    lab_mean = (at[12000] + at[40000] + at[90000]) / 3      # the simulated steps >= 10 kPa are lab steps
    assert row["met"]
    assert 0.9 * row["value"] + 0.05 == pytest.approx(lab_mean, abs=0.01)


def test_a_stage_can_read_its_lab_curves_from_another_folder(tmp_path):
    """lab_dir (relative to the study file) holds curves laid out as labresults/: a
    synthetic twin's targets. Fake wall friction mu = 0.9 x particle-steel friction + 0.05
    against a flat synthetic curve of 0.32 -> particle-steel friction 0.30."""
    (tmp_path / "twin_lab" / "curves").mkdir(parents=True)
    rows = "\n".join(f"{s},0.320,0.300,0.340,0.320,0.300,0.340,synthetic" for s in (12000, 40000, 86000))
    (tmp_path / "twin_lab" / "curves" / "wall_friction_gravel_dry.csv").write_text(
        "# synthetic twin\nstress_pa,mu_static,mu_static_low,mu_static_high,mu_dynamic,mu_dynamic_low,"
        "mu_dynamic_high,provenance\n" + rows + "\n")
    cfg = tmp_path / "fric.yaml"
    cfg.write_text("""
name: fric
seeds_count: 1
materials:
  M2:
    - stage: friction
      rig: wall_friction
      lab_dir: twin_lab
      response: friction_offset_mu_static
      target: {value: 0.0}
      tolerance_mu: 0.005
      parameter: {keys: [interactions.steel.friction_coefficient], start: 0.5, bounds: [0.05, 1.5], response_increases: true}
""")

    class Wall(FakeExecutor):
        def run(self, jobs, raise_on_error=True):
            mu = [0.9 * j["materials"]["M2"]["interactions"]["steel"]["friction_coefficient"] + 0.05 for j in jobs]
            return [{"rig": "wall_friction", "material": "M2", "job": j, "stress_pa": [12000, 40000, 86000],
                     "mu_static": [m] * 3, "mu_dynamic": [m] * 3, "sticks": [False] * 3} for j, m in zip(jobs, mu)]
    (row,) = Study(cfg, Wall(), tmp_path / "out", log=lambda m: None).run()
    assert row["met"] and row["value"] == pytest.approx(0.30, abs=0.006)
