"""--vtk (pycal.vtk_output.with_vtk): VTK snapshots are part of the job only when asked for.
Without --vtk the job (and its hash and folder) is exactly the job without the option; with
it the job gets `vtk: {interval_s, folder, recorders}` and a new job_id; a bad interval is
refused in one line (exit 2). The snapshots themselves: tests/yade/test_vtk.py and
tests/yade/test_transfer.py."""
import json

import pytest

from pycal.cli import main
from pycal.errors import ConfigError
from pycal.jobs import resolve_job
from pycal.vtk_output import RECORDERS, with_vtk


def _job_json(capsys, args):
    assert main(["job"] + args) in (None, 0)
    return json.loads(capsys.readouterr().out)


def test_without_vtk_the_job_is_unchanged(capsys):
    plain = resolve_job("fill", "M2", {}, seed=1)
    printed = _job_json(capsys, ["fill", "--material", "M2"])
    assert "vtk" not in printed and printed["job_id"] == plain["job_id"]


@pytest.mark.parametrize("rig, material", [("fill", "M2"), ("transfer", "mixed-dry"), ("aor_mixed", "mixed-wet")])
def test_vtk_changes_the_job_only_by_its_entry(capsys, rig, material):
    plain = resolve_job(rig, material, {}, seed=1)
    printed = _job_json(capsys, [rig, "--material", material, "--vtk", "0.1"])
    assert printed["vtk"] == {"interval_s": 0.1, "folder": "vtk", "recorders": RECORDERS}
    assert printed["job_id"] != plain["job_id"] and printed["job_id"].startswith(f"{rig}-{material}-s1-")
    assert {k: v for k, v in printed.items() if k not in ("vtk", "job_id")} == \
        {k: v for k, v in plain.items() if k != "job_id"}
    assert _job_json(capsys, [rig, "--material", material, "--vtk"])["vtk"]["interval_s"] == 0.05   # the default


def test_recorders_give_radius_velocity_material_and_walls():
    assert {"spheres", "velocity", "materialId", "facets"} <= set(RECORDERS)


@pytest.mark.parametrize("interval", [0.0, -1.0])
def test_a_bad_interval_is_refused(interval):
    with pytest.raises(ConfigError, match=r"--vtk: interval_s: .* must be a number of seconds > 0"):
        with_vtk(resolve_job("fill", "M2"), interval)


def test_too_many_snapshots_are_refused(capsys):
    # fill: up to 16.04 s simulated; 16.04 / 1e-4 = 160 400 snapshots > 20 000
    assert main(["job", "fill", "--material", "M2", "--vtk", "0.0001"]) == 2
    err = capsys.readouterr().err
    assert "--vtk: interval_s: 0.0001 s would write up to" in err and "limit 20000" in err
