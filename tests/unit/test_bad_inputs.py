"""Bad input, as a new user makes it: every case is refused before anything runs, in one
line naming the file (or option) and the key, with exit code 2 on the command line, and
nothing written. Cached results that are not the job's own are set aside and run again.

Groups: rig configs (pycal/rigs/<rig>.py + pycal/rigs/fields.py), material and boundary
values (pycal/plausible.py), command-line arguments (pycal/arguments.py), overrides
(--set), study configs, and the runs cache (pycal/executors/jobdirs.py).
"""
import json
import os

import pytest

from pycal.calibration.study_config import load_study
from pycal.cli import main
from pycal.configs import load_boundaries, load_material, load_numerics, load_rig
from pycal.errors import ConfigError

from config_copy import edit


def snapshot(folder):
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*")) if folder.exists() else []


def one_line_refusal(capsys, rc, *needles):
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert len(err.splitlines()) == 1, err
    for n in needles:
        assert n in err, err
    return err


# ---------------------------------------------------------------- rig configs (file, old, new, key, reason)
RIG_CASES = [
    ("aor", "lift_speed_m_s: 0.002", "lift_speed_m_s: 0", "procedure.lift_speed_m_s", "must be > 0"),
    ("aor", "lift_speed_m_s: 0.002", "lift_speed_m_s: -0.002", "procedure.lift_speed_m_s", "must be > 0"),
    ("aor", "cell_facet_segments_count: 32", "cell_facet_segments_count: 2", "geometry.cell_facet_segments_count",
     ">= 3"),
    ("aor", "cell_facet_segments_count: 32", "cell_facet_segments_count: 32.5", "geometry.cell_facet_segments_count",
     "whole number"),
    ("aor", "cell_inner_diameter_m: 0.145", "cell_inner_diameter_m: -0.145", "geometry.cell_inner_diameter_m",
     "must be > 0"),
    ("aor", "cell_height_m: 0.095", "cell_height_m: tall", "geometry.cell_height_m", "must be a number"),
    ("aor", "lift_speed_m_s: 0.002", "lift_sped_m_s: 0.002", "procedure.lift_sped_m_s", "did you mean lift_speed_m_s"),
    ("aor", "  table_material: steel", "  table_material: steel\n  plinth_height_m: 0.1", "geometry.plinth_height_m",
     "unknown key"),
    ("fill", "  pour_porosity_ratio: 0.7", "  # pour_porosity_ratio: 0.7", "procedure.pour_porosity_ratio", "missing"),
    ("internal_friction", "fill_each_step: fresh", "fill_each_step: daily", "procedure.fill_each_step",
     "must be one of fresh, sequential"),
    ("internal_friction", "max_tilt_deg: 90.0", "max_tilt_deg: 120.0", "procedure.max_tilt_deg", "<= 90"),
    ("internal_friction", "  tilt_rate_deg_s: 2.0", "  tilt_rate_deg_s: 0.0", "procedure.tilt_rate_deg_s",
     "must be > 0"),
    ("internal_friction", "settle_before_tilt: true", "settle_before_tilt: maybe", "procedure.settle_before_tilt",
     "true or false"),
    ("internal_friction", "particle_damping_during_tilt: undamped_when_sliding",
     "particle_damping_during_tilt: sometimes", "procedure.particle_damping_during_tilt", "must be one of"),
    ("internal_friction", "cell_gap_m: 0.002", "cell_gap_m: 0.0", "geometry.cell_gap_m", "shear plane"),
    ("wall_friction", "consolidation_stresses_pa: [3000, 6000, 12000, 24000, 40000, 60000, 90000]",
     "consolidation_stresses_pa: []", "procedure.consolidation_stresses_pa", "non-empty list"),
    ("wall_friction", "consolidation_stresses_pa: [3000, 6000, 12000, 24000, 40000, 60000, 90000]",
     "consolidation_stresses_pa: [3000, abc]", "procedure.consolidation_stresses_pa", "must be a number"),
    ("wall_friction", "pre_tilt_slide_fraction: 0.2", "pre_tilt_slide_fraction: 1.5",
     "procedure.pre_tilt_slide_fraction", "<= 1"),
    ("ccs", "load_steps_pa: [3000, 6000, 12000, 24000, 40000, 60000, 90000]", "load_steps_pa: [3000, .nan]",
     "load_steps_pa", "NaN"),
    ("ccs", "plate_material: steel", "plate_material: wood", "geometry.plate_material", "unknown boundary 'wood'"),
    ("ccs", "max_overlap_fraction: ", "max_overlap_fraction: 0 #", "numerics.max_overlap_fraction", "must be > 0"),
    ("ccs", "max_overlap_fraction: ", "max_overlapp_fraction: ", "numerics.max_overlapp_fraction",
     "did you mean max_overlap_fraction"),
    ("ccs", "servo_control_interval_s: 0.002", "servo_control_interval_s: 0", "procedure.servo_control_interval_s",
     "must be > 0"),
    ("fill", "name: fill", "name: filling", "name", "must equal the file name"),
    ("fill", "script: fill.py", "script: aor.py", "script", "must be 'fill.py'"),
    ("aor", "sector_half_width_deg: 45", "sector_half_width_deg: 0", "measure.sector_half_width_deg", "> 0"),
    ("surcharge", "vibration_frequency_hz: 25.0", "vibration_frequency_hz: -25.0", "procedure.vibration_frequency_hz",
     "must be > 0"),
    ("transfer", "plate_inclination_deg: 30.0", "plate_inclination_deg: 90.0", "geometry.plate_inclination_deg",
     "< 90"),
    ("fill", "fill_height_rule: centre_above_rim_removed", "fill_height_rule: by_eye", "measure.fill_height_rule",
     "must be one of"),
    ("ucs", "plate_diameter_m: 0.145", "plate_diameter_m: .inf", "geometry.plate_diameter_m", "finite"),
    ("aor_mixed", "pour_solid_fraction: 0.2", "pour_solid_fraction: 0.9", "procedure.pour_solid_fraction", "0.64"),
    ("transfer", "holdup_wait_s: 1.0", "holdup_wait_s: -1.0", "procedure.holdup_wait_s", ">= 0"),
]


@pytest.mark.parametrize("rig, old, new, key, why", RIG_CASES, ids=[f"{c[0]}:{c[3]}:{i}" for i, c in
                                                                  enumerate(RIG_CASES)])
def test_bad_rig_config(cfg, rig, old, new, key, why):
    edit(cfg / "rigs" / f"{rig}.yaml", old, new)
    with pytest.raises(ConfigError) as exc:
        load_rig(rig, cfg)
    msg = str(exc.value)
    assert "\n" not in msg and f"rigs/{rig}.yaml" in msg and key in msg and why in msg, msg


NUMERICS_CASES = [
    ("timestep_safety_factor: 0.5", "timestep_safety_factor: 1.5", "timestep_safety_factor", "<= 1"),
    ("contact_model: hertz_mindlin", "contact_model: dem", "contact_model", "must be one of"),
    ("gravity_m_s2: 9.81", "gravity_m_s2: 9.81\ngravity_direction_deg: 5", "gravity_direction_deg", "unknown key"),
    ("max_settle_time_s: 8.0", "max_settle_time_s: -8.0", "max_settle_time_s", "must be > 0"),
]


@pytest.mark.parametrize("old, new, key, why", NUMERICS_CASES)
def test_bad_numerics(cfg, old, new, key, why):
    edit(cfg / "numerics.yaml", old, new)
    with pytest.raises(ConfigError) as exc:
        load_numerics(cfg)
    msg = str(exc.value)
    assert "\n" not in msg and "numerics.yaml" in msg and key in msg and why in msg, msg


# ---------------------------------------------------------------- material and boundary values
M2_FRICTION = "  M2:\n    friction_coefficient: 0.6"
MATERIAL_CASES = [
    ("M2", None, "friction_coefficient: 20.0", "interactions.M2.friction_coefficient", "plausible range 0 - 2"),
    ("M2", "rolling_resistance_coefficient: 0.35", "rolling_resistance_coefficient: 35",
     "rolling_resistance_coefficient", "plausible range 0 - 2"),
    ("M2", "density_kg_m3: 2750", "density_kg_m3: 1.0e9", "particles.density_kg_m3", "plausible range"),
    ("M2", "density_kg_m3: 2750", "density_kg_m3: 2.75", "particles.density_kg_m3", "plausible range"),
    ("M2", "youngs_modulus_pa: 2.0e7", "youngs_modulus_pa: 1.0e3", "contact.youngs_modulus_pa", "plausible range"),
    ("M2", "youngs_modulus_pa: 2.0e7", "youngs_modulus_pa: .nan", "contact.youngs_modulus_pa", "finite"),
    ("M2", "diameter_m: ", "diameter_m: .inf #", "particles.diameter_m", "finite"),
    ("M2", "restitution_coefficient: 0.3", "restitution_coefficient: 0.01", "restitution_coefficient", "0.05"),
    ("M2", "poisson_ratio: 0.3", "poisson_ratio: 0.7", "contact.poisson_ratio", "0.5"),
    ("M3-wet", "force_fraction: ", "force_fraction: 1.0e6 #", "cohesion.force_fraction", "plausible range"),
    ("M2", "{model: none}", "{model: glue}", "cohesion.model", "must be one of"),
    ("M2", "density_kg_m3: 2750", "density_kg_m3: heavy", "particles.density_kg_m3", "must be a number"),
    ("M2", "name: M2", "name: M22", "name", "must equal the file name"),
    ("M2", "interactions:", "interactions:\n  rubber:\n    friction_coefficient: 0.5", "interactions.rubber",
     "unknown partner"),
]


@pytest.mark.parametrize("material, old, new, key, why", MATERIAL_CASES,
                         ids=[f"{c[0]}:{c[3]}:{i}" for i, c in enumerate(MATERIAL_CASES)])
def test_bad_material_value(cfg, material, old, new, key, why):
    path = cfg / "materials" / f"{material}.yaml"
    if old is None:                                   # the material's own pair friction
        text = path.read_text()
        start = text.index(f"  {material}:\n", text.index("interactions:"))
        i = text.index("friction_coefficient:", start)
        j = text.index("\n", i)
        path.write_text(text[:i] + new + text[j:])
    else:
        edit(path, old, new)
    with pytest.raises(ConfigError) as exc:
        load_material(material, cfg)
    msg = str(exc.value)
    assert "\n" not in msg and f"materials/{material}.yaml" in msg and key in msg and why in msg, msg


@pytest.mark.parametrize("old, new, why", [
    ("youngs_modulus_pa: 2.38e11", "youngs_modulus_pa: 2.38e14", "plausible range"),
    ("density_kg_m3: 1400", "density_kg_m3: 1.4", "plausible range"),
])
def test_bad_boundary_value(cfg, old, new, why):
    edit(cfg / "boundaries.yaml", old, new)
    with pytest.raises(ConfigError) as exc:
        load_boundaries(cfg)
    assert "boundaries.yaml" in str(exc.value) and why in str(exc.value)


# ---------------------------------------------------------------- command line and overrides
def cli_cases():
    run = ["run", "fill", "--material", "M2"]
    return [
        (run + ["--seeds", "0"], "--seeds"),
        (run + ["--seeds", "-1"], "--seeds"),
        (run + ["--seed", "-3"], "--seed"),
        (run + ["--workers", "0"], "--workers"),
        (run + ["--workers", "-1"], "--workers"),
        (run + ["--cpu-limit-s", "0"], "--cpu-limit-s"),
        (run + ["--timeout-s", "-5"], "--cpu-limit-s"),
        (run + ["--cpu-limit-s", "nan"], "--cpu-limit-s"),
        (run + ["--replicas", "0"], "--replicas"),
        (run + ["--vtk", "0"], "--vtk"),
        (run + ["--seeds", "abc"], "--seeds"),
        (run + ["--workers"], "--workers"),
        (["run", "fil", "--material", "M2"], "unknown rig 'fil'"),
        (["run", "fill", "--material", "M9"], "unknown material"),
        (run + ["--set", "particles.density_kg_m3"], "--set"),
        (run + ["--set", "particles.colour=red"], "no such key"),
        (run + ["--set", "rig.procedure.strike_level_height_m=0"], "--set: rig.procedure.strike_level_height_m=0"),
        (run + ["--set", "interactions.M2.friction_coefficient=20"], "--set: interactions.M2.friction_coefficient=20"),
        (run + ["--set", "contact.youngs_modulus_pa=.nan"], "finite"),
        (run + ["--set", "particles.density_kg_m3=1e9"], "plausible range"),
        (run + ["--set", "rig.geometry.cell_inner_diameter_m=0.01"], "does not hold one particle"),
        (run + ["--set", "rig.procedure.pour_height_factor=abc"], "must be a number"),
        (["run", "aor", "--material", "mixed-dry"], "is a material set"),
        (["run", "internal_friction", "--material", "M3-dry", "--set", "rig.procedure.lid_during_tilt=loose"],
         "must be one of joined, free"),
        (["run", "internal_friction", "--material", "M3-dry", "--set", "rig.procedure.fill_each_step=sequential",
          "--set", "rig.procedure.sliding_cell_rotations=free"], "needs procedure.fill_each_step: fresh"),
        (["run", "internal_friction", "--material", "M3-dry", "--set", "rig.procedure.slide_read_at=rim"],
         "must be one of body, shear_plane"),
        (["run", "internal_friction", "--material", "M3-dry", "--set", "rig.procedure.fill_each_step=sequential",
          "--set", "rig.procedure.slide_read_at=shear_plane"], "needs procedure.fill_each_step: fresh"),
        (["run", "wall_friction", "--material", "M3-dry", "--set", "rig.procedure.lid_during_tilt=free"],
         "no such key to override"),
        (["run", "internal_friction", "--material", "M3-dry", "--set", "rig.procedure.shear_drive=force_ramp"],
         "needs procedure.measure_dynamic_friction: false"),
        (["job", "fill", "--material", "M2", "--seeds", "0"], "--seeds"),
        (["batch-table", "fill", "--material", "M2", "--table", "t.table", "--workers", "0"], "--workers"),
        (["calibrate", "--seed-base", "-1"], "--seed-base"),
        (["calibrate", "--seeds-per-run", "0"], "--seeds-per-run"),
        (["calibrate", "--workers", "0"], "--workers"),
        (["fit-density", "--material", "M2", "--max-runs", "0"], "--max-runs"),
        (["impact", "--drop-height-m", "x", "--belt-speed-m-s", "4", "--flow-t-h", "1500",
          "--bulk-density-kg-m3", "1800"], "--drop-height-m"),
    ]


@pytest.mark.parametrize("args, needle", cli_cases(), ids=lambda v: " ".join(v) if isinstance(v, list) else None)
def test_bad_argument_one_line_exit_2_nothing_written(tmp_path, capsys, monkeypatch, args, needle):
    monkeypatch.chdir(tmp_path)
    out = ["--out", str(tmp_path / "runs")] if args[0] in ("run", "job", "batch-table") else []
    out += ["--runs", str(tmp_path / "runs")] if args[0] in ("calibrate", "fit-density") else []
    before = snapshot(tmp_path)
    try:
        rc = main(args + out)
    except SystemExit as exc:                         # argparse's own refusal (OneLineParser)
        rc = exc.code
    one_line_refusal(capsys, rc, needle)
    assert snapshot(tmp_path) == before


def test_output_paths_that_cannot_be_written(tmp_path, capsys):
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    (tmp_path / "a_dir").mkdir()
    cases = [
        (["run", "fill", "--material", "M2", "--out", str(a_file)], "is a file, not a folder"),
        (["run", "fill", "--material", "M2", "--out", str(a_file / "runs")], "is a file"),
        (["batch-table", "fill", "--material", "M2", "--out", str(tmp_path / "runs"), "--table",
          str(tmp_path / "a_dir")], "is a folder, not a file"),
        (["batch-table", "fill", "--material", "M2", "--out", str(tmp_path / "runs"), "--table",
          str(a_file / "t.table")], "its folder"),
        (["calibrate", "--runs", str(a_file)], "--runs"),
    ]
    if os.geteuid() != 0:                             # root writes into read-only folders
        ro = tmp_path / "ro"
        ro.mkdir(mode=0o500)
        cases.append((["run", "fill", "--material", "M2", "--out", str(ro)], "is not writable"))
    for args, needle in cases:
        before = snapshot(tmp_path)
        one_line_refusal(capsys, main(args), needle)
        assert snapshot(tmp_path) == before, args


# ---------------------------------------------------------------- study configs
STUDY = """
name: bad
seeds_count: 2
materials:
  M2:
    - stage: rolling_resistance
      rig: aor
      response: aor_mean_deg
      target: {sample: gravel_dry, test: angle_of_repose, band_deg: 2.0}
      parameter: {keys: [interactions.M2.rolling_resistance_coefficient], start: 0.35, bounds: [0.02, 1.5],
                  response_increases: true, tolerance_coefficient: 0.05}
"""
STUDY_CASES = [
    ("rig: aor", "rig: aorr", "materials.M2[0].rig", "did you mean aor"),
    ("rig: aor", "rig: fill", "materials.M2[0].response", "rig fill does not give aor_mean_deg"),
    ("response: aor_mean_deg", "response: pile_width_m", "materials.M2[0].response", "not a result key of rig aor"),
    ("response: aor_mean_deg", "response: aor_mood", "materials.M2[0].response", "not a known response"),
    ("  M2:\n", "  M7:\n", "materials.M7", "unknown material 'M7'"),
    ("keys: [interactions.M2.rolling_resistance_coefficient]", "keys: [interactions.M2.rolling_coefficient]",
     "materials.M2[0].parameter.keys", "no such key"),
    ("stage: rolling_resistance", "stage: rolling", "materials.M2[0].stage", ""),
    ("start: 0.35", "start: 3.5", "materials.M2[0].parameter.start", "outside bounds"),
    ("seeds_count: 2", "seeds_count: 0", "seeds_count", ""),
    ("sample: gravel_dry", "sample: gravle_dry", "materials.M2[0].target", "gravle_dry"),
    ("      response: aor_mean_deg\n", "      response: aor_mean_deg\n      out_of_reach_factor: 0.5\n",
     "materials.M2[0].out_of_reach_factor", "must be >= 1"),
    ("      response: aor_mean_deg\n", "      response: aor_mean_deg\n      out_of_reach_factor: soon\n",
     "materials.M2[0].out_of_reach_factor", "must be a number"),
]


@pytest.mark.parametrize("old, new, key, why", STUDY_CASES)
def test_bad_study_config_is_refused_before_any_run(tmp_path, old, new, key, why):
    p = tmp_path / "bad.yaml"
    assert old in STUDY
    p.write_text(STUDY.replace(old, new, 1))
    with pytest.raises(ConfigError) as exc:
        load_study(p)
    msg = str(exc.value)
    assert "\n" not in msg and "bad.yaml" in msg and key in msg and why in msg, msg


def test_the_study_template_itself_loads(tmp_path):
    p = tmp_path / "ok.yaml"
    p.write_text(STUDY)
    assert load_study(p)


# ---------------------------------------------------------------- the runs cache
def _fill_job(seed=1):
    from pycal.jobs import resolve_job
    return resolve_job("fill", "M2", seed=seed)


def _run(runs, jobs):
    from pycal.runner import LocalPool
    pool = LocalPool(runs, workers=1, progress=False)
    return pool.run(jobs), pool


def tamper_cases():
    def other_jobs_result(folder, other):
        (folder / "result.json").write_text((other / "result.json").read_text())

    def empty_object(folder, other):
        (folder / "result.json").write_text("{}")

    def truncated(folder, other):
        (folder / "result.json").write_text((folder / "result.json").read_text()[:40])

    def a_list(folder, other):
        (folder / "result.json").write_text("[1, 2]")

    def missing_key(folder, other):
        r = json.loads((folder / "result.json").read_text())
        del r["bulk_density_kg_m3"]
        (folder / "result.json").write_text(json.dumps(r))

    def other_job_inside(folder, other):
        r = json.loads((folder / "result.json").read_text())
        r["job"]["seed"] = 99
        (folder / "result.json").write_text(json.dumps(r))

    return [(f, w) for f, w in [(other_jobs_result, "it is the result of job"), (empty_object, "it is the result"),
                                (truncated, "not valid JSON"), (a_list, "not a JSON object"),
                                (missing_key, "incomplete (no bulk_density_kg_m3)"),
                                (other_job_inside, "content hash differs")]]


@pytest.mark.parametrize("tamper, why", tamper_cases(), ids=lambda v: getattr(v, "__name__", None))
def test_a_result_that_is_not_the_jobs_own_is_set_aside_and_run_again(tmp_path, fake_yade, capsys, tamper, why):
    from pycal.executors.jobdirs import job_dir
    runs = tmp_path / "runs"
    a, b = _fill_job(1), _fill_job(2)
    _run(runs, [a, b])
    assert fake_yade() == 2
    tamper(job_dir(a, runs), job_dir(b, runs))
    capsys.readouterr()
    results, pool = _run(runs, [a])
    assert fake_yade() == 3 and pool.simulated_count == 1          # run again
    assert results[0]["job_id"] == a["job_id"]
    err = capsys.readouterr().err
    warning = [line for line in err.splitlines() if line.startswith("warning:")]
    assert len(warning) == 1 and str(job_dir(a, runs) / "result.json") in warning[0] and why in warning[0], err
    assert len(list((runs / "quarantine" / "fill").iterdir())) == 1


def test_a_garbage_job_file_is_replaced_by_job_write_and_batch_table(tmp_path, capsys):
    from pycal.executors.jobdirs import job_dir
    runs = tmp_path / "runs"
    job = _fill_job(1)
    folder = job_dir(job, runs)
    for args in (["job", "fill", "--material", "M2", "--write"],
                 ["batch-table", "fill", "--material", "M2", "--table", str(tmp_path / "t.table")]):
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "job.json").write_text('{"rig": "fill", "garbage": tru')
        assert main(args + ["--out", str(runs)]) == 0
        assert json.loads((folder / "job.json").read_text()) == json.loads(json.dumps(job))
    capsys.readouterr()


def test_a_failed_attempt_is_cleaned_once_the_job_completes(tmp_path, fake_yade, monkeypatch):
    from pycal.executors.jobdirs import failed_dir
    runs = tmp_path / "runs"
    job = _fill_job(1)
    monkeypatch.setenv("FAKE_MODE", "fail")
    with pytest.raises(Exception):
        _run(runs, [job])
    assert failed_dir(job, runs).is_dir()
    monkeypatch.setenv("FAKE_MODE", "ok")
    _run(runs, [job])
    assert not failed_dir(job, runs).exists()
