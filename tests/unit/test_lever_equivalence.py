"""bench/lever_equivalence.py: the slope from a study's runs.csv, the recorded one where the
study has no runs of the stage, and each lever judged by the equivalence rule."""
import json

from bench_scripts import load_bench_script

lev = load_bench_script("lever_equivalence")


def test_the_slope_comes_from_the_study_and_judges_the_levers(tmp_path):
    rows = ["material,stage,rig,parameters,seed,response,value"]
    for i, (x, y) in enumerate([(0.4, -0.02), (0.4, -0.03), (0.6, 0.07), (0.6, 0.08), (0.8, 0.17), (0.8, 0.18)]):
        p = json.dumps({"interactions.steel.friction_coefficient": x}).replace('"', '""')
        rows.append(f'M2,wall_friction,wall_friction,"{p}",{i + 1},friction_offset_mu_static,{y}')
    (tmp_path / "runs.csv").write_text("\n".join(rows) + "\n")
    slope, where = lev.slope_of(lev.WALL, tmp_path)
    assert abs(slope - 0.5) < 1e-9 and "6 runs" in where
    assert lev.slope_of(lev.WET, tmp_path) == (371.0, "371 (recorded)")
    text = lev.table(tmp_path)
    wall_05 = next(line for line in text.splitlines() if "tilt 5 deg/s" in line and "steel 0.5" in line)
    assert "| 0.005 |" in wall_05 and wall_05.endswith("**no** |")     # margin 0.2 x 0.05 x 0.5; upper end 0.0061
    wet = [line for line in text.splitlines() if line.startswith("| M3-wet")]
    assert len(wet) == 3 and all(line.endswith("**yes** |") for line in wet)
