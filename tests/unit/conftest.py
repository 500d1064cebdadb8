"""Fixtures of the unit layer."""
import shutil

import pytest

from pycal import CONFIG_DIR


@pytest.fixture
def cfg(tmp_path):
    """A writable copy of configs/ (edit it with config_copy.edit)."""
    dst = tmp_path / "configs"
    shutil.copytree(CONFIG_DIR, dst)
    return dst
