"""What each rig measures at a geometric scale (issue 49 item 2): mean, seed SD, slopes and cost.

    /usr/bin/python3 bench/scaled_rigs.py RUNS_DIR CAMPAIGN [CAMPAIGN ...] [--scales 1,1.5,2] \
        [--seeds-at 1:8,1.5:4,2:3] [--workers 2] [--table-only] [--out tables.md]
    /usr/bin/python3 bench/scaled_rigs.py --list

A campaign is one rig and material over a few points of the parameters it may calibrate
(CAMPAIGNS below: base values, points, the responses read, the slopes asked for), run at
every scale of --scales (geometry.scale, pycal/rigs/scaling.py) with seeds SEED_BASE,
SEED_BASE+1, ... (seeds the shipped study never uses). The runs go through pycal's local
executor into RUNS_DIR, one YADE process per seed (CPU per run read from each result's
provenance), cached by job id: a stopped campaign resumes where it stopped.

Per scale and point it prints the mean, seed SD and count of each response, the particle
count and the median CPU per run; per slope (two points that differ in one parameter) the
change per unit of the parameter with its standard error, and the parameter's SD per CPU
hour: (seed SD / |slope|) / sqrt(runs per CPU hour), i.e. how well one CPU hour of runs at
that point would pin the parameter if the response were read there.
"""
import argparse
import math
import statistics
import sys
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
from pycal import LAB_DIR  # noqa: E402
from pycal.files import write_text  # noqa: E402
from pycal.post import responses  # noqa: E402

SEED_BASE = 1001               # the shipped study uses seed bases 1 and 101 (seeds below ~1000)
LIFT_10MM = {"rig.procedure.lift_speed_m_s": 0.01}     # the study's AoR stages and predictions


def rolling(material, value):
    """The rolling-resistance keys the study's rolling stages set together (the material's
    own pair and the steel and PVC walls) at `value`."""
    return {f"interactions.{m}.rolling_resistance_coefficient": value for m in (material, "steel", "pvc")}


def friction(material, value):
    return {f"interactions.{material}.friction_coefficient": value}


@dataclass(frozen=True)
class Campaign:
    rig: str
    material: str
    base: dict                      # overrides every point starts from
    points: dict                    # label -> overrides on top of base
    responses: tuple                # result keys or pycal.post.responses names
    slopes: tuple = ()              # (parameter label, point a, point b, override key read for x)
    about: str = ""
    extra: dict = field(default_factory=dict)


def pile_points(material):
    """Particle friction and rolling resistance over their study bounds (friction 0.1 - 1.0,
    rolling 0.02 - 1.5), one at a time around friction 0.5 / rolling 0.15."""
    def pt(f, r):
        return {**friction(material, f), **rolling(material, r)}
    return {"f0.5 r0.05": pt(0.5, 0.05), "f0.5 r0.15": pt(0.5, 0.15), "f0.5 r0.35": pt(0.5, 0.35),
            "f0.5 r1.0": pt(0.5, 1.0), "f0.15 r0.15": pt(0.15, 0.15), "f0.8 r0.15": pt(0.8, 0.15)}


def pile_slopes(material):
    fk, rk = f"interactions.{material}.friction_coefficient", f"interactions.{material}.rolling_resistance_coefficient"
    return (("rolling", "f0.5 r0.05", "f0.5 r0.15", rk), ("rolling", "f0.5 r0.15", "f0.5 r0.35", rk),
            ("rolling", "f0.5 r0.35", "f0.5 r1.0", rk),
            ("friction", "f0.15 r0.15", "f0.5 r0.15", fk), ("friction", "f0.5 r0.15", "f0.8 r0.15", fk))


def m2_first_look():
    """The three points of the issue's first look (friction / rolling 0.6 / 0.35, 0.6 / 0.15, 0.3 / 0.35)."""
    def pt(f, r):
        return {**friction("M2", f), **rolling("M2", r)}
    return {"f0.6 r0.35": pt(0.6, 0.35), "f0.6 r0.15": pt(0.6, 0.15), "f0.3 r0.35": pt(0.3, 0.35)}


FRICTION_CELL = {"rig.procedure.consolidation_stresses_pa": [12000, 90000],
                 "rig.procedure.measure_dynamic_friction": False,
                 "rig.procedure.pre_tilt_rate_deg_s": 20.0, "rig.procedure.tilt_rate_deg_s": 5.0}
E_CALIBRATED = {"contact.youngs_modulus_pa": 1.0e8}     # the stiffness stages end at their upper bound

CAMPAIGNS = {
    "aor_M2": Campaign(
        "aor", "M2", dict(LIFT_10MM), m2_first_look(), ("aor_mean_deg", "n_particles", "pile_height_m"),
        (("rolling", "f0.6 r0.15", "f0.6 r0.35", "interactions.M2.rolling_resistance_coefficient"),
         ("friction", "f0.3 r0.35", "f0.6 r0.35", "interactions.M2.friction_coefficient")),
        "M2 start values (E 2e7 Pa, density 2750), lift 10 mm/s"),
    "surcharge_M3-dry": Campaign(
        "surcharge", "M3-dry", dict(LIFT_10MM), pile_points("M3-dry"),
        ("aor_mean_deg", "surcharge_mean_deg", "n_particles", "pile_height_m"), pile_slopes("M3-dry"),
        "M3-dry start values (E 2e7 Pa, density 2750, adhesion 0.05 x weight), lift 10 mm/s; one run gives the "
        "pile before (aor_mean_deg) and after the vibration"),
    "fill_M2": Campaign(
        "fill", "M2", {}, {"start": {}}, ("solid_fraction", "bulk_density_kg_m3", "n_particles"), (),
        "M2 start values (density 2750)"),
    "internal_M3-dry": Campaign(
        "internal_friction", "M3-dry", {**FRICTION_CELL, **E_CALIBRATED},
        {f"f{f}": friction("M3-dry", f) for f in (0.1, 0.3, 0.5, 0.7)}
        | {"f0.5 r0.05": {**friction("M3-dry", 0.5), **rolling("M3-dry", 0.05)},
           "f0.5 r0.8": {**friction("M3-dry", 0.5), **rolling("M3-dry", 0.8)}},
        ("mean_mu_static", "friction_offset_mu_static", "n_particles"),
        (("friction", "f0.1", "f0.3", "interactions.M3-dry.friction_coefficient"),
         ("friction", "f0.3", "f0.5", "interactions.M3-dry.friction_coefficient"),
         ("friction", "f0.5", "f0.7", "interactions.M3-dry.friction_coefficient"),
         ("rolling", "f0.5 r0.05", "f0.5", "interactions.M3-dry.rolling_resistance_coefficient"),
         ("rolling", "f0.5", "f0.5 r0.8", "interactions.M3-dry.rolling_resistance_coefficient")),
        "cell free to tip, 12 + 90 kPa, static onset only, pre-tilt 20 deg/s then 5 deg/s, E 1e8 Pa, M3-dry "
        "start values otherwise (rolling 0.35)"),
    "wall_M2": Campaign(
        "wall_friction", "M2", {"rig.procedure.consolidation_stresses_pa": [12000, 40000, 90000], **E_CALIBRATED},
        {"steel0.3": {"interactions.steel.friction_coefficient": 0.3},
         "steel0.5": {"interactions.steel.friction_coefficient": 0.5}},
        ("mean_mu_static", "friction_offset_mu_static", "n_particles"),
        (("steel friction", "steel0.3", "steel0.5", "interactions.steel.friction_coefficient"),),
        "the study's wall stage: 12 / 40 / 90 kPa, E 1e8 Pa, M2 start values otherwise"),
}
WET_COHESION = {"model": "hysteretic", "force_fraction": 0.5, "pressure_fraction": 0.0896, "update_interval_s": 0.01}
CAMPAIGNS["internal_M3-wet"] = Campaign(
    "internal_friction", "M3-wet",
    {"rig.procedure.consolidation_stresses_pa": [12000, 40000, 90000], "rig.procedure.pre_tilt_rate_deg_s": 20.0,
     "rig.procedure.tilt_rate_deg_s": 5.0, "rig.procedure.pre_tilt_slide_fraction": 0.5,
     "rig.procedure.tilt_restart_rate_deg_s": 12.0, **E_CALIBRATED, **friction("M3-wet", 0.374),
     **rolling("M3-wet", 0.19), "interactions.M3-wet.cohesion": WET_COHESION},
    {"calibrated": {}}, ("friction_angle_offset_deg", "mean_mu_static", "n_particles"), (),
    "the wet cohesion stage's settings (12 / 40 / 90 kPa, holds after the onset) at e8de67a's calibrated wet "
    "values: hysteretic cohesion pressure_fraction 0.0896 with weight part 0.5, friction 0.374, rolling 0.19, "
    "E 1e8 Pa; the cohesion law is per contact of the same 25 mm spheres at every scale, so it is not rescaled")
CAMPAIGNS["fill_M3-dry"] = Campaign("fill", "M3-dry", {}, {"start": {}}, CAMPAIGNS["fill_M2"].responses, (),
                                    "M3-dry start values (density 2750)")


def value(result, name):
    """One response of one result: mean_mu_static (mean static friction over the steps, a
    step that sticks as pycal's STICKS_MU), a pycal.post.responses name, or a result key."""
    if name == "mean_mu_static":
        from pycal.post.friction import compared_values
        return statistics.mean(compared_values(result, "mu_static"))
    if name in responses.RESPONSES:
        return responses.get(name).value(result, LAB_DIR)
    v = result.get(name)
    return math.nan if v is None else float(v)


def parse_seeds_at(text):
    """'1:8,2:3' -> {1.0: 8, 2.0: 3}."""
    out = {}
    for part in text.split(","):
        s, n = part.split(":")
        out[float(s)] = int(n)
    return out


def jobs_of(campaign, scale, seeds):
    """[(point label, job)] of one campaign at one scale."""
    from pycal.jobs import resolve_job
    out = []
    for label, ov in campaign.points.items():
        o = {**campaign.base, **ov}
        if scale != 1:
            o["rig.geometry.scale"] = scale
        out += [(label, resolve_job(campaign.rig, campaign.material, o, seed=s)) for s in seeds]
    return out


def run(runs, names, seeds_at, workers):
    """Run every campaign at every scale (largest scale first: the longest runs start first)."""
    from pycal.runner import make_executor
    labelled = []
    for scale in sorted(seeds_at, reverse=True):
        for name in names:
            labelled += [(name, scale, label, job) for label, job in
                         jobs_of(CAMPAIGNS[name], scale, range(SEED_BASE, SEED_BASE + seeds_at[scale]))]
    ex = make_executor("local", runs_dir=runs, workers=workers, timeout_s=7200.0)
    ex.run([j for *_, j in labelled], raise_on_error=False)
    for msg in ex.last_errors:
        print(f"[refused] {msg}", flush=True)


def collect(runs, name, scales, seeds_at):
    """{scale: {point: [result or None]}} from RUNS_DIR (jobs resolved again: same ids)."""
    from pycal.runner import cached_result
    out = {}
    for scale in scales:
        pts = {}
        for label, job in jobs_of(CAMPAIGNS[name], scale, range(SEED_BASE, SEED_BASE + seeds_at[scale])):
            pts.setdefault(label, []).append(cached_result(job, runs))
        out[scale] = pts
    return out


def mean_sd(xs):
    v = [x for x in xs if x is not None and not math.isnan(x)]
    if not v:
        return math.nan, math.nan, 0
    return statistics.mean(v), (statistics.stdev(v) if len(v) > 1 else math.nan), len(v)


def fmt(x, digits=3):
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{digits}g}"


def point_rows(campaign, collected):
    """Markdown: scale, point, each response mean (SD; n), failed seeds, CPU per run."""
    head = "| scale | point | " + " | ".join(f"{r}: mean (SD; n)" for r in campaign.responses) + \
           " | seeds without a result | CPU s per run (median) |"
    lines = [head, "|" + "---|" * (len(campaign.responses) + 4)]
    for scale, pts in collected.items():
        for label, rs in pts.items():
            ok = [r for r in rs if r is not None]
            cells = []
            for resp in campaign.responses:
                m, sd, n = mean_sd([value(r, resp) for r in ok])
                cells.append(f"{fmt(m, 4)} ({fmt(sd, 2)}; {n})")
            cpu = statistics.median(r["provenance"]["cpu_time_s"] for r in ok) if ok else math.nan
            lines.append(f"| {scale:g} | {label} | " + " | ".join(cells) + f" | {len(rs) - len(ok)} | {fmt(cpu, 3)} |")
    return "\n".join(lines)


def slope(campaign, pts, a, b, key, resp):
    """(slope per unit, its SE, pooled seed SD, CPU s per run) of `resp` between points a and b."""
    ra, rb = [r for r in pts[a] if r is not None], [r for r in pts[b] if r is not None]
    xa, xb = (({**campaign.base, **campaign.points[p]})[key] for p in (a, b))
    ma, sa, na = mean_sd([value(r, resp) for r in ra])
    mb, sb, nb = mean_sd([value(r, resp) for r in rb])
    if na < 2 or nb < 2:
        return math.nan, math.nan, math.nan, math.nan
    dx = xb - xa
    sd = math.sqrt(((na - 1) * sa ** 2 + (nb - 1) * sb ** 2) / (na + nb - 2))
    cpu = statistics.median(r["provenance"]["cpu_time_s"] for r in ra + rb)
    return (mb - ma) / dx, math.sqrt(sa ** 2 / na + sb ** 2 / nb) / abs(dx), sd, cpu


def slope_rows(campaign, collected):
    """Markdown: per scale, slope and response: change per unit +- SE, pooled seed SD, the
    parameter's SD of one run (SD / |slope|) and of one CPU hour of runs."""
    lines = ["| scale | response | parameter: from -> to | change per unit (+- SE) | seed SD (pooled) | "
             "parameter SD of one run | parameter SD per CPU hour |", "|---|---|---|---|---|---|---|"]
    for scale, pts in collected.items():
        for resp in campaign.responses:
            if resp == "n_particles" or resp == "pile_height_m":
                continue
            for label, a, b, key in campaign.slopes:
                k, se, sd, cpu = slope(campaign, pts, a, b, key, resp)
                one = sd / abs(k) if k and not math.isnan(k) else math.nan
                hour = one / math.sqrt(3600.0 / cpu) if not math.isnan(one) else math.nan
                lines.append(f"| {scale:g} | {resp} | {label}: {a} -> {b} | {fmt(k, 3)} (+- {fmt(se, 2)}) | "
                             f"{fmt(sd, 2)} | {fmt(one, 2)} | {fmt(hour, 2)} |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs", nargs="?")
    ap.add_argument("campaigns", nargs="*")
    ap.add_argument("--list", action="store_true", help="list the campaigns and exit")
    ap.add_argument("--seeds-at", default="1:8,1.5:4,2:3", help="scale:seeds,... (default 1:8,1.5:4,2:3)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--table-only", action="store_true", help="only tabulate the runs already in RUNS_DIR")
    ap.add_argument("--out", default=None, help="also write the tables (markdown) here")
    args = ap.parse_args(argv)
    if args.list or not args.runs:
        for name, c in CAMPAIGNS.items():
            print(f"{name}: rig {c.rig}, {c.material}, {len(c.points)} points; {c.about}")
        return
    unknown = [n for n in args.campaigns if n not in CAMPAIGNS]
    if unknown or not args.campaigns:
        raise SystemExit(f"bench/scaled_rigs.py: campaigns: {', '.join(unknown) or 'none given'} "
                         f"(known: {', '.join(CAMPAIGNS)})")
    seeds_at = parse_seeds_at(args.seeds_at)
    if not args.table_only:
        run(args.runs, args.campaigns, seeds_at, args.workers)
    text = []
    for name in args.campaigns:
        c = CAMPAIGNS[name]
        got = collect(args.runs, name, sorted(seeds_at), seeds_at)
        text += [f"#### {name}: rig {c.rig}, {c.material} ({c.about}); seeds from {SEED_BASE}", "",
                 point_rows(c, got), ""]
        if c.slopes:
            text += [slope_rows(c, got), ""]
    print("\n".join(text))
    if args.out:
        write_text(Path(args.out), "\n".join(text) + "\n")


if __name__ == "__main__":
    main()
