"""pycal: configs -> YADE rig jobs -> post-processing -> calibration -> report.

Nothing in pycal imports YADE; rig scripts in yade_scripts/ run inside YADE.
"""
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
CONFIG_DIR = REPO_ROOT / "configs"
LAB_DIR = REPO_ROOT / "labresults"
SCRIPT_DIR = REPO_ROOT / "yade_scripts"
