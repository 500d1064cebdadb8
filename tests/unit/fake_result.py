"""Write a whole result.json for a job, as a rig would (for the fake YADE of the unit
layer): the measurements given, the job, its id, the keys every rig writes, and any key
the rig's descriptor requires that the measurements leave out (as null).

    python3 fake_result.py JOB_FILE '{"bulk_density_kg_m3": 1600.0}' [OUT_FILE]
"""
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from pycal import rigs  # noqa: E402

job = json.loads(Path(sys.argv[1]).read_text())
result = dict(json.loads(sys.argv[2]))
result.update({"job_id": job["job_id"], "rig": job["rig"], "material": job["material"], "job": job,
               "provenance": {"yade_version": "fake"}, "timestep_s": 1e-5})
if "seeds" in job:
    result["seeds"] = job["seeds"]
    result.setdefault("replicas", [])
else:
    result["seed"] = job["seed"]
    for k in rigs.get(job["rig"]).required_result_keys():
        result.setdefault(k, None)
Path(sys.argv[3] if len(sys.argv) > 3 else "result.json").write_text(json.dumps(result))
