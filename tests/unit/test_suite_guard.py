"""The suite fails (it does not skip) when the YADE layer is selected and YADE is missing."""
import os
import subprocess
import sys

from pycal import REPO_ROOT


def pytest_run(*args):
    env = dict(os.environ, PYCAL_YADE="no-such-yade-binary")
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--co", *args],
                          cwd=REPO_ROOT, env=env, capture_output=True, text=True, timeout=120)


def test_missing_yade_fails_the_suite_with_a_clear_message():
    proc = pytest_run("tests/yade/test_pile_physics.py")
    assert proc.returncode != 0
    assert "YADE layer cannot run: 'no-such-yade-binary' is not installed" in proc.stdout + proc.stderr


def test_the_unit_layer_alone_runs_without_yade():
    proc = pytest_run("tests", "-m", "not yade")
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
