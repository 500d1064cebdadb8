"""The command line shared by the post-processing modules:

    /usr/bin/python3 -m pycal.post.<module> RESULT.json [...] [--out DIR]

A file that is missing, is not JSON or is not a rig result prints one line
`error: <file>: <reason>` and exits 2; nothing is written for it.
"""
import argparse
import json
import sys
from pathlib import Path

from ..errors import ConfigError, PycalError


def read_result(path):
    """result.json of a rig run as a dict; ConfigError naming the file otherwise."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(path, "", "file not found")
    try:
        data = json.loads(path.read_text())
    except (ValueError, UnicodeDecodeError) as exc:
        raise ConfigError(path, "", f"not valid JSON: {exc}") from None
    if not isinstance(data, dict) or "rig" not in data:
        raise ConfigError(path, "rig", "missing: not the result.json of a rig run")
    return data


def run(argv, prog, description, handle):
    """Parse `RESULT.json [...] [--out DIR]`, read the results and call
    handle([(path, result), ...], out_dir or None). Returns the exit code."""
    p = argparse.ArgumentParser(prog=prog, description=description)
    p.add_argument("results", nargs="+", metavar="RESULT.json")
    p.add_argument("--out", default=None, help="output folder (default: the folder of each result)")
    args = p.parse_args(sys.argv[1:] if argv is None else argv)
    try:
        loaded = [(path, read_result(path)) for path in args.results]
        handle(loaded, args.out)
    except PycalError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0
