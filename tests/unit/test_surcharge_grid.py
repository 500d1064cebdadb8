"""bench/surcharge_grid.py: its runs found again from their overrides, and the table's means."""
import json
import math

import numpy as np
import yaml

from bench_scripts import load_bench_script

grid = load_bench_script("surcharge_grid")


def fake_run(folder, friction, rolling, seed, aor, surcharge, heights=(0.08, 0.05), material="M3-dry", lift=0.01,
             amplitude_mm=0.125):
    ov = {**grid.settings(material, friction, rolling), "rig.procedure.lift_speed_m_s": lift,
          "particles.density_kg_m3": 3459.0}
    m = {"aor_mean_deg": aor, "surcharge_mean_deg": surcharge, "surcharge_left_deg": surcharge,
         "surcharge_right_deg": None, "pile_height_m": heights[0],
         "surcharge_pile_height_m": heights[1]}
    name = f"job-{friction}-{rolling}-{seed}-{lift}-{amplitude_mm}"
    r = batch_result(name, material, [seed], ov, rig(amplitude_mm), [replica(seed, m)], 20.0 + seed)
    d = folder / "surcharge" / name
    d.mkdir(parents=True)
    (d / "result.json").write_text(json.dumps(r))


def replica(seed, measurements, status="ok"):
    return {"seed": seed, "status": status, "measurements": measurements, "output_dir": f"s{seed}",
            "simulated_time_s": 10.0, "steps_count": 1000, "failure": None if status == "ok" else "no rest"}


def batch_result(name, material, seeds, overrides, rig_config, replicas, cpu):
    """A batch job's result.json as the rig writes it."""
    job = {"job_id": name, "rig": "surcharge", "material": material, "seeds": seeds, "overrides": overrides,
           "rig_config": rig_config}
    return {"job_id": name, "rig": "surcharge", "material": material, "seeds": seeds, "job": job,
            "contact_model": "hertz_mindlin", "replicas": replicas, "provenance": {"cpu_time_s": cpu}}


MEASURE = yaml.safe_load((grid.ROOT / "configs" / "rigs" / "surcharge.yaml").read_text())["measure"]


def rig(amplitude_mm):
    """The resolved rig config's procedure and measure settings as a job records them."""
    return {"procedure": {"vibration_frequency_hz": 25.0, "vibration_amplitude_horizontal_m": amplitude_mm * 1e-3,
                          "vibration_amplitude_vertical_m": amplitude_mm * 0.6e-3}, "measure": MEASURE}


def cone_pile(angle_deg, r=0.0125, height=0.11):
    """Spheres stacked in rings so that their tops lie on a cone of flank angle angle_deg."""
    rows = []
    for k in range(int(height / (2 * r))):
        z = r + 2 * r * k
        ring = (height - (z + r)) / math.tan(math.radians(angle_deg))
        rho = ring
        while rho > 0:
            count = max(1, int(2 * math.pi * rho / (2 * r)))
            rows += [(rho * math.cos(2 * math.pi * j / count), rho * math.sin(2 * math.pi * j / count), z, r)
                     for j in range(count)]
            rho -= 2 * r
        rows.append((0.0, 0.0, z, r))
    return np.array(rows)


def write_pile(path, a):
    path.write_text("x_m,y_m,z_m,radius_m\n" + "".join(f"{x},{y},{z},{r}\n" for x, y, z, r in a))


def test_the_other_readings_read_a_cone_pile_before_and_after(tmp_path):
    folder = tmp_path / "s1"
    folder.mkdir()
    write_pile(folder / "pile_particles.csv", cone_pile(35.0))
    write_pile(folder / "surcharge_particles.csv", cone_pile(20.0))
    got = grid.readings({"folder": folder, "measure": MEASURE})
    assert abs(got[("cone", "before")] - 35.0) < 5.0 and abs(got[("cone", "after")] - 20.0) < 5.0
    assert got[("rotated_sector_mean", "before")] > got[("rotated_sector_mean", "after")] + 5.0


def test_grid_points_are_found_from_their_overrides_and_tabulated(tmp_path):
    fake_run(tmp_path, 0.5, 0.15, 1, 40.0, 20.0)
    fake_run(tmp_path, 0.5, 0.15, 2, 36.0, None)           # flattened: no angle after the vibration
    fake_run(tmp_path, 0.8, 0.05, 1, 45.0, 30.0)
    fake_run(tmp_path, 0.8, 0.05, 2, 44.0, 28.0, lift=0.002)   # another lift speed: not a grid run
    fake_run(tmp_path, 0.8, 0.05, 3, 30.0, 10.0, material="M2")
    fake_run(tmp_path, 0.8, 0.05, 4, 44.0, 35.0, amplitude_mm=0.5)   # another vibration: its own grid point
    two = batch_result("two", "M3-dry", [5, 6], grid.settings("M3-dry", 0.3, 0.4), rig(0.125),
                       [replica(5, {"aor_mean_deg": 30.0, "pile_height_m": 0.07, "surcharge_pile_height_m": 0.03}),
                        replica(6, {}, "failed")], 50.0)              # two seeds in one job, one failed
    (tmp_path / "surcharge" / "two").mkdir()
    (tmp_path / "surcharge" / "two" / "result.json").write_text(json.dumps(two))
    groups = grid.load(tmp_path, "M3-dry")
    v1, v4 = (25.0, 0.000125, 0.000075), (25.0, 0.0005, 0.0003)
    assert sorted(groups) == [(0.3, 0.4, v1), (0.5, 0.15, v1), (0.8, 0.05, v1), (0.8, 0.05, v4)]
    assert [(r["seed"], r["cpu_time_s"]) for r in groups[(0.3, 0.4, v1)]] == [(5, 25.0)]   # the job's CPU over 2 seeds
    assert len(groups[(0.5, 0.15, v1)]) == 2 and len(groups[(0.8, 0.05, v1)]) == 1
    text = grid.table(groups)
    row = next(line for line in text.splitlines() if line.startswith("| 0.5 | 0.15 |"))
    assert "| 0.125 / 0.075 (0.31 / 0.19) at 25 Hz |" in row
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[4] == "38.0 (2.8)"          # AoR mean (SD) over both seeds
    assert cells[5] == "20.0"                # surcharge: the one seed with an angle, no SD
    assert cells[6] == "1 of 2"
    assert cells[7] == "20.0; 1 / -; 0"      # left: one seed's angle; right: none
    assert cells[8] == "80 / 50"             # pile height before / after, mm
    assert cells[9] == "22"                  # median CPU of 21 and 22 s


def test_peak_acceleration_of_a_sinusoid():
    # 25 Hz at 0.5 mm: (2 pi 25)^2 0.0005 = 12.34 m/s2 = 1.258 g
    assert abs(grid.peak_acceleration_g(25.0, 0.0005) - 12.337 / 9.81) < 1e-3
    assert abs(grid.peak_acceleration_g(1.0 / (2 * 3.141592653589793), 9.81) - 1.0) < 1e-12
