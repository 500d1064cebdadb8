"""What a rig run and pycal agree on (one place, imported by pycal and by yade_scripts).

A job folder holds JOB_FILE (the resolved job) and, once the run succeeded,
RESULT_FILE (written last, atomically). When the rig itself refuses the run (no rest,
blow-up: a RigFailure) it writes RIG_FAILURE_FILE instead and exits with
EXIT_RIG_FAILURE; any other error exits with EXIT_ERROR. YADE's output goes to LOG_FILE.
"""

JOB_FILE = "job.json"
RESULT_FILE = "result.json"
RIG_FAILURE_FILE = "rig_failure.txt"
LOG_FILE = "yade.log"

EXIT_OK = 0
EXIT_RIG_FAILURE = 3        # the rig refused the run: same job and seed fail the same way (kept as a verdict)
EXIT_ERROR = 4              # a bug or a crash: not a verdict, the job runs again

# ---------------------------------------------------------------- batch jobs (replicas)
# A batch job holds the seeds of one rig point under BATCH_SEEDS_KEY instead of `seed`; the
# rig runs one replica per seed in one scene (yade_scripts/demlib/replicas.py) and writes
# ONE result.json for the batch, with a `replicas` list (one entry per seed: measurements
# or the failure). pycal.replicas makes batch jobs and expands their results per seed.
BATCH_SEEDS_KEY = "seeds"
LAYOUT_KEY = "replica_layout"       # side_by_side (one scene) | sequential (one scene after the other)


def replica_dir_name(seed):
    """Folder of one replica's files inside the batch's job folder."""
    return f"s{seed}"


def seed_job(batch_job, seed):
    """The job one replica of a batch runs: the batch job with `seed` instead of the seed
    list, and its own job_id '<batch job_id>-s<seed>' (a replica's numbers are not a lone
    run's: they depend on the batch)."""
    job = {k: v for k, v in batch_job.items() if k not in (BATCH_SEEDS_KEY, LAYOUT_KEY, "job_id")}
    job["seed"] = seed
    job["job_id"] = f"{batch_job['job_id']}-s{seed}"
    return job


# ---------------------------------------------------------------- optional rig keys
# Keys a rig config may leave out, with the value the rig uses then (the rig as it always ran:
# leaving them out keeps the job ids). The tilt-table options of the internal-friction audit:
# the sliding cell's rotations during the tilt, the lid joined to the cell or free on the
# contents, and the shear drive: the table tilted (gravity rotated) or, as the case study's own
# DEM model, a horizontal force on the mobile cell that rises as W tan(angle) under vertical
# gravity (docs/rigs.md, "internal_friction"); and where a cell free to turn has its slide read:
# "body" (its centre of mass; a guided cell: its reference member) or "shear_plane" (the centre
# of its bottom rim).
TILT_OPTION_DEFAULTS = {"sliding_cell_rotations": "blocked", "lid_during_tilt": "joined", "shear_drive": "tilt",
                        "slide_read_at": "body"}


def tilt_option(procedure, key):
    """procedure[key], or its default when the config left it out."""
    return procedure.get(key, TILT_OPTION_DEFAULTS[key])
