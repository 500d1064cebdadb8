"""pycal.step_estimate: a job's step count is estimated before it runs and an implausible
one is refused (one line, exit 2, nothing written). Hand-computed answers:

- M2 at its start values: radius 0.0125 m, E 2e7 Pa, density 2750 kg/m3, safety factor
  0.5: dt = 0.5 x 0.0125 / sqrt(2e7 / 2750) = 0.5 x 0.0125 / 85.2803 = 7.3288e-5 s;
- the fill rig waits at most twice (pour, strike) 8 s + one 0.02 s rest check:
  16.04 s / 7.3288e-5 s = 218 863 steps;
- E x 100 -> dt / 10 (dt ~ 1 / sqrt(E));
- the mixed sets' smallest sphere is a member of a 25 mm oblong M1 lump: box
  (1, 0.7, 1.7) / 1.7 x 25 mm, radius min(10.29 mm / 2, 25 mm / 4) = 5.147 mm ->
  dt = 0.5 x 5.147e-3 / 85.2803 = 3.018e-5 s.
"""
import pytest

from pycal import step_estimate as se
from pycal.cli import main
from pycal.configs import load_rig, material_names, material_set_names, rig_names
from pycal.errors import ConfigError
from pycal.jobs import resolve_job

from config_copy import edit

DT_M2 = 7.3288e-5


def test_time_step_of_the_start_values():
    dt, material, radius = se.critical_timestep(resolve_job("fill", "M2"))
    assert dt == pytest.approx(DT_M2, rel=1e-4) and material == "M2" and radius == 0.0125


def test_time_step_goes_as_one_over_root_of_youngs_modulus():
    dt = se.critical_timestep(resolve_job("fill", "M2", {"contact.youngs_modulus_pa": 2.0e9}))[0]
    assert dt == pytest.approx(DT_M2 / 10, rel=1e-4)


def test_the_smallest_lump_member_sets_the_mixed_time_step():
    dt, material, radius = se.critical_timestep(resolve_job("aor_mixed", "mixed-dry"))
    assert material == "M1" and radius == pytest.approx(5.147e-3, abs=1e-6)
    assert dt == pytest.approx(3.018e-5, rel=1e-3)


def test_fill_steps_of_the_start_values():
    e = se.estimate(resolve_job("fill", "M2"))
    assert e["simulated_time_s"] == pytest.approx(16.04)
    assert e["steps_count"] == pytest.approx(218863, rel=1e-3)


def test_every_shipped_rig_and_material_runs_at_its_start_values():
    """No shipped default job is refused (the largest, the 7-step wall friction, is
    ~1.2e7 steps: 8 x below the limit)."""
    for rig in rig_names():
        names = material_set_names() if load_rig(rig).get("accepts_material_sets") else \
            [m for m in material_names() if m != "M1"]
        for m in names:
            e = se.estimate(resolve_job(rig, m))
            assert e["steps_count"] < 0.2 * load_rig(rig)["numerics"]["max_estimated_steps_count"], (rig, m)


def test_the_calibration_bounds_run():
    """The M2 stiffness stage may go to its upper bound 1e9 Pa, and the wall friction
    stage after it runs 3 steps there (~7e7 steps): still accepted."""
    job = resolve_job("wall_friction", "M2", {"contact.youngs_modulus_pa": 1.0e9,
                                              "rig.procedure.consolidation_stresses_pa": [12000, 40000, 90000]})
    assert se.estimate(job)["steps_count"] < 1.0e8


def test_a_far_too_stiff_particle_is_refused_naming_the_value():
    with pytest.raises(ConfigError) as exc:
        resolve_job("fill", "M2", {"contact.youngs_modulus_pa": 1.0e12, "particles.diameter_m": 0.001})
    msg = str(exc.value)
    assert msg.startswith("--set: contact.youngs_modulus_pa=1e+12: fill with M2 would take up to 1.22e+09 time steps")
    assert "max_estimated_steps_count 1e+08" in msg and "time step 1.31e-08 s" in msg


def test_a_far_too_slow_lift_is_refused_naming_the_lift_speed():
    with pytest.raises(ConfigError) as exc:
        resolve_job("aor", "M2", {"rig.procedure.lift_speed_m_s": 1.0e-6})
    msg = str(exc.value)
    assert msg.startswith("--set: rig.procedure.lift_speed_m_s=1e-06:") and "of it cylinder lift" in msg


def test_the_limit_can_be_raised_for_one_job():
    job = resolve_job("fill", "M2", {"contact.youngs_modulus_pa": 1.0e12, "particles.diameter_m": 0.001,
                                     "rig.numerics.max_estimated_steps_count": 1.0e10})
    assert se.estimate(job)["steps_count"] == pytest.approx(1.22e9, rel=1e-2)


def test_a_stiff_material_config_is_refused_naming_the_limit(cfg):
    edit(cfg / "materials" / "M2.yaml", "youngs_modulus_pa: 2.0e7", "youngs_modulus_pa: 1.0e12")
    edit(cfg / "materials" / "M2.yaml", "diameter_m: 0.025", "diameter_m: 0.001")
    with pytest.raises(ConfigError) as exc:
        resolve_job("fill", "M2", {"rig.geometry.scale": 1}, config_dir=cfg)      # the lab's cell
    assert str(exc.value).startswith("configs/numerics.yaml: max_estimated_steps_count: fill with M2")
    assert "contact.youngs_modulus_pa 1e+12" in str(exc.value)


def test_cli_refusal_is_one_line_exit_2_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "runs"
    assert main(["run", "fill", "--material", "M2", "--set", "contact.youngs_modulus_pa=1e12",
                 "--set", "particles.diameter_m=0.001", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: --set: contact.youngs_modulus_pa=1e+12:")
    assert not out.exists()


def test_the_transfer_rig_runs_its_feed_and_its_holdup_wait():
    # no rest waits: feed_time_s 1.2 s + holdup_wait_s 1.0 s at M2's step: 2.2 / 7.3288e-5 = 30 018 steps;
    # the mixed sets at the smallest lump member's step: 2.2 / 3.018e-5 = 72 900
    e = se.estimate(resolve_job("transfer", "M2"))
    assert e["simulated_time_s"] == pytest.approx(2.2) and e["steps_count"] == pytest.approx(30018, rel=1e-3)
    assert [key for _, _, key in e["phases"]] == ["rig.procedure.feed_time_s", "rig.procedure.holdup_wait_s"]
    assert se.estimate(resolve_job("transfer", "mixed-wet"))["steps_count"] == pytest.approx(72900, rel=2e-3)
