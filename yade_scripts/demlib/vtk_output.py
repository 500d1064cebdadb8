"""VTK snapshots of a rig run for ParaView (runs inside YADE): the job's `vtk` entry
(pycal/vtk_output.py, `--vtk`) makes every scene write YADE VTKRecorder snapshots.

demlib.scene.World.__init__ calls end_scene() before it resets YADE and begin_scene(job)
once its engines are built; jobio.run_rig calls finish() after the rig's main() returned.
Per YADE scene k (one per World: a rig with a fresh fill per step or a sequential batch has
several; side-by-side replicas share one) a dead VTKRecorder in O.engines and a
PyRunner that calls it every `interval_s` of simulated time, the first at the scene's first
step, and a last snapshot when the scene ends. Files in <job folder>/<folder>/:

    <rig>-scene<k>-spheres.<step>.vtu    particle spheres (clump members included): radii,
                                         linVelVec/linVelLen, angVelVec/angVelLen,
                                         materialId, clumpId, mass
    <rig>-scene<k>-facets.<step>.vtu     the facets (cell, table, plates)
    <rig>-spheres.pvd, <rig>-facets.pvd  ParaView collections of all snapshots in order, each
                                         with its simulated time (s; scenes after the first
                                         continue from the time the one before ended)
"""
import os

import __main__

HOOK = "_pycal_vtk_snapshot"
KINDS = ("spheres", "facets")

_STATE = {"job": None, "scene": 0, "time_offset_s": 0.0, "recorder": None, "prefix": None,
          "last_iter": None, "snapshots": []}


def _folder(job):
    from . import job_folder
    return os.path.join(job_folder.get(), job["vtk"]["folder"])


def begin_scene(job):
    """Add the recorder and its PyRunner to the engines of a new scene (no-op without job["vtk"])."""
    cfg = job.get("vtk")
    if not cfg:
        return
    from yade import O
    from yade.wrapper import PyRunner, VTKRecorder
    st = _STATE
    st["job"] = job
    st["scene"] += 1
    folder = _folder(job)
    os.makedirs(folder, exist_ok=True)
    st["prefix"] = f"{job['rig']}-scene{st['scene']}-"
    st["recorder"] = VTKRecorder(fileName=os.path.join(folder, st["prefix"]), recorders=list(cfg["recorders"]),
                                 dead=True, label="vtk_recorder")
    st["last_iter"] = None
    setattr(__main__, HOOK, snapshot)
    O.engines = O.engines + [st["recorder"], PyRunner(virtPeriod=float(cfg["interval_s"]), initRun=True,
                                                        command=HOOK + "()", label="vtk_snapshots")]


def snapshot():
    """Write one snapshot of the current scene (once per time step)."""
    from yade import O
    st = _STATE
    if st["recorder"] is None or st["last_iter"] == O.iter:
        return
    st["recorder"]()
    st["last_iter"] = O.iter
    st["snapshots"].append((st["time_offset_s"] + O.time, st["prefix"], O.iter))


def end_scene():
    """Last snapshot of the scene that ends; later scenes' times continue from its end."""
    from yade import O
    st = _STATE
    if st["recorder"] is None:
        return
    snapshot()
    st["time_offset_s"] += O.time
    st["recorder"] = None


def finish():
    """End the last scene and write the .pvd collections. Returns the number of snapshots,
    or None when the job asked for none."""
    st = _STATE
    if st["job"] is None:
        return None
    end_scene()
    folder = _folder(st["job"])
    rig = st["job"]["rig"]
    for kind in KINDS:
        lines = ['<?xml version="1.0"?>',
                 '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">', "  <Collection>"]
        for t, prefix, it in st["snapshots"]:
            name = f"{prefix}{kind}.{it}.vtu"
            if os.path.isfile(os.path.join(folder, name)):
                lines.append(f'    <DataSet timestep="{t:.9g}" group="" part="0" file="{name}"/>')
        lines += ["  </Collection>", "</VTKFile>", ""]
        path = os.path.join(folder, f"{rig}-{kind}.pvd")
        with open(path + ".part", "w") as f:
            f.write("\n".join(lines))
        os.replace(path + ".part", path)
    return len(st["snapshots"])
