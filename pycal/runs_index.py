"""The runs folder as a table: one row per seed run (`pycal runs`, bench scripts, results page).

    from pycal.runs_index import runs_table
    df = runs_table("runs", study_dir="runs/study/zinc_ore")     # a pandas DataFrame

Columns (SI units, units in the names):
- job_id, rig, material, seed: the run (a replica of a batch job has its own seed job id);
- status: ok (result.json), refused (the rig's rig_failure.txt: the physics' verdict, kept),
  failed (the last failed attempt <job_id>.failed/, no verdict), pending (a job folder written
  by `pycal job --write` or `pycal batch-table`, not run yet); message: why, when not ok;
- cpu_time_s: the run's CPU seconds (a replica: its batch's divided by the batch's replicas),
  wall_time_s (the YADE process's), steps_count, simulated_time_s, batch_job_id, git_commit,
  yade_version, finished_utc, folder (the run's files: a replica's folder inside its batch's);
- stage: the study sections that asked for the run (`material/stage`, ';'-joined), when a
  study folder is given (its jobs.csv); '' for a run no stage of it asked for. A job the
  study lists without a folder in the runs folder is a row of status `missing`;
- set.<key>: each override of the job (the values that differ from the configs: the
  parameters a study or --set gave), e.g. set.particles.density_kg_m3;
- every scalar measurement of the result, under the rig's own name (aor_mean_deg, ...).
The runs folder's layout: pycal/executors/jobdirs.py. Reading only: nothing is written.
"""
import csv
import json
from pathlib import Path

import pandas as pd

from . import rigs
from .rig_contract import JOB_FILE, RESULT_FILE, RIG_FAILURE_FILE

ID_COLUMNS = ["job_id", "rig", "material", "seed", "status", "message", "cpu_time_s", "wall_time_s",
              "steps_count", "simulated_time_s", "batch_job_id", "git_commit", "yade_version", "finished_utc",
              "folder", "stage"]
SET_PREFIX = "set."
_NOT_RESPONSES = {"job_id", "rig", "material", "seed", "contact_model", "job", "provenance", "replicas"}


def _read_json(path):
    try:
        return json.loads(Path(path).read_text())
    except (OSError, ValueError, UnicodeDecodeError):
        return None


def _measurements(result):
    return {k: v for k, v in result.items()
            if k not in _NOT_RESPONSES and isinstance(v, (int, float, str, bool)) and k not in ID_COLUMNS}


def _row(job, status, folder, result=None, message="", share=1.0, batch_id=""):
    prov = (result or {}).get("provenance") or {}
    ident = {k: (result or {}).get(k, job.get(k)) for k in ("job_id", "rig", "material", "seed")}
    row = {"job_id": ident["job_id"] or Path(folder).name, "rig": ident["rig"] or Path(folder).parent.name,
           "material": ident["material"] or "", "seed": ident["seed"], "status": status, "message": message,
           "cpu_time_s": prov["cpu_time_s"] * share if prov.get("cpu_time_s") is not None else None,
           "wall_time_s": prov.get("wall_time_s"), "steps_count": prov.get("steps_count"),
           "simulated_time_s": prov.get("simulated_time_s"), "batch_job_id": batch_id,
           "git_commit": prov.get("git_commit", ""), "yade_version": prov.get("yade_version", ""),
           "finished_utc": prov.get("finished_utc", ""), "folder": str(folder), "stage": ""}
    row.update({SET_PREFIX + k: v for k, v in sorted((job.get("overrides") or {}).items())})
    if result is not None:
        row.update(_measurements(result))
    return row


def _folder_runs(folder):
    """[(row, result or None)] of one job folder (a batch folder: one per replica, its result
    expanded as a lone run's)."""
    from .replicas import expand
    from .rig_contract import BATCH_SEEDS_KEY, replica_dir_name, seed_job
    name = folder.name
    result = _read_json(folder / RESULT_FILE) if not name.endswith(".failed") else None
    job = (result or {}).get("job") or _read_json(folder / JOB_FILE) or {}
    if result is not None and "replicas" in result:
        n = max(1, len(result["replicas"]))
        out = []
        for seed, res, failure in expand(result):
            own = folder / replica_dir_name(seed)
            if res is None:
                out.append((_row(seed_job(job, seed), "failed", own, message=failure, batch_id=job["job_id"]), None))
            else:
                out.append((_row(res["job"], "ok", own, res, share=1.0 / n, batch_id=job["job_id"]), res))
        return out
    if result is not None:
        return [(_row(job, "ok", folder, result), result)]
    if not job:
        return []
    refusal = folder / RIG_FAILURE_FILE
    status = "refused" if refusal.is_file() else ("failed" if name.endswith(".failed") else "pending")
    message = refusal.read_text().strip() if refusal.is_file() else ""
    seeds = job.get(BATCH_SEEDS_KEY)
    if seeds:
        return [(_row(seed_job(job, s), status, folder / replica_dir_name(s), message=message,
                      batch_id=job["job_id"]), None) for s in seeds]
    return [(_row(job, status, folder, message=message), None)]


def study_jobs(study_dir):
    """{job_id: (sections 'material/stage;...', row of jobs.csv)} of the runs a study's stages
    asked for, in the order first asked."""
    path = Path(study_dir) / "jobs.csv"
    out = {}
    if path.is_file():
        with open(path, newline="") as f:
            for r in csv.DictReader(f):
                sections, _ = out.setdefault(r["job_id"], ([], r))
                if r["section"] not in sections:
                    sections.append(r["section"])
    return {k: (";".join(v), r) for k, (v, r) in out.items()}


def runs_with_results(runs_dir, study_dir=None, rig=None, material=None):
    """[(row, result or None)] of every run under `runs_dir` (optionally one rig / material),
    sorted by rig, material, job id: the row as in runs_table (module doc), the result shaped
    as a lone run's result.json (a replica's expanded from its batch, its job under 'job').
    Each result.json is read once. A failed attempt whose job has a result since is left out."""
    runs_dir = Path(runs_dir)
    pairs = []
    for name in rigs.names():
        if rig is not None and name != rig:
            continue
        rig_dir = runs_dir / name
        if not rig_dir.is_dir():
            continue
        done = {p.name for p in rig_dir.iterdir() if (p / RESULT_FILE).is_file()}
        for folder in sorted(rig_dir.iterdir()):
            if not folder.is_dir() or folder.name.startswith("."):
                continue
            if folder.name.endswith(".failed") and folder.name[:-len(".failed")] in done:
                continue
            pairs += _folder_runs(folder)
    if study_dir is not None:
        asked = study_jobs(study_dir)       # a replica is listed under its lone job's id and its batch
        by_batch = {(r.get("batch_job_id"), str(r["seed"])): j for j, (_, r) in asked.items() if r.get("batch_job_id")}
        found = set()
        for r, _ in pairs:
            j = r["job_id"] if r["job_id"] in asked else by_batch.get((r["batch_job_id"], str(r["seed"])))
            r["stage"] = asked[j][0] if j else ""
            found.add(j)
        pairs += [({"job_id": j, "rig": r["rig"], "material": r["material"], "seed": int(r["seed"]),
                    "status": "missing", "message": f"asked by the study ({r['status']}), no job folder in {runs_dir}",
                    "stage": sections, "batch_job_id": r.get("batch_job_id") or ""}, None)
                  for j, (sections, r) in asked.items()
                  if j not in found and (rig is None or r["rig"] == rig)]
    if material is not None:
        pairs = [(r, res) for r, res in pairs if r["material"] == material]
    return sorted(pairs, key=lambda p: (p[0]["rig"], p[0]["material"], p[0]["job_id"]))


def runs_table(runs_dir, study_dir=None, rig=None, material=None):
    """Every run under `runs_dir` (optionally one rig / material) as a DataFrame (module doc),
    sorted by rig, material, job id. A failed attempt whose job has a result since is left out."""
    rows = [r for r, _ in runs_with_results(runs_dir, study_dir, rig, material)]
    if not rows:
        return pd.DataFrame(columns=ID_COLUMNS)
    df = pd.DataFrame(rows)
    for c in ID_COLUMNS:
        if c not in df.columns:
            df[c] = None
    text = ["message", "batch_job_id", "git_commit", "yade_version", "finished_utc", "folder", "stage"]
    df[text] = df[text].fillna("")
    sets = sorted(c for c in df.columns if c.startswith(SET_PREFIX))
    rest = [c for c in df.columns if c not in ID_COLUMNS and c not in sets]
    return df[ID_COLUMNS + sets + rest].reset_index(drop=True)


def ok_results(runs_dir, rig=None, material=None):
    """[(row, result)] of every ok run, in the table's order (runs_with_results)."""
    return [(r, res) for r, res in runs_with_results(runs_dir, rig=rig, material=material) if r["status"] == "ok"]


def check_runs_dir(path):
    """A ConfigError naming RUNS_DIR when `path` is not a folder."""
    from .errors import ConfigError
    if not Path(path).is_dir():
        raise ConfigError("RUNS_DIR", str(path), "no such folder (a runs folder, e.g. runs/)")


def job_files(runs_dir, rig, material=None, status=None):
    """job.json of every lone run (not a batch's replica) of a rig [and material] [with that
    status], in the table's order: for scripts that rebuild the jobs with a change."""
    df = runs_table(runs_dir, rig=rig, material=material)
    df = df[(df["batch_job_id"] == "") & ((df["status"] == status) if status else True)]
    return [Path(f) / JOB_FILE for f in df["folder"]]


def parameter_columns(df):
    """The set.<key> columns of a runs table."""
    return [c for c in df.columns if c.startswith(SET_PREFIX)]


def summary_lines(df):
    """Counts per rig and material and status, CPU total: what `pycal runs` prints under the table."""
    if df.empty:
        return ["no runs"]
    out = []
    for (rig, mat), g in df.groupby(["rig", "material"], sort=True):
        counts = ", ".join(f"{n} {s}" for s, n in g["status"].value_counts().sort_index().items())
        out.append(f"{rig} {mat}: {counts}; CPU {g['cpu_time_s'].sum(min_count=1) or 0:.0f} s")
    out.append(f"{len(df)} runs, CPU {df['cpu_time_s'].sum(min_count=1) or 0:.0f} s")
    return out


def cli(args):
    """`pycal runs`: print the table's main columns and the counts; --csv writes every column."""
    from .errors import ConfigError
    from .files import atomic_path
    check_runs_dir(args.runs)
    if args.study and not (Path(args.study) / "jobs.csv").is_file():
        raise ConfigError("--study", str(args.study), "no jobs.csv there (a study's output folder, e.g. "
                                                      "runs/study/zinc_ore)")
    df = runs_table(args.runs, args.study, args.rig, args.material)
    if args.status:
        df = df[df["status"] == args.status]
    if args.csv:
        with atomic_path(args.csv) as tmp:
            df.to_csv(tmp, index=False)
        print(f"wrote {args.csv} ({len(df)} runs, {len(df.columns)} columns)")
    else:
        shown = df[["job_id", "seed", "status", "cpu_time_s", "stage"] if args.study else
                   ["job_id", "seed", "status", "cpu_time_s"]]
        with pd.option_context("display.max_rows", None, "display.width", 200):
            print(shown.to_string(index=False, float_format=lambda v: f"{v:.1f}") if len(df) else "")
    print("\n".join(summary_lines(df)))
