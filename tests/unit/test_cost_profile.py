"""bench/cost_profile.py: CPU per section, rig and phase from a study's jobs.csv and the
job folders' provenance (a batch's cost shared by its seeds, a job asked twice once)."""
import json

from bench_scripts import load_bench_script

cost = load_bench_script("cost_profile")


def write_result(runs, rig, folder, cpu, phases=None, replicas=None, seed=1):
    """A result.json as a rig writes it (a batch's: one entry per replica)."""
    d = runs / rig / folder
    d.mkdir(parents=True)
    job = {"job_id": folder, "rig": rig, "material": "M2", "overrides": {}}
    job.update({"seeds": replicas} if replicas else {"seed": seed})
    r = {"job_id": folder, "rig": rig, "material": "M2", "job": job, "contact_model": "hertz_mindlin",
         "provenance": {"cpu_time_s": cpu, "wall_time_s": cpu * 2, "steps_count": 1000,
                        "simulated_time_s": 1.0, "phase_cpu": phases}}
    if replicas:
        r["replicas"] = [{"seed": s, "status": "ok", "measurements": {}, "simulated_time_s": 1.0, "steps_count": 500}
                         for s in replicas]
    else:
        r["seed"] = seed
    (d / "result.json").write_text(json.dumps(r))


def test_profile_adds_up_sections_rigs_and_phases(tmp_path):
    runs, study = tmp_path / "runs", tmp_path / "runs" / "study" / "s"
    study.mkdir(parents=True)
    (study / "jobs.csv").write_text(
        "section,material,rig,seed,job_id,status,batch_job_id\n"
        "M2/density,M2,fill,1,fill-a-s1,ok,fill-a-s1x2\n"
        "M2/density,M2,fill,2,fill-a-s2,ok,fill-a-s1x2\n"
        "M2/wall_friction,M2,wall_friction,1,wf-1,ok,\n"
        "M2/wall_friction,M2,wall_friction,1,wf-1,ok,\n"        # asked again: cached, counted once
        "M2/wall_friction,M2,wall_friction,2,wf-2,failed,\n")
    write_result(runs, "fill", "fill-a-s1x2", 10.0, replicas=[1, 2])
    write_result(runs, "wall_friction", "wf-1", 100.0,
                 {"tilt_static": {"cpu_s": 60.0, "step_cpu_s": 57.0, "steps_count": 200000},
                  "consolidate": {"cpu_s": 30.0, "step_cpu_s": 29.0, "steps_count": 100000},
                  "outside_phases": {"cpu_s": 10.0, "step_cpu_s": 0.0, "steps_count": 0}})
    rows = cost.load(study, runs)
    assert len(rows) == 4 and [share for _, _, share in rows][:2] == [0.5, 0.5]
    text = cost.profile(rows)
    assert "Total CPU 110 s" in text
    assert "| M2/density | 2 | 0 | 10 | 9.1% | 5.0 | - |" in text
    assert "| M2/wall_friction | 2 | 1 | 100 | 90.9% | 100.0 |" in text
    assert "| tilt_static | 60 | 60.0% | 95% | 0.20 | 285 |" in text
