"""bench/rerun_with.py rebuilds a recorded job exactly before it changes one setting."""
import json

import pytest

from bench_scripts import load_bench_script
from pycal.jobs import resolve_job

rw = load_bench_script("rerun_with")


def test_a_recorded_job_is_rebuilt_exactly_and_then_changed(tmp_path):
    job = resolve_job("fill", "M2", {"particles.density_kg_m3": 3000.0}, seed=4)
    (tmp_path / "job.json").write_text(json.dumps(job))
    same, changed = rw.rebuilt(tmp_path / "job.json", {"rig.procedure.pour_porosity_ratio": 0.6})
    assert same["job_id"] == job["job_id"] and changed["job_id"] != job["job_id"]
    assert changed["rig_config"]["procedure"]["pour_porosity_ratio"] == 0.6 and changed["seed"] == 4
    job["job_id"] = "fill-M2-s4-000000000000"           # a job the configs no longer make
    (tmp_path / "job.json").write_text(json.dumps(job))
    with pytest.raises(SystemExit, match="not the same job"):
        rw.rebuilt(tmp_path / "job.json", {})
