"""The LIGGGHTS cross-code bench's bookkeeping (bench/liggghts_cross.py), without LIGGGHTS:
the rig geometry it writes and the naive copy it compares the conversions against."""
import math
import shutil

import pytest

from bench_scripts import load_bench_script
from pycal import CONFIG_DIR
from pycal.export.formats import export, load_calibrated

lc = load_bench_script("liggghts_cross")


def test_cylinder_and_table_are_the_rig_s_geometry(tmp_path):
    tris = lc.cylinder_triangles(0.0725, 0.0, 0.3, 32)
    assert len(tris) == 64
    radii = {round(math.hypot(x, y), 12) for tri in tris for x, y, _ in tri}
    assert radii == {0.0725}
    assert {z for tri in tris for _, _, z in tri} == {0.0, 0.3}
    lc.stl(tmp_path / "t.stl", lc.square_triangles(0.3, 0.0))
    text = (tmp_path / "t.stl").read_text()
    assert text.count("facet normal") == 2 and "vertex 0.3 0.3 0" in text


def test_the_naive_copy_keeps_the_rolling_coefficient_as_it_is(tmp_path):
    d = tmp_path / "study" / "calibrated"
    d.mkdir(parents=True)
    shutil.copyfile(CONFIG_DIR / "materials" / "M2.yaml", d / "M2.yaml")
    export(d.parent, "M2", "liggghts", tmp_path / "out")
    text = (tmp_path / "out" / "in.M2.liggghts").read_text()
    naive = lc.naive_fragment(text, load_calibrated(d.parent, "M2"))

    def rolling(t):
        line = next(l for l in t.splitlines() if "coefficientRollingFriction" in l)
        return [float(v) for v in line.split("peratomtypepair")[1].split()[1:]]
    assert rolling(text)[0] == pytest.approx(0.70) and rolling(naive)[0] == pytest.approx(0.35)   # M2-M2
    assert rolling(text)[1:] == rolling(naive)[1:]                                              # walls: the same
    assert [l for l in text.splitlines() if "Rolling" not in l] == [l for l in naive.splitlines() if "Rolling" not in l]


def test_prime_seeds():
    assert lc.prime_at_or_above(100003) == 100003 and lc.prime_at_or_above(100004) == 100019
