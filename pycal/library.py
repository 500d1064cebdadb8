"""The response library: every completed run as one row that a later study can reuse.

A row is a seed run (pycal/runs_index.py) with what its job hashes: rig, material, seed,
overrides (the values that differ from the configs, as JSON) and `point_id`, the content
hash of the whole resolved job except its seed (configs, contact law, numerics, rig config,
overrides: everything the job id covers). Two runs with the same point_id are draws at the
same point; a run from another contact law, rig config or numerics has another point_id and
is never mixed in. A row is `current` when this checkout's configs resolve its rig, material
and overrides to the same point_id; the YADE version is kept beside it.

    rows = library_rows("runs")                    # the runs folder's rows + imported ones
    export("runs", "zinc.csv")                     # carry a cluster's library to a laptop
    import_rows("runs", "zinc.csv")                # into runs/library.csv, beside the job cache

`pycal library [RUNS_DIR] [--export FILE | --import FILE]` does the same from the shell.
CSV always; Parquet when the file name ends in .parquet and pandas has an engine for it.
"""
import json
from pathlib import Path

import pandas as pd

from .errors import ConfigError
from .files import atomic_path
from .jobs import content_digest, resolve_job
from .rig_contract import BATCH_SEEDS_KEY, LAYOUT_KEY
from .runs_index import ID_COLUMNS, check_runs_dir, ok_results

LIBRARY_FILE = "library.csv"           # imported rows, in the runs folder
KEY_COLUMNS = ["point_id", "job_id", "rig", "material", "seed", "overrides_json"]
INFO_COLUMNS = ["cpu_time_s", "git_commit", "yade_version", "source"]
_NOT_RESPONSES = set(ID_COLUMNS) | set(KEY_COLUMNS) | set(INFO_COLUMNS)


def point_id(job):
    """12 hex: the content hash of a job without its seed(s), its replica layout and its id
    (a lone run and a batch's replica at the same point have the same one)."""
    return content_digest({k: v for k, v in job.items() if k not in ("seed", "job_id", BATCH_SEEDS_KEY, LAYOUT_KEY)})


def _row(row, result, source):
    job = result["job"]
    out = {"point_id": point_id(job), "job_id": row["job_id"], "rig": row["rig"], "material": row["material"],
           "seed": int(row["seed"]), "overrides_json": json.dumps(job.get("overrides") or {}, sort_keys=True),
           "cpu_time_s": row["cpu_time_s"], "git_commit": row["git_commit"], "yade_version": row["yade_version"],
           "source": source}
    out.update({k: v for k, v in row.items() if k not in _NOT_RESPONSES and not k.startswith("set.")
                and not (isinstance(v, float) and v != v)})
    return out


def _read(path):
    path = Path(path)
    if not path.is_file():
        raise ConfigError(str(path), "", "no such library file")
    try:
        df = pd.read_parquet(path) if path.suffix == ".parquet" else pd.read_csv(path)
    except (ImportError, ValueError) as exc:
        why = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ConfigError(str(path), "", f"cannot be read as a library ({why})") from None
    missing = [c for c in KEY_COLUMNS if c not in df.columns]
    if missing:
        raise ConfigError(str(path), missing[0], f"a library file needs the columns {', '.join(KEY_COLUMNS)}")
    for i, text in enumerate(df["overrides_json"]):
        try:
            if not isinstance(json.loads(text), dict):
                raise ValueError("not a mapping")
        except (TypeError, ValueError) as exc:
            raise ConfigError(str(path), f"overrides_json (row {i + 2})", f"{text!r}: not a JSON mapping ({exc})") \
                from None
    return df


def library_rows(runs_dir, rig=None, material=None):
    """DataFrame of the library: every ok run of the runs folder (source 'runs') and the rows
    imported into it (runs/library.csv), one row per (point_id, seed, job_id)."""
    rows = [_row(row, res, "runs") for row, res in ok_results(runs_dir, rig, material)]
    df = pd.DataFrame(rows, columns=None if rows else KEY_COLUMNS + INFO_COLUMNS)
    imported = Path(runs_dir) / LIBRARY_FILE
    if imported.is_file():
        extra = _read(imported)
        if rig is not None:
            extra = extra[extra["rig"] == rig]
        if material is not None:
            extra = extra[extra["material"] == material]
        df = pd.concat([df, extra], ignore_index=True) if len(df) else extra.reset_index(drop=True)
    return df.drop_duplicates(["point_id", "seed", "job_id"], keep="first").reset_index(drop=True)


def current_flags(df, config_dir=None):
    """True per row when this checkout's configs resolve its rig, material, overrides and seed
    to the same point_id (the row's runs could be this checkout's), else False."""
    kw = {} if config_dir is None else {"config_dir": config_dir}
    cache = {}
    out = []
    for rig, mat, over, pid in zip(df["rig"], df["material"], df["overrides_json"], df["point_id"]):
        key = (rig, mat, over)
        if key not in cache:
            try:
                cache[key] = point_id(resolve_job(rig, mat, json.loads(over), seed=1, **kw))
            except ConfigError:
                cache[key] = None           # a rig, material or key this checkout does not have
        out.append(cache[key] == pid)
    return out


def _write(df, path):
    with atomic_path(path) as tmp:
        if Path(path).suffix == ".parquet":
            try:
                df.to_parquet(tmp)
            except ImportError:
                raise ConfigError(str(path), "", "no Parquet engine here (pyarrow or fastparquet); give a .csv "
                                                 "name") from None
        else:
            df.to_csv(tmp, index=False)
    return path


def export(runs_dir, path, rig=None, material=None):
    """Write the library (library_rows) to `path`; returns the row count."""
    df = library_rows(runs_dir, rig, material)
    _write(df, path)
    return len(df)


def import_rows(runs_dir, path):
    """Add a library file's rows to runs/library.csv (rows already there kept once); returns
    (rows read, rows new)."""
    new = _read(path)
    new = new.assign(source=[f"imported: {Path(path).name}" if s in ("runs", None) or s != s else s
                             for s in new.get("source", [None] * len(new))])
    target = Path(runs_dir) / LIBRARY_FILE
    old = _read(target) if target.is_file() else None
    both = new if old is None else pd.concat([old, new], ignore_index=True)
    both = both.drop_duplicates(["point_id", "seed", "job_id"], keep="first").reset_index(drop=True)
    _write(both, target)
    return len(new), len(both) - (0 if old is None else len(old))


def summary_lines(df, flags):
    """Rows, points and current rows per rig and material, and the YADE versions."""
    if not len(df):
        return ["no rows"]
    d = df.assign(current=flags)
    out = []
    for (rig, mat), g in d.groupby(["rig", "material"], sort=True):
        versions = ", ".join(sorted({str(v) for v in g.get("yade_version", []) if v == v and v})) or "?"
        out.append(f"{rig} {mat}: {len(g)} rows at {g['point_id'].nunique()} points, {int(g['current'].sum())} "
                   f"current (this checkout's configs); YADE {versions}")
    out.append(f"{len(d)} rows, {int(d['current'].sum())} current")
    return out


def cli(args):
    """`pycal library`: list (default), --export FILE or --import FILE."""
    check_runs_dir(args.runs)
    if args.import_file:
        read, added = import_rows(args.runs, args.import_file)
        print(f"{args.import_file}: {read} rows read, {added} new in {Path(args.runs) / LIBRARY_FILE}")
        return
    if args.export:
        n = export(args.runs, args.export, args.rig, args.material)
        print(f"wrote {args.export} ({n} rows)")
        return
    df = library_rows(args.runs, args.rig, args.material)
    print("\n".join(summary_lines(df, current_flags(df) if len(df) else [])))


def register(sub):
    """The `pycal library` sub-command."""
    from .executors import DEFAULT_RUNS_DIR
    s = sub.add_parser("library", help="the response library: every completed run as a row with what its job "
                                       "hashes; lists it, --export FILE writes it, --import FILE adds a file's rows")
    s.add_argument("runs", nargs="?", default=str(DEFAULT_RUNS_DIR), help="runs folder (default runs/)")
    s.add_argument("--rig", default=None, help="only this rig")
    s.add_argument("--material", default=None, help="only this material (or material set)")
    group = s.add_mutually_exclusive_group()
    group.add_argument("--export", default=None, metavar="FILE", help="write the library to FILE (.csv or .parquet)")
    group.add_argument("--import", dest="import_file", default=None, metavar="FILE",
                       help="add FILE's rows to RUNS_DIR/library.csv")
    s.set_defaults(func=cli)
