"""Calibration commands (registered by pycal.extra_commands)."""
import sys


def _cmd_fit_density(args):
    from ..runner import LocalPool, DEFAULT_RUNS_DIR
    from .density import fit_density, default_out_dir
    runs = args.runs or str(DEFAULT_RUNS_DIR)
    out = args.out or str(default_out_dir(args.material))
    pool = LocalPool(runs_dir=runs, workers=args.workers, timeout_s=args.timeout_s)
    fit = fit_density(args.material, seeds=args.seeds, tolerance_percent=args.tolerance_percent,
                      max_iterations=args.max_iterations, executor=pool, out_dir=out,
                      first_seed=args.seed, start_density=args.start_density)
    print(f"{fit.material}: particle density {fit.particle_density_kg_m3:.1f} kg/m3, "
          f"solid fraction {fit.solid_fraction:.4f}, {fit.n_particles_mean:.1f} particles, "
          f"bulk density {fit.bulk_density_mean_kg_m3:.1f} +/- {fit.bulk_density_std_kg_m3:.1f} kg/m3 "
          f"(lab {fit.target_bulk_density_kg_m3:.0f}), misfit {fit.misfit_percent:+.2f} %, "
          f"{fit.iterations} iteration(s), {fit.wall_time_s:.0f} s, tolerance met: "
          f"{'yes' if fit.tolerance_met else 'NO'}")
    if not fit.tolerance_met:
        print(f"WARNING: {fit.message}", file=sys.stderr)


def register(sub):
    s = sub.add_parser("fit-density", help="calibrate the particle density on the cell fill "
                                           "(simulated bulk density = lab bulk density)")
    s.add_argument("--material", required=True, help="material name (configs/materials/<name>.yaml)")
    s.add_argument("--seeds", type=int, default=3, help="random fills per iteration (default 3)")
    s.add_argument("--seed", type=int, default=1, help="first seed (default 1)")
    s.add_argument("--tolerance-percent", type=float, default=1.0, help="tolerance on the mean (default 1 %%)")
    s.add_argument("--max-iterations", type=int, default=5, help="default 5")
    s.add_argument("--start-density", type=float, default=None,
                   help="start particle density (default: the material config's value)")
    s.add_argument("--workers", type=int, default=None, help="parallel YADE processes (default: cores)")
    s.add_argument("--timeout-s", type=float, default=3600.0, help="timeout per job in seconds")
    s.add_argument("--runs", default=None, help="runs directory for the job cache (default runs/)")
    s.add_argument("--out", default=None, help="output folder (default runs/density/<material>/)")
    s.set_defaults(func=_cmd_fit_density)
