"""The study's decisions, kept so that a resumed study asks for exactly the same runs.

A stage's choices come from floating-point work (a Gaussian process, an MCMC chain) that
is not bit-reproducible between processes: measured, the same wet-wall stage chose its
first free point at friction 0.3871 in one process and 0.3821 in another (BLAS kernels
depend on memory alignment; an MCMC chain amplifies the last bit). So every point a
stage runs, in order, and its result (the values carried into the next stages) are
written to <study>/journal.json as they are decided. A resumed study replays a stage's
points and result when the stage's fingerprint (its config, seeds, targets and the
values it starts from) is unchanged, and decides afresh from where the journal ends.
"""
import hashlib
import json

from ..files import finite, write_json


def fingerprint(*parts):
    """A short hash of JSON-able parts."""
    return hashlib.sha256(json.dumps(parts, sort_keys=True, default=str).encode()).hexdigest()[:16]


class Journal:
    """journal.json of one study folder: {stage key: {fingerprint, points, result}}."""

    def __init__(self, path):
        self.path = path
        self.data = json.loads(path.read_text()) if path.is_file() else {}

    def stage(self, key, print_):
        """The StageJournal of `key`; emptied when the fingerprint changed."""
        entry = self.data.get(key)
        if not entry or entry.get("fingerprint") != print_:
            entry = self.data[key] = {"fingerprint": print_, "points": [], "result": None}
        return StageJournal(self, entry)

    def save(self):
        write_json(self.path, finite(self.data), default=str)


class StageJournal:
    """Points of one stage in the order they were run, and its result once decided."""

    def __init__(self, journal, entry):
        self.journal, self.entry = journal, entry
        self.replayed = 0

    def next_recorded(self):
        """The next point to replay, or None when the journal has no more."""
        if self.replayed < len(self.entry["points"]):
            self.replayed += 1
            return self.entry["points"][self.replayed - 1]
        return None

    def record(self, point):
        """A point about to be run (past the replayed ones)."""
        if self.replayed < len(self.entry["points"]):
            return
        self.entry["points"].append(point)
        self.replayed += 1
        self.journal.save()

    @property
    def result(self):
        return self.entry["result"] if self.replayed >= len(self.entry["points"]) else None

    def finish(self, result):
        self.entry["result"] = result
        self.journal.save()
