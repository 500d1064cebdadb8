"""Lab analysis formulas and the `impact` / `analyse` commands."""
import math

import pandas as pd
import pytest

from pycal import lab_analysis as la
from pycal.cli import main

# Design case by hand: H = 7 m, v0 = 4.2 m/s, 1500 t/h, rho0 = 1800 kg/m3, g = 9.81
VZ = math.sqrt(2 * 9.81 * 7)            # 11.7192 m/s
V = math.sqrt(4.2 ** 2 + VZ ** 2)       # 12.4491 m/s
RHO_B = 1800 * 4.2 / V                  # 607.27 kg/m3
P = RHO_B * VZ ** 2                     # 83402.9 Pa
DESIGN = ["impact", "--drop-height-m", "7", "--belt-speed-m-s", "4.2", "--flow-t-h", "1500",
          "--bulk-density-kg-m3", "1800"]


def test_hand_values():
    assert VZ == pytest.approx(11.719, abs=1e-3) and V == pytest.approx(12.449, abs=1e-3)
    assert RHO_B == pytest.approx(607.27, abs=0.01) and P == pytest.approx(83402.9, abs=0.1)


def test_impact_stress_design_case():
    r = la.impact_stress(7.0, 4.2, 1500 / 3.6, 1800.0)
    assert r["impact_stress_pa"] == pytest.approx(83400, abs=500)
    assert r["impact_stress_pa"] == pytest.approx(P, rel=1e-9)
    assert r["impact_velocity_vertical_m_s"] == pytest.approx(VZ)
    assert r["impact_speed_m_s"] == pytest.approx(V)
    assert r["stream_bulk_density_kg_m3"] == pytest.approx(RHO_B)
    assert r["stream_area_m2"] == pytest.approx((1500 / 3.6) / (1800 * 4.2))
    # the stress does not depend on the flow, only the stream's cross-section does
    r2 = la.impact_stress(7.0, 4.2, 3000 / 3.6, 1800.0)
    assert r2["impact_stress_pa"] == pytest.approx(P) and r2["stream_area_m2"] == pytest.approx(2 * r["stream_area_m2"])
    with pytest.raises(ValueError):
        la.impact_stress(0.0, 4.2, 1.0, 1800.0)


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
    assert "impact stress: 83.40 kPa" in out
    assert "11.72 m/s" in out and "607.3 kg/m3" in out


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
    assert curve["drop_height_m"].iloc[0] == 0.5 and curve["drop_height_m"].iloc[-1] == 15.0
    assert (out / "impact_vs_drop_height.png").read_bytes()[:4] == b"\x89PNG"
    assert "impact_stress_pa" in capsys.readouterr().out
