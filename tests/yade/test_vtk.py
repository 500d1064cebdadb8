"""VTK snapshots for ParaView (--vtk) on a lab rig: the cell fill (one scene, pour, strike,
settle). Known without the code: the last snapshot holds the particles left in the struck
cell (result n_particles), every one of them an M2 sphere of radius 12.5 mm (YADE material
0: the job's first material), at rest (speed far below 1 m/s); the facets are the table
(a square of 2 triangles) and the cylinder wall (2 triangles per segment:
2 + 2 x 32 = 66); one snapshot per interval of simulated time, the first at the start and
one at the end. The transfer rig's snapshots are checked in test_transfer.py.
"""
import re

import pytest

from pycal.jobs import resolve_job
from pycal.runner import run_job
from pycal.vtk_output import with_vtk

from scene_runner import LAB_SIZE
from vtk_files import vtu_header

pytestmark = pytest.mark.yade

INTERVAL_S = 0.25


def test_fill_snapshots_hold_the_struck_cell(tmp_path_factory):
    runs = tmp_path_factory.mktemp("vtk_fill")
    plain = resolve_job("fill", "M2", LAB_SIZE, seed=2)
    job = with_vtk(plain, INTERVAL_S)
    assert job["job_id"] != plain["job_id"] and {k: v for k, v in job.items() if k not in ("vtk", "job_id")} == \
        {k: v for k, v in plain.items() if k != "job_id"}
    res = run_job(job, runs_dir=runs, timeout_s=600)
    folder = runs / "fill" / job["job_id"] / "vtk"
    text = (folder / "fill-spheres.pvd").read_text()
    snaps = [(float(t), folder / f) for t, f in re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', text)]
    assert len(snaps) == res["vtk_snapshots_count"] and all(f.is_file() for _, f in snaps)
    simulated = res["provenance"]["simulated_time_s"]
    assert simulated / INTERVAL_S <= len(snaps) <= simulated / INTERVAL_S + 2
    assert snaps[0][0] == 0.0 and snaps[-1][0] == pytest.approx(simulated, abs=1e-9)
    n, _, arrays = vtu_header(snaps[-1][1])
    print("last snapshot", snaps[-1], n, arrays)
    assert n == res["n_particles"]
    assert arrays["radii"] == (0.0125, 0.0125)
    assert arrays["materialId"] == (0.0, 0.0)
    assert arrays["linVelLen"][1] < 0.05
    facets = sorted(folder.glob("fill-scene1-facets.*.vtu"))
    assert len(facets) == len(snaps)
    _, cells, _ = vtu_header(facets[-1])
    assert cells == 2 + 2 * 32
