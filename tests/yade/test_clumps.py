"""M1 lumps as clumps of spheres (yade_scripts/demlib/clumps.py) and the mixed fill
(demlib/mixed.py), with known answers:

- a YADE clump made by clumps.make_clump has its centroid at the box centre (symmetry)
  and its principal frame follows the lump's axes; YADE's own grid integration agrees
  with the reference union values (mass 3 %, inertia 5 %), while its member sums count
  the overlaps again (far too heavy);
- a single slab dropped tilted and sliding onto the steel table comes to rest lying
  flat and stays put (no rolling: rolling resistance 0 on M1, the shape does it), and
  the table carries its weight: lump mass x g (the mass YADE moves is the union's);
- a generated mixed fill placed in YADE holds the planned masses without overlaps;
- the aor_mixed rig runs end to end (fast lift): a pile, lumps kept by the strike, and
  the time step of pycal.step_estimate.
The pure-numpy parts (reference integrator, lump rule, fill planning) are tested in
tests/unit/test_clumps_geometry.py.

YADE scenes are small scripts written into the test's tmp folder and run with
`yade -j1 -x -n`; each prints one JSON line.
"""
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from pycal.jobs import resolve_job
from pycal.runner import run_job, yade_env
from yade_scripts.demlib import clumps  # pure-Python parts: numpy only

from documented import assert_documented

pytestmark = pytest.mark.yade

SHAPES = resolve_job("aor_mixed", "mixed-dry")["materials"]["M1"]["particles"]["shapes"]
DENSITY = 2750.0
SIZE = 0.04

HEADER = f"""
import json, os, sys
from yade import O, utils
def done(data):
    print("JSON " + json.dumps(data), flush=True)
    sys.stdout.flush(); os._exit(0)
job = json.load(open(sys.argv[1]))
"""


def run_yade(tmp_path, body, job, timeout=300):
    d = Path(tmp_path)
    d.mkdir(parents=True, exist_ok=True)
    (d / "job.json").write_text(json.dumps(job))
    (d / "scene.py").write_text(HEADER + body)
    proc = subprocess.run(["yade", "-j1", "-x", "-n", "scene.py", "job.json"], cwd=d, capture_output=True,
                          text=True, timeout=timeout, env=yade_env())
    lines = [l for l in proc.stdout.splitlines() if l.startswith("JSON ")]
    assert proc.returncode == 0 and lines, f"scene failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    return json.loads(lines[-1][5:])


# ---------------------------------------------------------------- YADE clump mass and inertia

CLUMP_SCENE = """
import numpy as np, random
from yade.wrapper import CohFrictMat
from yade_scripts.demlib import clumps
mat = O.materials.append(CohFrictMat(density=2750, young=6e6))
shapes = job["materials"]["M1"]["particles"]["shapes"]
rng = random.Random(7)
out = {}
for name, s in sorted(shapes.items()):
    R = clumps.random_rotation(rng)[0]
    for tag, D, exact, rot in (("made", clumps.YADE_DISCRETIZATION, True, R), ("yade_D15_aligned", 15, False, None),
                               ("yade_D15_rotated", 15, False, R), ("yade_D0", 0, False, None)):
        cid, mids = clumps.make_clump(s, 0.04, 2750.0, mat, (0, 0, 1.0), rotation=rot, discretization=D, exact=exact)
        st = O.bodies[cid].state
        axes = [list(st.ori * v) for v in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
        out[name + "/" + tag] = {"mass": st.mass, "inertia": [st.inertia[k] for k in range(3)],
                                 "axes": axes, "R": R.tolist(), "centre": list(st.pos), "n": len(mids)}
        O.bodies.erase(cid, True)
done(out)
"""


@pytest.fixture(scope="module")
def yade_clumps(tmp_path_factory):
    return run_yade(tmp_path_factory.mktemp("clumps"), CLUMP_SCENE, resolve_job("aor_mixed", "mixed-dry"))


@pytest.mark.parametrize("shape", ["oblong", "rounded", "slab"])
def test_clump_mass_and_inertia(yade_clumps, shape):
    s = SHAPES[shape]
    m_ref = clumps.lump_mass(s, SIZE, DENSITY)
    i_ref = clumps.lump_principal_inertia(s, SIZE, DENSITY)
    made = yade_clumps[f"{shape}/made"]
    assert np.allclose(made["centre"], [0, 0, 1.0], atol=SIZE * 2e-3)   # centroid = box centre (symmetry)
    # YADE's principal frame: for an oblong the smallest inertia is about the long (local z)
    # axis, for a slab the largest about its thickness (local z): the ascending order of
    # the reference values matches YADE's
    R = np.array(made["R"])
    if shape == "oblong":
        assert abs(np.dot(made["axes"][0], R[:, 2])) > 0.999
    if shape == "slab":
        assert abs(np.dot(made["axes"][2], R[:, 2])) > 0.999
    # what YADE alone gives (reported; bounds from the measurement in clumps.py's doc)
    for tag in ("yade_D15_aligned", "yade_D15_rotated"):
        y = yade_clumps[f"{shape}/{tag}"]
        print(shape, tag, "mass err %+.4f" % (y["mass"] / m_ref - 1),
              "inertia err", np.round(np.array(y["inertia"]) / i_ref - 1, 4))
        assert y["mass"] == pytest.approx(m_ref, rel=0.03)
        assert y["inertia"] == pytest.approx(list(i_ref), rel=0.05)
    d0 = yade_clumps[f"{shape}/yade_D0"]
    print(shape, "sum of members (D=0): mass x %.3f" % (d0["mass"] / m_ref))
    assert d0["mass"] > 1.5 * m_ref          # overlaps counted again: far too heavy


# ---------------------------------------------------------------- a slab rests on a plate

SLAB_SCENE = """
import math, random
import numpy as np
from yade_scripts.demlib import clumps, mixed
sc = mixed.MixedScene(job)
table = sc.add_table(0.3, "steel")
sc.set_domain((-0.3, -0.3, -0.05), (0.3, 0.3, 0.3))
s = job["materials"]["M1"]["particles"]["shapes"]["slab"]
size = 0.04
R = clumps.random_rotation(random.Random(3))[0]
centres, r = clumps.shape_members(s, size)
z0 = clumps.bounding_radius(centres, r) + 0.02
sc.add_placements([({"material": "M1", "kind": "clump", "shape": "slab", "size_m": size}, (0, 0, z0), R)])
cid = list(sc.clumps)[0]
sc.set_timestep()
st = O.bodies[cid].state
st.vel = (0.1, 0, 0)                        # lands sliding
from yade_scripts.demlib.phases import drive
t_rest = drive(sc.settle("slab"))
pos0 = np.array(st.pos)
sc.advance(int(1.0 / O.dt))                 # one more second at rest
pos1 = np.array(st.pos)
weight = -sum(O.forces.f(i)[2] for i in table)   # what the table carries
# thickness axis = principal axis of the largest inertia
normal = np.array(st.ori * __import__("yade").Vector3(0, 0, 1))
done({"t_rest": t_rest, "drift_m": float(np.linalg.norm(pos1 - pos0)), "ang_vel": st.angVel.norm(),
      "vel": st.vel.norm(), "tilt_deg": math.degrees(math.acos(min(1.0, abs(normal[2])))),
      "height_m": float(pos1[2]), "thickness_m": 0.5 * size, "travel_m": float(pos1[0]),
      "ke_ratio": sc.kinetic_energy_ratio(), "dt": O.dt, "table_force_n": weight,
      "weight_n": clumps.lump_mass(s, size, job["materials"]["M1"]["particles"]["density_kg_m3"]) * sc.g})
"""


def test_single_slab_rests_flat_on_plate_without_rolling(tmp_path):
    job = resolve_job("aor_mixed", "mixed-dry")
    m = run_yade(tmp_path, SLAB_SCENE, job)
    print("slab", m)
    assert m["t_rest"] < 3.0                                  # comes to rest (no endless rolling)
    assert m["tilt_deg"] < 3.0                                # lies flat on a face
    assert m["height_m"] == pytest.approx(m["thickness_m"] / 2, rel=0.03)   # centre at half thickness
    assert m["drift_m"] < 1e-5 and m["ang_vel"] < 1e-3        # and stays put
    assert abs(m["travel_m"]) < 0.1
    # at rest the table carries the lump's weight: the mass YADE moves is the union's
    # (not the members' sum, 1.6 - 2.2 x heavier)
    assert m["table_force_n"] == pytest.approx(m["weight_n"], rel=0.005)


FILL_SCENE = """
from yade_scripts.demlib import mixed
sc = mixed.MixedScene(job)
gen = mixed.generate(job)
g = job["rig_config"]["geometry"]
sc.add_table(0.3, "steel")
sc.add_cylinder(g["cell_inner_diameter_m"], gen["column_height_m"] + 0.03, g["cell_facet_segments_count"], g["cell_material"])
sc.add_placements(gen["placements"])
masses = sc.component_masses()
sc.set_timestep()
O.step()
pen = [i.geom.penetrationDepth for i in O.interactions if i.isReal]
done({"masses": masses, "n_clumps": len(sc.clumps), "max_penetration_m": max(pen) if pen else 0.0,
      "planned": mixed.placed_masses(gen["placements"])[0]})
"""


def test_fill_in_yade_holds_the_planned_masses_without_overlaps(tmp_path):
    job = resolve_job("aor_mixed", "mixed-wet", seed=1)
    m = run_yade(tmp_path, FILL_SCENE, job)
    print("fill", m)
    assert m["n_clumps"] >= 1
    for name, kg in m["planned"].items():
        assert m["masses"][name] == pytest.approx(kg, rel=1e-9)
    assert m["max_penetration_m"] <= 1e-9


# ---------------------------------------------------------------- the rig end to end

def test_aor_mixed_rig_runs_and_reports(tmp_path):
    from pycal.step_estimate import critical_timestep
    job = resolve_job("aor_mixed", "mixed-dry", {"rig.procedure.lift_speed_m_s": 0.05}, seed=1)
    res = run_job(job, runs_dir=tmp_path, timeout_s=900)
    print({k: v for k, v in res.items() if k not in ("job", "provenance")})
    assert res["aor_mean_deg"] > 10.0                       # a pile, not a monolayer
    assert res["n_clumps_in_pile"] >= 1
    # the strike removes spheres only: the lumps' share can only grow, the mass only shrink
    assert res["mass_fraction_M1_final"] >= res["mass_fraction_M1_generated"]
    assert res["fill_mass_kg"] <= res["generated_mass_kg"]
    # YADE's time step comes from the smallest member sphere of the lumps drawn; pycal's
    # estimate before the run assumes the smallest possible one (a 25 mm oblong: 5.15 mm),
    # so it is never longer than YADE's, and a lump member is smaller than a 25 mm sphere
    # (whose step is 0.5 x 0.0125 m / sqrt(2e7 Pa / 2750 kg/m3) = 7.329e-5 s)
    assert critical_timestep(job)[0] <= res["timestep_s"] < 7.329e-5
    assert_documented(res)
    out = tmp_path / "aor_mixed" / job["job_id"]
    for f in ("pile_particles.csv", "pile_profile.csv", "pile_upper_profile.csv", "pile_side.png"):
        assert (out / f).is_file(), f
