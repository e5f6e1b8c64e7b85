"""What a user sees when an .rrd opens, read with rerun-sdk's RrdReader (independent of wraptree).

Usage: blueprint_check.py FILE.rrd. For every blueprint in the file: the views reachable from the
viewport's root container; the time panel's timeline, and the cursor the viewer opens at (following:
the timeline's last tick in the recording). For each view, the recording entities its queries
select that have something drawable on that timeline at the cursor (a static row, or a row at a
tick <= cursor). Prints JSON: {"blueprints": [{"timeline", "cursor", "views": [...]}]} where each
view has its class, name, the entities with data, and the problems found:
- a view with no entity that has data at the cursor;
- a 3D view without an eye, or whose eye does not see the whole scene (its bounding sphere within
  the 55 degree vertical field of view, looking at its centre);
- a plot whose series do not cover its whole x range, whose x range is not the whole run, or whose
  value range does not hold its values (or does not start at 0).
"""

import json
import math
import sys

from rerun.experimental import RrdReader

# Columns that draw something (a style-only row, e.g. colours, draws nothing).
DRAWABLE = (
    "Mesh3D:vertex_positions",
    "Mesh3D:triangle_indices",
    "Boxes3D:half_sizes",
    "Ellipsoids3D:half_sizes",
    "Scalars:scalars",
    "TextLog:text",
)
FOV_Y = math.radians(55.0)


def recording_entities(reader, store):
    """entity -> {"static": bool, "ticks": {timeline: [ticks of drawable rows]}, "values": [...]}"""
    out = {}
    for c in reader.stream(store=store):
        rb = c.to_record_batch()
        names = rb.schema.names
        e = out.setdefault(c.entity_path, {"static": False, "ticks": {}, "values": [], "raw": {}})
        drawable = [n for n in DRAWABLE if n in names]
        if not drawable:
            for n in names:
                if n.startswith("Transform3D:translation"):
                    e["raw"]["translation"] = rb.column(n).to_pylist()
            continue
        if c.is_static:
            e["static"] = True
        col = rb.column(drawable[0]).to_pylist()
        rows = [i for i, v in enumerate(col) if v is not None]
        for t in c.timeline_names:
            if t in names:
                ticks = rb.column(t).to_pylist()
                e["ticks"].setdefault(t, []).extend(ticks[i] for i in rows)
        if "Scalars:scalars" in names:
            for i in rows:
                e["values"].extend(x for x in col[i] if x is not None and math.isfinite(x))
        if c.entity_path == "/scene/primitives" and "Mesh3D:vertex_positions" in names:
            e["raw"]["positions"] = [p for row in col if row for p in row]
    return out


def blueprint_entities(reader, store):
    out = {}
    for c in reader.stream(store=store):
        rb = c.to_record_batch()
        e = out.setdefault(c.entity_path, {})
        for n in rb.schema.names:
            if ":" in n:
                vals = [v for v in rb.column(n).to_pylist() if v is not None]
                if vals:
                    e[n] = vals[-1]
    return out


def one(v):
    return v[0] if isinstance(v, list) and len(v) == 1 else v


def matches(query, entity):
    q = query[2:] if query[:2] in ("+ ", "- ") else query
    if q.endswith("/**"):
        base = q[:-3]
        return entity == base or entity.startswith(base + "/") or base == ""
    return entity == q


def scene_sphere(rec):
    prims = rec.get("/scene/primitives", {}).get("raw", {}).get("positions")
    if not prims:
        return None
    shift = one(rec.get("/scene", {}).get("raw", {}).get("translation", [[[0, 0, 0]]])[0]) or [0, 0, 0]
    lo = [min(p[i] for p in prims) + shift[i] for i in range(3)]
    hi = [max(p[i] for p in prims) + shift[i] for i in range(3)]
    center = [(a + b) / 2 for a, b in zip(lo, hi)]
    radius = math.dist(lo, hi) / 2
    return center, radius


def check(path):
    reader = RrdReader(path)
    recs = reader.recordings()
    rec = recording_entities(reader, recs[0])
    sphere = scene_sphere(rec)
    report = {"blueprints": []}
    for bp_store in reader.blueprints():
        bp = blueprint_entities(reader, bp_store)
        timeline = one(bp.get("/time_panel", {}).get("TimePanelBlueprint:timeline"))
        ticks = [t for e in rec.values() for t in e["ticks"].get(timeline, [])]
        cursor = max(ticks) if ticks else None
        root = bp.get("/viewport", {}).get("ViewportBlueprint:root_container")
        root = one(root)
        hexid = "".join(f"{b:02x}" for b in root) if root else ""
        root_path = f"/container/{hexid[:8]}-{hexid[8:12]}-{hexid[12:16]}-{hexid[16:20]}-{hexid[20:]}"
        views, stack = [], [root_path]
        while stack:
            node = stack.pop()
            if node.startswith("/view/"):
                views.append(node)
                continue
            contents = bp.get(node, {}).get("ContainerBlueprint:contents") or []
            stack.extend("/" + c for c in reversed(contents))
        out = {"timeline": timeline, "cursor": cursor, "views": []}
        for v in views:
            meta = bp.get(v, {})
            cls = one(meta.get("ViewBlueprint:class_identifier"))
            name = one(meta.get("ViewBlueprint:display_name"))
            queries = bp.get(v + "/ViewContents", {}).get("ViewContents:query") or []
            problems = []
            shown = []
            for ent, e in sorted(rec.items()):
                if not any(matches(q, ent) for q in queries if q.startswith("+")):
                    continue
                if any(matches(q, ent) for q in queries if q.startswith("-")):
                    continue
                t = e["ticks"].get(timeline, [])
                if e["static"] or (cursor is not None and t and min(t) <= cursor):
                    shown.append(ent)
            if not shown:
                problems.append(f"nothing to show on timeline {timeline} at tick {cursor}")
            if cls == "3D":
                eye = bp.get(v + "/EyeControls3D", {})
                pos, target = one(eye.get("EyeControls3D:position")), one(eye.get("EyeControls3D:look_target"))
                if pos is None or target is None:
                    problems.append("no eye: the viewer frames whatever has loaded")
                elif sphere:
                    center, radius = sphere
                    dist = math.dist(pos, center)
                    if math.dist(target, center) > 1e-3 * max(radius, 1e-9):
                        problems.append(f"the eye looks at {target}, not the scene's centre {center}")
                    if dist <= radius or math.asin(radius / dist) > FOV_Y / 2:
                        problems.append("the scene's bounding sphere does not fit the view")
            if cls == "TimeSeries":
                axis = one(bp.get(v + "/TimeAxis", {}).get("TimeAxis:view_range"))
                series = [rec[e] for e in shown]
                covered = [t for s in series for t in s["ticks"].get(timeline, [])]
                if axis is None:
                    problems.append("no x range: the plot follows the cursor")
                elif covered:
                    lo, hi = axis["start"], axis["end"]
                    if min(covered) > lo or max(covered) < hi:
                        problems.append(f"series cover ticks {min(covered)}..{max(covered)}, the x range is {lo}..{hi}")
                    if hi < max(covered):
                        problems.append(f"the x range {lo}..{hi} cuts off ticks up to {max(covered)}")
                yr = one(bp.get(v + "/ScalarAxis", {}).get("ScalarAxis:range"))
                values = [x for s in series for x in s["values"]]
                if yr is not None and values:
                    if yr[0] != 0.0:
                        problems.append(f"the value range starts at {yr[0]}, not 0")
                    if yr[1] < max(values) or yr[0] > min(values):
                        problems.append(f"the value range {yr} does not hold {min(values)}..{max(values)}")
                out.setdefault("y_ranges", 0)
                out["y_ranges"] += yr is not None
            out["views"].append({"class": cls, "name": name, "shown": shown, "problems": problems})
        report["blueprints"].append(out)
    return report


if __name__ == "__main__":
    print(json.dumps(check(sys.argv[1])))
