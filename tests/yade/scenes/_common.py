"""Shared set-up of the physics test scenes (runs inside YADE).

Usage: yade -j1 -x -n tests/yade/scenes/<scene>.py job.json
job.json is a job from pycal.jobs.resolve_job with an extra key `test_scene` holding
the scene's own parameters; the scene writes measurements.json next to job.json.
"""
import json
import os
import sys

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(sys.argv[0])))))


def load():
    args = [a for a in sys.argv[1:] if not a.startswith("-")]
    path = os.path.abspath(args[0])
    with open(path) as f:
        job = json.load(f)
    return job, job.get("test_scene", {}), os.path.dirname(path)


def finish(out_dir, data):
    with open(os.path.join(out_dir, "measurements.json"), "w") as f:
        json.dump(data, f, indent=1, sort_keys=True)
    print("MEASUREMENTS", json.dumps(data, sort_keys=True), flush=True)
    sys.stdout.flush()
    os._exit(0)


def run_main(main):
    try:
        main()
    except Exception:
        import traceback
        traceback.print_exc()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(4)
