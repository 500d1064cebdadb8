"""Command-line arguments checked up front: counts, limits and paths, before anything
is resolved or written. A bad one is a ConfigError naming the option (one line, exit 2).

OneLineParser makes argparse's own refusals (a missing or non-numeric argument) one line
too, `error: <option>: <reason>`, with exit code 2.
"""
import argparse
import math
import os
import sys
from pathlib import Path

from .errors import ConfigError

# dest -> (option, smallest value, None allowed); whole numbers
COUNTS = {"seeds": ("--seeds", 1, False), "seed": ("--seed", 0, False), "seed_base": ("--seed-base", 0, False),
          "workers": ("--workers", 1, True), "replicas": ("--replicas", 1, True),
          "seeds_per_run": ("--seeds-per-run", 1, True), "max_runs": ("--max-runs", 1, True)}
# dest -> option; a number > 0 (None allowed)
POSITIVE = {"timeout_s": "--cpu-limit-s", "vtk": "--vtk"}
# dest -> option; a folder the command writes into (exists as a writable folder, or can be made)
OUT_DIRS = {"out": "--out", "runs": "--runs"}
# dest -> option; a file the command writes (its folder writable, itself not a folder)
OUT_FILES = {"table": "--table"}


class OneLineParser(argparse.ArgumentParser):
    def error(self, message):
        print(f"error: {self.prog}: {message} (see {self.prog} --help)", file=sys.stderr)
        sys.exit(2)


def writable_folder_problem(path):
    """Why `path` cannot be (made into) a folder this process writes, or None."""
    p = Path(path)
    if p.exists():
        if not p.is_dir():
            return "is a file, not a folder"
        return None if os.access(p, os.W_OK | os.X_OK) else "is not writable"
    parent = p.parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        return f"cannot be created: {parent} is a file"
    return None if os.access(parent, os.W_OK | os.X_OK) else f"cannot be created: {parent} is not writable"


def check(args):
    """Refuse bad counts, limits and output paths of parsed `args` (ConfigError)."""
    for dest, (option, lo, none_ok) in COUNTS.items():
        v = getattr(args, dest, None)
        if v is None and (none_ok or not hasattr(args, dest)):
            continue
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            raise ConfigError(option, str(v), f"must be a whole number >= {lo}")
    for dest, option in POSITIVE.items():
        v = getattr(args, dest, None)
        if v is not None and not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise ConfigError(option, str(v), "must be a number > 0")
    for dest, option in OUT_DIRS.items():
        v = getattr(args, dest, None)
        if isinstance(v, (str, Path)):
            why = writable_folder_problem(v)
            if why:
                raise ConfigError(option, str(v), why)
    for dest, option in OUT_FILES.items():
        v = getattr(args, dest, None)
        if isinstance(v, (str, Path)):
            if Path(v).is_dir():
                raise ConfigError(option, str(v), "is a folder, not a file")
            why = writable_folder_problem(Path(v).parent)
            if why:
                raise ConfigError(option, str(v), f"its folder {why}")
