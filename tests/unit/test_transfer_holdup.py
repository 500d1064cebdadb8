"""bench/transfer_holdup.py: its variants change what they name and nothing else, and its table's means."""
import json

from bench_scripts import load_bench_script
from pycal.jobs import resolve_job

th = load_bench_script("transfer_holdup")

WET_WALL_LAW = {"model": "hysteretic", "force_fraction": 0.0, "pressure_fraction": 0.0212, "update_interval_s": 0.01}


def cohesion(job, a, b):
    return job["materials"][a]["interactions"][b]["cohesion"]


def test_the_plate_adhesion_variant_moves_the_plate_and_keeps_the_hold_on_gravel_and_lumps(tmp_path):
    job = resolve_job("transfer", "mixed-wet", {"M3-wet.interactions.steel.cohesion": WET_WALL_LAW,
                                                "M3-wet.interactions.M2.cohesion.force_fraction": 6.45}, seed=2)
    (tmp_path / "job.json").write_text(json.dumps(job))
    same, changed = th.rebuilt(tmp_path / "job.json", th.plate_adhesion(job, 0.2))
    assert same["job_id"] == job["job_id"] and changed["job_id"] != job["job_id"]
    assert cohesion(changed, "M3-wet", "steel")["pressure_fraction"] == 0.2
    for coarse in ("M1", "M2"):       # the hold on the coarse particles: as before, both parts
        assert cohesion(changed, coarse, "M3-wet") == cohesion(job, coarse, "M3-wet")
        assert cohesion(changed, coarse, "M3-wet")["pressure_fraction"] == 0.0212
    assert cohesion(changed, "M2", "M3-wet")["force_fraction"] == 6.45


def test_the_no_roll_variant_sets_fines_and_gravel_on_steel_only():
    job = resolve_job("transfer", "mixed-dry", th.no_roll_no_slide("M3-dry"), seed=1)
    for m in ("M3-dry", "M2"):
        steel = job["materials"][m]["interactions"]["steel"]
        assert (steel["rolling_resistance_coefficient"], steel["friction_coefficient"]) == (0.6, 0.7)
    plain = resolve_job("transfer", "mixed-dry", {}, seed=1)
    assert job["materials"]["M2"]["interactions"]["M3-dry"] == plain["materials"]["M2"]["interactions"]["M3-dry"]


def test_the_table_gives_mean_sd_and_counts():
    res = [{"holdup_mass_kg": h, "on_plate_mass_mean_kg": 1.0 + h, "outflow_ratio": 1.0, "impact_stress_pa": 36000.0 + s,
            "plugged": h > 0.5, "provenance": {"cpu_time_s": 20.0 + s / 1000}} for s, h in ((0, 0.0), (1000, 0.3), (2000, 0.6))]
    text = th.rows({("mixed-wet", "x"): (res, 1)})
    row = text.splitlines()[2]
    assert "| mixed-wet | x | 3 (1 failed) | 0.300 (0.300) | 0.000, 0.300, 0.600 | 1.300 (0.300) | 1.00 (0.00) |" in row
    assert "| 37.0 (1.0) | 1 of 3 | 21 |" in row
