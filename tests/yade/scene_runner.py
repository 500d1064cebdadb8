"""Run a physics test scene (tests/yade/scenes/<scene>.py) in YADE on a job and return its
measurements (shared by the YADE-layer test modules)."""
import copy
import json
import subprocess
from pathlib import Path

from pycal.jobs import resolve_job
from pycal.runner import yade_env

SCENES = Path(__file__).resolve().parent / "scenes"


LAB_SIZE = {"rig.geometry.scale": 1}   # the rig at the lab's size (the shipped fill, AoR and surcharge are scaled)


def scene_job(overrides=None, material="M2", rig="fill"):
    """A library job (the rig's config at the lab's size, the material's values) for a scene."""
    return resolve_job(rig, material, dict(LAB_SIZE, **(overrides or {})), seed=1)


def add_material(job, name, like, pairs):
    """Add a second particle material `name` to a job, a copy of material `like`;
    pairs = {partner: {property: value}} sets the pair values of `name` with its partners
    (both sides; itself and the boundaries included)."""
    mat = copy.deepcopy(job["materials"][like])
    mat["name"] = name
    mat["interactions"][name] = copy.deepcopy(mat["interactions"][like])
    job["materials"][name] = mat
    job["materials"][like]["interactions"][name] = copy.deepcopy(mat["interactions"][like])
    for partner, values in pairs.items():
        mat["interactions"][partner].update(values)
        if partner in job["materials"] and partner != name:
            job["materials"][partner]["interactions"][name].update(values)
    return job


def run_scene(tmp_path, scene, job, params, timeout=300):
    """Write job.json (job + test_scene parameters), run the scene, return its JSON."""
    job = dict(job, test_scene=params)
    d = Path(tmp_path)
    d.mkdir(parents=True, exist_ok=True)
    (d / "job.json").write_text(json.dumps(job))
    proc = subprocess.run(["yade", "-j1", "-x", "-n", str(SCENES / f"{scene}.py"), "job.json"],
                          cwd=d, capture_output=True, text=True, timeout=timeout, env=yade_env())
    out = d / "measurements.json"
    assert proc.returncode == 0 and out.is_file(), f"{scene} failed:\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}"
    return json.loads(out.read_text())
