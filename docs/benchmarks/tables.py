#!/usr/bin/env python3
"""The tables of docs/benchmarks.md, made from the raw results in docs/benchmarks/data/.

Each data file is one run: NAME_MACHINE_DATE.csv, a header row, then one row per scene as the
measuring command printed it (ratios without their ×). Each table of benchmarks.md that this
script makes sits between `<!-- table: KEY -->` and `<!-- end -->`.

    python3 docs/benchmarks/tables.py            # print every table
    python3 docs/benchmarks/tables.py KEY        # print one
    python3 docs/benchmarks/tables.py --check    # benchmarks.md's tables equal these (exit 1 if not)
    python3 docs/benchmarks/tables.py --write    # put these into benchmarks.md

Standard library only.
"""

import csv
import re
import statistics
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
DATA = HERE / "data"
DOC = HERE.parent / "benchmarks.md"


def load(name):
    """The rows (dicts) of the one data file whose name starts with `name_`."""
    files = sorted(DATA.glob(f"{name}_*.csv"))
    if len(files) != 1:
        sys.exit(f"error: {DATA}: expected one {name}_*.csv, found {len(files)}")
    with open(files[0], newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def num(s):
    """The first number in a cell ("0.092 (0.020)" → 0.092)."""
    m = re.search(r"-?\d+(\.\d+)?", s.replace(",", ""))
    if not m:
        raise ValueError(f"no number in {s!r}")
    return float(m.group(0))


def count(n):
    """A primitive count as written in the tables: 12,144; 10^5 for round powers of ten."""
    n = int(n)
    if n >= 10_000 and 10 ** (len(str(n)) - 1) == n:
        return f"10^{len(str(n)) - 1}"
    return f"{n:,}"


def times(x):
    return f"{x:.2f}×"


def markdown(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(lines)


def select(name, columns, n_column="N"):
    """The data file's `columns` as they are (the primitive count written as `count`)."""
    rows = []
    for r in load(name):
        rows.append([count(r[c]) if c == n_column else r[c] for c in columns])
    return markdown(columns, rows)


def ratio_summary(values):
    """Median and range of ratios."""
    return times(statistics.median(values)), f"{min(values):.2f}–{max(values):.2f}×"


# Mesh sizes of the summaries: the fast path refines differently below 1,024 primitives; the
# partitioned schedule groups up to 12,288 whole; its chunks change at 2^18.
BANDS = [(0, 1024), (1024, 12_288), (12_288, 100_000), (100_000, 1 << 40)]


def band_name(lo, hi):
    if lo == 0:
        return f"under {hi:,}"
    if hi >= 1 << 40:
        return f"{lo:,} and more"
    return f"{lo:,}–{hi - 1:,}"


def fast_summary(name):
    """The fast path against PLOC and the best peer, by mesh size."""
    data = load(name)
    header = [
        "N",
        "meshes",
        "fast / PLOC: median",
        "range",
        "within 2×",
        "SAH at or below the best peer",
        "point and distance queries at or below",
        "contact queries at or below",
    ]
    rows = []
    for lo, hi in BANDS + [(None, None)]:
        group = [r for r in data if lo is None or lo <= int(r["N"]) < hi]
        if not group:
            continue
        t = [num(r["fast / PLOC"]) for r in group]
        at_or_below = lambda c: sum(num(r[c]) <= 1.0 for r in group)  # noqa: E731
        rows.append(
            [
                "all" if lo is None else band_name(lo, hi),
                len(group),
                *ratio_summary(t),
                sum(x <= 2.0 for x in t),
                at_or_below("SAH / best peer"),
                at_or_below("point and distance queries"),
                at_or_below("contact queries"),
            ]
        )
    return markdown(header, rows)


def thread_summary(name):
    """The fast path against PLOC by thread count."""
    data = load(name)
    header = ["threads", "fast / PLOC: median", "range", "within 2×", "at or below PLOC"]
    rows = []
    for t in [1, 2, 4, 8, 16]:
        v = [num(r[f"fast / PLOC, {t} thread" + ("s" if t > 1 else "")]) for r in data]
        rows.append([t, *ratio_summary(v), sum(x <= 2.0 for x in v), sum(x <= 1.0 for x in v)])
    return markdown(header, rows)


def exact_summary(name):
    """The exact schedule against PLOC by thread count, and by mesh size on one thread."""
    data = load(name)
    header = ["threads", "meshes", "exact / PLOC: median", "range", "CPU time ratio: median"]
    rows = []
    for t, suffix in [(1, "1 thread"), (2, "2 threads")]:
        v = [num(r[f"exact / PLOC, {suffix}"]) for r in data]
        cpu = (
            times(statistics.median(num(r["CPU ratio, 1 thread"]) for r in data))
            if t == 1
            else ""
        )
        rows.append([t, len(v), *ratio_summary(v), cpu])
    return markdown(header, rows)


def partitioned_by_size(name):
    """The partitioned default (δ by size) against chunks of 4, on every mesh it splits."""
    data = load(name)
    header = [
        "chunks",
        "meshes",
        "within 2 % of the exact tree (SAH and node tests)",
        "largest SAH / exact",
        "time / exact, 1 thread: median",
        "range",
    ]
    rows = []
    for label, quality, time in [
        ("δ by size (default)", "by size: SAH / node tests", "time / exact, 1 thread: by size"),
        ("δ = 4", "δ = 4: SAH / node tests", "time / exact, 1 thread: δ = 4"),
    ]:
        pairs = [[float(x) for x in r[quality].split(" / ")] for r in data]
        within = sum(max(p) <= 1.02 for p in pairs)
        t = [num(r[time]) for r in data]
        rows.append(
            [label, len(data), within, f"{max(p[0] for p in pairs):.3f}", *ratio_summary(t)]
        )
    return markdown(header, rows)


GENERATED = ("soup", "44 robot bases")


def per_scene_summary(name, columns, below_one=()):
    """Median (range) of each ratio column over the generated scenes, the bundled meshes and
    all; for the columns in `below_one`, also how many scenes are at or below 1."""
    data = load(name)
    groups = [
        ("soups, 44 robot bases", [r for r in data if r["scene"] in GENERATED]),
        ("bundled meshes", [r for r in data if r["scene"] not in GENERATED]),
        ("all", data),
    ]
    rows = []
    for label, group in groups:
        row = [label, len(group)]
        for c in columns:
            v = [num(r[c]) for r in group]
            d = len(group[0][c].split(".")[1]) if "." in group[0][c] else 0
            cell = f"{statistics.median(v):.{d}f} ({min(v):.{d}f}–{max(v):.{d}f})"
            if c in below_one:
                cell += f"; {sum(x <= 1.0 for x in v)} ≤ 1"
            row.append(cell)
        rows.append(row)
    return markdown(["scenes", "count", *columns], rows)


def agreement(name):
    """Median fast / PLOC over the meshes, per measuring program and run."""
    data = load(name)
    header = ["measured by", "run 1", "run 2", "run 3"]
    table = statistics.median(num(r["table (2026-11-28)"]) for r in data)
    rows = [["the fast-path table above", times(table), "", ""]]
    for label, prefix in [
        ("`method_timing` at the table's commit (313a445)", "method_timing at 313a445"),
        ("`method_timing` now", "method_timing"),
        ("`wraptree bench` now", "wraptree bench"),
    ]:
        rows.append(
            [label]
            + [
                times(statistics.median(num(r[f"{prefix}, run {i}"]) for r in data))
                for i in (1, 2, 3)
            ]
        )
    return markdown(header, rows)


TABLES = {
    "bench-vs-table": lambda: agreement("bench-vs-table-13"),
    "fast-path": lambda: fast_summary("fast-path-69"),
    "fast-path-threads": lambda: thread_summary("fast-path-threads-69"),
    "soup-threads": lambda: select(
        "soup-1e6-threads",
        ["threads", "partitioned ms", "fast ms", "PLOC ms", "partitioned / PLOC", "fast / PLOC"],
        n_column=None,
    ),
    "fast-path-cgal": lambda: fast_summary("fast-path-cgal-24"),
    "exact": lambda: exact_summary("exact-vs-ploc"),
    "partitioned": lambda: per_scene_summary(
        "partitioned",
        ["p/P 1t", "p/P 2t", "SAH p/e", "qry p/e"],
        below_one=["SAH p/e", "qry p/e"],
    ),
    "partitioned-by-size": lambda: partitioned_by_size("partitioned-by-size"),
    "grouping-vs-peers": lambda: per_scene_summary(
        "grouping-vs-peers",
        ["t/PLOC", "t/bin", "SAH/bin", "qry/bin", "con/bin"],
        below_one=["SAH/bin", "qry/bin", "con/bin"],
    ),
    "refine": lambda: per_scene_summary(
        "refine-vs-best-peer",
        ["ref/PLOC", "SAH/best", "qry/best", "con/best", "p SAH/best", "p qry/best",
         "p con/best"],
        below_one=["SAH/best", "qry/best", "con/best", "p SAH/best", "p qry/best",
                   "p con/best"],
    ),
    "pregroup": lambda: select(
        "pregroup",
        ["scene", "method", "build ms", "t/PLOC", "SAH", "node tests/query"],
        n_column=None,
    ),
    "builders": lambda: select(
        "wrappers",
        ["method", "12,144 polygons: build / SAH / depth / tests", "kuka-link0 (3,038)",
         "soup 10^5"],
        n_column=None,
    ),
    "recording": lambda: select(
        "recording",
        ["scene", "N", "--detail", "grouping", "grouping + recording", "ratio", "median",
         ".rrd", ".mcap"],
    ),
    "bench-wall-time": lambda: select(
        "bench-wall-time", ["scene", "primitives", "wall time", "peak memory"], n_column="primitives"
    ),
}

BLOCK = re.compile(r"^<!-- table: (\S+) -->\n(.*?)^<!-- end -->$", re.S | re.M)


def main(args):
    if args and args[0] in ("--check", "--write"):
        doc = DOC.read_text(encoding="utf-8")
        keys = [m.group(1) for m in BLOCK.finditer(doc)]
        unknown = [k for k in keys if k not in TABLES]
        if unknown:
            sys.exit(f"error: {DOC}: unknown tables {unknown}")
        made = {k: TABLES[k]() for k in keys}
        if args[0] == "--write":
            doc = BLOCK.sub(lambda m: f"<!-- table: {m.group(1)} -->\n{made[m.group(1)]}\n<!-- end -->", doc)
            DOC.write_text(doc, encoding="utf-8")
            return 0
        differ = [m.group(1) for m in BLOCK.finditer(doc) if m.group(2) != made[m.group(1)] + "\n"]
        for k in differ:
            print(f"{DOC}: table {k} differs from the data; run tables.py --write", file=sys.stderr)
        if not differ:
            print(f"{len(keys)} tables match the data")
        return 1 if differ else 0
    for k in args or TABLES:
        if k not in TABLES:
            sys.exit(f"error: no table {k!r}; tables: {', '.join(TABLES)}")
        print(f"<!-- table: {k} -->\n{TABLES[k]()}\n<!-- end -->\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
