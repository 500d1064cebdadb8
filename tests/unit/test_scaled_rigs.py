"""bench/scaled_rigs.py: slopes, seed SD and the parameter's SD per CPU hour, on results
whose answers are known (no YADE)."""
import math

import pytest

from bench_scripts import load_bench_script


@pytest.fixture(scope="module")
def sr():
    return load_bench_script("scaled_rigs")


def fake(angle, cpu=100.0):
    return {"aor_mean_deg": angle, "provenance": {"cpu_time_s": cpu}}


def test_slope_se_pooled_sd_and_cost(sr):
    c = sr.CAMPAIGNS["aor_M2"]
    # rolling 0.15 -> 0.35: +4 deg, i.e. 20 deg per unit; each point SD 1 (values m-1, m, m+1)
    pts = {"f0.6 r0.15": [fake(39.0), fake(40.0), fake(41.0)], "f0.6 r0.35": [fake(43.0), fake(44.0), fake(45.0)],
           "f0.3 r0.35": [fake(44.0), None, fake(44.0)]}
    k, se, sd, cpu = sr.slope(c, pts, "f0.6 r0.15", "f0.6 r0.35", "interactions.M2.rolling_resistance_coefficient",
                              "aor_mean_deg")
    assert k == pytest.approx(20.0)
    assert sd == pytest.approx(1.0)
    assert se == pytest.approx(math.sqrt(1 / 3 + 1 / 3) / 0.2)
    assert cpu == 100.0
    rows = sr.slope_rows(c, {2.0: pts})
    # one run pins rolling to SD / slope = 0.05; an hour holds 36 runs: 0.05 / 6
    line = next(x for x in rows.splitlines() if "f0.6 r0.15 -> f0.6 r0.35" in x)
    assert "| 0.05 | 0.0083 |" in line
    # a seed without a result (None) is left out: two equal values, no change
    k, *_ = sr.slope(c, pts, "f0.3 r0.35", "f0.6 r0.35", "interactions.M2.friction_coefficient", "aor_mean_deg")
    assert k == pytest.approx(0.0)


def test_point_rows_count_the_seeds_without_a_result(sr):
    c = sr.CAMPAIGNS["fill_M2"]
    res = [{"solid_fraction": 0.4, "bulk_density_kg_m3": 1100.0, "n_particles": 80, "provenance": {"cpu_time_s": 3.0}},
           None]
    text = sr.point_rows(c, {1.0: {"start": res}})
    assert "| 1 | start | 0.4 (-; 1) | 1100 (-; 1) | 80 (-; 1) | 1 | 3 |" in text


def test_seeds_at_and_the_campaign_jobs_at_a_scale(sr):
    assert sr.parse_seeds_at("1:8,1.5:4,2:3") == {1.0: 8, 1.5: 4, 2.0: 3}
    jobs = sr.jobs_of(sr.CAMPAIGNS["aor_M2"], 2.0, [1001, 1002])
    assert len(jobs) == 6
    label, job = jobs[0]
    assert job["rig_config"]["geometry"]["cell_inner_diameter_m"] == pytest.approx(0.29)
    assert job["seed"] == 1001 and job["rig_config"]["procedure"]["lift_speed_m_s"] == 0.01
    assert sr.SEED_BASE > 500            # the study's seed bases 1 and 101 never reach it
