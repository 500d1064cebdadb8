"""Exporting a calibrated material to other DEM codes: each conversion on a case computed
by hand, and the four formats written from a study folder."""
import math
import shutil

import pytest

from pycal import CONFIG_DIR
from pycal.cli import main
from pycal.export import conversions as cv


def test_liggghts_rolling_coefficient_keeps_the_same_moment_cap():
    # equal 25 mm spheres: reff = R / 2, so rmu = 2 mu_r; on a wall reff = R: rmu = mu_r
    assert cv.liggghts_rolling_coefficient(0.35, 0.0125, 0.0125) == pytest.approx(0.70)
    assert cv.liggghts_rolling_coefficient(0.35, 0.0125) == pytest.approx(0.35)
    # 10 and 20 mm radii: ours caps at 0.35 x 0.01 |Fn|; reff = 0.02 / 3 m -> rmu = 0.35 x 1.5
    assert cv.liggghts_rolling_coefficient(0.35, 0.01, 0.02) == pytest.approx(0.525)
    assert cv.liggghts_rolling_coefficient(0.35, 0.01, 0.02) * 0.02 / 3 == pytest.approx(0.35 * 0.01)


def test_shear_modulus_timestep_rayleigh_time_and_pull_off_by_hand():
    assert cv.shear_modulus_pa(1.0e8, 0.3) == pytest.approx(1.0e8 / 2.6)
    assert cv.hertz_timestep_s(0.0125, 1.0e8, 3260.0, 0.5) == pytest.approx(0.5 * 0.0125 * math.sqrt(3.26e-5))
    g = 1.0e8 / 2.6
    assert cv.rayleigh_time_s(0.0125, 1.0e8, 0.3, 3260.0) == pytest.approx(
        math.pi * 0.0125 * math.sqrt(3260.0 / g) / (0.1631 * 0.3 + 0.8766))
    weight = 3260.0 * 4.0 / 3.0 * math.pi * 0.0125 ** 3 * 9.81           # 0.2616 N
    assert cv.pull_off_force_n(0.05, 0.0125, 3260.0) == pytest.approx(0.05 * weight)


@pytest.fixture
def study(tmp_path):
    d = tmp_path / "study"
    (d / "calibrated").mkdir(parents=True)
    for m in ("M2", "M1"):
        shutil.copyfile(CONFIG_DIR / "materials" / f"{m}.yaml", d / "calibrated" / f"{m}.yaml")
    return d


def test_every_format_is_written_with_its_conversions(study, tmp_path, capsys):
    out = tmp_path / "out"
    for fmt in ("yaml", "liggghts", "rocky", "edem"):
        assert main(["export", "--calibrated", str(study), "--material", "M2", "--format", fmt, "--out", str(out)]) == 0
    assert {p.name for p in out.iterdir()} == {"M2.yaml", "in.M2.liggghts", "M2.rocky.csv", "M2.edem.csv"}
    lig = (out / "in.M2.liggghts").read_text()
    line = next(l for l in lig.splitlines() if "coefficientRollingFriction" in l)
    values = [float(v) for v in line.split("peratomtypepair")[1].split()[1:]]
    assert values[0] == pytest.approx(2 * 0.35) and values[1] == pytest.approx(0.35)   # M2-M2, M2-steel
    assert "rolling_friction epsd2" in lig and "timestep" in lig
    edem = (out / "M2.edem.csv").read_text()
    assert f"shear modulus,{2.0e7 / 2.6:.6g},Pa" in edem


def test_a_clump_material_or_unknown_format_is_refused_in_one_line(study, tmp_path, capsys):
    args = ["export", "--calibrated", str(study), "--out", str(tmp_path / "o")]
    assert main(args + ["--material", "M1", "--format", "liggghts"]) == 2
    assert "--material: M1: a clump material" in capsys.readouterr().err
    assert main(args + ["--material", "M7", "--format", "yaml"]) == 2
    assert "no calibrated/M7.yaml" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


@pytest.fixture
def set_study(tmp_path):
    """A study folder whose summary holds calibrated overrides of M2 and M3-wet."""
    import json
    d = tmp_path / "set_study"
    (d / "calibrated").mkdir(parents=True)
    overrides = {"M2": {"particles.density_kg_m3": 3700.0, "interactions.M2.rolling_resistance_coefficient": 0.2},
                 "M3-wet": {"particles.density_kg_m3": 2700.0, "interactions.M3-wet.friction_coefficient": 0.31,
                            "interactions.M3-wet.rolling_resistance_coefficient": 0.4}}
    (d / "summary.json").write_text(json.dumps({"overrides": overrides}))
    return d


def test_a_material_set_is_written_with_its_components_calibrated_values_and_cross_pairs(set_study, tmp_path):
    out = tmp_path / "out"
    for fmt in ("yaml", "liggghts", "rocky", "edem"):
        assert main(["export", "--calibrated", str(set_study), "--material", "mixed-wet", "--format", fmt,
                     "--out", str(out)]) == 0
    assert {p.name for p in out.iterdir()} == {"mixed-wet.set.yaml", "in.mixed-wet.liggghts", "mixed-wet.rocky.csv",
                                               "mixed-wet.edem.csv"}
    lig = (out / "in.mixed-wet.liggghts").read_text().splitlines()
    types = next(l for l in lig if l.startswith("# atom types")).split(": ", 1)[1].split(", ")
    names = [t.split(" = ")[1] for t in types]
    assert names[:3] == ["M1", "M2", "M3-wet"] and "steel" in names and "pvc" in names

    def pair(key, a, b):
        line = next(l for l in lig if f"property/global {key} " in l)
        vals = [float(v) for v in line.split("peratomtypepair")[1].split()[1:]]
        return vals[names.index(a) * len(names) + names.index(b)]
    # the gravel-fines pair takes the wet fines' calibrated friction (the set's from_components rule)
    assert pair("coefficientFriction", "M2", "M3-wet") == pytest.approx(0.31)
    assert pair("coefficientFriction", "M3-wet", "M2") == pytest.approx(0.31)
    # and their rolling resistance, x2 between equal spheres; M2-M2 its own 0.2 x2
    assert pair("coefficientRollingFriction", "M2", "M3-wet") == pytest.approx(0.8)
    assert pair("coefficientRollingFriction", "M2", "M2") == pytest.approx(0.4)
    # the sphere components' mass fractions, renormalised without the clumps: 32.5 / (32.5 + 37.3)
    dist = next(l for l in lig if "particledistribution/discrete" in l).split()
    assert float(dist[dist.index("pts2") + 1]) == pytest.approx(32.5 / 69.8, rel=1e-5)
    assert float(dist[dist.index("pts3") + 1]) == pytest.approx(37.3 / 69.8, rel=1e-5)
    dens = {l.split()[6]: float(l.split()[9]) for l in lig if "particletemplate/sphere" in l}
    assert dens == {"2": 3700.0, "3": 2700.0}
    assert any(l.startswith("# M1: a clump material") for l in lig)
    rocky = (out / "mixed-wet.rocky.csv").read_text()
    assert "M1,shape,clump" in rocky and "M2-M3-wet,static friction,0.31" in rocky
    import yaml
    doc = yaml.safe_load((out / "mixed-wet.set.yaml").read_text())
    assert doc["components"]["M2"]["particles"]["density_kg_m3"] == 3700.0


def test_a_set_without_a_study_summary_is_refused_in_one_line(study, tmp_path, capsys):
    assert main(["export", "--calibrated", str(study), "--material", "mixed-wet", "--format", "yaml",
                 "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "no summary.json" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()
