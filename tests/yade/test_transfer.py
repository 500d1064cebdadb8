"""Physics of the transfer rig (real YADE runs, short feeds), with answers known without the
code:

- the feed is the design case's flow through the slice: fed mass = Q W / B x feed time
  (416.67 kg/s x 0.1 / 0.8 = 52.08 kg/s), within one particle;
- mass balance: fed = on the plate + run off + spilled + in flight, within one particle,
  when the feed stops (every term but the spill > 0) and at the end;
- free fall: the stream passes the gauge at sqrt(v0^2 + 2 g (H - h)), h its height above
  the first contact at the impact point;
- momentum: in steady flow the plate carries the stream's normal momentum flux plus the
  weight of what lies on it, Q W / B x u_n + m g cos a (u_n = vz cos a - v0 sin a);
- the VTK snapshots of the same run (--vtk): the last one holds the scene's particle
  spheres, the plate is one facet, and mid-feed the fastest particle moves at the stream's
  speed between the injection window and the plate (12.33 - 12.45 m/s).

M2 (spheres, seed 1) with a 0.5 s feed; mixed-dry and mixed-wet (lumps too) with a 0.25 s
feed for the balance with lumps and their VTK snapshots (lump members carry their clump's
id). Each run takes well under a minute of wall time.
"""
import math
import re

import pytest

from pycal.jobs import resolve_job
from pycal.runner import run_job
from pycal.vtk_output import with_vtk

from documented import assert_documented
from vtk_files import vtu_header

pytestmark = pytest.mark.yade

G = 9.81
H, V0, Q, RHO0 = 7.0, 4.2, 1500 / 3.6, 1800.0       # configs/calibrations/zinc_ore.yaml: design_case
W, B, ALPHA = 0.1, 0.8, math.radians(30.0)          # configs/rigs/transfer.yaml
SLICE_FLOW = Q * W / B                              # 52.083 kg/s
M2_PARTICLE_KG = 2750 * 4 / 3 * math.pi * 0.0125 ** 3   # 0.02250 kg
SHORT = {"rig.procedure.feed_time_s": 0.5, "rig.procedure.holdup_wait_s": 0.1, "rig.measure.steady_from_s": 0.3,
         "rig.measure.frame_interval_s": 0.25}
VTK_INTERVAL_S = 0.1


@pytest.fixture(scope="module")
def m2(tmp_path_factory):
    runs = tmp_path_factory.mktemp("transfer_m2")
    job = with_vtk(resolve_job("transfer", "M2", SHORT, seed=1), VTK_INTERVAL_S)
    return run_job(job, runs_dir=runs, timeout_s=900), runs / "transfer" / job["job_id"]


def balance(res, when):
    parts = ("on_plate", "run_off", "spilled_upstream", "in_flight")
    if when == "at_feed_stop":
        return res["fed_mass_at_feed_stop_kg"], {p: res[f"{p}_mass_at_feed_stop_kg"] for p in parts}
    return res["fed_mass_kg"], {p: res["holdup_mass_kg" if p == "on_plate" else f"{p}_mass_kg"] for p in parts}


def test_the_feed_is_the_design_flow_of_the_slice(m2):
    res, _ = m2
    feed = SHORT["rig.procedure.feed_time_s"]
    print("fed", res["fed_mass_at_feed_stop_kg"], "expected", SLICE_FLOW * feed)
    assert res["fed_mass_at_feed_stop_kg"] == pytest.approx(SLICE_FLOW * feed, abs=M2_PARTICLE_KG)
    assert res["fed_mass_kg"] == res["fed_mass_at_feed_stop_kg"]            # nothing fed after the stop
    assert res["throughput_in_kg_s"] == pytest.approx(SLICE_FLOW, rel=0.02)


@pytest.mark.parametrize("when", ["at_feed_stop", "at_end"])
def test_mass_balance_within_one_particle(m2, when):
    res, _ = m2
    fed, parts = balance(res, when)
    print(when, "fed", fed, parts)
    assert abs(fed - sum(parts.values())) <= M2_PARTICLE_KG
    if when == "at_feed_stop":       # the balance holds with mass on the plate, run off and in flight
        assert parts["on_plate"] > 10 * M2_PARTICLE_KG and parts["run_off"] > 10 * M2_PARTICLE_KG
        assert parts["in_flight"] > M2_PARTICLE_KG


def test_the_stream_falls_freely_to_the_plate(m2):
    res, _ = m2
    h = res["stream_gauge_height_m"]
    expected = math.sqrt(V0 ** 2 + 2 * G * (H - h))
    print("gauge", res["stream_speed_at_gauge_m_s"], "expected", expected, "at h", h, "n", res["stream_gauge_count"])
    assert res["stream_gauge_count"] > 100
    assert res["stream_speed_at_gauge_m_s"] == pytest.approx(expected, rel=1e-4)
    assert res["design_impact_speed_m_s"] == pytest.approx(math.sqrt(V0 ** 2 + 2 * G * H), rel=1e-12)


def test_the_plate_carries_the_streams_momentum_and_the_bed(m2):
    res, _ = m2
    vz = math.sqrt(2 * G * H)
    u_n = vz * math.cos(ALPHA) - V0 * math.sin(ALPHA)
    expected = res["throughput_in_kg_s"] * u_n + res["on_plate_mass_mean_kg"] * G * math.cos(ALPHA)
    print("plate force", res["plate_normal_force_n"], "expected", expected, "impact stress", res["impact_stress_pa"],
          "momentum flux", res["momentum_flux_stress_pa"], "design", res["design_impact_stress_pa"])
    assert res["plate_normal_force_n"] == pytest.approx(expected, rel=0.05)
    assert res["design_impact_stress_pa"] == pytest.approx(RHO0 * V0 * vz, rel=1e-12)
    # the footprint takes most of the stream's normal momentum, never more than all of it and the bed
    assert 0.5 * res["momentum_flux_stress_pa"] < res["impact_stress_pa"] < 1.2 * res["momentum_flux_stress_pa"]
    assert not res["plugged"] and res["outflow_ratio"] > 0.8
    assert_documented(res)


def _collection(folder, rig, kind):
    text = (folder / f"{rig}-{kind}.pvd").read_text()
    return [(float(t), folder / f) for t, f in re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', text)]


def test_vtk_snapshots_hold_the_scene(m2):
    res, folder = m2
    vtk = folder / "vtk"
    spheres, facets = _collection(vtk, "transfer", "spheres"), _collection(vtk, "transfer", "facets")
    assert len(spheres) == len(facets) == res["vtk_snapshots_count"]
    assert all(f.is_file() for _, f in spheres + facets)
    times = [t for t, _ in spheres]
    assert times == sorted(times) and times[-1] == pytest.approx(res["provenance"]["simulated_time_s"], abs=1e-9)
    total = SHORT["rig.procedure.feed_time_s"] + SHORT["rig.procedure.holdup_wait_s"]
    assert total / VTK_INTERVAL_S <= len(spheres) <= total / VTK_INTERVAL_S + 2
    n, _, arrays = vtu_header(spheres[-1][1])
    assert n == res["n_particle_spheres_end"]
    for name in ("radii", "linVelVec", "linVelLen", "materialId", "clumpId"):
        assert name in arrays, name
    _, cells, _ = vtu_header(facets[-1][1])
    assert cells == 1                                   # the plate is one facet
    mid = min(spheres, key=lambda s: abs(s[0] - 0.3))   # mid-feed: the stream is there
    n_mid, _, arrays = vtu_header(mid[1])
    print("mid-feed snapshot", mid, n_mid, arrays["linVelLen"], arrays["radii"])
    assert arrays["radii"] == (0.0125, 0.0125)
    assert 12.3 < arrays["linVelLen"][1] < 12.46       # the stream between window and plate, nothing faster


@pytest.mark.parametrize("material, fines", [("mixed-dry", "M3-dry"), ("mixed-wet", "M3-wet")])
def test_a_mixed_set_keeps_its_balance_with_lumps(tmp_path_factory, material, fines):
    over = {"rig.procedure.feed_time_s": 0.25, "rig.procedure.holdup_wait_s": 0.05, "rig.measure.steady_from_s": 0.1,
            "rig.measure.frame_interval_s": 0.3}
    job = with_vtk(resolve_job("transfer", material, over, seed=2), VTK_INTERVAL_S)
    runs = tmp_path_factory.mktemp("transfer_mixed")
    res = run_job(job, runs_dir=runs, timeout_s=900)
    # the heaviest particle: a 50 mm rounded lump, the union of 27 spheres of 12.5 mm on a 3 x 3 x 3
    # grid 12.5 mm apart, at most a 50 mm cube of 2750 kg/m3 (0.344 kg)
    heaviest = 2750 * 0.05 ** 3
    for when in ("at_feed_stop", "at_end"):
        fed, parts = balance(res, when)
        print(when, "fed", fed, parts)
        assert abs(fed - sum(parts.values())) <= heaviest
    assert res["fed_mass_kg"] == pytest.approx(SLICE_FLOW * 0.25, abs=heaviest)
    for name in ("M1", "M2", fines):
        assert res[f"mass_fraction_{name}_fed"] == pytest.approx(res[f"mass_fraction_{name}_requested"], abs=0.03)
    # the last VTK snapshot holds every particle sphere left (lump members counted), the lumps' members
    # with their clump's id, three materials at most (YADE ids 0 - 2: the set's components)
    vtk = runs / "transfer" / job["job_id"] / "vtk"
    spheres = _collection(vtk, "transfer", "spheres")
    assert len(spheres) == res["vtk_snapshots_count"] and all(f.is_file() for _, f in spheres)
    mid = min(spheres, key=lambda s: abs(s[0] - 0.2))        # the stream, lumps among it
    n_mid, _, arrays = vtu_header(mid[1])
    print("mid-feed snapshot", mid, n_mid, arrays)
    assert n_mid > 50 and arrays["clumpId"][1] >= 0 and 0.0 <= arrays["materialId"][0] <= arrays["materialId"][1] <= 2.0
    n_end, _, _ = vtu_header(spheres[-1][1])
    assert n_end == res["n_particle_spheres_end"]
    assert_documented(res)
