"""Replicas: several seeds of one rig point in one YADE run (a batch job), and their results
per seed.

A batch job is a job with `seeds` (a list) instead of `seed`; the rig builds one copy of
itself per seed side by side in one scene (yade_scripts/demlib/replicas.py) and writes one
result.json for the batch, with a `replicas` list: per seed its measurements or its failure.
A replica's numbers depend on its batch-mates in the last bits (and chaos makes that a
different sample of the same distribution), so the batch is the cached unit: one job
folder per batch, named by its content hash (seeds included); the same batch gives the
same numbers bit for bit.

What pays: a YADE process costs ~1-2 s of CPU before and after its time steps (start-up,
imports, outputs), shared by the replicas of a batch; the time steps themselves cost the
same per seed in a batch as alone (bench/README.md). REPLICA_RIGS lists the rigs whose
script runs replicas and the largest batch.

    jobs -> results:   ReplicaExecutor(executor).run(jobs)      (drop-in for an executor)
    seeds -> results:  run_seeds(executor, rig, material, overrides, seeds)
    batch result -> per-seed results:  expand(batch_result)
"""
import copy
import math

from . import rigs
from .errors import ConfigError, RunError
from .jobs import canonical_json, content_digest, resolve_job
from .rig_contract import BATCH_SEEDS_KEY, LAYOUT_KEY, replica_dir_name, seed_job

LAYOUTS = ("side_by_side", "sequential")

# rig -> largest batch (replicas per YADE run; replicas_max of its descriptor). Not listed: the tilt-table friction rigs
# (gravity is rotated for the whole scene: replicas would share one tilt, and a seed's
# hold at its own onset angle could not happen; their process cost is < 1 % of a curve)
# aor_mixed (its time step comes from the lumps drawn: replicas would share the
# smallest of the batch) and transfer (a periodic cell: no room for a copy beside it).
REPLICA_RIGS = {name: rigs.get(name).replicas_max for name in rigs.names() if rigs.get(name).replicas_max}


def is_batch(job):
    return BATCH_SEEDS_KEY in job


def batch_job(job, seeds, layout="sequential"):
    """The batch job of a resolved single-seed job (pycal.jobs.resolve_job) for `seeds`:
    the same job with `seeds` instead of `seed` and the replica layout (side_by_side: one
    scene; sequential: one scene after the other in the same process), named
    '<rig>-<material>-s<first>x<count>-<hash>'."""
    if layout not in LAYOUTS:
        raise ConfigError("--replica-layout", str(layout), f"must be one of {', '.join(LAYOUTS)}")
    if job["rig"] not in REPLICA_RIGS:
        raise ConfigError("--replicas", job["rig"], f"rig {job['rig']} does not run replicas "
                          f"(rigs that do: {', '.join(sorted(REPLICA_RIGS))})")
    seeds = [int(s) for s in seeds]
    if not 1 <= len(seeds) <= REPLICA_RIGS[job["rig"]] or len(set(seeds)) != len(seeds):
        raise ConfigError("--replicas", str(len(seeds)), f"a batch of {job['rig']} holds 1 to "
                          f"{REPLICA_RIGS[job['rig']]} different seeds, not {seeds}")
    batch = {k: copy.deepcopy(v) for k, v in job.items() if k not in ("seed", "job_id")}
    batch[BATCH_SEEDS_KEY] = seeds
    batch[LAYOUT_KEY] = layout
    batch["job_id"] = f"{job['rig']}-{job['material']}-s{seeds[0]}x{len(seeds)}-{content_digest(batch)}"
    return batch


def resolve_batch(rig, material, overrides, seeds, layout="sequential", config_dir=None):
    """Batch job of `seeds` for a rig point (rig, material, overrides as resolve_job)."""
    kw = {} if config_dir is None else {"config_dir": config_dir}
    return batch_job(resolve_job(rig, material, overrides, seed=seeds[0], **kw), seeds, layout)


def batch_size(rig, seeds_count, workers, replicas=None):
    """Replicas per batch. `replicas` given (--replicas N): N, at most the rig's largest
    batch; 1 turns replicas off. Default: spread the seeds over the workers, as many per
    batch as there are seeds per worker (every core busy, one process per core), at
    most the rig's largest batch; 1 for a rig without replicas."""
    largest = REPLICA_RIGS.get(rig, 1)
    if replicas is not None:
        if isinstance(replicas, bool) or not isinstance(replicas, int) or replicas < 1:
            raise ConfigError("--replicas", str(replicas), "must be a whole number >= 1")
        return min(replicas, largest)
    return max(1, min(largest, math.ceil(seeds_count / max(1, workers or 1))))


def split(seeds, size):
    """Consecutive batches of at most `size` seeds, in the given order."""
    return [list(seeds[i:i + size]) for i in range(0, len(seeds), size)]


def expand(batch_result):
    """Per-seed results of a batch result.json: [(seed, result or None, failure message or
    None)] in the batch's order. A result is shaped like a lone run's result.json:
    the replica's measurements, job_id ('<batch job_id>-s<seed>'), rig, material, seed,
    contact_model, job (the replica's job: the batch job with its seed) and provenance (the
    batch's, with the replica's own simulated_time_s and steps_count, batch_job_id,
    batch_seeds and replica_dir: the folder of its files inside the batch's)."""
    batch = batch_result["job"]
    prov = batch_result["provenance"]
    out = []
    for row in batch_result["replicas"]:
        seed = row["seed"]
        job = seed_job(batch, seed)
        if row["status"] != "ok":
            out.append((seed, None, f"{job['job_id']}: no result ({row['failure']}; replica of batch "
                                    f"{batch['job_id']})"))
            continue
        res = dict(row["measurements"])
        res.update({"job_id": job["job_id"], "rig": batch["rig"], "material": batch["material"], "seed": seed,
                    "contact_model": batch_result["contact_model"], "job": job,
                    "provenance": dict(prov, simulated_time_s=row["simulated_time_s"],
                                       steps_count=row["steps_count"], batch_job_id=batch["job_id"],
                                       batch_seeds=list(batch[BATCH_SEEDS_KEY]),
                                       replica_dir=replica_dir_name(seed))})
        out.append((seed, res, None))
    return out


DEFAULT_LAYOUT = "sequential"      # measured cheaper than side_by_side on every rig (bench/README.md)


def result_folder(result, job, runs_dir):
    """Folder of the files of the result of single-seed `job`: its job folder, or the
    replica's folder inside its batch's."""
    prov = result.get("provenance", {})
    if "batch_job_id" in prov:
        return f"{runs_dir}/{job['rig']}/{prov['batch_job_id']}/{prov['replica_dir']}"
    return f"{runs_dir}/{job['rig']}/{job['job_id']}"


def _point_key(job):
    return canonical_json({k: v for k, v in job.items() if k not in ("seed", "job_id")})


def plan(jobs, workers=1, replicas=None, layout=DEFAULT_LAYOUT):
    """The jobs to run for single-seed `jobs`: [(batch or lone job, [indices into jobs])].
    Jobs of one rig point (equal but for the seed) of a rig in REPLICA_RIGS are split, in
    the order given, into batches of batch_size(rig, their count, workers, replicas); a
    batch of one seed, and every other job, stays a single job."""
    groups, order = {}, []
    for i, job in enumerate(jobs):
        key = _point_key(job) if job["rig"] in REPLICA_RIGS and not is_batch(job) else f"lone-{i}"
        if key not in groups:
            groups[key] = []
            order.append(key)
        groups[key].append(i)
    out = []
    for key in order:
        idx = groups[key]
        size = 1 if key.startswith("lone-") else batch_size(jobs[idx[0]]["rig"], len(idx), workers, replicas)
        if size == 1:
            out += [(jobs[i], [i]) for i in idx]
            continue
        for part in split(idx, size):
            if len(part) == 1:         # a batch of one is a single job (and its cache entry)
                out.append((jobs[part[0]], part))
            else:
                out.append((batch_job(jobs[part[0]], [jobs[i]["seed"] for i in part], layout), part))
    return out


def candidate_batches(seed, asked, largest):
    """Seed lists of the batches `seed` may have run in: runs of consecutive seeds and
    contiguous parts of `asked` (the seeds asked for its point, in order), 2 to `largest`
    long, that hold it."""
    out = []
    for n in range(2, largest + 1):
        out += [list(range(start, start + n)) for start in range(seed - n + 1, seed + 1)]
        out += [asked[k:k + n] for k in range(len(asked) - n + 1) if seed in asked[k:k + n]]
    unique = []
    for c in out:
        if c not in unique:
            unique.append(c)
    return unique


def cached_seed_results(jobs, runs_dir):
    """({index into jobs: per-seed result}, {index: failure message}) for the single-seed
    jobs of rigs with replicas whose seed already ran alone or in a sequential batch
    (candidate_batches) in runs_dir. A sequential replica's numbers equal its lone run's bit
    for bit, so either stands for the seed, whatever batches the current worker count would
    make; a seed its batch refused is refused again (kept, as a lone job's failure is)."""
    from .executors.jobdirs import cached_result
    asked = {}
    for job in jobs:
        if job["rig"] in REPLICA_RIGS and not is_batch(job):
            asked.setdefault(_point_key(job), []).append(job["seed"])
    out, refused = {}, {}
    for i, job in enumerate(jobs):
        if job["rig"] not in REPLICA_RIGS or is_batch(job):
            continue
        lone = cached_result(job, runs_dir)
        if lone is not None:
            out[i] = lone
            continue
        for seeds in candidate_batches(job["seed"], asked[_point_key(job)], REPLICA_RIGS[job["rig"]]):
            res = cached_result(batch_job(job, seeds, "sequential"), runs_dir)
            row = res and next((x for x in expand(res) if x[0] == job["seed"]), None)
            if row:
                if row[1] is not None:
                    out[i] = row[1]
                else:
                    refused[i] = row[2]
                break
    return out, refused


class ReplicaExecutor:
    """An executor (pycal.runner interface: run(jobs, raise_on_error) -> results in the
    order of jobs) that runs single-seed jobs of rigs with replicas as batch jobs on an
    inner executor and hands back per-seed results (expand). Jobs of one rig point
    (equal but for the seed) are split into batches in the order given (batch_size);
    other jobs pass through. simulated_count counts seeds (replicas) simulated;
    last_errors has one message per failed seed."""

    def __init__(self, inner, replicas=None, layout=DEFAULT_LAYOUT):
        if layout not in LAYOUTS:
            raise ConfigError("--replica-layout", str(layout), f"must be one of {', '.join(LAYOUTS)}")
        self.inner = inner
        self.replicas = replicas
        self.layout = layout
        self.simulated_count = 0
        self.last_errors = []

    def __getattr__(self, name):           # runs_dir, workers, timeout_s ... of the inner executor
        if name == "inner":                # (not set yet: no recursion while unpickling)
            raise AttributeError(name)
        return getattr(self.inner, name)

    def close(self):
        """Close the inner executor (a Dask cluster it started)."""
        close = getattr(self.inner, "close", None)
        if close:
            close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def plan(self, jobs):
        """plan() with the inner executor's workers."""
        return plan(jobs, getattr(self.inner, "workers", 1), self.replicas, self.layout)

    def run(self, jobs, raise_on_error=True):
        """Results of single-seed `jobs` (executor interface). In the sequential layout a seed
        that already ran, alone or in any batch, is taken from there (cached_seed_results):
        the batches of another worker count are not simulated again."""
        found, refused = {}, {}
        if self.layout == "sequential" and self.replicas is None and hasattr(self.inner, "runs_dir"):
            found, refused = cached_seed_results(jobs, self.inner.runs_dir)
        if not found and not refused:
            return self._run(jobs, raise_on_error)
        rest = [i for i in range(len(jobs)) if i not in found and i not in refused]
        results = [found.get(i) for i in range(len(jobs))]
        errors = list(refused.values())
        self.last_errors = []
        if rest:
            for i, r in zip(rest, self._run([jobs[i] for i in rest], raise_on_error=False)):
                results[i] = r
        self.last_errors = errors + self.last_errors
        if self.last_errors and raise_on_error:
            raise RunError(f"{len(self.last_errors)} of {len(jobs)} seed run(s) failed; first: {self.last_errors[0]}")
        return results

    def _run(self, jobs, raise_on_error=True):
        from .runner import cached_failure, cached_result
        # an executor without a runs folder (a stand-in) cannot read batch results: no batches
        plan = self.plan(jobs) if hasattr(self.inner, "runs_dir") else [(j, [i]) for i, j in enumerate(jobs)]
        if not any(is_batch(j) for j, _ in plan):      # nothing to batch: the inner executor as it is
            before = getattr(self.inner, "simulated_count", 0)
            try:
                return self.inner.run(jobs, raise_on_error=raise_on_error)
            finally:
                self.simulated_count += getattr(self.inner, "simulated_count", 0) - before
                self.last_errors = list(getattr(self.inner, "last_errors", []))
        runs_dir = self.inner.runs_dir
        to_simulate = sum(len(idx) for job, idx in plan
                          if cached_result(job, runs_dir) is None and cached_failure(job, runs_dir) is None)
        outs = self.inner.run([j for j, _ in plan], raise_on_error=False)
        inner_errors = list(getattr(self.inner, "last_errors", []))

        def inner_error(job):
            return next((e for e in inner_errors if job["job_id"] in e), f"{job['job_id']}: no result")

        results, errors = [None] * len(jobs), []
        for (job, idx), out in zip(plan, outs):
            if not is_batch(job):
                if out is None:
                    errors.append(inner_error(job))
                results[idx[0]] = out
            elif out is None:          # the whole batch failed (a crash, a timeout): every seed of it
                errors += [f"seed {jobs[i]['seed']}: {inner_error(job)}" for i in idx]
            else:
                for (seed, res, msg), i in zip(expand(out), idx):
                    results[i] = res
                    if msg:
                        errors.append(msg)
        self.simulated_count += to_simulate
        self.last_errors = errors
        if errors and raise_on_error:
            raise RunError(f"{len(errors)} of {len(jobs)} seed run(s) failed; first: {errors[0]}")
        return results


def run_seeds(executor, rig, material, overrides, seeds, replicas=None, layout=DEFAULT_LAYOUT, config_dir=None):
    """The seeds of one rig point through batch jobs: (results, errors) with results[i] the
    per-seed result of seeds[i] (shaped like a lone result.json) or None, and one error
    message per failed seed. `replicas`: batch size (None: batch_size's default)."""
    kw = {} if config_dir is None else {"config_dir": config_dir}
    jobs = [resolve_job(rig, material, overrides, seed=s, **kw) for s in seeds]
    ex = ReplicaExecutor(executor, replicas, layout)
    results = ex.run(jobs, raise_on_error=False)
    return results, list(ex.last_errors)
