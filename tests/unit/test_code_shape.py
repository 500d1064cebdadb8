"""The shape the project keeps its driver in: no class over 200 lines and no function over 80
in pycal/, and no switch on a stage kind's name outside the stage registry
(pycal/calibration/stages/): a kind is a registered StageKind, asked what it does."""
import ast
from pathlib import Path

from pycal import REPO_ROOT
from pycal.calibration import stages

MAX_CLASS_LINES = 200
MAX_FUNCTION_LINES = 80
REGISTRY = REPO_ROOT / "pycal" / "calibration" / "stages"


def too_long(tree, where):
    out = []
    for n in ast.walk(tree):
        if isinstance(n, (ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            lines = n.end_lineno - n.lineno + 1
            limit = MAX_CLASS_LINES if isinstance(n, ast.ClassDef) else MAX_FUNCTION_LINES
            if lines > limit:
                out.append(f"{where}:{n.lineno} {n.name} ({lines} lines > {limit})")
    return out


def kind_switches(tree, where, kinds):
    """Comparisons of something called `kind` (a name, an attribute, a ["kind"] item) with a
    stage kind's name: `st["kind"] == "inherit"`, `kind in ("density", ...)`."""
    def is_kind(node):
        if isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Constant):
            return node.slice.value == "kind"
        return (isinstance(node, ast.Name) and node.id == "kind") or (
            isinstance(node, ast.Attribute) and node.attr == "kind")

    def names_kind(node):
        consts = [node] if isinstance(node, ast.Constant) else (
            list(node.elts) if isinstance(node, (ast.Tuple, ast.List, ast.Set)) else [])
        return any(isinstance(c, ast.Constant) and c.value in kinds for c in consts)

    out = []
    for n in ast.walk(tree):
        if isinstance(n, ast.Compare):
            sides = [n.left] + list(n.comparators)
            if any(is_kind(s) for s in sides) and any(names_kind(s) for s in sides):
                out.append(f"{where}:{n.lineno}")
    return out


def pycal_modules():
    for path in sorted((REPO_ROOT / "pycal").rglob("*.py")):
        yield path, ast.parse(path.read_text()), str(path.relative_to(REPO_ROOT))


def test_the_scans_see_what_they_look_for():
    long_fn = "def f():\n" + "    x = 1\n" * 90
    assert too_long(ast.parse(long_fn), "t") == ["t:1 f (91 lines > 80)"]
    src = 'a = st["kind"] == "inherit"\nb = kind in ("density", "x")\nc = s.kind != "joint"\nd = r["kind"] == "flag"\n'
    assert kind_switches(ast.parse(src), "t", set(stages.names())) == ["t:1", "t:2", "t:3"]


def test_no_long_class_or_function_in_pycal():
    assert [hit for path, tree, where in pycal_modules() for hit in too_long(tree, where)] == []


def test_no_stage_kind_switch_outside_the_registry():
    kinds = set(stages.names())
    assert {"density", "joint", "inherit"} <= kinds
    hits = [hit for path, tree, where in pycal_modules() if REGISTRY not in path.parents
            for hit in kind_switches(tree, where, kinds)]
    assert hits == []
