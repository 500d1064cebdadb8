"""Shared test setup: the repo root on sys.path; the `yade` marker for the YADE layer.

The YADE layer is part of the suite: when tests marked `yade` are selected and YADE is
not installed, the session fails at once with a clear message (a machine without YADE
must not pass green without any physics). `-m "not yade"` runs the unit layer alone.
"""
import shutil
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


def pytest_configure(config):
    config.addinivalue_line("markers", "yade: runs real YADE scenes (the short physics layer)")


def pytest_collection_finish(session):
    from pycal.runner import yade_executable
    YADE = yade_executable()
    physics = [item for item in session.items if item.get_closest_marker("yade")]
    if physics and shutil.which(YADE) is None:
        raise pytest.UsageError(
            f"YADE layer cannot run: '{YADE}' is not installed or not on PATH, and {len(physics)} selected "
            "test(s) need it (tests/yade). Install it (./run.sh test installs Debian's yade package), or run "
            "the unit layer alone with -m \"not yade\" (CI runs both).")
