"""Independent readers for tests/scene_formats.rs: trimesh for meshes, urdf_parser_py for URDF.

    python formats_reader.py mesh FILE...          one JSON object per file
    python formats_reader.py urdf FILE [NAME=VALUE...]

`mesh`: the triangles trimesh reads (process=False: nothing merged or dropped; polygons are
triangulated), in the scene graph's placement, and the bounds of the vertices the triangles use;
for a small mesh (200 triangles or fewer) those vertices too; for COLLADA the file's unit
(pycollada's `<unit meter>`, which trimesh records but does not apply).

`urdf`: for each link with visuals, in file order: the triangles of its meshes (read by
trimesh), the shapes it has, and, when it has only boxes and meshes, the bounds of their
vertices placed by the joints (forward kinematics written here with numpy, from
urdf_parser_py's parse), at the joint values given (others 0; mimic joints followed).
"""

import json
import math
import os
import sys

import numpy as np
import trimesh


def bounds(points):
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return points.min(axis=0).tolist(), points.max(axis=0).tolist()


def mesh(path):
    scene = trimesh.load(path, process=False, force="scene")
    meshes = scene.dump()
    tris = sum(len(m.faces) for m in meshes)
    out = {"file": os.path.basename(path), "triangles": int(tris), "geometries": len(meshes)}
    if tris:
        used = np.concatenate([m.vertices[m.faces.ravel()] for m in meshes if len(m.faces)])
        out["min"], out["max"] = bounds(used)
        if tris <= 200:
            out["points"] = used.tolist()
    if path.lower().endswith(".dae"):
        import collada

        out["unit"] = collada.Collada(path).assetInfo.unitmeter or 1.0
    return out


def rpy_matrix(r, p, y):
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def origin(o):
    t = np.eye(4)
    if o is None:
        return t
    t[:3, :3] = rpy_matrix(*(o.rpy or [0, 0, 0]))
    t[:3, 3] = o.xyz or [0, 0, 0]
    return t


def motion(joint, q):
    t = np.eye(4)
    if q == 0:
        return t
    axis = np.array(joint.axis if joint.axis is not None else [1.0, 0.0, 0.0], dtype=float)
    axis /= np.linalg.norm(axis)
    if joint.type in ("revolute", "continuous"):
        k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        t[:3, :3] = np.eye(3) + math.sin(q) * k + (1 - math.cos(q)) * (k @ k)
    elif joint.type == "prismatic":
        t[:3, 3] = axis * q
    return t


def urdf(path, given):
    from urdf_parser_py.urdf import URDF, Box, Cylinder, Mesh, Sphere

    with open(path) as f:
        robot = URDF.from_xml_string(f.read())
    joints = {j.name: j for j in robot.joints}

    def value(name, depth=0):
        if name in given:
            return given[name]
        m = joints[name].mimic
        if m is None or depth > len(joints):
            return 0.0
        return (m.multiplier if m.multiplier is not None else 1.0) * value(m.joint, depth + 1) + (
            m.offset or 0.0
        )

    pose = {robot.get_root(): np.eye(4)}
    pending = list(robot.joints)
    while pending:
        rest = []
        for j in pending:
            if j.parent in pose:
                pose[j.child] = pose[j.parent] @ origin(j.origin) @ motion(j, value(j.name))
            else:
                rest.append(j)
        if len(rest) == len(pending):
            raise SystemExit("unreachable links")
        pending = rest
    out = []
    base = os.path.dirname(path)
    for link in robot.links:
        if not link.visuals:
            continue
        tris, shapes, pts, exact = 0, [], [], True
        for v in link.visuals:
            t = pose[link.name] @ origin(v.origin)
            g = v.geometry
            if isinstance(g, Mesh):
                m = trimesh.load(os.path.join(base, g.filename), process=False, force="mesh")
                tris += len(m.faces)
                p = m.vertices[m.faces.ravel()] * np.array(g.scale or [1, 1, 1])
            elif isinstance(g, Box):
                shapes.append("box")
                h = np.array(g.size) / 2
                p = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h
            else:
                shapes.append({Cylinder: "cylinder", Sphere: "sphere"}.get(type(g), "other"))
                exact = False
                continue
            pts.append(p @ t[:3, :3].T + t[:3, 3])
        item = {"name": link.name, "mesh_triangles": int(tris), "shapes": shapes}
        if exact and pts:
            item["min"], item["max"] = bounds(np.concatenate(pts))
        out.append(item)
    return out


def main():
    mode, args = sys.argv[1], sys.argv[2:]
    if mode == "mesh":
        print(json.dumps([mesh(p) for p in args]))
    elif mode == "urdf":
        given = {k: float(v) for k, v in (a.split("=", 1) for a in args[1:])}
        print(json.dumps(urdf(args[0], given)))
    else:
        raise SystemExit(f"unknown mode {mode}")


if __name__ == "__main__":
    main()
