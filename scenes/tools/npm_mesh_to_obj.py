#!/usr/bin/env python3
"""Write the mesh of an npm "simplicial complex" module (e.g. the `bunny` package) as OBJ.

Such a module's `index.js` is `exports.positions=[[x,y,z],...]` and `exports.cells=[[a,b,c],...]`
with 0-based indices. Vertices and faces are written in the module's order, unchanged: each
`v` line holds the coordinate text as the module spells it (the numbers are parsed only to
check them), each `f` line the cell's indices plus one. Standard library only:

    npm pack bunny@1.0.1 && tar xzf bunny-1.0.1.tgz
    python3 scenes/tools/npm_mesh_to_obj.py package/index.js scenes/bunny.obj \
        --header "npm bunny@1.0.1, index.js (Public Domain)"
"""

import argparse
import json
import math
import re
import sys
from pathlib import Path


def fail(msg):
    print(f"npm_mesh_to_obj: {msg}", file=sys.stderr)
    sys.exit(1)


def array_text(js, name):
    """The literal text of `exports.NAME=[...]`, up to its matching bracket."""
    m = re.search(rf"exports\.{name}\s*=\s*\[", js)
    if not m:
        fail(f"no `exports.{name}=[` in the module")
    depth, start = 0, m.end() - 1
    for i in range(start, len(js)):
        depth += {"[": 1, "]": -1}.get(js[i], 0)
        if depth == 0:
            return js[start:i + 1]
    fail(f"`exports.{name}` is not closed")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("module", type=Path, help="the package's index.js")
    ap.add_argument("out", type=Path)
    ap.add_argument("--header", default="", help="provenance line written as an OBJ comment")
    args = ap.parse_args()
    js = args.module.read_text(encoding="utf-8")
    pos_text = array_text(js, "positions")
    cells = json.loads(array_text(js, "cells"))
    rows = re.findall(r"\[([^\[\]]*)\]", pos_text[1:-1])
    lines = [f"# {args.module.parent.name}/{args.module.name} written as OBJ by "
             "scenes/tools/npm_mesh_to_obj.py"]
    if args.header:
        lines.append(f"# Source: {args.header}")
    for row in rows:
        coords = row.split(",")
        if len(coords) != 3 or not all(math.isfinite(float(c)) for c in coords):
            fail(f"position [{row}] is not three finite numbers")
        lines.append("v " + " ".join(c.strip() for c in coords))
    for cell in cells:
        if len(cell) < 3 or not all(isinstance(i, int) and 0 <= i < len(rows) for i in cell):
            fail(f"cell {cell} does not index {len(rows)} positions")
        lines.append("f " + " ".join(str(i + 1) for i in cell))
    args.out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print(f"{args.out}: {len(rows)} vertices, {len(cells)} faces")


if __name__ == "__main__":
    main()
