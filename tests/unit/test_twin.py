"""bench/twin.py bookkeeping with a fake executor (no YADE): hidden values from the command
line or a YAML list, targets with their standard errors, per-parameter error and whether
the hidden value lies inside the 95 % interval, the markdown table."""
import json

import pytest

from bench_scripts import load_bench_script
from fake_rigs import FakeRigs


@pytest.fixture(scope="module")
def twin():
    return load_bench_script("twin")


def test_a_twin_from_the_command_line_recovers_its_hidden_values(twin, tmp_path):
    ex = FakeRigs()
    code = twin.main(["--hidden", "particle_density_kg_m3=3600", "rolling_resistance_coefficient=0.15",
                      "--out", str(tmp_path)], executor=ex, results=tmp_path / "results.jsonl", commit="abc123")
    assert code == 0
    (s,) = json.loads((tmp_path / "twins.json").read_text())
    targets = [j for j in ex.asked if j["seed"] >= 101]
    assert {j["rig"] for j in targets} == {"fill", "aor"} and len(targets) == 6      # 3 target seeds per rig
    assert s["runs_requested"] == len(ex.asked) - len(targets)
    assert s["targets"]["aor_mean_deg"]["value"] == pytest.approx(20 + 40 * 0.15, abs=1.0)
    assert s["targets"]["aor_mean_deg"]["standard_error"] > 0
    for name, hidden in (("particle_density_kg_m3", 3600.0), ("rolling_resistance_coefficient", 0.15)):
        p = s["parameters"][name]
        assert p["hidden"] == hidden
        assert p["error"] == pytest.approx((p["estimate"] - hidden) / hidden)
        assert p["inside"] == (p["low"] <= hidden <= p["high"])
        tolerance = {"particle_density_kg_m3": 60.0, "rolling_resistance_coefficient": 0.05}[name]   # shipped study
        assert abs(p["estimate"] - hidden) <= tolerance
    # the final pass ran last: its values and intervals are the ones scored
    assert [st["stage"] for st in s["stages"]] == ["density", "rolling_resistance", "rolling_density_final"]
    line = json.loads((tmp_path / "results.jsonl").read_text().splitlines()[0])
    assert line["git_commit"] == "abc123" and line["twin"] == "twin"
    md = (tmp_path / "twins.md").read_text()
    assert "| twin | particle_density_kg_m3 | 3600 |" in md and "parameter-twin pairs inside" in md
    # the twin's study file is a valid study config that names the targets' standard errors
    cfg = (tmp_path / "twin" / "twin.yaml").read_text()
    assert "standard_error_deg" in cfg and "standard_error_kg_m3" in cfg
    assert cfg.count("standard_error_seeds_count: 3") == 4      # density, AoR, final pass's fill and AoR


def test_a_list_of_twins_from_yaml(twin, tmp_path):
    spec = tmp_path / "twins.yaml"
    spec.write_text("- {name: light, hidden: {particle_density_kg_m3: 3000}}\n"
                    "- {name: heavy, hidden: {particle_density_kg_m3: 4500}}\n")
    code = twin.main(["--twins", str(spec), "--out", str(tmp_path / "out")], executor=FakeRigs(),
                     results=tmp_path / "results.jsonl", commit="abc123")
    assert code == 0
    summaries = json.loads((tmp_path / "out" / "twins.json").read_text())
    assert [s["twin"] for s in summaries] == ["light", "heavy"]
    assert len((tmp_path / "results.jsonl").read_text().splitlines()) == 2
    for s, hidden in zip(summaries, (3000.0, 4500.0)):
        p = s["parameters"]["particle_density_kg_m3"]
        assert abs(p["estimate"] - hidden) / hidden < 0.03


def test_table_counts_pairs_inside_and_the_largest_error(twin):
    def twin_summary(name, est, low, high, runs):
        return {"twin": name, "runs_requested": runs, "parameters": {
            "rolling_resistance_coefficient": {"hidden": 0.15, "estimate": est, "low": low, "high": high,
                                               "error": (est - 0.15) / 0.15, "inside": low <= 0.15 <= high}}}
    text = twin.table([twin_summary("a", 0.16, 0.14, 0.18, 40), twin_summary("b", 0.12, 0.11, 0.13, 52)])
    assert "| a | rolling_resistance_coefficient | 0.15 | 0.16 | 0.14 - 0.18 | +6.7 % | yes | 40 |" in text
    assert "| b | rolling_resistance_coefficient | 0.15 | 0.12 | 0.11 - 0.13 | -20.0 % | no | 52 |" in text
    assert "1 of 2 parameter-twin pairs inside their 95 % interval (50 %" in text
    assert "largest |error| 20.0 %" in text and "runs per twin 40, 52" in text


@pytest.mark.parametrize("argv, message", [
    (["--hidden", "density=3600"], "density: not a parameter a twin can hide"),
    (["--hidden", "particle_density_kg_m3=heavy"], "'heavy' is not a number"),
    (["--twins", "/nonexistent/twins.yaml"], "file not found"),
])
def test_bad_twin_definitions_exit_2_with_one_line(twin, tmp_path, capsys, argv, message):
    code = twin.main(argv + ["--out", str(tmp_path)], executor=FakeRigs(), results=tmp_path / "r.jsonl",
                     commit="x")
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "r.jsonl").exists()


def test_a_refused_target_seed_is_replaced_by_the_next_one(twin, tmp_path):
    """Seed 102 of the hidden fill is refused: the target is the mean of seeds 101, 103, 104."""
    ex = FakeRigs(refuse=lambda job: "blow-up" if job["seed"] == 102 else None)
    lab = tmp_path / "lab"
    out = twin.simulate_targets(ex, {"particle_density_kg_m3": 3600.0}, [101, 102, 103], lab)
    assert [j["seed"] for j in ex.asked] == [101, 102, 103, 104]
    assert out["bulk_density_kg_m3"][1] > 0
    never = FakeRigs(refuse=lambda job: "blow-up")
    with pytest.raises(twin.TwinError, match="fill: more than 3 target seeds refused"):
        twin.simulate_targets(never, {"particle_density_kg_m3": 3600.0}, [101, 102, 103], tmp_path / "lab2")
