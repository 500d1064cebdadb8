"""What a study's outputs were made with: when, where, by which command, from which
code (commit, dirty flag), libraries (the fits depend on scikit-learn and emcee) and
inputs (a SHA-256 over the lab files and one over the study config). The YADE versions
of the runs are read from their results (summary.json: yade_versions)."""
import datetime
import hashlib
import platform
import socket
import sys
from pathlib import Path

from .. import LAB_DIR
from ..gitinfo import git_commit, git_dirty

LIBRARIES = ("numpy", "scipy", "sklearn", "emcee", "pandas", "matplotlib", "yaml")


def library_versions():
    out = {"python": platform.python_version()}
    for name in LIBRARIES:
        try:
            module = __import__(name)
            out[name] = str(getattr(module, "__version__", "?"))
        except ImportError:
            out[name] = "not installed"
    return out


def files_sha256(paths):
    """SHA-256 over the files' relative names and bytes, in name order."""
    h = hashlib.sha256()
    for root, path in sorted(paths, key=lambda rp: str(rp[1])):
        h.update(str(Path(path).relative_to(root)).encode())
        h.update(Path(path).read_bytes())
    return h.hexdigest()


def study_provenance(config_path, lab_dir=None):
    lab = Path(lab_dir or LAB_DIR)
    lab_files = [(lab, p) for p in lab.rglob("*") if p.is_file()]
    return {"started_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "host": socket.gethostname(), "command": " ".join(sys.argv),
            "git_commit": git_commit(), "git_dirty": git_dirty(), "libraries": library_versions(),
            "lab_files_sha256": files_sha256(lab_files), "lab_files_count": len(lab_files),
            "study_config_sha256": hashlib.sha256(Path(config_path).read_bytes()).hexdigest()}
