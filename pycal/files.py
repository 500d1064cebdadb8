"""Atomic file writers: a file is either complete or absent, never half-written.

Each writer writes `<path>.part` next to the file and renames it over `<path>`
(os.replace: atomic on one file system). If writing fails, the `.part` file is
removed and the error goes on to the caller.
"""
import contextlib
import csv
import json
import math
import os
from pathlib import Path

PART_SUFFIX = ".part"


@contextlib.contextmanager
def atomic_path(path):
    """Yield the temporary path to write; on success it replaces `path`, on an error it
    is removed. For writers that take a file name (e.g. fig.savefig, DataFrame.to_csv:
    give them the format explicitly, the temporary name ends in .part)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + PART_SUFFIX)
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise


def write_text(path, text):
    """Write a text file atomically. Returns path."""
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return path


def finite(obj):
    """obj with every NaN / infinite float replaced by None, through dicts and lists (so
    that it can be written as JSON, which has no NaN)."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {str(k): finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite(v) for v in obj]
    return obj


def write_bytes(path, data):
    """Write bytes atomically. Returns path."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return path


def write_json(path, data, indent=1, sort_keys=True, default=None):
    """Write strict JSON atomically (NaN or infinity is an error: JSON has neither; write
    None for 'no value'); `default` converts other objects (e.g. str). Returns path."""
    return write_text(path, json.dumps(data, indent=indent, sort_keys=sort_keys, allow_nan=False,
                                       default=default) + "\n")


def write_csv(path, header, rows):
    """Write a CSV atomically: header = column names (with units), rows = sequences;
    None is written as an empty cell. Returns path."""
    with atomic_path(path) as tmp:
        with open(tmp, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(header)
            for row in rows:
                w.writerow(["" if v is None else v for v in row])
    return path
