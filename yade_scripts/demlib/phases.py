"""How a rig procedure advances time (runs inside YADE).

A rig procedure (and every phase of it: settle, lift, load step ...) is a generator. It
never steps YADE itself; it yields what it needs:

- an int n >= 1: "advance n time steps, then resume me" (the procedure then checks its
  guards, reads forces, moves its kinematic bodies ...);
- a Barrier: "run this action once, when every procedure of the scene is waiting for it,
  and send me its value" (the time step: YADE's P-wave step over every particle of the
  scene, set once all replicas have poured their particles).

A lone scene is driven by drive(); the replicas of a batch job share one scene and are
driven together by demlib.replicas, each on its own timeline: it is resumed after exactly
the steps it asked for, as if it ran alone.

    cell = yield from rigs.fill_cell(scene)      # inside a procedure
    cell = drive(rigs.fill_cell(scene))          # a lone scene (tests, the friction rigs)
"""


class Barrier:
    """A point every procedure of the scene must reach before any goes on; `action()`
    runs once there and its value is sent to each of them."""

    def __init__(self, action):
        self.action = action


def steps_of(seconds, dt):
    """Whole time steps in `seconds` (s) at time step dt (s), at least 1."""
    return max(1, int(round(seconds / dt)))


def drive(procedure):
    """Run one procedure alone (the scene has no other): step YADE as it asks, run its
    barriers at once. Returns the procedure's return value."""
    from .phase_clock import CLOCK
    value = None
    try:
        while True:
            request = procedure.send(value)
            if isinstance(request, Barrier):
                value = request.action()
            else:
                CLOCK.steps(request)
                value = None
    except StopIteration as stop:
        return stop.value
