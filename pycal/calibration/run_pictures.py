"""The pictures and per-seed values of a set of runs for the report (pycal.calibration.
gallery for the stages, pycal.calibration.validation for the predictions): where a run's
folder is, a pile's doubtful flank fits, a prediction's pictures and values per seed.
"""
import shutil
from pathlib import Path

from .. import rigs
from ..executors.base import wrapped_chain
from ..replicas import result_folder


def runs_dir_of(executor):
    """The runs folder of an executor (through wrappers such as ReplicaExecutor), or None."""
    return next((Path(e.runs_dir) for e in wrapped_chain(executor) if getattr(e, "runs_dir", None) is not None), None)


def run_flank_flags(result, runs):
    """{sector: reason} of a pile's doubtful flank fits (pycal.post.aor method step 7): from
    result.json, or refitted from the run's pile_profile.csv for runs made before the flag."""
    if "aor_flank_flags" in result:
        return result["aor_flank_flags"] or {}
    if runs is None:
        return {}
    from ..post import aor
    profile = Path(result_folder(result, result["job"], runs)) / "pile_profile.csv"
    return aor.flank_flags({"fits": aor.read_profile_fits(profile)}) if profile.is_file() else {}


def copy_pictures(study, src, names, rig, prefix, caption):
    """Copy the pictures `names` a run wrote into its folder `src` to <prefix><name>
    (inside the study folder) for the report: [{'file': path relative to the study
    folder, 'rig', 'caption': caption + name}] of those that exist."""
    out = []
    for name in names:
        if (Path(src) / name).is_file():
            dest = Path(f"{prefix}{name}")
            dest.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(Path(src) / name, dest)
            out.append({"file": str(dest.relative_to(study.out)), "rig": rig, "caption": caption + name})
    return out


def prediction_pictures(study, name, rig, results, seeds_shown=3):
    """[{'file', 'rig', 'caption'}] of a validation prediction: the pictures its rig writes
    (e.g. the side view of the mixed pile with every sector's angle) for its first
    seeds_shown seeds, copied into <study>/plots/validation-<name>/."""
    runs = runs_dir_of(study.executor)
    pictures = rigs.get(rig).pictures
    if runs is None or not pictures:
        return []
    folder = study.out / "plots" / f"validation-{name}"
    out = []
    for r in results[:seeds_shown]:
        out += copy_pictures(study, result_folder(r, r["job"], runs), pictures, rig, folder / f"seed{r['seed']}-",
                             f"{name}, seed {r['seed']}: ")
    return out


def seed_values(study, results, responses):
    """Per seed the compared responses of a prediction (None: no value) and, for a pile,
    its doubtful flank fits: [{'seed', response: value, ..., 'flank_flags'}]."""
    runs = runs_dir_of(study.executor)
    rows = []
    for r in results:
        row = {"seed": r["seed"], **{k: r.get(k) for k in responses if not isinstance(r.get(k), (list, dict))}}
        if any(k.startswith("aor_") for k in responses):
            row["flank_flags"] = run_flank_flags(r, runs)
        rows.append(row)
    return rows
