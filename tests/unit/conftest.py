"""Fixtures of the unit layer."""
import shutil
import stat
from pathlib import Path

import pytest

from pycal import CONFIG_DIR


@pytest.fixture
def cfg(tmp_path):
    """A writable copy of configs/ (edit it with config_copy.edit)."""
    dst = tmp_path / "configs"
    shutil.copytree(CONFIG_DIR, dst)
    return dst


FAKE_RESULT = Path(__file__).with_name("fake_result.py")
FAKE_YADE = """#!/bin/sh
# fake yade: args are -j1 -x -n SCRIPT JOB; behaviour chosen by $FAKE_MODE
job="$5"
[ -f "$job" ] || { echo "RIG FAILED: job file $job: cannot read it"; exit 4; }
echo "fake yade running $4 $job"
echo run >> "$FAKE_COUNT"
case "$FAKE_MODE" in
  ok) /usr/bin/python3 FAKE_RESULT "$job" '{"bulk_density_kg_m3": 1600.0, "n_particles": 100}' ;;
  fail) echo "RIG FAILED: blow-up: particle 7 left the rig domain"; exit 3 ;;
  refuse) echo "RIG FAILED: pile settle: no rest after 8 s" | tee rig_failure.txt; exit 3 ;;
  partial) echo '{"bulk' > result.json.part; exit 4 ;;
  sleep) sleep 5 ;;
  sleep_then_ok) sleep 2; /usr/bin/python3 FAKE_RESULT "$job" '{"bulk_density_kg_m3": 1600.0, "n_particles": 100}' ;;
  spin) while :; do :; done ;;
esac
""".replace("FAKE_RESULT", str(FAKE_RESULT))


def install_fake_yade(tmp_path, monkeypatch, script):
    """`script` as the YADE program ($PYCAL_YADE); returns the file where it logs its runs ($FAKE_COUNT)."""
    exe = tmp_path / "fake-yade"
    exe.write_text(script)
    exe.chmod(exe.stat().st_mode | stat.S_IEXEC)
    monkeypatch.setenv("PYCAL_YADE", str(exe))
    count = tmp_path / "count"
    count.write_text("")
    monkeypatch.setenv("FAKE_COUNT", str(count))
    return count


@pytest.fixture
def fake_yade(tmp_path, monkeypatch):
    count = install_fake_yade(tmp_path, monkeypatch, FAKE_YADE)
    monkeypatch.setenv("FAKE_MODE", "ok")
    return lambda: len(count.read_text().split())
