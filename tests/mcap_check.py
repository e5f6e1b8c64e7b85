#!/usr/bin/env python3
"""Independent check of a wraptree .mcap recording (run by tests/mcap_roundtrip.rs).

Usage: python3 tests/mcap_check.py FILE.mcap N

Uses only PyPI readers: `mcap` (with CRC validation), `mcap-protobuf-support` (decodes every
message with the schema embedded in the file) and `foxglove-schemas-protobuf` (decodes every
SceneUpdate again with the official schema). Checks:
  - every message on every channel decodes; the wraptree metadata and scene attachment exist,
    the scene as it is (`model/obj`) or compressed (`<scene_file>.zst`, `application/zstd`,
    decompressed with `zstandard`), and its SHA-256 is the metadata's `scene_sha256`;
  - /grouping/merge holds N-1 messages with steps 0..N-2 and log times increase;
  - for a finished run recorded with levels, /levels/0 .. /levels/<levels_written - 1> (the
    metadata key; depth_max + 1 with --all-levels) each hold one
    SceneUpdate; its wrapper entities (`spheres`, `hulls`, `boxes`, `obbs`, whichever were
    recorded) hold the same number of wrappers (one per interior node of the cut), and for each
    of them every input vertex (the /scene triangle points) lies in some wrapper of that entity
    or is a vertex of the `leaves` entity's triangles. Spheres and boxes (axis-aligned or
    oriented, rotated by their pose's quaternion) allow 1e-6 x the scene diagonal. Hulls (one
    TriangleListPrimitive each) allow 1e-5 x the scene diagonal (hulls are decided in f32): a
    closed hull mesh is a solid, tested against the planes of its well-shaped faces (twice the
    area >= 1e-3 x the longest edge squared, as in the Rust `Hull::excess`), each oriented away
    from the mean of the hull's points; an open one (a flat polygon, or a degenerate triangle
    standing for a segment or a point) by the point's distance to its triangles.
  - when /cover exists (one SceneUpdate, entities `spheres`, `boxes`, `hulls`, `leaves`): every
    input vertex lies in some cover wrapper (same tolerances) or is a vertex of a cover leaf, and
    the metadata's cover_size counts its wrappers and cover_max_error <= cover_tolerance.
Exits 0 and prints one summary line on success; prints `mcap_check: FAIL ...` and exits 1
otherwise (2 when a required module is missing).
"""

import hashlib
import math
import sys

try:
    import zstandard
    from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory
except ImportError as e:  # CI installs them; a missing module must not pass silently
    print(f"mcap_check: FAIL missing Python module ({e}); "
          "pip install mcap mcap-protobuf-support foxglove-schemas-protobuf zstandard", file=sys.stderr)
    sys.exit(2)


def fail(msg):
    print(f"mcap_check: FAIL {msg}", file=sys.stderr)
    sys.exit(1)


def triangle_points(tri):
    """Points a TriangleListPrimitive draws (indexed or not)."""
    pts = [(p.x, p.y, p.z) for p in tri.points]
    if tri.indices:
        if len(tri.indices) % 3 or max(tri.indices) >= len(pts):
            fail("triangle list with bad indices")
        return [pts[i] for i in tri.indices]
    if len(pts) % 3:
        fail("triangle list with a partial triangle")
    return pts


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def point_segment(p, a, b):
    ab = sub(b, a)
    den = dot(ab, ab)
    t = 0.0 if den == 0 else min(1.0, max(0.0, dot(sub(p, a), ab) / den))
    return math.dist(p, (a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]))


def point_triangle(p, a, b, c):
    """Distance from p to the triangle abc (to its edges when it is degenerate)."""
    ab, ac, ap = sub(b, a), sub(c, a), sub(p, a)
    n = cross(ab, ac)
    nn = dot(n, n)
    if nn > 0:
        # Barycentric coordinates of p's projection onto the plane.
        v = dot(cross(ap, ac), n) / nn
        w = dot(cross(ab, ap), n) / nn
        if v >= 0 and w >= 0 and v + w <= 1:
            return abs(dot(ap, n)) / math.sqrt(nn)
    return min(point_segment(p, a, b), point_segment(p, b, c), point_segment(p, c, a))


def rotate(q, v):
    """v rotated by the unit quaternion q = (x, y, z, w)."""
    u = q[:3]
    t = cross(u, v)
    t = (2 * t[0], 2 * t[1], 2 * t[2])
    s = cross(u, t)
    return (v[0] + q[3] * t[0] + s[0], v[1] + q[3] * t[1] + s[1], v[2] + q[3] * t[2] + s[2])


def quat(pose):
    o = pose.orientation
    q = (o.x, o.y, o.z, o.w)
    norm = math.sqrt(sum(c * c for c in q))
    if not norm > 0:
        fail("box with a zero quaternion")
    return tuple(c / norm for c in q)


def sphere_wrapper(s, tol):
    sx, sy, sz = s.size.x, s.size.y, s.size.z
    if not (sx == sy == sz) or sx < 0:
        fail(f"sphere with size {sx}, {sy}, {sz}")
    c = (s.pose.position.x, s.pose.position.y, s.pose.position.z)
    r = sx / 2
    return ([x - r for x in c], [x + r for x in c], lambda v: math.dist(v, c) <= r + tol)


def cube_wrapper(b, tol):
    half = (b.size.x / 2, b.size.y / 2, b.size.z / 2)
    if min(half) < 0:
        fail(f"box with size {b.size}")
    c = (b.pose.position.x, b.pose.position.y, b.pose.position.z)
    q = quat(b.pose)
    inv = (-q[0], -q[1], -q[2], q[3])
    # Bounding box of the rotated box: the extent along each world axis.
    axes = [rotate(q, e) for e in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
    ext = [sum(abs(axes[a][k]) * half[a] for a in range(3)) for k in range(3)]

    def inside(v):
        local = rotate(inv, sub(v, c))
        return all(abs(local[k]) <= half[k] + tol for k in range(3))

    return ([c[k] - ext[k] for k in range(3)], [c[k] + ext[k] for k in range(3)], inside)


def hull_wrapper(tri, tol):
    pts = [(p.x, p.y, p.z) for p in tri.points]
    idx = list(tri.indices)
    if not pts or not idx or len(idx) % 3 or max(idx) >= len(pts):
        fail("hull triangle list without points or with bad indices")
    tris = [(pts[idx[k]], pts[idx[k + 1]], pts[idx[k + 2]]) for k in range(0, len(idx), 3)]
    edges = {}
    for k in range(0, len(idx), 3):
        for a, b in ((idx[k], idx[k + 1]), (idx[k + 1], idx[k + 2]), (idx[k + 2], idx[k])):
            key = (min(a, b), max(a, b))
            edges[key] = edges.get(key, 0) + 1
    closed = len(tris) >= 4 and all(n == 2 for n in edges.values())
    lo = [min(p[k] for p in pts) for k in range(3)]
    hi = [max(p[k] for p in pts) for k in range(3)]
    if not closed:
        return (lo, hi, lambda v: min(point_triangle(v, *t) for t in tris) <= tol)
    mean = tuple(sum(p[k] for p in pts) / len(pts) for k in range(3))
    planes = []
    for a, b, c in tris:
        n = cross(sub(b, a), sub(c, a))
        e = [math.dist(a, b), math.dist(b, c), math.dist(c, a)]
        norm = math.sqrt(dot(n, n))
        if norm >= 1e-3 * max(e) ** 2 and min(e) > 0:
            n = tuple(x / norm for x in n)
            if dot(n, sub(a, mean)) < 0:
                n = tuple(-x for x in n)
            planes.append((n, a))
    if not planes:
        fail("a closed hull without a well-shaped face")

    def inside(v):
        if any(v[k] < lo[k] - tol or v[k] > hi[k] + tol for k in range(3)):
            return False
        return all(dot(n, sub(v, a)) <= tol for n, a in planes)

    return (lo, hi, inside)


def covered(where, kind, wrappers, vertices, drawn, tol):
    """Fails unless every vertex is in one of `wrappers` ((lo, hi, inside) triples) or drawn."""
    # Uniform grid with cell = the largest wrapper extent: each wrapper touches <= 8 cells.
    cell = max([max(h - l for l, h in zip(lo, hi)) for lo, hi, _ in wrappers] + [tol, 1e-300])
    grid = {}
    for i, (lo, hi, _) in enumerate(wrappers):
        a = [math.floor((c - tol) / cell) for c in lo]
        b = [math.floor((c + tol) / cell) for c in hi]
        for gx in range(a[0], b[0] + 1):
            for gy in range(a[1], b[1] + 1):
                for gz in range(a[2], b[2] + 1):
                    grid.setdefault((gx, gy, gz), []).append(i)
    for v in vertices:
        if v in drawn:
            continue
        key = tuple(math.floor(c / cell) for c in v)
        if not any(wrappers[i][2](v) for i in grid.get(key, ())):
            fail(f"{where}: input vertex {v} is in no {kind} and on no drawn leaf")


def check_level(d, update, vertices, tol, hull_tol):
    """Checks one level; returns the number of wrappers per recorded kind."""
    wrappers = {}
    drawn = set()
    for ent in update.entities:
        if ent.id == "leaves":
            for tri in ent.triangles:
                drawn.update(triangle_points(tri))
        elif ent.id == "spheres":
            wrappers[ent.id] = [sphere_wrapper(s, tol) for s in ent.spheres]
        elif ent.id == "hulls":
            wrappers[ent.id] = [hull_wrapper(t, hull_tol) for t in ent.triangles]
        elif ent.id in ("boxes", "obbs"):
            wrappers[ent.id] = [cube_wrapper(b, tol) for b in ent.cubes]
        else:
            fail(f"/levels/{d}: unexpected entity {ent.id!r}")
    if not wrappers:
        fail(f"/levels/{d}: no wrapper entity")
    counts = {k: len(w) for k, w in wrappers.items()}
    if len(set(counts.values())) != 1:
        fail(f"/levels/{d}: wrapper entities disagree on the cut's interior nodes: {counts}")
    for kind, ws in sorted(wrappers.items()):
        covered(f"/levels/{d}", kind, ws, vertices, drawn, tol)
    return counts


def check_cover(updates, run, vertices, tol, hull_tol):
    """Checks the /cover level; returns its number of wrappers (leaves drawn count one each)."""
    if len(updates) != 1:
        fail(f"/cover holds {len(updates)} messages, expected 1")
    wrappers, drawn, size = [], set(), 0
    for ent in updates[0].entities:
        if ent.id == "leaves":
            for tri in ent.triangles:
                drawn.update(triangle_points(tri))
            size += len(ent.triangles)
        elif ent.id == "spheres":
            wrappers += [sphere_wrapper(s, tol) for s in ent.spheres]
            size += len(ent.spheres)
        elif ent.id == "hulls":
            wrappers += [hull_wrapper(t, hull_tol) for t in ent.triangles]
            size += len(ent.triangles)
        elif ent.id == "boxes":
            wrappers += [cube_wrapper(b, tol) for b in ent.cubes]
            size += len(ent.cubes)
        else:
            fail(f"/cover: unexpected entity {ent.id!r}")
    covered("/cover", "cover wrapper", wrappers, vertices, drawn, tol)
    for key in ("cover_tolerance", "cover_size", "cover_max_error"):
        if key not in run:
            fail(f"/cover written without metadata key {key}")
    if int(run["cover_size"]) != size:
        fail(f"metadata cover_size {run['cover_size']}, /cover draws {size}")
    if not 0 <= float(run["cover_max_error"]) <= float(run["cover_tolerance"]):
        fail(f"cover_max_error {run['cover_max_error']} above cover_tolerance "
             f"{run['cover_tolerance']}")
    return size


def cube_corners(c):
    """Lower and upper corners of an axis-aligned CubePrimitive."""
    p, s = c.pose.position, c.size
    return ((p.x - s.x / 2, p.y - s.y / 2, p.z - s.z / 2),
            (p.x + s.x / 2, p.y + s.y / 2, p.z + s.z / 2))


def check_detail_topics(run, merges, bodies, active):
    """Per-round active sets with merges/full; per-merge boxes (pair, then the new body, whose
    box is the merge event's AABB, or the union of the pair's where the event leaves it out)
    with full only."""
    detail = run["detail"]
    want_active = int(run["rounds"]) if detail in ("merges", "full") else 0
    if len(active) != want_active:
        fail(f"/grouping/active holds {len(active)} messages, expected {want_active} ({detail})")
    if detail != "full":
        if bodies:
            fail(f"/grouping/bodies written with detail {detail}")
        return
    # Only the last BODIES_CAP merges of the run (src/record/mod.rs).
    last = int(run["primitives"]) - 1
    capped = [m for m in merges if m.step + 4096 >= last]
    if len(bodies) != len(capped):
        fail(f"/grouping/bodies holds {len(bodies)} messages for {len(capped)} merges")
    for i, (update, m) in enumerate(zip(bodies, capped)):
        cubes = [c for e in update.entities for c in e.cubes]
        if len(cubes) != 3:
            fail(f"/grouping/bodies message {i} has {len(cubes)} boxes, expected 3")
        new = cubes[2]
        lo, hi = (m.min_x, m.min_y, m.min_z), (m.max_x, m.max_y, m.max_z)
        if lo + hi == (0.0,) * 6:  # left out (read as 0): the union of the pair's boxes
            corners = [cube_corners(c) for c in cubes[:2]]
            lo = tuple(min(c[0][k] for c in corners) for k in range(3))
            hi = tuple(max(c[1][k] for c in corners) for k in range(3))
        centre = (new.pose.position.x, new.pose.position.y, new.pose.position.z)
        size = (new.size.x, new.size.y, new.size.z)
        for k in range(3):
            tol = 1e-9 * max(1.0, abs(lo[k]), abs(hi[k]))
            if abs(centre[k] - (lo[k] + hi[k]) / 2) > tol or abs(size[k] - (hi[k] - lo[k])) > tol:
                fail(f"/grouping/bodies message {i}: new body's box is not merge {i}'s AABB")


def check_scene_attachment(run, attachments):
    """The scene file is attached as it is or compressed, and hashes to `scene_sha256`."""
    name = run.get("scene_file")
    scene = None
    for a_name, media_type, data in attachments:
        if a_name == name and media_type == "model/obj":
            scene = data
        elif a_name == f"{name}.zst" and media_type == "application/zstd":
            try:
                scene = zstandard.ZstdDecompressor().stream_reader(data).read()
            except zstandard.ZstdError as e:
                fail(f"scene attachment {a_name!r} does not decompress: {e}")
    if scene is None:
        have = [(n, mt, len(d)) for n, mt, d in attachments]
        fail(f"scene attachment {name!r} missing (have {have})")
    if hashlib.sha256(scene).hexdigest() != run.get("scene_sha256"):
        fail(f"scene attachment of {name!r} does not match scene_sha256")


def main():
    if len(sys.argv) != 3:
        fail("usage: mcap_check.py FILE.mcap N")
    path, n = sys.argv[1], int(sys.argv[2])
    merges = []
    bodies = []
    active = []
    levels = {}
    cover = []
    scene = None
    counts = {}
    last_time = {}
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True, decoder_factories=[DecoderFactory()])
        meta = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        attachments = [(a.name, a.media_type, bytes(a.data)) for a in reader.iter_attachments()]
        try:
            for schema, channel, message, decoded in reader.iter_decoded_messages():
                topic = channel.topic
                counts[topic] = counts.get(topic, 0) + 1
                if message.log_time < last_time.get(topic, -1):
                    fail(f"{topic}: log time goes backwards")
                last_time[topic] = message.log_time
                if schema.name == "foxglove.SceneUpdate":
                    official = SceneUpdate.FromString(message.data)
                    if official.SerializeToString() != decoded.SerializeToString():
                        fail(f"{topic}: embedded and official SceneUpdate schemas disagree")
                if topic == "/grouping/merge":
                    merges.append(decoded)
                elif topic == "/grouping/bodies":
                    bodies.append(decoded)
                elif topic == "/grouping/active":
                    active.append(decoded)
                elif topic == "/scene":
                    scene = decoded
                elif topic.startswith("/levels/"):
                    levels.setdefault(int(topic.split("/")[2]), []).append(decoded)
                elif topic == "/cover":
                    cover.append(decoded)
        except Exception as e:  # any decode error fails the check
            fail(f"decoding messages: {type(e).__name__}: {e}")

    run = meta.get("wraptree")
    if run is None:
        fail("no `wraptree` metadata record")
    check_scene_attachment(run, attachments)
    if int(run["primitives"]) != n:
        fail(f"metadata says {run['primitives']} primitives, expected {n}")
    if len(merges) != n - 1:
        fail(f"/grouping/merge holds {len(merges)} messages, expected {n - 1}")
    for i, m in enumerate(merges):
        if m.step != i or m.new != n + i or not (m.a < m.b < m.new):
            fail(f"merge {i} inconsistent: step {m.step}, {m.a} + {m.b} -> {m.new}")
    check_detail_topics(run, merges, bodies, active)
    if scene is None or not scene.entities or not scene.entities[0].triangles:
        fail("/scene has no triangles")
    vertices = set()
    for ent in scene.entities:
        for tri in ent.triangles:
            vertices.update(triangle_points(tri))
    lo = [min(v[k] for v in vertices) for k in range(3)]
    hi = [max(v[k] for v in vertices) for k in range(3)]
    diagonal = max(math.dist(lo, hi), 1e-300)
    tol, hull_tol = 1e-6 * diagonal, 1e-5 * diagonal

    wrappers = {}
    if run["detail"] in ("levels", "full") and run["complete"] == "true":
        depth_max = int(run["depth_max"])
        written = int(run.get("levels_written", -1))
        if not 1 <= written <= depth_max + 1:
            fail(f"levels_written {run.get('levels_written')!r} not in 1..={depth_max + 1}")
        if sorted(levels) != list(range(written)):
            fail(f"levels {sorted(levels)}, expected 0..{written}")
        for d, updates in sorted(levels.items()):
            if len(updates) != 1:
                fail(f"/levels/{d} holds {len(updates)} messages, expected 1")
            for kind, n_kind in check_level(d, updates[0], vertices, tol, hull_tol).items():
                wrappers[kind] = wrappers.get(kind, 0) + n_kind
    elif levels:
        fail(f"levels written with detail {run['detail']} / complete {run['complete']}")
    if cover:
        if not levels:
            fail("/cover written without levels")
        wrappers["cover wrappers"] = check_cover(cover, run, vertices, tol, hull_tol)
    elif any(k.startswith("cover_") for k in run):
        fail("cover metadata without a /cover topic")
    print(f"mcap_check: ok {path}: {sum(counts.values())} messages on {len(counts)} topics, "
          f"{len(merges)} merges, {len(levels)} levels, "
          f"{', '.join(f'{n} {k}' for k, n in sorted(wrappers.items())) or 'no wrappers'}, "
          f"{len(vertices)} vertices")


if __name__ == "__main__":
    main()
