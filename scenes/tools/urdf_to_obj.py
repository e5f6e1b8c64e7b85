#!/usr/bin/env python3
"""Compose a robot's visual meshes into one Wavefront OBJ, posed at zero configuration.

Reads a URDF, walks its joint tree from the root link and places every link at the pose its
joint origins give when every joint variable is 0 (revolute, continuous and prismatic joints
contribute their <origin> only). Each <visual> with a <mesh> (STL, binary or ASCII, or OBJ)
becomes one `o` object named after its link, with the visual's <origin> and the mesh's
`scale` applied. Primitive visuals (<box>, <cylinder>, <sphere>) are skipped and reported.

The faces of every mesh are written in file order with their vertex order unchanged; within
an object, vertices with bit-identical positions are merged (STL stores three per triangle).
Coordinates are written with 9 significant digits. Only numpy is needed, and the output is a
pure function of the inputs, so running the same command again gives the same bytes:

    python3 scenes/tools/urdf_to_obj.py PATH/husky/husky.urdf scenes/husky.obj \
        --header "pybullet 3.2.7 wheel, pybullet_data/husky/husky.urdf (BSD-3-Clause)"
"""

import argparse
import math
import re
import struct
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np


def fail(msg):
    print(f"urdf_to_obj: {msg}", file=sys.stderr)
    sys.exit(1)


def floats(text, n, what):
    try:
        vals = [float(t) for t in (text or "").split()]
    except ValueError:
        fail(f"{what}: not {n} numbers: {text!r}")
    if len(vals) != n:
        fail(f"{what}: expected {n} numbers, got {text!r}")
    return vals


def rpy_matrix(r, p, y):
    """URDF convention: fixed-axis roll about x, then pitch about y, then yaw about z."""
    cr, sr, cp, sp, cy, sy = (math.cos(r), math.sin(r), math.cos(p), math.sin(p),
                              math.cos(y), math.sin(y))
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def origin_transform(elem, what):
    """4x4 transform of an <origin> child of `elem` (identity if absent)."""
    t = np.eye(4)
    o = elem.find("origin") if elem is not None else None
    if o is None:
        return t
    t[:3, :3] = rpy_matrix(*floats(o.get("rpy", "0 0 0"), 3, f"{what} rpy"))
    t[:3, 3] = floats(o.get("xyz", "0 0 0"), 3, f"{what} xyz")
    return t


def read_stl(path):
    data = path.read_bytes()
    if len(data) >= 84:
        (n,) = struct.unpack_from("<I", data, 80)
        if 84 + 50 * n == len(data):
            rec = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)),
                                                      ("a", "<u2")]), count=n, offset=84)
            tris = rec["v"].astype(np.float64)
            return tris.reshape(-1, 3), [list(range(3 * i, 3 * i + 3)) for i in range(n)]
    text = data.decode("ascii", errors="strict")
    pts = [floats(m, 3, f"{path} vertex") for m in re.findall(r"vertex\s+([^\n]+)", text)]
    if len(pts) % 3:
        fail(f"{path}: ASCII STL vertex count {len(pts)} is not a multiple of 3")
    return np.array(pts, dtype=np.float64), [list(range(i, i + 3)) for i in range(0, len(pts), 3)]


def read_obj(path):
    verts, faces = [], []
    for line in path.read_text(encoding="utf-8", errors="strict").splitlines():
        tok = line.split()
        if not tok:
            continue
        if tok[0] == "v":
            verts.append(floats(" ".join(tok[1:4]), 3, f"{path} v"))
        elif tok[0] == "f":
            face = []
            for t in tok[1:]:
                i = int(t.split("/")[0])
                face.append(i - 1 if i > 0 else len(verts) + i)
            faces.append(face)
    return np.array(verts, dtype=np.float64), faces


def read_mesh(path):
    ext = path.suffix.lower()
    if ext == ".stl":
        return read_stl(path)
    if ext == ".obj":
        return read_obj(path)
    fail(f"{path}: unsupported mesh format {ext!r} (STL and OBJ only)")


def link_poses(robot):
    """World pose of every link reachable from the root at zero configuration."""
    joints = {}
    for j in robot.findall("joint"):
        parent, child = j.find("parent"), j.find("child")
        if parent is None or child is None:
            fail(f"joint {j.get('name')!r} lacks <parent> or <child>")
        joints.setdefault(parent.get("link"), []).append((j, child.get("link")))
    children = {c for js in joints.values() for _, c in js}
    roots = [l.get("name") for l in robot.findall("link") if l.get("name") not in children]
    if len(roots) != 1:
        fail(f"expected one root link, found {roots}")
    poses, stack = {roots[0]: np.eye(4)}, [roots[0]]
    while stack:
        name = stack.pop()
        for j, child in joints.get(name, []):
            poses[child] = (poses[name], j)
            stack.append(child)
    return roots[0], poses


def pose_of(name, poses, cache):
    """Resolve lazily so joints of links without visuals (xacro leftovers) are never parsed."""
    if name in cache:
        return cache[name]
    entry = poses[name]
    if isinstance(entry, np.ndarray):
        t = entry
    else:
        parent_pose, joint = entry
        parent_name = joint.find("parent").get("link")
        t = pose_of(parent_name, poses, cache) @ origin_transform(joint, f"joint {joint.get('name')}")
    cache[name] = t
    return t


def fmt(x):
    s = f"{x:.9g}"
    return "0" if s == "-0" else s


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("urdf", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--header", default="", help="provenance line written as an OBJ comment")
    args = ap.parse_args()
    robot = ET.parse(args.urdf).getroot()
    _, poses = link_poses(robot)
    cache = {}
    lines = [f"# {robot.get('name')}: visual meshes of {args.urdf.name} at zero configuration,",
             "# composed by scenes/tools/urdf_to_obj.py (one `o` object per link visual)."]
    if args.header:
        lines.append(f"# Source: {args.header}")
    base, total_faces, objects = 1, 0, 0
    for link in robot.findall("link"):
        name = link.get("name")
        visuals = link.findall("visual")
        for k, vis in enumerate(visuals):
            mesh = vis.find("geometry/mesh")
            if mesh is None:
                geom = vis.find("geometry")
                kind = [c.tag for c in geom] if geom is not None else []
                print(f"urdf_to_obj: {name}: skipping non-mesh visual {kind}", file=sys.stderr)
                continue
            if name not in poses:
                fail(f"link {name!r} is not connected to the root")
            path = args.urdf.parent / mesh.get("filename").removeprefix("package://")
            pts, faces = read_mesh(path)
            scale = np.array(floats(mesh.get("scale", "1 1 1"), 3, f"{name} mesh scale"))
            t = pose_of(name, poses, cache) @ origin_transform(vis, f"{name} visual")
            world = (pts * scale) @ t[:3, :3].T + t[:3, 3]
            keys = np.ascontiguousarray(world).view(np.dtype((np.void, 24))).ravel()
            _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
            order = np.argsort(first, kind="stable")  # unique vertices in first-use order
            rank = np.empty_like(order)
            rank[order] = np.arange(len(order))
            obj_name = name if len(visuals) == 1 else f"{name}_{k}"
            lines.append(f"o {obj_name}")
            lines.extend("v " + " ".join(fmt(c) for c in world[first[i]]) for i in order)
            lines.extend("f " + " ".join(str(base + rank[inverse[i]]) for i in f) for f in faces)
            base += len(order)
            total_faces += len(faces)
            objects += 1
    args.out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print(f"{args.out}: {objects} objects, {total_faces} faces, {base - 1} vertices")


if __name__ == "__main__":
    main()
