"""pycal.rigs.transfer.stream: the transfer rig's stream and plate from the job alone (no YADE), with
answers computed by hand, and the refusal of geometries that cannot work (one line naming
the key of configs/rigs/transfer.yaml, exit 2, nothing written).

Hand values for the design case (H 7 m, v0 4.2 m/s, Q 1500 t/h = 416.67 kg/s, rho0
1800 kg/m3, g 9.81 m/s2) and the shipped rig (plate 30 deg, B 0.8 m, W 0.1 m):
- vz = sqrt(2 x 9.81 x 7) = 11.7192 m/s; P_design = 1800 x 4.2 x 11.7192 = 88 597 Pa;
- rho_b = 1800 x 4.2 / 11.7192 = 645.09 kg/m3;
- u_n = 11.7192 cos 30 - 4.2 sin 30 = 10.1491 - 2.1 = 8.0491 m/s; rho_b u_n^2 = 41 795 Pa;
- A = 416.67 / (1800 x 4.2) = 0.055115 m2, Lf = A / 0.8 = 0.068893 m;
- footprint of a straight stream: Lf vz / u_n = 0.10031 m (the trajectories bend a little
  over the 0.15 m above the plate);
- slice flow 416.67 x 0.1 / 0.8 = 52.083 kg/s.
"""
import math

import pytest

from pycal.rigs.transfer import stream
from pycal.cli import main
from pycal.configs import load_yaml
from pycal import CONFIG_DIR
from pycal.jobs import resolve_job


def job(over=None, material="M2"):
    return resolve_job("transfer", material, over or {})


def test_the_rig_carries_the_studys_design_case():
    study = load_yaml(CONFIG_DIR / "calibrations" / "zinc_ore.yaml")["design_case"]
    p = job()["rig_config"]["procedure"]
    assert p["design_drop_height_m"] == study["drop_height_m"]
    assert p["design_belt_speed_m_s"] == study["belt_speed_m_s"]
    assert p["design_mass_flow_kg_s"] == pytest.approx(study["flow_t_h"] / 3.6, rel=1e-12)
    assert p["design_belt_bulk_density_kg_m3"] == study["bulk_density_kg_m3"]


def test_stream_and_reference_stresses_by_hand():
    g = stream.geometry(job())
    assert g["vertical_speed_at_plate_m_s"] == pytest.approx(11.7192, abs=1e-4)
    assert g["design_impact_stress_pa"] == pytest.approx(88597, rel=1e-4)
    assert g["stream_bulk_density_at_plate_kg_m3"] == pytest.approx(645.09, abs=0.01)
    assert g["momentum_flux_stress_pa"] == pytest.approx(41795, rel=1e-4)
    assert g["stream_length_m"] == pytest.approx(0.068893, rel=1e-4)
    assert g["slice_mass_flow_kg_s"] == pytest.approx(52.083, rel=1e-4)
    assert g["footprint_length_m"] == pytest.approx(0.10031, rel=0.01)
    assert 0.0 < g["footprint_start_m"] < 0.15 < g["footprint_end_m"] < 0.8
    assert g["speed_at_plate_m_s"] == pytest.approx(math.sqrt(4.2 ** 2 + 2 * 9.81 * 7), rel=1e-12)


def test_a_horizontal_plate_sees_the_design_stress():
    g = stream.geometry(job({"rig.geometry.plate_inclination_deg": 0.0}))
    assert g["momentum_flux_stress_pa"] == pytest.approx(g["design_impact_stress_pa"], rel=1e-12)
    # a horizontal plate: the footprint is the stream's own horizontal length
    assert g["footprint_length_m"] == pytest.approx(g["stream_length_m"], rel=1e-9)


def test_the_injection_keeps_the_stream_on_its_free_fall():
    g = stream.geometry(job())
    h = job()["rig_config"]["procedure"]["injection_height_m"]
    assert g["vertical_speed_at_injection_m_s"] == pytest.approx(math.sqrt(2 * 9.81 * (7 - h)), rel=1e-12)
    # the stream's mass flux is the same through the window as at the plate: rho_b vz = rho0 v0
    assert g["stream_bulk_density_at_injection_kg_m3"] * g["vertical_speed_at_injection_m_s"] == \
        pytest.approx(1800 * 4.2, rel=1e-12)


def test_layers_cover_the_feed_time_and_stay_thin():
    j = job()
    n, dt = stream.layer_times(j)
    p = j["rig_config"]["procedure"]
    assert n * dt == pytest.approx(p["feed_time_s"], rel=1e-12)
    assert stream.geometry(j)["vertical_speed_at_injection_m_s"] * dt <= p["injection_layer_thickness_m"] + 1e-12


@pytest.mark.parametrize("over, key, why", [
    ({"rig.procedure.design_drop_height_m": 0.5}, "procedure.design_drop_height_m", "below v0^2 / (2 g) = 0.899 m"),
    ({"rig.geometry.plate_inclination_deg": 80}, "geometry.plate_inclination_deg", "must be within 0 - 75 deg"),
    ({"rig.geometry.impact_point_from_plate_top_m": 0.9}, "geometry.impact_point_from_plate_top_m",
     "must lie on the plate"),
    ({"rig.geometry.impact_point_from_plate_top_m": 0.75}, "geometry.impact_point_from_plate_top_m",
     "the stream does not meet the plate within its length (footprint 0.7 - 0.8 m"),
    ({"rig.procedure.design_drop_height_m": 1.0, "rig.procedure.injection_height_m": 1.2},
     "procedure.injection_height_m", "must be below the drop height 1 m"),
    ({"rig.procedure.injection_height_m": 0.01}, "procedure.injection_height_m", "less than one largest particle"),
    # 5.2 m above the plate the stream has fallen 1.8 m: vz 5.94 m/s, 1272 kg/m3, solid fraction 0.46
    ({"rig.procedure.injection_height_m": 5.2}, "procedure.injection_height_m", "solid fraction at the injection "
                                                                              "window would be 0.46"),
    ({"rig.geometry.slice_width_m": 0.02}, "geometry.slice_width_m", "wider than the largest particle"),
    ({"rig.measure.steady_from_s": 1.5}, "measure.steady_from_s", "before the feed stops"),
    ({"rig.measure.plug_outflow_ratio": 0.0}, "measure.plug_outflow_ratio", "must be > 0"),
    ({"rig.procedure.feed_time_s": -1.0}, "procedure.feed_time_s", "must be > 0"),
    ({"rig.measure.steady_from_s": "abc"}, "measure.steady_from_s", "'abc' must be a number"),
    ({"rig.procedure.holdup_wait_s": -0.5}, "procedure.holdup_wait_s", "must be >= 0"),
    ({"rig.procedure.placement_max_attempts_count": 0}, "procedure.placement_max_attempts_count",
     "0 must be >= 1"),
    ({"rig.geometry.plate_material": "wood"}, "geometry.plate_material", "unknown boundary 'wood'"),
])
def test_bad_geometry_is_refused_in_one_line(tmp_path, capsys, over, key, why):
    args = ["run", "transfer", "--material", "M2", "--out", str(tmp_path)]
    for k, v in over.items():
        args += ["--set", f"{k}={v}"]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    # a single key out of its range: the --set that put it there (pycal/rigs/fields.py); a
    # value the stream cannot run: the rig config's key (pycal.rigs.transfer.stream)
    assert len(err.splitlines()) == 1, err
    assert err.startswith((f"error: configs/rigs/transfer.yaml: {key}: ", f"error: --set: rig.{key}=")), err
    assert why in err, err
    assert not any(tmp_path.iterdir())          # nothing written


def test_the_largest_lump_sets_the_narrowest_slice(capsys):
    # mixed sets: a 50 mm rounded lump has a bounding sphere of 0.683 x 50 mm = 34.2 mm radius
    assert stream.largest_bounding_radius_m(job(material="mixed-dry")) == pytest.approx(0.0342, abs=1e-4)
    assert main(["job", "transfer", "--material", "mixed-dry", "--set", "rig.geometry.slice_width_m=0.06"]) == 2
    assert "geometry.slice_width_m: 0.06 must be wider than the largest particle" in capsys.readouterr().err
