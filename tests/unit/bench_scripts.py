"""Load a bench/ script as a module (bench/ is not a package), so that its bookkeeping
is tested without YADE."""
import importlib.util

from pycal import REPO_ROOT


def load_bench_script(name):
    """The module of bench/<name>.py."""
    spec = importlib.util.spec_from_file_location(f"bench_{name}", REPO_ROOT / "bench" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod
