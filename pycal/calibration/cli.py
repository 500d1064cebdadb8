"""`pycal fit-density`: the particle density of one material from the cell fill, as a
one-stage study (the same driver, runs and outputs as `pycal calibrate`)."""
from pathlib import Path

from ..errors import ConfigError

STUDY = """# written by pycal fit-density: one density stage
name: fit_density_{material}
seeds_count: {seeds}
materials:
  {material}:
    - stage: density
      rig: fill
      target: {{band_percent: {band}}}
      parameter: {{bounds: [{lo}, {hi}], tolerance_kg_m3: {tol}{start}}}
      max_runs_count: {budget}
"""


def _cmd_fit_density(args):
    from ..files import write_text
    from ..runner import LocalPool, DEFAULT_RUNS_DIR
    from .study import Study
    runs = Path(args.runs or DEFAULT_RUNS_DIR)
    out = Path(args.out or runs / "density")
    for name in ("seeds", "max_runs"):
        if getattr(args, name) < 1:
            raise ConfigError(f"--{name.replace('_', '-')}", "", "must be >= 1")
    start = f", start: {args.start_density}" if args.start_density is not None else ""
    cfg = out / f"fit_density_{args.material}.yaml"
    write_text(cfg, STUDY.format(material=args.material, seeds=args.seeds, band=args.band_percent,
                                        lo=args.bounds[0], hi=args.bounds[1], tol=args.tolerance_kg_m3,
                                        start=start, budget=args.max_runs))
    pool = LocalPool(runs_dir=runs, workers=args.workers, timeout_s=args.timeout_s)
    study = Study(cfg, pool, out, seed_base=args.seed)
    (row,) = study.run()
    p = row["parameters"][0]
    print(f"{args.material}: particle density {p['estimate']:.1f} kg/m3, 95 % interval "
          f"[{p['low']:.1f}, {p['high']:.1f}] (tolerance +-{p['tolerance']:g}): "
          f"{'met' if row['met'] else 'NOT met'}, {row['stop_reason']}; {row['runs_requested']} runs; "
          f"outputs in {study.out}")


def register(sub):
    s = sub.add_parser("fit-density", help="calibrate the particle density on the cell fill "
                                           "(simulated bulk density = lab bulk density)")
    s.add_argument("--material", required=True, help="material name (configs/materials/<name>.yaml)")
    s.add_argument("--seeds", type=int, default=3, help="runs (random fills) per point (default 3)")
    s.add_argument("--seed", type=int, default=1, help="first seed (default 1)")
    s.add_argument("--tolerance-kg-m3", type=float, default=50.0,
                   help="stop when the 95 %% interval is within +- this of the estimate (default 50 kg/m3)")
    s.add_argument("--band-percent", type=float, default=1.0, help="lab band on the bulk density (default 1 %%)")
    s.add_argument("--bounds", type=float, nargs=2, default=[1500.0, 9000.0], metavar=("LO", "HI"),
                   help="particle density bounds in kg/m3 (default 1500 9000)")
    s.add_argument("--max-runs", type=int, default=24, help="run budget (default 24)")
    s.add_argument("--start-density", type=float, default=None,
                   help="start particle density (default: the material config's value)")
    s.add_argument("--workers", type=int, default=None, help="parallel YADE processes (default: cores)")
    s.add_argument("--cpu-limit-s", "--timeout-s", dest="timeout_s", type=float, default=3600.0,
                   help="CPU-time limit per job in seconds (a starved run on a loaded machine is not stopped; "
                        "one that used no CPU for 10x this long is); --timeout-s is the old name")
    s.add_argument("--runs", default=None, help="runs directory for the job cache (default runs/)")
    s.add_argument("--out", default=None, help="output folder (default runs/density/)")
    s.set_defaults(func=_cmd_fit_density)
