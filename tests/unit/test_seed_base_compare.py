"""bench/seed_base_compare.py: which calibrated intervals of two seed bases overlap."""
import json

import pytest

from bench_scripts import load_bench_script


@pytest.fixture(scope="module")
def compare():
    return load_bench_script("seed_base_compare")


def _summary(seed_base, params):
    """A summary.json with one stage per (material, stage, label, estimate, low, high, stop)."""
    return {"seed_base": seed_base, "git_commit": "abc",
            "stages": [{"material": m, "stage": s, "stop_reason": stop,
                        "parameters": [{"label": lab, "estimate": e, "low": lo, "high": hi}]}
                       for m, s, lab, e, lo, hi, stop in params]}


def test_overlap_disjoint_touching_and_one_sided_rows(compare, tmp_path):
    a = _summary(1, [("M2", "density", "particle density", 3750, 3700, 3800, "met"),
                     ("M2", "rolling", "rolling", 0.2, 0.15, 0.25, "budget"),
                     ("M2", "wall", "friction", 0.5, 0.45, 0.55, "met"),
                     ("M3", "rolling_from_dry", "rolling", 0.2, 0.1, 0.3, "inherited: budget"),
                     ("M3", "density", "particle density", 2700, 2650, 2750, "met")])
    b = _summary(101, [("M2", "density", "particle density", 3850, 3801, 3900, "met"),   # 1 kg/m3 apart
                       ("M2", "rolling", "rolling", 0.3, 0.25, 0.35, "budget"),         # touching
                       ("M2", "wall", "friction", 0.52, 0.5, 0.54, "met"),              # inside
                       ("M3", "rolling_from_dry", "rolling", 0.9, 0.8, 1.0, "inherited: budget")])
    lines = compare.compare(a, b)
    rows = {" ".join(c.strip("| ") for c in l.split(" | ")[:2]): l for l in lines if l.startswith("| M")}
    assert rows["M2 density"].endswith("| **no** |")
    assert rows["M2 rolling"].endswith("| yes |")
    assert rows["M2 wall"].endswith("| yes |")
    assert rows["M3 rolling_from_dry"].endswith("| (inherited) |")
    assert rows["M3 density"].endswith("| - | - |")
    assert lines[-1] == "2 of 3 parameters calibrated by both runs have overlapping 95 % intervals."
    pa, pb, out = tmp_path / "a.json", tmp_path / "b.json", tmp_path / "t.md"
    pa.write_text(json.dumps(a))
    pb.write_text(json.dumps(b))
    assert compare.main([str(pa), str(pb), "--out", str(out)]) == 0
    assert "2 of 3" in out.read_text()


def test_a_file_that_is_not_a_summary_exits_2(compare, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"study": "x"}')
    with pytest.raises(SystemExit) as exc:
        compare.main([str(bad), str(bad)])
    assert exc.value.code == 2
