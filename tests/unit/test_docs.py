"""The repo carries its own documentation: nothing points outside it, and every
RIG FAILED message a rig can print is explained in docs/troubleshooting.md."""
import ast
import re
import subprocess

from pycal import REPO_ROOT

DOCS = REPO_ROOT / "docs"
# the outside pages the code used to cite (pieced together so that this file does not match itself)
OUTSIDE = "shared" + r"/spec|/work" + r"/|method\.md|lab-tests\.md|yade-notes\.md"


def _squash(text):
    return re.sub(r"\s+", " ", text.replace("**", "").replace("`", ""))


def test_nothing_points_outside_the_repo():
    out = subprocess.run(["git", "grep", "-nE", OUTSIDE],
                         cwd=REPO_ROOT, capture_output=True, text=True).stdout
    bad = []
    for line in out.splitlines():
        path, _, text = line.split(":", 2)
        # a link to a docs/ page is fine; anything else names a file the repo does not have
        rest = re.sub(r"docs/(method|lab-tests|rigs|troubleshooting|glossary|contact-models|report)\.md", "", text)
        if path.startswith("docs/"):
            rest = re.sub(r"\((method|lab-tests|rigs|troubleshooting|glossary)\.md\)|\b(contact-models|method|"
                          r"lab-tests)\.md", "", rest)
        if re.search(OUTSIDE, rest):
            bad.append(line)
    assert not bad, "references outside the repo:\n" + "\n".join(bad)


def _failure_texts():
    """(file, longest literal piece) of every RigFailure / OverlapLimitExceeded raised in yade_scripts."""
    for path in sorted((REPO_ROOT / "yade_scripts").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) in ("RigFailure", "OverlapLimitExceeded") \
                    and node.args:
                arg = node.args[0]
                if isinstance(arg, ast.Name):          # a message built before the raise (loading.load_to)
                    continue
                parts = [arg] if isinstance(arg, ast.Constant) else [v for v in ast.walk(arg) if isinstance(v, ast.Constant)
                                                                      and isinstance(v.value, str)]
                text = max((p.value for p in parts), key=len)
                yield path.relative_to(REPO_ROOT), text


def test_every_rig_failure_message_is_in_troubleshooting():
    doc = _squash((DOCS / "troubleshooting.md").read_text())
    texts = list(_failure_texts())
    assert len(texts) > 25          # the extraction finds the messages (34 when written)
    missing = [f"{p}: {t!r}" for p, t in texts if _squash(t).strip(" (;:") not in doc]
    assert not missing, "RIG FAILED messages not explained in docs/troubleshooting.md:\n" + "\n".join(missing)


def test_the_load_step_failure_is_in_troubleshooting():
    src = (REPO_ROOT / "yade_scripts" / "demlib" / "loading.py").read_text()
    assert "not reached at rest after" in src
    assert "not reached at rest after" in _squash((DOCS / "troubleshooting.md").read_text())


def test_every_rig_has_a_descriptor_and_its_result_keys_are_documented():
    """A rig config without a descriptor, or a descriptor's result key that docs/rigs.md
    does not name (the yade layer checks that real results hold them)."""
    import sys
    from pycal import REPO_ROOT, rigs
    from pycal.configs import rig_names
    sys.path.insert(0, str(REPO_ROOT / "tests" / "yade"))
    from documented import documented_keys
    assert set(rig_names()) == set(rigs.names())
    for name in rigs.names():
        desc = rigs.get(name)
        assert (REPO_ROOT / "yade_scripts" / desc.script).is_file(), desc.script
        names = documented_keys(name)
        missing = [k for k in desc.required_result_keys()
                   if k not in names and "." + k not in names and not any(n.startswith(k + ".") for n in names)]
        assert not missing, (name, missing)
        assert not desc.post or (REPO_ROOT / "pycal" / "post" / f"{desc.post}.py").is_file(), desc.post
