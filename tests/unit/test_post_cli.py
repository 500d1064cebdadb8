"""The shared command line of pycal.post.compression and pycal.post.friction: a bad
file is one line `error: <file>: <reason>`, exit 2, nothing written."""
import json

from pycal.post import compression, friction


def test_missing_file_is_one_line_exit_2(tmp_path, capsys):
    for mod in (compression, friction):
        assert mod.main([str(tmp_path / "nope.json")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert err == [f"error: {tmp_path / 'nope.json'}: file not found"]
    assert list(tmp_path.iterdir()) == []


def test_not_a_result_is_one_line_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    other = tmp_path / "other.json"
    other.write_text(json.dumps({"x": 1}))
    assert compression.main([str(bad)]) == 2
    assert "not valid JSON" in capsys.readouterr().err
    assert friction.main([str(other)]) == 2
    assert capsys.readouterr().err.strip() == f"error: {other}: rig: missing: not the result.json of a rig run"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.json", "other.json"]


def test_friction_refuses_results_of_two_rigs(tmp_path, capsys):
    paths = []
    for rig in ("wall_friction", "ccs"):
        p = tmp_path / f"{rig}.json"
        p.write_text(json.dumps({"rig": rig, "material": "M2", "seed": 1, "stress_pa": [3000]}))
        paths.append(str(p))
    assert friction.main(paths + ["--out", str(tmp_path / "out")]) == 2
    assert "results of one friction rig" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()
