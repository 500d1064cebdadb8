"""Density calibration update rule with a fake executor (no YADE)."""
import csv
import random

import pytest
import yaml

from pycal.calibration import density
from pycal.calibration.density import fit_density, lab_bulk_density, update_density
from pycal.configs import load_material


class FakeFill:
    """Stands in for LocalPool: bulk density = solid_fraction x particle density x (1 + noise)."""

    def __init__(self, solid_fraction=0.365, noise=0.01, density_effect=0.0):
        self.sf = solid_fraction
        self.noise = noise
        self.density_effect = density_effect   # packing change per kg/m3 (heavier -> denser)
        self.calls = []

    def run(self, jobs, raise_on_error=True):
        self.calls.append(jobs)
        out = []
        for job in jobs:
            mat = job["materials"][job["material"]]
            rho = mat["particles"]["density_kg_m3"]
            rnd = random.Random(job["seed"])          # common random numbers per seed, like real fills
            sf = self.sf * (1 + self.density_effect * (rho - 2750)) * (1 + self.noise * rnd.gauss(0, 1))
            out.append({"bulk_density_kg_m3": sf * rho, "solid_fraction": sf, "n_particles": 70,
                        "job_id": job["job_id"]})
        return out


def test_update_rule_is_proportional():
    assert update_density(2750, 1004.0, 1603.0) == pytest.approx(2750 * 1603 / 1004, abs=0.05)


def test_lab_bulk_density_of_the_three_samples():
    assert lab_bulk_density(load_material("M2")) == 1603
    assert lab_bulk_density(load_material("M3-dry")) == 1601
    assert lab_bulk_density(load_material("M3-wet")) == 1146


def test_fallback_when_labdata_is_unusable(monkeypatch):
    import sys, types
    monkeypatch.setitem(sys.modules, "pycal.labdata", types.ModuleType("pycal.labdata"))  # no sample()
    assert lab_bulk_density({"lab_sample": "fines_wet"}) == 1146


@pytest.mark.parametrize("density_effect", [0.0, 2e-5])
def test_converges_within_tolerance_in_three_iterations(tmp_path, density_effect):
    fake = FakeFill(noise=0.02, density_effect=density_effect)
    fit = fit_density("M2", seeds=3, tolerance_percent=1.0, max_iterations=5, executor=fake,
                      out_dir=tmp_path, progress=None)
    assert fit.tolerance_met
    assert fit.iterations <= 3
    assert abs(fit.bulk_density_mean_kg_m3 - 1603) <= 0.01 * 1603
    assert fit.particle_density_kg_m3 > 2750                 # low solid fraction -> heavier particles
    # every iteration used the same seeds, and the density override reached the jobs
    assert all([j["seed"] for j in call] == [1, 2, 3] for call in fake.calls)
    rows = list(csv.DictReader(open(tmp_path / "history.csv")))
    assert list(rows[0])[:6] == density.HISTORY_COLUMNS
    assert len(rows) == fit.iterations
    res = yaml.safe_load((tmp_path / "result.yaml").read_text())
    assert res["tolerance_met"] == "yes"
    assert res["calibrated_particle_density_kg_m3"] == pytest.approx(fit.particle_density_kg_m3)
    assert (tmp_path / "bulk_density.png").stat().st_size > 1000


def test_non_converging_is_reported_not_met(tmp_path):
    class Stuck(FakeFill):                      # bulk density does not respond to the particle density
        def run(self, jobs, raise_on_error=True):
            return [{"bulk_density_kg_m3": 1000.0 + j["seed"], "solid_fraction": 0.3, "n_particles": 70}
                    for j in jobs]
    with pytest.warns(UserWarning, match="NOT CONVERGED"):
        fit = fit_density("M2", seeds=2, max_iterations=4, executor=Stuck(), out_dir=tmp_path, progress=None)
    assert not fit.tolerance_met
    assert fit.iterations == 4
    assert "NOT CONVERGED" in fit.message
    assert yaml.safe_load((tmp_path / "result.yaml").read_text())["tolerance_met"] == "no"


def test_cached_rerun_replays_the_same_jobs(tmp_path):
    a, b = FakeFill(), FakeFill()
    fit_density("M2", executor=a, progress=None)
    fit_density("M2", executor=b, progress=None)
    ids = lambda f: [[j["job_id"] for j in call] for call in f.calls]
    assert ids(a) == ids(b)                      # same job hashes -> a resumed calibration hits the cache


def test_a_miss_inside_the_seed_noise_is_met_and_says_so(tmp_path):
    """Fill noise (std 5 % over 3 seeds: 2 standard errors ~6 %) larger than the 1 %
    tolerance, and every iteration lands 2-3 % off: the verdict is met within the noise,
    never tighter than the seed spread; the same 2.5 % miss with quiet seeds is not met."""
    class Jumpy(FakeFill):
        def run(self, jobs, raise_on_error=True):
            spread = {1: -0.05, 2: 0.0, 3: 0.05} if self.noise else {1: 0.0, 2: 0.0, 3: 0.0}
            return [{"bulk_density_kg_m3": 1603.0 * 1.025 * (1 + spread[j["seed"]]),
                     "solid_fraction": 0.4, "n_particles": 70} for j in jobs]
    fit = fit_density("M2", seeds=3, max_iterations=2, executor=Jumpy(noise=1), out_dir=tmp_path, progress=None)
    assert fit.tolerance_met and "within the seed noise" in fit.message
    with pytest.warns(UserWarning, match="NOT CONVERGED"):
        fit = fit_density("M2", seeds=3, max_iterations=2, executor=Jumpy(noise=0), out_dir=tmp_path,
                          progress=None)
    assert not fit.tolerance_met
