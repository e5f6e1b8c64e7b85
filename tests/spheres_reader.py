"""Reads wraptree's sphere sets with independent readers and checks them against the robot.

spheres_reader.py ROBOT.urdf PREFIX
Reads PREFIX.urdf with urdf_parser_py, PREFIX.yml with PyYAML, PREFIX.srdf with Python's xml,
and ROBOT.urdf's collision geometry (meshes with trimesh; boxes by their corners, cylinders by
32 rim points per cap, spheres by their poles) in link frames. Prints JSON: the spheres of each
format by link, the spherized URDF's joint and visual counts, and for each link the largest
distance of a collision point outside every sphere of the URDF set."""
import json, os, sys, xml.etree.ElementTree as ET
import numpy as np, trimesh, yaml
from urdf_parser_py.urdf import URDF, Box, Cylinder, Sphere, Mesh


def rpy(r, p, y):
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array([[cy*cp, cy*sp*sr - sy*cr, cy*sp*cr + sy*sr],
                     [sy*cp, sy*sp*sr + cy*cr, sy*sp*cr - cy*sr],
                     [-sp, cp*sr, cp*cr]])


def points(geom, base):
    if isinstance(geom, Box):
        h = np.array(geom.size) / 2
        return np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h
    if isinstance(geom, Cylinder):
        a = 2 * np.pi * np.arange(32) / 32
        ring = np.stack([geom.radius * np.cos(a), geom.radius * np.sin(a)], 1)
        return np.vstack([np.hstack([ring, np.full((32, 1), z)]) for z in (-geom.length / 2, geom.length / 2)])
    if isinstance(geom, Sphere):
        return np.vstack([np.eye(3), -np.eye(3)]) * geom.radius
    if isinstance(geom, Mesh):
        m = trimesh.load(os.path.join(base, geom.filename), force='mesh', process=False)
        s = np.array(geom.scale if geom.scale else [1, 1, 1], float)
        return np.asarray(m.vertices) * s
    return np.zeros((0, 3))


robot_path, prefix = sys.argv[1], sys.argv[2]
robot = URDF.from_xml_string(open(robot_path).read())
out = {}
sph = URDF.from_xml_string(open(prefix + '.urdf').read())
out['urdf'] = {l.name: [list(c.origin.xyz) + [c.geometry.radius] for c in l.collisions]
               for l in sph.links if l.collisions}
out['joints'] = len(sph.joints)
out['visuals'] = sum(len(l.visuals) for l in sph.links)
y = yaml.safe_load(open(prefix + '.yml'))
out['curobo'] = {k: [list(s['center']) + [s['radius']] for s in v] for k, v in y['collision_spheres'].items()}
root = ET.parse(prefix + '.srdf').getroot()
out['srdf'] = {a.get('link'): [[float(x) for x in s.get('center').split()] + [float(s.get('radius'))]
                               for a2 in [a] for s in a2.findall('sphere')]
               for a in root.findall('link_sphere_approximation')}
outside = {}
for link in robot.links:
    pts = []
    for c in link.collisions:
        p = points(c.geometry, os.path.dirname(robot_path))
        o = c.origin
        R = rpy(*(o.rpy if o is not None and o.rpy else [0, 0, 0]))
        t = np.array(o.xyz if o is not None and o.xyz else [0, 0, 0])
        pts.append(p @ R.T + t)
    if not pts:
        continue
    pts = np.vstack(pts)
    s = np.array(out['urdf'].get(link.name, []))
    if len(s) == 0:
        outside[link.name] = None
        continue
    d = np.linalg.norm(pts[:, None, :] - s[None, :, :3], axis=2) - s[None, :, 3]
    outside[link.name] = float(d.min(axis=1).max())
out['outside'] = outside
print(json.dumps(out))
