"""Two runs of the main job with different seed bases, side by side: do their intervals overlap?

    /usr/bin/python3 bench/seed_base_compare.py RUNS_A/study/zinc_ore/summary.json \\
        RUNS_B/study/zinc_ore/summary.json [--out table.md]

Per calibrated parameter (material, stage, parameter): each run's estimate with its 95 %
interval, its stop reason, and whether the two intervals overlap. A parameter that only
one run calibrated is listed with "-" for the other; an inherited value (a copy of another
material's) is listed but not counted twice. Prints a markdown table (and writes
it to --out); exit code 2 on a file that is not a study summary.
"""
import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from pycal.files import write_text  # noqa: E402  (atomic: no half-written table)


def parameter_rows(summary):
    """{(material, stage, parameter label): parameter dict + stop reason} of one summary.json."""
    out = {}
    for st in summary["stages"]:
        for p in st.get("parameters") or []:
            out[(st["material"], st["stage"], p["label"])] = dict(p, stop_reason=st.get("stop_reason", ""))
    return out


def overlap(a, b):
    """True when the closed intervals [a.low, a.high] and [b.low, b.high] share a point."""
    return a["low"] <= b["high"] and b["low"] <= a["high"]


def _fmt(p):
    return "-" if p is None else f"{p['estimate']:.4g} [{p['low']:.4g}, {p['high']:.4g}] ({p['stop_reason']})"


def compare(summary_a, summary_b):
    """Markdown lines: one row per parameter in either summary, in the order of the first."""
    rows_a, rows_b = parameter_rows(summary_a), parameter_rows(summary_b)
    keys = list(rows_a) + [k for k in rows_b if k not in rows_a]
    lines = [f"| material | stage | parameter | seed base {summary_a.get('seed_base', '?')} "
             f"| seed base {summary_b.get('seed_base', '?')} | intervals overlap |",
             "|---|---|---|---|---|---|"]
    n_both = n_overlap = 0
    for k in keys:
        a, b = rows_a.get(k), rows_b.get(k)
        verdict = "-"
        if a is not None and b is not None and a["stop_reason"].startswith("inherited"):
            verdict = "(inherited)"
        elif a is not None and b is not None:
            both = overlap(a, b)
            n_both, n_overlap = n_both + 1, n_overlap + both
            verdict = "yes" if both else "**no**"
        lines.append(f"| {k[0]} | {k[1]} | {k[2]} | {_fmt(a)} | {_fmt(b)} | {verdict} |")
    lines.append("")
    lines.append(f"{n_overlap} of {n_both} parameters calibrated by both runs have overlapping 95 % intervals.")
    return lines


def _load(path):
    try:
        s = json.loads(Path(path).read_text())
        s["stages"]
        return s
    except (OSError, ValueError, KeyError, TypeError) as exc:
        print(f"seed_base_compare: {path}: not a study summary.json ({exc})", file=sys.stderr)
        raise SystemExit(2)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="seed_base_compare", description=__doc__.splitlines()[0])
    ap.add_argument("summary_a")
    ap.add_argument("summary_b")
    ap.add_argument("--out", help="also write the table to this markdown file")
    args = ap.parse_args(argv)
    a, b = _load(args.summary_a), _load(args.summary_b)
    lines = compare(a, b)
    for s, path in ((a, args.summary_a), (b, args.summary_b)):
        lines.append(f"- {path}: seed base {s.get('seed_base')}, commit {s.get('git_commit')}")
    text = "\n".join(lines) + "\n"
    print(text, end="")
    if args.out:
        write_text(args.out, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
