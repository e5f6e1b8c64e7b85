#!/usr/bin/env python3
"""Independent check of a wraptree .mcap recording (run by tests/mcap_roundtrip.rs).

Usage: python3 tests/mcap_check.py FILE.mcap N

Uses only PyPI readers: `mcap` (with CRC validation), `mcap-protobuf-support` (decodes every
message with the schema embedded in the file) and `foxglove-schemas-protobuf` (decodes every
SceneUpdate again with the official schema). Checks:
  - every message on every channel decodes; the wraptree metadata and scene attachment exist;
  - /grouping/merge holds N-1 messages with steps 0..N-2 and log times increase;
  - for a finished run recorded with levels, /levels/0 .. /levels/<depth_max> each hold one
    SceneUpdate, and every input vertex (the /scene triangle points) lies in some sphere of the
    level (tolerance 1e-6 x scene diagonal) or is a vertex of a drawn leaf triangle.
Exits 0 and prints one summary line on success; prints `mcap_check: FAIL ...` and exits 1
otherwise (2 when a required module is missing).
"""

import math
import sys

try:
    from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory
except ImportError as e:  # CI installs them; a missing module must not pass silently
    print(f"mcap_check: FAIL missing Python module ({e}); "
          "pip install mcap mcap-protobuf-support foxglove-schemas-protobuf", file=sys.stderr)
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


def check_level(d, update, vertices, tol):
    spheres = []
    drawn = set()
    for ent in update.entities:
        for s in ent.spheres:
            sx, sy, sz = s.size.x, s.size.y, s.size.z
            if not (sx == sy == sz) or sx < 0:
                fail(f"/levels/{d}: sphere with size {sx}, {sy}, {sz}")
            p = s.pose.position
            spheres.append((p.x, p.y, p.z, sx / 2))
        for tri in ent.triangles:
            drawn.update(triangle_points(tri))
    # Uniform grid with cell = the largest sphere diameter: each sphere touches <= 8 cells.
    cell = max([2 * r for *_, r in spheres] + [tol, 1e-300])
    grid = {}
    for i, (x, y, z, r) in enumerate(spheres):
        lo = [math.floor((c - r - tol) / cell) for c in (x, y, z)]
        hi = [math.floor((c + r + tol) / cell) for c in (x, y, z)]
        for gx in range(lo[0], hi[0] + 1):
            for gy in range(lo[1], hi[1] + 1):
                for gz in range(lo[2], hi[2] + 1):
                    grid.setdefault((gx, gy, gz), []).append(i)
    for v in vertices:
        if v in drawn:
            continue
        key = tuple(math.floor(c / cell) for c in v)
        if not any(math.dist(v, spheres[i][:3]) <= spheres[i][3] + tol for i in grid.get(key, ())):
            fail(f"/levels/{d}: input vertex {v} is in no sphere and on no drawn leaf")
    return len(spheres)


def main():
    if len(sys.argv) != 3:
        fail("usage: mcap_check.py FILE.mcap N")
    path, n = sys.argv[1], int(sys.argv[2])
    merges = []
    levels = {}
    scene = None
    counts = {}
    last_time = {}
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True, decoder_factories=[DecoderFactory()])
        meta = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        attachments = [(a.name, a.media_type, len(a.data)) for a in reader.iter_attachments()]
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
                elif topic == "/scene":
                    scene = decoded
                elif topic.startswith("/levels/"):
                    levels.setdefault(int(topic.split("/")[2]), []).append(decoded)
        except Exception as e:  # any decode error fails the check
            fail(f"decoding messages: {type(e).__name__}: {e}")

    run = meta.get("wraptree")
    if run is None:
        fail("no `wraptree` metadata record")
    if not any(name == run.get("scene_file") and mt == "model/obj" for name, mt, _ in attachments):
        fail(f"scene attachment {run.get('scene_file')!r} missing (have {attachments})")
    if int(run["primitives"]) != n:
        fail(f"metadata says {run['primitives']} primitives, expected {n}")
    if len(merges) != n - 1:
        fail(f"/grouping/merge holds {len(merges)} messages, expected {n - 1}")
    for i, m in enumerate(merges):
        if m.step != i or m.new != n + i or not (m.a < m.b < m.new):
            fail(f"merge {i} inconsistent: step {m.step}, {m.a} + {m.b} -> {m.new}")
    if scene is None or not scene.entities or not scene.entities[0].triangles:
        fail("/scene has no triangles")
    vertices = set()
    for ent in scene.entities:
        for tri in ent.triangles:
            vertices.update(triangle_points(tri))
    lo = [min(v[k] for v in vertices) for k in range(3)]
    hi = [max(v[k] for v in vertices) for k in range(3)]
    tol = 1e-6 * max(math.dist(lo, hi), 1e-300)

    spheres = 0
    if run["detail"] in ("levels", "full") and run["complete"] == "true":
        depth_max = int(run["depth_max"])
        if sorted(levels) != list(range(depth_max + 1)):
            fail(f"levels {sorted(levels)}, expected 0..={depth_max}")
        for d, updates in sorted(levels.items()):
            if len(updates) != 1:
                fail(f"/levels/{d} holds {len(updates)} messages, expected 1")
            spheres += check_level(d, updates[0], vertices, tol)
    elif levels:
        fail(f"levels written with detail {run['detail']} / complete {run['complete']}")
    print(f"mcap_check: ok {path}: {sum(counts.values())} messages on {len(counts)} topics, "
          f"{len(merges)} merges, {len(levels)} levels, {spheres} spheres, {len(vertices)} vertices")


if __name__ == "__main__":
    main()
