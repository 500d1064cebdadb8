"""Cross-code check of the export (issue 30): the cell fill and the cylinder-lift AoR of
this project's own geometry, run in LIGGGHTS-PUBLIC from `pycal export --format liggghts`
and in YADE from the same calibrated study, compared seed for seed over many seeds.

    /usr/bin/python3 bench/liggghts_cross.py --calibrated runs/study/zinc_ore \
        --material M2 --seeds 10 --out runs/bench_liggghts

For each material: the fill's bulk density (kg/m3) and the AoR mean angle (deg) of
--seeds fills in YADE (`pycal run`, the calibration's lift at 10 mm/s), in LIGGGHTS from
the export ("converted"), and in LIGGGHTS from the same numbers without the conversions
("naive": the rolling coefficient copied as it is). The LIGGGHTS deck follows the rig
configs: the 32-facet PVC cylinder (the pour column's height) on the steel table (STL
written from configs/rigs/*.yaml), a loose pour of the rig's porosity, settle, strike at
the rim (centres above it removed), settle; the AoR lifts the cylinder until its bottom is
the clearance above the highest particle, removes it and settles the pile; the pile is
read by pycal.post.aor, the same reading as YADE's. Rest = translational kinetic energy
below the numerics' rest_kinetic_energy_ratio x weight x diameter (YADE also asks for the
unbalanced force ratio). Output: <out>/cross_code.md and cross_code.json (means, SD, n,
difference of means and its standard error per quantity and variant).
LIGGGHTS comes from Debian (`apt-get install liggghts`; `./run.sh bench liggghts_cross`
installs it).
"""
import argparse
import json
import math
import re
import shutil
import statistics
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from pycal.configs import load_numerics, load_rig  # noqa: E402
from pycal.export.conversions import liggghts_rolling_coefficient  # noqa: E402
from pycal.export.formats import export, load_calibrated  # noqa: E402
from pycal.post import aor as aor_post  # noqa: E402
from pycal.runs_index import ok_results  # noqa: E402

LIFT_SPEED_M_S = 0.01       # the calibration's AoR stages (configs/calibrations/zinc_ore.yaml)


def prime_at_or_above(n):
    """LIGGGHTS wants prime seeds above 10000."""
    def is_prime(k):
        return k > 1 and all(k % d for d in range(2, int(k ** 0.5) + 1))
    while not is_prime(n):
        n += 1
    return n


def stl(path, triangles):
    """ASCII STL of [(v1, v2, v3)] (m)."""
    out = ["solid rig"]
    for tri in triangles:
        out += ["facet normal 0 0 0", "outer loop"] + [f"vertex {x:.9g} {y:.9g} {z:.9g}" for x, y, z in tri]
        out += ["endloop", "endfacet"]
    Path(path).write_text("\n".join(out + ["endsolid rig"]) + "\n")


def cylinder_triangles(radius, z0, z1, segments):
    """Side wall of a cylinder, vertices on the radius (as YADE's facetCylinder)."""
    pts = [(radius * math.cos(2 * math.pi * k / segments), radius * math.sin(2 * math.pi * k / segments))
           for k in range(segments)]
    tris = []
    for k in range(segments):
        (xa, ya), (xb, yb) = pts[k], pts[(k + 1) % segments]
        tris += [((xa, ya, z0), (xb, yb, z0), (xb, yb, z1)), ((xa, ya, z0), (xb, yb, z1), (xa, ya, z1))]
    return tris


def square_triangles(half, z):
    a, b, c, d = (-half, -half, z), (half, -half, z), (half, half, z), (-half, half, z)
    return [(a, b, c), (a, c, d)]


def atom_types(fragment):
    """{name: LIGGGHTS atom type} from the export's '# atom types: 1 = M2, 2 = steel' line."""
    listed = re.search(r"# atom types: (.*)", fragment).group(1)
    return {t.split(" = ")[1]: int(t.split(" = ")[0]) for t in listed.split(", ")}


def naive_fragment(text, ex):
    """The exported fragment with the rolling coefficients copied as they are (no radius
    convention converted): the 'naive' copy the conversions are measured against."""
    types = atom_types(text)
    names = sorted(types, key=types.get)

    def raw(a, b):
        p = ex.pair(a, b)
        return 0.0 if p is None else p["rolling_resistance_coefficient"]
    table = " ".join(f"{raw(a, b):.6g}" for a in names for b in names)
    return re.sub(r"(coefficientRollingFriction peratomtypepair \d+) .*", rf"\1 {table}", text)


def deck(fragment_file, types, rig, mat_diameter_m, seed, num, pile, dt_s):
    """The LIGGGHTS input of one fill (pile=False) or one AoR pile (pile=True)."""
    g, p = rig["geometry"], rig["procedure"]
    d, h = g["cell_inner_diameter_m"], g["cell_height_m"]
    r = 0.5 * mat_diameter_m
    column = p["pour_height_factor"] * h
    half = g.get("table_radius_m", 0.5 * d + 0.05)
    ke_ratio = num["rest_kinetic_energy_ratio"]
    chunk = 2000
    max_chunks = int(num["max_settle_time_s"] / (dt_s * chunk)) + 1
    insert_seed = prime_at_or_above(100003 + 7919 * 3 * seed)

    def settle(tag):
        return [f"variable n_{tag} loop {max_chunks}", f"label loop_{tag}", f"run {chunk}",
                f'if "$(ke) < $({ke_ratio:g}*mass(all)*9.81*{mat_diameter_m:g})" then "jump SELF done_{tag}"',
                f"next n_{tag}", f"jump SELF loop_{tag}", f'print "NOT_AT_REST {tag}"', "quit", f"label done_{tag}"]
    lines = [f"region domain block {-half - 0.05:g} {half + 0.05:g} {-half - 0.05:g} {half + 0.05:g} -0.05 "
             f"{column + 2 * h + 0.1:g} units box", f"include {fragment_file}",
             "neighbor 0.004 bin", "neigh_modify delay 0", "thermo_modify lost ignore norm no",
             "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
             f"fix table all mesh/surface file table.stl type {types[g['table_material']]}",
             f"fix cyl all mesh/surface file cyl.stl type {types[g['cell_material']]}",
             "fix walls all wall/gran model hertz tangential history rolling_friction epsd2 mesh n_meshes 2 "
             "meshes table cyl",
             f"region pour cylinder z 0 0 {0.5 * d - 1.01 * r:.6g} 0 {column:.6g} units box",
             f"fix ins all insert/pack seed {insert_seed} distributiontemplate pdd insert_every once "
             f"overlapcheck yes all_in yes volumefraction_region {1.0 - p['pour_porosity_ratio']:.6g} region pour",
             "fix integr all nve/sphere", "thermo 20000", "run 1"]
    lines += settle("pour")
    lines += [f"region above block INF INF INF INF {p['strike_level_height_m']:.6g} INF units box",
              "delete_atoms region above", "run 1"]
    lines += settle("strike")
    lines += ['print "FILL_MASS_KG $(mass(all)) FILL_COUNT $(count(all))"']
    if pile:
        clear = p["lift_clearance_m"]
        lines += [f"variable lift_s equal ($(bound(all,zmax))+{r + clear:g})/{LIFT_SPEED_M_S:g}",
                  f"fix lift all move/mesh mesh cyl linear 0. 0. {LIFT_SPEED_M_S:g}",
                  "run $(ceil(v_lift_s/dt))", "unfix lift", "unfix walls", "unfix cyl",
                  "fix walls all wall/gran model hertz tangential history rolling_friction epsd2 mesh n_meshes 1 "
                  "meshes table", "run 1"]
        lines += settle("pile")
        lines += ["region offtable block INF INF INF INF INF -0.001 units box", "delete_atoms region offtable",
                  "dump final all custom 1 pile.txt id type x y z radius", "run 0", "undump final"]
    return "\n".join(lines) + "\n"


def run_liggghts(folder, fragment, ex, material, rig_name, seed, num):
    """One LIGGGHTS run; returns {'bulk_density_kg_m3'} or {'aor_mean_deg', ...}."""
    rig = load_rig(rig_name)
    g = rig["geometry"]
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "material.liggghts").write_text(fragment)
    types = atom_types(fragment)
    column = rig["procedure"]["pour_height_factor"] * g["cell_height_m"]
    dia = ex.components[material]["particles"]["diameter_m"]
    stl(folder / "cyl.stl", cylinder_triangles(0.5 * g["cell_inner_diameter_m"], 0.0, column + dia,
                                               g["cell_facet_segments_count"]))
    stl(folder / "table.stl", square_triangles(g.get("table_radius_m", 0.5 * g["cell_inner_diameter_m"] + 0.05), 0.0))
    dt = float(re.search(r"^timestep (\S+)", fragment, re.M).group(1))
    (folder / "in.rig").write_text(deck("material.liggghts", types, rig, dia, seed, num, rig_name == "aor", dt))
    proc = subprocess.run(["liggghts", "-in", "in.rig", "-log", "log.liggghts"], cwd=folder, capture_output=True,
                          text=True)
    text = proc.stdout
    if proc.returncode != 0 or "NOT_AT_REST" in text or "ERROR" in text:
        raise RuntimeError(f"{folder}: LIGGGHTS failed: {(text + proc.stderr)[-600:]}")
    mass = float(re.search(r"FILL_MASS_KG (\S+)", text).group(1))
    vol = math.pi * 0.25 * g["cell_inner_diameter_m"] ** 2 * g["cell_height_m"]
    out = {"bulk_density_kg_m3": mass / vol}
    if rig_name == "aor":
        rows = [l.split() for l in (folder / "pile.txt").read_text().splitlines()[9:] if l.strip()]
        pos = [(float(x), float(y), float(z), float(rad)) for _, _, x, y, z, rad in rows]
        m = aor_post.measure_from_config(pos, rig["measure"])
        out = {"aor_mean_deg": m["mean_deg"], "aor_sectors_count": m["sectors_count"], "n_particles": len(pos)}
    return out


def run_yade(study, material, rig_name, seeds, out):
    """The same rig in YADE through `pycal run` (cached: a job is its result)."""
    cmd = [sys.executable, "-m", "pycal", "run", rig_name, "--material", material, "--calibrated", str(study),
           "--seeds", str(seeds), "--out", str(out), "--replicas", "1"]
    if rig_name == "aor":
        cmd += ["--set", f"rig.procedure.lift_speed_m_s={LIFT_SPEED_M_S}"]
    subprocess.run(cmd, cwd=REPO, check=True, capture_output=True, text=True)
    key = "aor_mean_deg" if rig_name == "aor" else "bulk_density_kg_m3"
    vals = []
    for _, r in ok_results(out, rig_name, material):
        if r["job"]["seed"] <= seeds and r.get(key) is not None:
            vals.append(r[key])
    return vals


def variant_study(study, out, material, settings):
    """A copy of the study's calibrated values of `material` with KEY=VALUE settings
    applied in both places the two codes read them (summary.json overrides for YADE's
    `pycal run --calibrated`, calibrated/<material>.yaml for the export): to find which
    convention makes the codes differ (e.g. rolling resistance 0 in both)."""
    import yaml
    dst = Path(out) / "study"
    (dst / "calibrated").mkdir(parents=True, exist_ok=True)
    summ = json.loads((Path(study) / "summary.json").read_text())
    mat = yaml.safe_load((Path(study) / "calibrated" / f"{material}.yaml").read_text())
    for key, value in settings.items():
        summ["overrides"].setdefault(material, {})[key] = value
        node = mat
        *head, last = key.split(".")
        for k in head:
            node = node[k]
        node[last] = value
    (dst / "summary.json").write_text(json.dumps({"overrides": summ["overrides"]}))
    (dst / "calibrated" / f"{material}.yaml").write_text(yaml.safe_dump(mat, sort_keys=False))
    return dst


def summary(values):
    v = [x for x in values if x is not None and not math.isnan(x)]
    sd = statistics.stdev(v) if len(v) > 1 else float("nan")
    return {"mean": statistics.fmean(v) if v else float("nan"), "sd": sd, "n": len(v)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--calibrated", required=True)
    ap.add_argument("--material", action="append", required=True)
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--out", default="runs/bench_liggghts")
    ap.add_argument("--rigs", nargs="+", default=["fill", "aor"])
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a material key set in both codes (e.g. interactions.M2.rolling_resistance_coefficient=0)")
    args = ap.parse_args(argv)
    if shutil.which("liggghts") is None:
        sys.exit("liggghts not found: apt-get install liggghts (or ./run.sh bench liggghts_cross)")
    out = Path(args.out)
    num = load_numerics()
    table = []
    settings = {k: float(v) for k, v in (item.split("=", 1) for item in args.set)}
    for material in args.material:
        study = variant_study(args.calibrated, out / material, material, settings) if settings else args.calibrated
        ex = load_calibrated(study, material)
        frag_dir = out / material / "export"
        export(study, material, "liggghts", frag_dir)
        converted = (frag_dir / f"in.{material}.liggghts").read_text()
        variants = {"converted": converted, "naive": naive_fragment(converted, ex)}
        for rig in args.rigs:
            key = "aor_mean_deg" if rig == "aor" else "bulk_density_kg_m3"
            yade = summary(run_yade(study, material, rig, args.seeds, out / material / "yade"))
            row = {"material": material, "rig": rig, "quantity": key, "yade": yade}
            for name, frag in variants.items():
                vals = []
                for seed in range(1, args.seeds + 1):
                    res = run_liggghts(out / material / f"liggghts-{name}" / f"{rig}-s{seed}", frag, ex, material,
                                       rig, seed, num)
                    vals.append(res[key])
                    print(f"{material} {rig} {name} seed {seed}: {key} {res[key]:.4g}", flush=True)
                s = summary(vals)
                se = math.sqrt(s["sd"] ** 2 / s["n"] + yade["sd"] ** 2 / yade["n"])
                row[name] = dict(s, diff=s["mean"] - yade["mean"], se=se)
            table.append(row)
            print(json.dumps(row), flush=True)
    (out / "cross_code.json").write_text(json.dumps(table, indent=1))
    lines = ["| material | quantity | YADE mean (SD, n) | LIGGGHTS converted (SD, n) | diff +- SE | "
             "LIGGGHTS naive (SD, n) | diff +- SE |", "|---|---|---|---|---|---|---|"]
    for r in table:
        cells = [r["material"], r["quantity"], f"{r['yade']['mean']:.4g} ({r['yade']['sd']:.3g}, {r['yade']['n']})"]
        for name in ("converted", "naive"):
            v = r[name]
            cells += [f"{v['mean']:.4g} ({v['sd']:.3g}, {v['n']})", f"{v['diff']:+.3g} +- {v['se']:.3g}"]
        lines.append("| " + " | ".join(cells) + " |")
    (out / "cross_code.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
