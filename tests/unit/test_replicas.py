"""Batch jobs (pycal.replicas): planning the batches, the job format, the per-seed
expansion, the executor wrapper and `pycal run --replicas`, with a fake YADE that writes
a batch result.json the way yade_scripts/demlib/replicas.py does."""
import json

import pytest

from conftest import install_fake_yade
from pycal import replicas, runner
from pycal.cli import main
from pycal.errors import ConfigError, RunError
from pycal.jobs import resolve_job
from pycal.rig_contract import seed_job

FAKE_YADE = r"""#!/usr/bin/python3
# fake yade: args -j1 -x -n SCRIPT JOB. A lone job: bulk density 1000 + seed. A batch job:
# one replica per seed (seed $FAKE_FAIL_SEED is refused); $FAKE_CRASH=1 crashes (exit 4).
import json, os, sys
job = json.load(open(sys.argv[5]))
with open(os.environ["FAKE_COUNT"], "a") as f:
    f.write(job["job_id"] + "\n")
if os.environ.get("FAKE_CRASH") == "1":
    print("Traceback ...\nRIG FAILED: KeyError: 'x'")
    sys.exit(4)
prov = {"yade_version": "fake", "git_commit": "c", "wall_time_s": 1.0, "simulated_time_s": 9.0, "steps_count": 99}
common = {"job_id": job["job_id"], "rig": job["rig"], "material": job["material"], "contact_model": "hertz_mindlin",
          "job": job, "provenance": prov}
if "seeds" in job:
    rows = []
    for s in job["seeds"]:
        if str(s) == os.environ.get("FAKE_FAIL_SEED"):
            rows.append({"seed": s, "status": "failed", "failure": "RIG FAILED: pour: no rest after 8 s",
                         "simulated_time_s": 8.0, "steps_count": 800, "output_dir": f"s{s}"})
        else:
            rows.append({"seed": s, "status": "ok", "measurements": {"bulk_density_kg_m3": 1000.0 + s},
                         "simulated_time_s": 0.1 * s, "steps_count": 10 * s, "output_dir": f"s{s}"})
    result = dict(common, seeds=job["seeds"], replicas=rows, replicas_count=len(rows),
                  replicas_failed_count=sum(r["status"] != "ok" for r in rows), replica_spacing_m=1.0)
else:
    result = dict(common, seed=job["seed"], bulk_density_kg_m3=1000.0 + job["seed"], mass_kg=1.0, n_particles=9,
                  solid_fraction=0.4, timestep_s=1e-5)
json.dump(result, open("result.json", "w"))
"""


@pytest.fixture
def fake_yade(tmp_path, monkeypatch):
    count = install_fake_yade(tmp_path, monkeypatch, FAKE_YADE)
    monkeypatch.delenv("FAKE_FAIL_SEED", raising=False)
    monkeypatch.delenv("FAKE_CRASH", raising=False)
    return lambda: count.read_text().split()


def jobs_of(seeds, rig="fill", overrides=None):
    return [resolve_job(rig, "M2", overrides or {}, seed=s) for s in seeds]


# ---------------------------------------------------------------- planning

def test_seeds_are_spread_over_the_workers():
    """8 seeds on 2 workers: 2 batches of 4 (one process per core); on 8 workers: single runs."""
    plan = replicas.plan(jobs_of(range(1, 9)), workers=2)
    assert [idx for _, idx in plan] == [[0, 1, 2, 3], [4, 5, 6, 7]]
    assert [j["seeds"] for j, _ in plan] == [[1, 2, 3, 4], [5, 6, 7, 8]]
    assert all("seed" not in j for j, _ in plan)
    assert [len(idx) for _, idx in replicas.plan(jobs_of(range(1, 9)), workers=8)] == [1] * 8


def test_a_batch_of_one_is_the_single_job():
    """3 seeds on 2 workers: a batch of 2 and the third seed as its own single job (the same
    job, and the same cache entry, as without replicas)."""
    jobs = jobs_of([1, 2, 3])
    plan = replicas.plan(jobs, workers=2)
    assert [idx for _, idx in plan] == [[0, 1], [2]]
    assert plan[1][0] is jobs[2]


def test_replicas_one_turns_batches_off_and_n_caps_the_batch():
    assert all(len(idx) == 1 for _, idx in replicas.plan(jobs_of(range(1, 5)), workers=1, replicas=1))
    assert [len(idx) for _, idx in replicas.plan(jobs_of(range(1, 6)), workers=1, replicas=2)] == [2, 2, 1]
    with pytest.raises(ConfigError, match="whole number >= 1"):
        replicas.plan(jobs_of([1, 2]), workers=1, replicas=0)


def test_rigs_without_replicas_and_different_points_stay_apart():
    """The tilt-table rigs run one seed per job; jobs that differ in more than the seed
    (another override) are different points and never share a batch."""
    wall = jobs_of([1, 2, 3], rig="wall_friction")
    assert all(len(idx) == 1 for _, idx in replicas.plan(wall, workers=1))
    mixed = jobs_of([1, 2]) + jobs_of([1, 2], overrides={"particles.density_kg_m3": 3000})
    plan = replicas.plan(mixed, workers=1)
    assert [idx for _, idx in plan] == [[0, 1], [2, 3]]
    assert plan[0][0]["job_id"] != plan[1][0]["job_id"]


def test_batch_job_format_and_its_replicas_jobs():
    """A batch job = the single-seed job with `seeds` (and the layout) instead of `seed`; its
    content hash names it; a replica's job is the single job of its seed, named after the batch."""
    lone = jobs_of([1, 2, 3])
    batch = replicas.batch_job(lone[0], [1, 2, 3])
    assert batch["seeds"] == [1, 2, 3] and batch["replica_layout"] == "sequential" and "seed" not in batch
    assert batch["job_id"].startswith("fill-M2-s1x3-")
    assert replicas.batch_job(lone[0], [1, 2])["job_id"] != batch["job_id"]
    assert replicas.batch_job(lone[0], [1, 2, 3], "side_by_side")["job_id"] != batch["job_id"]
    for job in lone:
        rj = seed_job(batch, job["seed"])
        assert rj["job_id"] == f"{batch['job_id']}-s{job['seed']}"
        assert {k: v for k, v in rj.items() if k != "job_id"} == {k: v for k, v in job.items() if k != "job_id"}
    with pytest.raises(ConfigError, match="does not run replicas"):
        replicas.batch_job(jobs_of([1], rig="internal_friction")[0], [1, 2])
    with pytest.raises(ConfigError, match="different seeds"):
        replicas.batch_job(lone[0], [1, 1])
    with pytest.raises(ConfigError, match="replica-layout"):
        replicas.batch_job(lone[0], [1, 2], "diagonal")


# ---------------------------------------------------------------- expansion

def batch_result(seeds, failed=()):
    batch = replicas.batch_job(jobs_of([seeds[0]])[0], seeds)
    rows = [{"seed": s, "status": "failed", "failure": "RIG FAILED: blow-up: x", "simulated_time_s": 1.0,
             "steps_count": 5, "output_dir": f"s{s}"} if s in failed else
            {"seed": s, "status": "ok", "measurements": {"bulk_density_kg_m3": 1000.0 + s, "n_particles": 80},
             "simulated_time_s": 0.5, "steps_count": 7, "output_dir": f"s{s}"} for s in seeds]
    return {"job_id": batch["job_id"], "rig": "fill", "material": "M2", "seeds": seeds, "job": batch,
            "contact_model": "hertz_mindlin", "provenance": {"git_commit": "c", "wall_time_s": 3.0},
            "replicas": rows, "replicas_count": len(rows), "replicas_failed_count": len(failed)}


def test_expand_gives_single_seed_results():
    """Per seed: the measurements plus seed, job (the replica's), contact_model and provenance
    (the replica's own simulated time and steps, its batch): what post-processing reads."""
    out = replicas.expand(batch_result([4, 5]))
    assert [s for s, _, _ in out] == [4, 5]
    seed, res, msg = out[1]
    assert msg is None
    assert res["seed"] == 5 and res["bulk_density_kg_m3"] == 1005.0 and res["n_particles"] == 80
    assert res["job"]["seed"] == 5 and "seeds" not in res["job"] and res["job_id"] == res["job"]["job_id"]
    assert res["rig"] == "fill" and res["material"] == "M2" and res["contact_model"] == "hertz_mindlin"
    prov = res["provenance"]
    assert prov["git_commit"] == "c" and prov["steps_count"] == 7 and prov["simulated_time_s"] == 0.5
    assert prov["batch_job_id"] == res["job_id"][:-3] and prov["batch_seeds"] == [4, 5] and prov["replica_dir"] == "s5"
    from pycal import post
    assert post.seed_statistics([r for _, r, _ in out])["bulk_density_kg_m3"][0] == 1004.5


def test_expand_keeps_a_failed_seeds_message():
    out = replicas.expand(batch_result([1, 2, 3], failed={2}))
    assert [r is None for _, r, _ in out] == [False, True, False]
    assert "RIG FAILED: blow-up: x" in out[1][2] and "-s2" in out[1][2]


# ---------------------------------------------------------------- the executor and the CLI

def test_executor_runs_batches_once_and_counts_seeds(tmp_path, fake_yade):
    inner = runner.LocalPool(tmp_path / "runs", workers=1, progress=False)
    ex = replicas.ReplicaExecutor(inner)
    jobs = jobs_of([1, 2, 3])
    res = ex.run(jobs)
    assert [r["bulk_density_kg_m3"] for r in res] == [1001.0, 1002.0, 1003.0]
    assert [r["seed"] for r in res] == [1, 2, 3]
    assert len(fake_yade()) == 1 and fake_yade()[0].startswith("fill-M2-s1x3-")
    assert ex.simulated_count == 3
    assert ex.run(jobs) == res and len(fake_yade()) == 1 and ex.simulated_count == 3      # cached


def test_a_failed_replica_does_not_lose_its_batch_mates(tmp_path, fake_yade, monkeypatch):
    monkeypatch.setenv("FAKE_FAIL_SEED", "2")
    ex = replicas.ReplicaExecutor(runner.LocalPool(tmp_path / "runs", workers=1, progress=False))
    res = ex.run(jobs_of([1, 2, 3]), raise_on_error=False)
    assert [r and r["seed"] for r in res] == [1, None, 3]
    assert len(ex.last_errors) == 1 and "no rest after 8 s" in ex.last_errors[0]
    with pytest.raises(RunError, match="1 of 3 seed run"):
        ex.run(jobs_of([1, 2, 3]))
    assert len(fake_yade()) == 1        # the batch is complete: kept, not run again


def test_a_crashed_batch_fails_every_seed_and_runs_again(tmp_path, fake_yade, monkeypatch):
    monkeypatch.setenv("FAKE_CRASH", "1")
    ex = replicas.ReplicaExecutor(runner.LocalPool(tmp_path / "runs", workers=1, progress=False))
    assert ex.run(jobs_of([1, 2]), raise_on_error=False) == [None, None]
    assert len(ex.last_errors) == 2 and all("KeyError" in e for e in ex.last_errors)
    monkeypatch.setenv("FAKE_CRASH", "0")
    assert [r["seed"] for r in ex.run(jobs_of([1, 2]))] == [1, 2] and len(fake_yade()) == 2


def test_run_seeds_for_the_study(tmp_path, fake_yade):
    inner = runner.LocalPool(tmp_path / "runs", workers=2, progress=False)
    results, errors = replicas.run_seeds(inner, "fill", "M2", {}, [7, 8, 9, 10])
    assert [r["seed"] for r in results] == [7, 8, 9, 10] and errors == []
    assert sorted(len(x.split("x")) for x in fake_yade()) == [2, 2]      # 2 batches of 2


def test_cli_run_uses_replicas_and_prints_each_seed(tmp_path, fake_yade, capsys):
    runs = tmp_path / "runs"
    rc = main(["run", "fill", "--material", "M2", "--seeds", "3", "--workers", "1", "--out", str(runs)])
    out = capsys.readouterr().out
    assert rc == 0 and len(fake_yade()) == 1 and "over 3 seeds" in out
    batch = fake_yade()[0]
    for s in (1, 2, 3):
        assert f"{batch}-s{s}: {runs}/fill/{batch}/s{s}" in out
    rc = main(["run", "fill", "--material", "M2", "--seeds", "3", "--replicas", "1", "--workers", "1",
               "--out", str(runs)])
    assert rc == 0 and len(fake_yade()) == 4      # three single jobs: not the batch's cache entries


def test_cli_reports_a_failed_seed_exit_3(tmp_path, fake_yade, monkeypatch, capsys):
    monkeypatch.setenv("FAKE_FAIL_SEED", "2")
    rc = main(["run", "fill", "--material", "M2", "--seeds", "3", "--workers", "1", "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert rc == 3 and "no rest after 8 s" in err and "-s2" in err


def test_another_worker_count_reuses_the_seeds_already_run(tmp_path, fake_yade):
    """A study resumed with another --workers makes other batches; a seed that ran alone
    or in a sequential batch is taken from there, not simulated again (its numbers are the
    same bit for bit)."""
    jobs = jobs_of([1, 2, 3])
    lone = replicas.ReplicaExecutor(runner.LocalPool(tmp_path / "runs", workers=3, progress=False))
    first = lone.run(jobs)                                   # 3 workers: 3 lone jobs
    assert len(fake_yade()) == 3
    two = replicas.ReplicaExecutor(runner.LocalPool(tmp_path / "runs", workers=2, progress=False))
    assert two.run(jobs) == first and len(fake_yade()) == 3 and two.simulated_count == 0
    # the other way: one batch of 3 (1 worker), then lone jobs (3 workers) and a new seed
    jobs = jobs_of([11, 12, 13])
    one = replicas.ReplicaExecutor(runner.LocalPool(tmp_path / "runs", workers=1, progress=False))
    batch = one.run(jobs)
    assert len(fake_yade()) == 4 and fake_yade()[-1].startswith("fill-M2-s11x3-")
    three = replicas.ReplicaExecutor(runner.LocalPool(tmp_path / "runs", workers=3, progress=False))
    again = three.run(jobs_of([11, 12, 13, 14]))
    assert again[:3] == batch and again[3]["bulk_density_kg_m3"] == 1014.0
    assert len(fake_yade()) == 5 and three.simulated_count == 1


def test_side_by_side_batches_are_not_reused_for_other_batches(tmp_path, fake_yade):
    """Side by side, a replica's numbers depend on its batch-mates: no reuse."""
    jobs = jobs_of([1, 2])
    replicas.ReplicaExecutor(runner.LocalPool(tmp_path / "runs", workers=1, progress=False),
                             layout="side_by_side").run(jobs)
    two = replicas.ReplicaExecutor(runner.LocalPool(tmp_path / "runs", workers=2, progress=False),
                                   layout="side_by_side")
    two.run(jobs)
    assert len(fake_yade()) == 3
