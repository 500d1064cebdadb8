"""The import structure: pycal never imports yade_scripts (rig scripts import pycal's
contracts, not the other way), and no module of either imports itself through others
(an import circle), counting imports inside functions too."""
import ast
from pathlib import Path

from pycal import REPO_ROOT

PACKAGES = ("pycal", "yade_scripts")


def module_name(path):
    parts = list(path.relative_to(REPO_ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def exists(name):
    base = REPO_ROOT.joinpath(*name.split("."))
    return base.with_suffix(".py").is_file() or (base / "__init__.py").is_file()


def imports_of(path):
    """Names of the project modules `path` imports (absolute, resolved)."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            targets = [f"{mod}.{a.name}" if exists(f"{mod}.{a.name}") else mod for a in node.names]
        else:
            continue
        for t in targets:
            while t and not exists(t):
                t = t.rsplit(".", 1)[0] if "." in t else ""
            if t and t.split(".")[0] in PACKAGES and t != name:
                out.add(t)
    return out


def registry_imports():
    """The imports a registry makes by name (importlib), which the scan of import statements
    cannot see: pycal.rigs loads every rig descriptor module, pycal.calibration.stages every
    stage kind module, gallery.py the post module of each rig."""
    from pycal import rigs
    out = {"pycal.rigs": {f"pycal.rigs.{name}" for name in rigs.names()},
           "pycal.calibration.gallery": {module_name(p) for p in (REPO_ROOT / "pycal" / "post").glob("*.py")
                                         if p.name != "__init__.py"}}
    stages = REPO_ROOT / "pycal" / "calibration" / "stages"
    if stages.is_dir():
        from pycal.calibration import stages as stage_registry
        out["pycal.calibration.stages"] = {f"pycal.calibration.stages.{k}" for k in stage_registry.module_names()}
    return out


def graph():
    g = {}
    for pkg in PACKAGES:
        for path in sorted((REPO_ROOT / pkg).rglob("*.py")):
            g[module_name(path)] = imports_of(path)
    for name, targets in registry_imports().items():
        g[name] = g.get(name, set()) | targets
    return g


def circles(g):
    """Strongly connected groups of more than one module (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in g.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(g):
        if v not in index:
            visit(v)
    return out


def test_the_scan_sees_a_circle_and_a_wrong_way_import():
    assert circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    g = graph()
    assert "pycal.rig_contract" in g["yade_scripts.demlib.jobio"]        # the scan reads real imports
    assert "pycal.calibration.validation" in g["pycal.calibration.study"]  # also inside functions
    assert "pycal.rigs.transfer" in g["pycal.rigs"]                       # and the registries' own loads
    assert "pycal.calibration.stages.joint" in g["pycal.calibration.stages"]


def test_pycal_never_imports_yade_scripts():
    wrong = {m: sorted(t for t in ts if t.startswith("yade_scripts")) for m, ts in graph().items()
             if m.startswith("pycal")}
    assert not {m: ts for m, ts in wrong.items() if ts}


def test_no_import_circle():
    assert circles(graph()) == []
