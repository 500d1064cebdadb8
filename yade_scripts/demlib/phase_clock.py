"""CPU time and time steps per named phase of one YADE run (runs inside YADE).

A rig marks its phases with `with CLOCK.phase("pour"): ...`; every stepping loop of the
demlib (Scene.advance, phases.drive, replicas.Driver) steps through CLOCK.steps(n), which
counts the steps and the CPU time spent inside YADE's O.step() for the phase open at the
time. A phase inside another is counted once, in the inner one. CPU time is the process's
(time.process_time, s): a run starved of a core on a loaded machine reads the same.
provenance() (demlib.jobio) writes CLOCK.report() into every result.json, where
bench/cost_profile.py reads it.
"""
import time
from contextlib import contextmanager

from yade import O

OUTSIDE = "outside_phases"       # what no phase covered: start-up, scene set-up, outputs


class PhaseClock:
    def __init__(self):
        self.totals = {}          # name -> [cpu s, of it inside O.step() s, steps]
        self.stack = []           # open phases: [name, cpu s of the phases inside it]

    def _row(self, name):
        return self.totals.setdefault(name, [0.0, 0.0, 0])

    @contextmanager
    def phase(self, name):
        """Count the CPU time of the block under `name`, less that of the phases inside it
        (time steps are counted in the innermost open phase by steps())."""
        cpu0 = time.process_time()
        self.stack.append([name, 0.0])
        row = self._row(name)
        try:
            yield
        finally:
            _, inner_cpu = self.stack.pop()
            cpu = time.process_time() - cpu0
            row[0] += cpu - inner_cpu
            if self.stack:
                self.stack[-1][1] += cpu

    def steps(self, n):
        """Run n YADE time steps now (O.step() in a Python loop), counted in the open phase."""
        step = O.step
        cpu0 = time.process_time()
        for _ in range(int(n)):
            step()
        row = self._row(self.stack[-1][0] if self.stack else OUTSIDE)
        row[1] += time.process_time() - cpu0
        row[2] += int(n)

    def report(self):
        """{phase: {'cpu_s', 'step_cpu_s', 'steps_count'}}; the phase OUTSIDE gets the
        process CPU time no phase counted (YADE start-up, set-up, outputs)."""
        out = {name: {"cpu_s": round(v[0], 3), "step_cpu_s": round(v[1], 3), "steps_count": v[2]}
               for name, v in self.totals.items() if name != OUTSIDE}
        counted = sum(v[0] for name, v in self.totals.items() if name != OUTSIDE)
        rest = self.totals.get(OUTSIDE, [0.0, 0.0, 0])
        out[OUTSIDE] = {"cpu_s": round(max(0.0, time.process_time() - counted), 3),
                        "step_cpu_s": round(rest[1], 3), "steps_count": rest[2]}
        return out


CLOCK = PhaseClock()
