"""Replicas: the seeds of a batch job run side by side in one YADE scene (runs inside YADE).

A batch job (pycal.replicas: `seeds` instead of `seed`) holds several seeds of one rig
point. Each seed gets its own copy of the rig (a demlib.scene.Scene: its own table,
cylinder, plate, servo, lift, rest criterion, guards and measurement), standing
replica_spacing_m further along x than the one before, in its own collision group
(Body.mask): bodies of two replicas never interact, whatever happens. The copies share
the time step (YADE's P-wave step over every particle: the same as alone for one sphere
material) and gravity.

Each replica runs its own procedure (a generator, demlib.phases) on its own timeline:
the driver advances the scene to the next step any replica asked for and resumes exactly
the replicas whose steps are done, so a replica goes through the same phases, checks and
step counts as it does alone. It does not wait for its batch-mates: a replica that has
finished is measured at once (or its failure recorded) and its bodies are erased, so the
others go on without it. A replica's numbers still differ from a lone run's in the last
bits (positions at another offset round differently; body ids and the order of the
contacts differ), which chaotic dynamics grow into another sample of the same
distribution: the batch, not the seed, is the unit that reproduces bit for bit (and that
the cache keeps).

A replica the rig refuses (RigFailure: no rest, blow-up) is recorded as failed with its
message and its batch-mates go on; any other error fails the whole batch (a bug).
"""
import os

from yade import O

from pycal.rig_contract import BATCH_SEEDS_KEY, LAYOUT_KEY, replica_dir_name, seed_job

from .jobio import RigFailure
from .phase_clock import CLOCK
from .phases import Barrier
from .scene import Scene, World

MAX_REPLICAS = 30        # one collision-group bit each (Body.mask is a 32-bit int)


def replica_spacing_m(job, half_width_m):
    """Distance (m) between the axes of two neighbouring replicas: each rig's guarded box
    (half_width_m from its axis plus numerics.domain_margin_m, on both sides) and two
    particle diameters between them."""
    num = job["rig_config"]["numerics"]
    sizes = [m["particles"]["diameter_m"] for m in job["materials"].values()]
    return 2.0 * (half_width_m + num["domain_margin_m"]) + 2.0 * max(sizes)


def rig_main(procedure, half_width_m=None, scene_class=Scene):
    """main(job, out_dir) of a rig for jobio.run_rig, from its procedure(scene, out_dir)
    (a generator returning the measurements). A lone job runs one Scene and returns its
    measurements; a batch job runs one replica per seed (run_batch), if the rig gives
    half_width_m(geometry) (m: how far its guarded box reaches from its axis)."""
    def main(job, out_dir):
        if BATCH_SEEDS_KEY not in job:
            return run_lone(job, out_dir, procedure, scene_class)
        if half_width_m is None:
            raise RigFailure(f"rig {job['rig']} does not run replicas (batch job of seeds {job[BATCH_SEEDS_KEY]})")
        return run_batch(job, out_dir, procedure, half_width_m(job["rig_config"]["geometry"]), scene_class)
    return main


def run_lone(job, out_dir, procedure, scene_class=Scene):
    """One rig alone in its world: the procedure driven by the same loop as a batch.
    A RigFailure propagates (jobio.run_rig records it)."""
    scene = scene_class(job)
    outcome = Driver(scene.world, [(scene, procedure(scene, out_dir))], retire=False).run()[0]
    if outcome["status"] != "ok":
        raise outcome["error"]
    return outcome["measurements"]


def run_batch(job, out_dir, procedure, half_width_m, scene_class=Scene):
    """Every seed of a batch job as a replica in one scene. Returns
    {'replicas': [{'seed', 'status': 'ok' | 'failed', 'measurements' | 'failure',
    'simulated_time_s', 'steps_count', 'output_dir'}], 'replicas_count',
    'replicas_failed_count', 'replica_spacing_m'}; per-seed files go to out_dir/s<seed>/."""
    seeds = job[BATCH_SEEDS_KEY]
    if not 1 <= len(seeds) <= MAX_REPLICAS or len(set(seeds)) != len(seeds):
        raise RigFailure(f"batch seeds {seeds}: need 1 to {MAX_REPLICAS} different seeds")
    layout = job.get(LAYOUT_KEY, "side_by_side")
    spacing = replica_spacing_m(job, half_width_m)
    jobs = [seed_job(job, s) for s in seeds]
    dirs = [os.path.join(out_dir, replica_dir_name(sj["seed"])) for sj in jobs]
    for d in dirs:
        os.makedirs(d, exist_ok=True)
    if layout == "sequential":
        outcomes = []
        for sj, d in zip(jobs, dirs):
            scene = scene_class(sj)          # a world of its own (O.reset): a lone run of this seed
            outcomes += Driver(scene.world, [(scene, procedure(scene, d))], retire=False).run()
    elif layout == "side_by_side":
        world = World(jobs[0])
        world.shared = True
        runs = []
        for k, (sj, d) in enumerate(zip(jobs, dirs)):
            scene = scene_class(sj, world=world, origin=(k * spacing, 0.0, 0.0), index=k)
            runs.append((scene, procedure(scene, d)))
        outcomes = Driver(world, runs, retire=True).run()
    else:
        raise RigFailure(f"{LAYOUT_KEY}: {layout!r} must be side_by_side or sequential")
    out = []
    for sj, o in zip(jobs, outcomes):
        row = {"seed": sj["seed"], "status": o["status"], "simulated_time_s": o["simulated_time_s"],
               "steps_count": o["steps_count"], "output_dir": replica_dir_name(sj["seed"])}
        if o["status"] == "ok":
            row["measurements"] = o["measurements"]
        else:
            row["failure"] = f"RIG FAILED: {o['error']}"
            print(f"replica seed {sj['seed']}: RIG FAILED: {o['error']}", flush=True)
        out.append(row)
    return {"replicas": out, "replicas_count": len(out),
            "replicas_failed_count": sum(1 for r in out if r["status"] != "ok"),
            "replica_spacing_m": spacing}


class Driver:
    """Steps one world for several procedures (one per replica), each resumed after the
    steps it asked for; barriers run once every live procedure waits at one.
    retire: erase a replica's bodies when it has finished or failed."""

    def __init__(self, world, runs, retire):
        self.world = world
        self.scenes = [s for s, _ in runs]
        self.procs = [p for _, p in runs]
        self.retire_done = retire
        self.outcomes = [None] * len(runs)
        self.waiting = {}            # replica index -> steps still to go, or a Barrier

    def run(self):
        for k in range(len(self.procs)):
            self._resume(k, None)
        while self.waiting:
            barriers = {k: r for k, r in self.waiting.items() if isinstance(r, Barrier)}
            if len(barriers) == len(self.waiting):
                first = min(barriers)
                try:
                    value = barriers[first].action()
                except RigFailure as exc:          # e.g. no plausible time step: every replica fails
                    for k in sorted(barriers):
                        self._finish(k, "failed", error=exc)
                    continue
                for k in sorted(barriers):
                    del self.waiting[k]
                    self._resume(k, value)
                continue
            n = min(r for r in self.waiting.values() if not isinstance(r, Barrier))
            CLOCK.steps(n)
            for k in sorted(self.waiting):
                r = self.waiting[k]
                if isinstance(r, Barrier):
                    continue
                if r == n:
                    del self.waiting[k]
                    self._resume(k, None)
                else:
                    self.waiting[k] = r - n
        return self.outcomes

    def _resume(self, k, value):
        first_new = len(O.bodies)
        try:
            request = self.procs[k].send(value)
        except StopIteration as stop:
            self.world.claim(k, first_new)
            self._finish(k, "ok", measurements=stop.value)
            return
        except RigFailure as exc:
            self.world.claim(k, first_new)
            self._finish(k, "failed", error=exc)
            return
        self.world.claim(k, first_new)
        if not isinstance(request, Barrier):
            request = int(request)
            if request < 1:
                raise ValueError(f"replica {k}: a procedure must ask for at least one step, asked {request}")
        self.waiting[k] = request

    def _finish(self, k, status, measurements=None, error=None):
        self.waiting.pop(k, None)
        self.outcomes[k] = {"status": status, "measurements": measurements, "error": error,
                            "simulated_time_s": O.time, "steps_count": O.iter}
        if self.retire_done:
            self.world.retire(k)
