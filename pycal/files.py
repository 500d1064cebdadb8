"""Atomic file writes: a reader (or a killed run) never sees half a file.

Each helper writes a temporary file in the same folder (named after the target and the
process id) and renames it over the target (os.replace, atomic on POSIX); on any error
the temporary file is removed and the target is left as it was.
"""
import csv
import io
import json
import os
from pathlib import Path


def atomic_write_bytes(path, data):
    """Write bytes to path atomically; returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.part")
    try:
        with open(tmp, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def atomic_write_text(path, text):
    """Write text (UTF-8) to path atomically; returns the path."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_json(path, data, indent=1):
    """Write data as JSON atomically (NaN written as null is the caller's choice: json's
    default writes NaN); returns the path."""
    return atomic_write_text(path, json.dumps(data, indent=indent, default=str) + "\n")


def atomic_write_csv(path, columns, rows):
    """Write a CSV (header `columns`, then `rows`) atomically; returns the path."""
    buf = io.StringIO(newline="")
    w = csv.writer(buf)
    w.writerow(columns)
    w.writerows(rows)
    return atomic_write_text(path, buf.getvalue())


def atomic_savefig(fig, path, dpi=110):
    """Save a matplotlib figure as PNG atomically; returns the path."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return atomic_write_bytes(path, buf.getvalue())
