"""Profile one rig job inside YADE: per-engine times (O.timingEnabled), time spent in the
O.step() loops against the Python work between them (rest checks, guards, servo, records,
measurement and outputs).

    cp runs/<rig>/<job id>/job.json /tmp/prof/ && cd /tmp/prof
    PYTHONPATH=<repo root> yade -j1 -x -n <repo root>/bench/profile_rig.py job.json [out.json]

job.json: the one in any job folder a study or `pycal run` wrote, copied to an empty
folder first: the rig runs again and writes its outputs next to it (in the job folder
itself it would overwrite the cached result). Writes out.json (default profile.json
next to the job):
{'wall_s', 'cpu_s', 'steps', 'engines_s': {label: s}, 'engine_shares': {label: fraction},
'step_loop_s', 'step_loop_cpu_s', 'python_between_s', 'python_between_cpu_s', 'result': the
rig's measurements}. The engines' execTime is wall-clock time: on a loaded machine read
their shares, and the CPU times (time.process_time) for the split loop / Python.
"""
import json
import os
import sys
import time

import yade_scripts.demlib.jobio as jobio

_captured = []
jobio.run_rig = lambda main: _captured.append(main)     # take the rig's main() instead of running it


def main():
    from yade import O
    import yade_scripts.demlib.scene as scene_mod
    args = [a for a in sys.argv[1:] if not a.startswith("-")]
    job_path = os.path.abspath(args[0])
    out_path = args[1] if len(args) > 1 else os.path.join(os.path.dirname(job_path), "profile.json")
    job = json.load(open(job_path))
    script = job["script"]
    import importlib
    mod = importlib.import_module("yade_scripts." + script[:-3])
    rig_main = _captured[-1] if _captured else mod.main
    loop = {"s": 0.0, "cpu_s": 0.0, "steps": 0}
    real_step = O.step
    clock, cpu_clock = time.perf_counter, time.process_time

    def timed_step():
        t, c = clock(), cpu_clock()
        real_step()
        loop["s"] += clock() - t
        loop["cpu_s"] += cpu_clock() - c
        loop["steps"] += 1

    # every stepping loop of the rigs goes through O.step (Scene.advance, the servo, the tilt):
    # the demlib modules see a proxy of O whose step() is timed
    class _TimedO:
        def __getattr__(self, name):
            return timed_step if name == "step" else getattr(O, name)

        def __setattr__(self, name, value):
            setattr(O, name, value)

    proxy = _TimedO()
    for extra in ("phase_clock", "scene", "rigs", "loading", "compression", "tilt", "tilt_test", "tilt_bodies", "mixed"):
        importlib.import_module("yade_scripts.demlib." + extra)
    for name in list(sys.modules):
        m = sys.modules[name]
        if name.startswith("yade_scripts") and getattr(m, "O", None) is O:
            m.O = proxy
    O.timingEnabled = True
    t0, c0 = time.perf_counter(), time.process_time()
    result = rig_main(job, os.path.dirname(job_path))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    engines = {}
    for e in O.engines:
        name = e.label or type(e).__name__
        engines[name] = engines.get(name, 0.0) + e.execTime * 1e-9
    total = sum(engines.values()) or 1.0
    prof = {"wall_s": wall, "cpu_s": cpu, "steps": O.iter, "engines_s": engines,
            "engine_shares": {k: v / total for k, v in engines.items()},
            "step_loop_s": loop["s"], "python_between_s": wall - loop["s"],
            "step_loop_cpu_s": loop["cpu_s"], "python_between_cpu_s": cpu - loop["cpu_s"],
            "engines_total_s": sum(engines.values()),
            "result": {k: v for k, v in (result or {}).items() if k != "job"}}
    with open(out_path, "w") as f:
        json.dump(prof, f, indent=1, default=str)
    from yade import timing
    timing.stats()
    print("PROFILE", json.dumps({k: v for k, v in prof.items() if k != "result"}, default=str), flush=True)
    sys.stdout.flush()
    os._exit(0)


main()
