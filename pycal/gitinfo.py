"""The git state of the repository, for provenance (results, benchmarks, reports)."""
import subprocess

from . import REPO_ROOT


def _git(*args):
    """Output of `git -C <repo> args` ('' when git or the repository is not there)."""
    try:
        return subprocess.run(["git", "-C", str(REPO_ROOT)] + list(args), capture_output=True, text=True,
                              timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""


def git_commit(short=False):
    """The commit checked out (full or short hash), or 'unknown'."""
    args = ("rev-parse", "--short", "HEAD") if short else ("rev-parse", "HEAD")
    return _git(*args) or "unknown"


def git_dirty():
    """True when tracked files differ from the commit (untracked files do not count)."""
    return bool(_git("status", "--porcelain", "--untracked-files=no"))
