"""A study that starts from the library (pycal/calibration/library_start.py), on the fake
executor of tests/unit/fake_rigs.py writing each run's result.json into a runs folder: after
a changed lab angle the density stage simulates nothing and the rolling stage starts from
the earlier study's runs; no run counts twice; a resumed study takes the same runs."""
import json

from fake_rigs import ROLLING_STUDY_HEAD, FakeRigs
from pycal.calibration.study import Study

DENSITY_STAGE = """    - stage: density
      rig: fill
      target: {band_percent: 1.0}
      parameter: {bounds: [1500.0, 9000.0], tolerance_kg_m3: 30.0}
      max_runs_count: 24
"""
LAB_TARGET = "target: {sample: fines_dry, test: angle_of_repose, band_deg: 1.0}"


class WritingFake(FakeRigs):
    """FakeRigs that also leaves each run's result.json in its job folder, as the real executors do."""

    def run(self, jobs, raise_on_error=True):
        out = super().run(jobs, raise_on_error)
        for job, r in zip(jobs, out):
            folder = self.runs_dir / job["rig"] / job["job_id"]
            folder.mkdir(parents=True, exist_ok=True)
            if r is not None and not (folder / "result.json").exists():
                (folder / "result.json").write_text(json.dumps({**r, "contact_model": "hertz_mindlin"}))
        return out


def config(tmp_path, angle):
    """The fake AoR study of fake_rigs.py with a density stage first and the lab angle `angle`."""
    assert LAB_TARGET in ROLLING_STUDY_HEAD
    text = ROLLING_STUDY_HEAD.replace(LAB_TARGET, f"target: {{value: {angle}, band_deg: 1.0}}")
    p = tmp_path / f"lib-{angle}.yaml"
    p.write_text("name: lib\n" + text.replace("  M3-dry:\n", "  M3-dry:\n" + DENSITY_STAGE, 1))
    return p


def stage(rows, name):
    return next(r for r in rows if r["stage"] == name)


def test_a_changed_lab_angle_starts_from_the_earlier_runs(tmp_path):
    runs, cache = tmp_path / "runs", {}
    runs.mkdir()
    first = WritingFake(cache=cache, runs_dir=runs)
    rows1 = Study(config(tmp_path, 38.0), first, tmp_path / "out1", log=lambda m: None).run()
    asked_before = {j["job_id"] for j in first.asked}

    lib = WritingFake(cache=cache, runs_dir=runs)
    rows2 = Study(config(tmp_path, 40.0), lib, tmp_path / "out2", log=lambda m: None, use_library=True).run()
    scratch = FakeRigs()                                    # the same change from an empty cache
    rows3 = Study(config(tmp_path, 40.0), scratch, tmp_path / "out3", log=lambda m: None).run()

    dens1, dens2 = stage(rows1, "density"), stage(rows2, "density")
    assert dens2["runs_from_library"] == dens1["runs_requested"] and dens2["runs_requested"] == 0
    assert dens2["parameters"][0]["estimate"] == dens1["parameters"][0]["estimate"]
    roll1, roll2, roll3 = stage(rows1, "rolling_resistance"), stage(rows2, "rolling_resistance"), \
        stage(rows3, "rolling_resistance")
    assert roll2["runs_from_library"] == roll1["runs_requested"]
    assert lib.simulated_count < scratch.simulated_count
    truth = (40.0 - 20.0) / 40.0                              # fake law: angle = 20 + 40 x rolling resistance
    for r in (roll2, roll3):
        p = r["parameters"][0]
        assert r["met"] and p["low"] <= truth <= p["high"]
    assert not {j["job_id"] for j in lib.asked} & asked_before   # a library run is never asked (counted) again
    summary = json.loads((tmp_path / "out2" / "lib" / "summary.json").read_text())
    assert len(summary["runs"]) == sum(r["runs_requested"] + r["runs_from_library"] for r in rows2)

    again = WritingFake(cache=cache, runs_dir=runs)         # resumed: the journal names the runs it took
    rows4 = Study(config(tmp_path, 40.0), again, tmp_path / "out2", log=lambda m: None, use_library=True).run()
    assert again.simulated_count == 0
    assert [r["parameters"] for r in rows4] == [r["parameters"] for r in rows2]


def test_without_the_flag_a_study_uses_its_own_runs_only(tmp_path):
    runs, cache = tmp_path / "runs", {}
    runs.mkdir()
    Study(config(tmp_path, 38.0), WritingFake(cache=cache, runs_dir=runs), tmp_path / "out1", log=lambda m: None).run()
    again = WritingFake(cache=cache, runs_dir=runs)
    rows = Study(config(tmp_path, 38.0), again, tmp_path / "out2", log=lambda m: None).run()
    assert again.simulated_count == 0 and all(r["runs_from_library"] == 0 for r in rows)
