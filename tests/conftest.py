"""Shared test setup: the repo root on sys.path; `yade` marker for the YADE layer."""
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


def pytest_configure(config):
    config.addinivalue_line("markers", "yade: runs real YADE scenes (the short physics layer)")
