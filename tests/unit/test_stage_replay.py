"""bench/stage_replay.py: a study's 1-D stages replayed point by point from runs.csv."""
import json

import pytest

from bench_scripts import load_bench_script


@pytest.fixture(scope="module")
def replay():
    return load_bench_script("stage_replay")


def _row(x, value):
    return {"parameters": json.dumps({"k": x}), "value": str(value)}


def test_points_are_consecutive_runs_of_one_value_three_at_a_time(replay):
    """A value run twice in a row is two points (the limit run over and over in the main job)."""
    rows = [_row(0.35, 44), _row(0.35, 52), _row(0.35, 47), _row(0.1025, 36), _row(0.1025, 43), _row(0.1025, 37),
            _row(0.1025, 42), _row(0.1025, 26), _row(0.1025, 48), _row(0.45, 50)]
    pts = replay.points_of(rows, "k", 3)
    assert [x for x, _ in pts] == [0.35, 0.1025, 0.1025, 0.45]
    assert pts[2][1] == [42.0, 26.0, 48.0] and pts[3][1] == [50.0]


def test_a_folder_without_runs_csv_is_refused_with_exit_2(replay, tmp_path, capsys):
    assert replay.main([str(tmp_path)]) == 2
    assert "runs.csv: not found" in capsys.readouterr().err
