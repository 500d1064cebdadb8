"""The shipped study (configs/calibrations/zinc_ore.yaml) from its first stage to its last on
fake rigs: every stage kind runs (density, rolling resistance, stiffness in log E, wall
friction, inheritance, the wet cohesion from the wet internal-friction curve, the
wet wall joint fit, the density checked again, the wet fines' hold on
gravel on the wet -50 mm pile, a stage on a material set), the outputs and the report
are written. The fake laws are smooth and the noise small: this checks the plumbing of the
real config, not its numbers (those need YADE)."""
import math
import random

import pytest

from fake_rigs import FakeRigs, aor_law, wall_result
from pycal.calibration.calibrate_cli import DEFAULT_STUDY
from pycal.calibration.study import Study
from pycal.post import responses
from pycal.report import write_report


def stiffness(job):
    """A CCS-expansion stand-in: ln(simulated / lab unloading stiffness) = 0.5 ln(E / 2e7)."""
    e = job["materials"][job["material"]]["contact"]["youngs_modulus_pa"]
    return {"fake_log_ratio": 0.5 * math.log(e / 2e7)}


def internal(job):
    """Internal friction: mu = 0.2 + 0.5 particle friction + 0.4 cohesion force fraction x
    stress / 40 kPa; the cell hangs on where that exceeds 1.5."""
    name = job["material"]
    inter = job["materials"][name]["interactions"][name]
    ff = inter["cohesion"].get("force_fraction", 0.0) if inter["cohesion"]["model"] != "none" else 0.0
    stresses = job["rig_config"]["procedure"]["consolidation_stresses_pa"]
    rng = random.Random(job["job_id"])
    mu = [0.2 + 0.5 * inter["friction_coefficient"] + 0.4 * ff * s / 40000 + 0.01 * rng.gauss(0, 1)
          for s in stresses]
    sticks = [m > 1.5 for m in mu]
    return {"stress_pa": stresses, "mu_static": [None if st else m for m, st in zip(mu, sticks)],
            "mu_dynamic": [None if st else m for m, st in zip(mu, sticks)], "sticks": sticks}


def cross_hold_footprint_fraction(force_fraction):
    """The share of the wet mixed pile inside the cylinder's footprint at the weight part of
    the fines' hold on gravel: 0.65 (a cone) without hold, 1 (it stands) at a strong one."""
    return 1.0 - 0.35 * math.exp(-force_fraction / 4.0)


def mixed_pile(job):
    """The mixed -50 mm pile: dry, every direction and the upper part at 35 deg and 0.7 of it
    inside the footprint; wet, cross_hold_footprint_fraction of the fines-gravel pair's weight
    part (M2 - M3-wet)."""
    angle, share = 35.0, 0.7
    if job["material"] == "mixed-wet":
        share = cross_hold_footprint_fraction(
            job["materials"]["M2"]["interactions"]["M3-wet"]["cohesion"]["force_fraction"])
    out = {k: angle for k in ("aor_left_deg", "aor_right_deg", "aor_front_deg", "aor_back_deg",
                              "aor_upper_left_deg", "aor_upper_right_deg")}
    return dict(out, aor_mean_deg=angle, pile_footprint_fraction=share)


def surcharge(job):
    """The surcharge run (validation): the pile before the vibration (the fake AoR law) and
    10 deg lower after it."""
    before = aor_law(job)
    after = before - 10.0
    return {"aor_mean_deg": before, "aor_left_deg": before, "aor_right_deg": before,
            "surcharge_mean_deg": after, "surcharge_left_deg": after, "surcharge_right_deg": after}


def ucs(job):
    """A UCS stand-in on the lab's own curve shape (validation): bulk stiffness 60 x stress,
    bulk density 2750 - 1149 exp(-stress / 150 kPa)."""
    stress = [3000.0, 6000.0, 12000.0, 24000.0, 40000.0]
    return {"stress_pa": stress, "stiffness_pa": [60 * s for s in stress],
            "bulk_density_kg_m3": [2750 - 1149 * math.exp(-s / 150000) for s in stress]}


def transfer(job):
    """The transfer chute (application): impact stress 1e5 Pa x the fines-steel friction of
    the set (calibrated on the fines' wall friction curve), design 88.6 kPa, wet fines plug."""
    fines = next(m for m in job["materials"] if m.startswith("M3"))
    mu = job["materials"][fines]["interactions"]["steel"]["friction_coefficient"]
    return {"impact_stress_pa": 1e5 * mu, "design_impact_stress_pa": 88600.0, "momentum_flux_stress_pa": 41800.0,
            "throughput_in_kg_s": 52.0, "throughput_out_kg_s": 51.0, "holdup_mass_kg": 0.1,
            "plugged": fines == "M3-wet"}


def wall(steel, s):
    coh = steel["cohesion"]
    return steel["friction_coefficient"] + (3e-4 * coh.get("pressure_fraction", 0.0) * s
                                            if coh["model"] == "hysteretic" else 0.0)


@pytest.fixture
def fake_stiffness_response(monkeypatch):
    """The stiffness response read from the stand-in's key (the real one reads spring curves)."""
    fake = responses.Response("unloading_stiffness_log_ratio", "log_ratio", False,
                              lambda r, lab: float(r["fake_log_ratio"]))
    monkeypatch.setitem(responses.RESPONSES, "unloading_stiffness_log_ratio", fake)


def test_the_shipped_study_runs_every_stage_on_fake_rigs(tmp_path, fake_stiffness_response):
    def wall_rig(job):
        stresses = job["rig_config"]["procedure"]["consolidation_stresses_pa"]
        return wall_result(wall, stresses=tuple(stresses))(job)
    ex = FakeRigs(results={"ccs_expansion": stiffness, "internal_friction": internal, "wall_friction": wall_rig,
                           "aor_mixed": mixed_pile, "surcharge": surcharge, "ucs": ucs, "transfer": transfer},
                  noise={"fake_log_ratio": 0.03})
    study = Study(DEFAULT_STUDY, ex, tmp_path / "out", log=lambda m: None, seed_base=7)
    rows = study.run()
    labels = [(r["material"], r["stage"]) for r in rows]
    assert len(labels) == sum(len(s) for s in study.cfg["materials"].values())
    assert study.runs_requested <= study.cfg["max_runs_count"]
    by = {(r["material"], r["stage"]): r for r in rows}
    # E: log ratio 0 at 2e7 Pa (M3-dry's bound is 2.4e7: reachable)
    for m in ("M2", "M3-dry"):
        e = by[(m, "stiffness")]["parameters"][0]
        assert e["low"] <= 2e7 <= e["high"] or abs(e["estimate"] / 2e7 - 1) < 0.2
    # the wet cohesion stage ran on the internal-friction rig and the wet cell hangs on
    coh = by[("M3-wet", "cohesion")]
    assert coh["responses"][0]["response"] == "friction_angle_offset_deg" and coh["points_count"] >= 2
    # the dry materials' rolling resistance on the AoR pile (the fake law's root), the density checked again last
    for m in ("M2", "M3-dry"):
        roll = by[(m, "rolling_resistance")]["parameters"][0]
        assert roll["low"] <= roll["estimate"] <= roll["high"]
        assert by[(m, "density_recheck")]["parameters"][0]["keys"] == ["particles.density_kg_m3"]
    dry_jobs = [j for j in ex.asked if j["material"] == "M3-dry" and j["rig"] in ("surcharge", "aor")]
    assert {j["rig"] for j in dry_jobs} == {"aor", "surcharge"}       # the rolling stage on aor, a prediction on surcharge
    # the fines' particle friction is held (configs/materials/M3-*.yaml), in every wet cohesion run
    wet_cohesion_jobs = [j for j in ex.asked if j["material"] == "M3-wet" and j["rig"] == "internal_friction"]
    assert wet_cohesion_jobs and all(j["materials"]["M3-wet"]["interactions"]["M3-wet"]["friction_coefficient"]
                                     == 0.6 for j in wet_cohesion_jobs)
    assert "interactions.M3-dry.friction_coefficient" not in study.overrides["M3-dry"]
    assert all(j["seed"] >= 7 for j in ex.asked)
    # the wet fines' hold on gravel, on the wet -50 mm pile (a set): the weight part whose pile keeps
    # the stage's target share (faces leaning 2 deg out) of its volume inside the footprint
    cross = by[("M3-wet", "cross_binding")]["parameters"][0]
    target = study.cfg["materials"]["M3-wet"][-1]["target"]["value"]
    root = -4.0 * math.log((1.0 - target) / 0.35)
    assert cross["low"] <= root <= cross["high"] and abs(cross["estimate"] / root - 1) < 0.1
    stage_jobs = [j for j in ex.asked if j["rig"] == "aor_mixed" and j["material"] == "mixed-wet"]
    assert stage_jobs and all(j["materials"]["M2"]["particles"]["density_kg_m3"]      # the gravel as calibrated
                              == study.overrides["M2"]["particles.density_kg_m3"] for j in stage_jobs)
    held = {h["key"]: h["value"] for h in by[("M3-wet", "cross_binding")]["held"]}
    assert held["M2.particles.density_kg_m3"] == study.overrides["M2"]["particles.density_kg_m3"]
    wet_jobs = [j for j in ex.asked if j["rig"] == "transfer" and j["material"] == "mixed-wet"]
    assert wet_jobs and all(j["materials"][m]["interactions"]["M3-wet"]["cohesion"]["force_fraction"]
                            == cross["estimate"] for j in wet_jobs for m in ("M1", "M2"))
    # validation: every prediction of the shipped config ran with the calibrated values
    names = [r["prediction"] for r in study.validation_rows]
    assert names == [p["name"] for p in study.cfg["validation"]["predictions"]]
    dry = next(r for r in study.validation_rows if r["prediction"] == "mixed_dry_pile")
    assert dry["comparisons"][0]["sim_mean"] == pytest.approx(35.0, abs=2.0)
    assert all(j["seed"] >= 7 for j in ex.asked if j["rig"] == "aor_mixed")
    fines = next(r for r in study.validation_rows if r["prediction"] == "fines_dry_ucs")
    assert fines["comparisons"][0]["n"] > 0 and fines["comparisons"][0]["inside"]
    # application: the transfer dry and wet on the calibrated fines-steel friction
    dry_t, wet_t = study.application_rows
    mu = study.overrides["M3-dry"]["interactions.steel.friction_coefficient"]
    assert dry_t["responses"][0]["mean"] == pytest.approx(1e5 * mu)
    assert (wet_t["responses"][-1]["true_count"], dry_t["responses"][-1]["true_count"]) == (3, 0)
    html = write_report(study.out).read_text()
    assert "YADE 2023.02a-fake" in html and "density_recheck" in html and "Application (design runs" in html
    assert "cross_binding (runs on the material set mixed-wet)" in html
