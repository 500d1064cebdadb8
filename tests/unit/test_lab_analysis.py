"""Lab analysis formulas and the `impact` / `analyse` commands."""

import pandas as pd
import pytest

from pycal import lab_analysis as la
from pycal.cli import main

# Design case by hand: H = 7 m, v0 = 4.2 m/s, 1500 t/h, rho0 = 1800 kg/m3, g = 9.81.
# Only the vertical velocity counts, in the stream's density as in the stress:
#   vz = sqrt(2 x 9.81 x 7) = 11.7192 m/s
#   rho_b = 1800 x 4.2 / 11.7192 = 645.09 kg/m3   (rho_b vz = rho0 v0: same section, same flow)
#   P = rho_b vz^2 = 1800 x 4.2 x 11.7192 = 88 597 Pa
VZ = 11.7192
RHO_B = 645.09
P = 88597.0
V = 12.4491                             # sqrt(4.2^2 + vz^2): reported, used nowhere
DESIGN = ["impact", "--drop-height-m", "7", "--belt-speed-m-s", "4.2", "--flow-t-h", "1500",
          "--bulk-density-kg-m3", "1800"]


def test_impact_stress_design_case():
    r = la.impact_stress(7.0, 4.2, 1500 / 3.6, 1800.0)
    assert r["impact_stress_pa"] == pytest.approx(P, abs=2.0)
    assert r["impact_velocity_vertical_m_s"] == pytest.approx(VZ, abs=1e-4)
    assert r["impact_speed_m_s"] == pytest.approx(V, abs=1e-4)
    assert r["stream_bulk_density_kg_m3"] == pytest.approx(RHO_B, abs=0.01)
    assert r["stream_area_m2"] == pytest.approx((1500 / 3.6) / (1800 * 4.2))
    # the stress does not depend on the flow, only the stream's cross-section does
    r2 = la.impact_stress(7.0, 4.2, 3000 / 3.6, 1800.0)
    assert r2["impact_stress_pa"] == pytest.approx(P, abs=2.0)
    assert r2["stream_area_m2"] == pytest.approx(2 * r["stream_area_m2"])
    with pytest.raises(ValueError):
        la.impact_stress(0.0, 4.2, 1.0, 1800.0)


def test_impact_stress_is_rho0_v0_vz():
    """rho_b vz = rho0 v0, so P = rho0 v0 vz: doubling the belt speed doubles the stress,
    four times the drop height doubles it (vz ~ sqrt(H))."""
    p = la.impact_stress(5.0, 3.0, 100.0, 1500.0)["impact_stress_pa"]
    assert la.impact_stress(5.0, 6.0, 100.0, 1500.0)["impact_stress_pa"] == pytest.approx(2 * p)
    assert la.impact_stress(20.0, 3.0, 100.0, 1500.0)["impact_stress_pa"] == pytest.approx(2 * p)


def test_impact_rule_refuses_a_drop_below_the_belt_speed_height():
    """Below H = v0^2 / (2 g) (0.899 m at 4.2 m/s) vz < v0 and rho_b = rho0 v0 / vz would
    exceed the belt's bulk density: no number, an error."""
    assert la.min_drop_height_m(4.2) == pytest.approx(0.8991, abs=1e-4)
    with pytest.raises(ValueError, match="denser than on the belt"):
        la.impact_stress(0.85, 4.2, 1.0, 1800.0)
    r = la.impact_stress(0.8992, 4.2, 1.0, 1800.0)
    assert r["stream_bulk_density_kg_m3"] == pytest.approx(1800.0, rel=1e-4)


def test_shipped_load_steps_cover_the_design_impact_stress():
    """Every compression and friction rig's top step, and the calibration's, is at or above
    the impact stress of the design case of labresults/samples.yaml (88.6 kPa)."""
    from pycal import labdata
    from pycal.configs import load_rig, load_yaml
    from pycal import CONFIG_DIR
    s = labdata.load_samples()
    belt = s["belt"]
    p = la.impact_stress(s["design"]["drop_height_m"], belt["speed_m_s"], la.t_h_to_kg_s(belt["flow_t_h"]),
                         s["material"]["mine_bulk_density_kg_m3"])["impact_stress_pa"]
    assert p == pytest.approx(P, abs=2.0)
    tops = {}
    for rig in ("ccs", "ccs_expansion", "ucs", "wall_friction", "internal_friction"):
        proc = load_rig(rig)["procedure"]
        tops[rig] = max(proc.get("load_steps_pa") or proc["consolidation_stresses_pa"])
    study = load_yaml(CONFIG_DIR / "calibrations" / "zinc_ore.yaml")
    for mat, stages in study["materials"].items():
        for st in stages:
            steps = st.get("rig_overrides", {}).get("rig.procedure.consolidation_stresses_pa")
            if steps:
                tops[f"{mat}/{st.get('name', st['stage'])}"] = max(steps)
    assert all(top >= p for top in tops.values()), tops


def test_impact_rises_with_drop_height():
    df = la.impact_vs_drop_height([0.5, 1, 7, 15], 4.2, 1500 / 3.6, 1800)
    assert df["impact_stress_pa"].is_monotonic_increasing
    assert df["stream_bulk_density_kg_m3"].is_monotonic_decreasing


def test_moisture_and_densities():
    assert la.moisture_percent_dry_basis(105.4, 100.0) == pytest.approx(5.4)
    assert la.moisture_percent_dry_basis(0.02108, 0.02) == pytest.approx(5.4)
    with pytest.raises(ValueError):
        la.moisture_percent_dry_basis(1.0, 0.0)
    assert la.solid_fraction(1800, 2750) == pytest.approx(0.6545, abs=1e-4)
    assert la.dry_bulk_density(1054, 5.4) == pytest.approx(1000)
    assert la.belt_load_kg_m(1500, 4.2) == pytest.approx(99.2, abs=0.05)


def test_rolling_resistance_estimate():
    assert la.rolling_resistance_from_aspect_ratio(1.7) == pytest.approx(0.35)
    assert la.rolling_resistance_from_aspect_ratio(1.0) == 0.0
    with pytest.raises(ValueError):
        la.rolling_resistance_from_aspect_ratio(0.5)


def test_cli_impact(capsys):
    assert main(DESIGN) == 0
    out = capsys.readouterr().out
    assert "impact stress (rho_b vz^2): 88.60 kPa" in out
    assert "11.72 m/s" in out and "645.1 kg/m3" in out


def test_cli_impact_below_the_rule_height_is_a_one_line_error(capsys):
    argv = list(DESIGN)
    argv[argv.index("--drop-height-m") + 1] = "0.5"
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: --drop-height-m: drop_height_m: 0.5 m is below")


@pytest.mark.parametrize("flag,field", [("--drop-height-m", "drop_height_m"),
                                        ("--flow-t-h", "flow_t_h"),
                                        ("--bulk-density-kg-m3", "bulk_density_kg_m3"),
                                        ("--belt-speed-m-s", "belt_speed_m_s")])
def test_cli_impact_bad_argument(capsys, flag, field):
    argv = list(DESIGN)
    argv[argv.index(flag) + 1] = "-1" if field == "drop_height_m" else "0"
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"{flag}: {field}:" in err and "must be > 0" in err


def test_cli_analyse(tmp_path, capsys):
    out = tmp_path / "analysis"
    assert main(["analyse", "--out", str(out)]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == ["derived_quantities.csv", "impact_vs_drop_height.csv", "impact_vs_drop_height.png"]
    table = pd.read_csv(out / "derived_quantities.csv")
    assert list(table.columns) == ["name", "value", "unit", "source"]
    value = dict(zip(table["name"], table["value"]))
    assert value["impact_stress_pa"] == pytest.approx(P, rel=1e-5)
    assert value["belt_load_kg_m"] == pytest.approx(99.21, abs=0.01)
    assert value["rolling_resistance_estimate"] == pytest.approx(0.35)
    assert value["solid_fraction_fines_dry"] == pytest.approx(1601 / 2750, rel=1e-5)
    assert value["mass_percent_minus_6mm"] == pytest.approx(37.3)
    curve = pd.read_csv(out / "impact_vs_drop_height.csv")
    assert curve["drop_height_m"].iloc[0] == 1.0 and curve["drop_height_m"].iloc[-1] == 15.0   # from 0.9 m on
    assert (out / "impact_vs_drop_height.png").read_bytes()[:4] == b"\x89PNG"
    assert "impact_stress_pa" in capsys.readouterr().out
