"""A one-parameter stage that starts from the library (pycal/library.py): the runs already in
the runs folder whose job is exactly one the stage would run at some value of its parameter
(the same point_id: configs, contact law, numerics, rig config, the values the study holds,
the stage's rig overrides and run_at), taken as the stage's first points.

A run counts once, as one draw: one run per point and seed, and the stage's own later points
take seeds above the library's (they never ask a job the library answered). Which runs were
taken is written in the stage's journal, so a resumed study takes the same ones; a stage
journalled before (its points or its result) takes none. Joint stages do not start from the
library yet.
"""
import math

from ..errors import ConfigError
from ..jobs import resolve_job
from ..library import point_id
from ..runs_index import ok_results
from .run_pictures import runs_dir_of


def matching_runs(study, material, st, extra_of):
    """[(x, seed, job_id, result)] of the runs folder's runs that this stage would have run at
    x (inside its bounds) with that seed, sorted by x, seed and job id."""
    runs_dir = runs_dir_of(study.executor)
    if runs_dir is None or not runs_dir.is_dir():
        return []
    p, rig, label = st["parameter"], st["rig"], st["label"]
    lo, hi = p["bounds"]
    name = study.job_material(material, label, {})[0]         # the material, or the stage's material set
    expected, seen, out = {}, set(), []
    for row, res in ok_results(runs_dir, rig, name):
        over = res["job"].get("overrides") or {}
        values = {repr(over.get(k)) for k in p["keys"]}
        x = over.get(p["keys"][0])
        if len(values) != 1 or isinstance(x, bool) or not isinstance(x, (int, float)) or not lo <= x <= hi:
            continue
        if x not in expected:
            try:
                expected[x] = point_id(resolve_job(rig, *study.job_material(material, label, extra_of(x)), seed=1))
            except ConfigError:
                expected[x] = None
        seed = int(row["seed"])
        if point_id(res["job"]) != expected[x] or (expected[x], seed) in seen:
            continue
        seen.add((expected[x], seed))
        out.append((float(x), seed, row["job_id"], res))
    return sorted(out, key=lambda t: (t[0], t[1], t[2]))


def take(study, material, st, jr, extra_of, response, lab_dir):
    """[(x, value)] of the library runs the stage starts from (module doc), booked in the
    study's runs and points; their seeds marked used for the stage's rig."""
    entry = jr.entry
    if "library" in entry:                                     # a resumed study: the runs taken before
        wanted = [r["job_id"] for r in entry["library"]]
        found = {t[2]: t for t in matching_runs(study, material, st, extra_of)}
        runs = [found[j] for j in wanted if j in found]
        if len(runs) < len(wanted):
            study.log(f"  WARNING: {len(wanted) - len(runs)} of the {len(wanted)} library runs this stage took "
                      "are gone from the runs folder: the stage goes on without them")
    elif entry["points"] or entry["result"] is not None or not study.use_library:
        return []
    else:
        runs = matching_runs(study, material, st, extra_of)
        entry["library"] = [{"x": x, "seed": seed, "job_id": j} for x, seed, j, _ in runs]
        jr.journal.save()
    out, by_x = [], {}
    for x, seed, _, res in runs:
        v = response.value(res, lab_dir)
        if v is None or (not isinstance(v, list) and math.isnan(v)):
            continue
        out.append((x, v))
        by_x.setdefault(x, []).append((seed, v, res))
    label, rig = st["label"], st["rig"]
    study.mark_seeds_used(material, label, rig, [seed for _, seed, _, _ in runs])
    for x, kept in by_x.items():
        extra = extra_of(x)
        study.point_results.setdefault(study.point_key(material, label, rig, extra), []).extend(r for _, _, r in kept)
        study.book_point(material, label, rig, extra, response, [(s, v) for s, v, _ in kept], note="from the library")
    if out:
        study.log(f"  {len(out)} run(s) from the library at {len(by_x)} point(s)")
    return out
