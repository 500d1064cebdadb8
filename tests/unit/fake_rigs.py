"""A fake executor for the calibration tests: known response laws, seed noise, and a job
cache like pycal.runner's (a job asked again is not simulated again)."""
import base64
import random
from pathlib import Path

from pycal.errors import RunError

YADE_VERSION = "2023.02a-fake"


def aor_law(job):
    """AoR (deg) = 20 + 40 x rolling resistance + 8 x cohesion force fraction (wet fines)."""
    name = job["material"]
    mat = job["materials"][name]
    eta = mat["interactions"][name]["rolling_resistance_coefficient"]
    coh = mat["interactions"][name]["cohesion"]
    f = coh.get("force_fraction", 0.0) if name == "M3-wet" else 0.0
    return 20 + 40 * eta + 8 * f


def bulk_law(job):
    """Bulk density (kg/m3) = 0.35 x particle density x (1 - 0.1 x rolling resistance)."""
    mat = job["materials"][job["material"]]
    eta = mat["interactions"][job["material"]]["rolling_resistance_coefficient"]
    return 0.35 * mat["particles"]["density_kg_m3"] * (1 - 0.1 * eta)


# The head of a study config that calibrates the dry fines' rolling resistance on the fake
# AoR law (above), for the tests of what runs after the calibration (validation, application):
# a test puts its name before it and its own section after it.
ROLLING_STUDY_HEAD = """seeds_count: 3
max_runs_count: 300
materials:
  M3-dry:
    - stage: rolling_resistance
      rig: aor
      response: aor_mean_deg
      target: {sample: fines_dry, test: angle_of_repose, band_deg: 1.0}
      parameter:
        keys: [interactions.M3-dry.rolling_resistance_coefficient,
               interactions.steel.rolling_resistance_coefficient,
               interactions.pvc.rolling_resistance_coefficient]
        start: 0.35
        bounds: [0.05, 1.5]
        response_increases: true
        tolerance_coefficient: 0.02
      max_runs_count: 30
"""


PNG_1PX = base64.b64decode("iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQAAAABJRU5ErkJggg==")


class FakeRigs:
    """run(jobs, raise_on_error) -> results like runner.LocalPool, with .simulated_count and
    .last_errors. results: {rig: function(job) -> dict of measurements}; noise: {key: sd}
    (relative when the key is in relative); seed_offsets: {key: relative sd} of an offset
    that belongs to the seed and repeats at every point (a pour that holds more spheres
    whatever the density); refuse(job) -> message or None."""

    def __init__(self, results=None, noise=None, relative=("bulk_density_kg_m3",), refuse=None, cache=None,
                 seed_offsets=None, runs_dir=None):
        self.results = {"fill": lambda j: {"bulk_density_kg_m3": bulk_law(j)},
                        "aor": lambda j: {"aor_mean_deg": aor_law(j)}, **(results or {})}
        self.noise = {"bulk_density_kg_m3": 0.005, "aor_mean_deg": 0.5, **(noise or {})}
        self.relative = relative
        self.seed_offsets = seed_offsets or {}
        self.refuse = refuse or (lambda job: None)
        self.cache = {} if cache is None else cache
        self.simulated_count, self.last_errors, self.asked = 0, [], []
        if runs_dir is not None:     # each run writes its rig's pictures (a 1-pixel PNG) into its job folder
            self.runs_dir = runs_dir     # (no attribute otherwise: replicas take a stand-in without one as such)

    def run(self, jobs, raise_on_error=True):
        out, self.last_errors = [], []
        for job in jobs:
            self.asked.append(job)
            if job["job_id"] in self.cache:
                out.append(self.cache[job["job_id"]])
                continue
            self.simulated_count += 1
            why = self.refuse(job)
            if why:
                self.last_errors.append(f"{job['job_id']}: no result (RIG FAILED: {why})")
                out.append(None)
                continue
            rng = random.Random(job["job_id"])           # the same job gives the same fill
            r = self.results[job["rig"]](job)
            for k, sd in self.noise.items():
                if isinstance(r.get(k), float):
                    r[k] = r[k] * (1 + sd * rng.gauss(0, 1)) if k in self.relative else r[k] + sd * rng.gauss(0, 1)
            for k, sd in self.seed_offsets.items():
                if isinstance(r.get(k), float):
                    r[k] *= 1 + sd * random.Random(f"seed {job['seed']}").gauss(0, 1)
            r.update({"rig": job["rig"], "material": job["material"], "seed": job["seed"], "job": job,
                      "job_id": job["job_id"], "provenance": {"yade_version": YADE_VERSION}})
            self.cache[job["job_id"]] = r
            if getattr(self, "runs_dir", None) is not None:
                from pycal import rigs
                folder = Path(self.runs_dir) / job["rig"] / job["job_id"]
                folder.mkdir(parents=True, exist_ok=True)
                for name in rigs.get(job["rig"]).pictures:
                    (folder / name).write_bytes(PNG_1PX)
            out.append(r)
        if self.last_errors and raise_on_error:
            raise RunError(self.last_errors[0])
        return out


def stiffness_result(ratio_law):
    """A ccs_expansion stand-in whose unloading_stiffness_log_ratio response is ratio_law(E)
    (read through the fallback: a scalar result key with a unit suffix)."""
    def f(job):
        e = job["materials"][job["material"]]["contact"]["youngs_modulus_pa"]
        return {"stiffness_log_ratio": float(ratio_law(e))}
    return f


def wall_result(mu_law, stresses=(12000, 40000, 86000), noise_sd=0.01):
    """A wall_friction stand-in: mu_static = mu_law(steel interaction dict, stress) + seed
    noise at every step."""
    def f(job):
        steel = job["materials"][job["material"]]["interactions"]["steel"]
        rng = random.Random(job["job_id"] + "wall")
        mu = [float(mu_law(steel, s)) + noise_sd * rng.gauss(0, 1) for s in stresses]
        return {"stress_pa": list(stresses), "mu_static": mu, "mu_dynamic": mu, "sticks": [False] * len(stresses)}
    return f



def holds(p, truth):
    """The truth inside a parameter's 95 % interval, give or take a quarter of its half
    width. One draw misses 1 time in 20, and the GP/MCMC arithmetic is not bit-identical
    between processes, so a single-draw test allows that much; the coverage itself is
    tested over many draws in test_stats_*."""
    slack = 0.25 * 0.5 * (p["high"] - p["low"])
    return p["low"] - slack <= truth <= p["high"] + slack
