#!/usr/bin/env python3
# CAD-like parts made by constructive solid geometry, triangulated the way CAD
# exporters do it (long needles fanned across flat faces, sliver triangles where
# solids meet), as an unseen check of the mesher beside the OpenSCAD corpus:
#     scripts/csg-parts.py PART out.stl   (needs the pip packages trimesh and
#     manifold3d)
# PART: bracket (a 120 x 60 x 3 plate with three holes and two bosses through it),
# finball (a sphere with a box cut out and a thin fin through it), cross (two
# cylinders crossing at 70 degrees), drilled (a sphere with six holes of mixed sizes
# drilled through its centre at random directions: the booleans leave triangles with an
# edge of 4e-6 beside edges of 14, aspect ratios up to 1.9 million), drilled2 (the same
# with two holes: 5,916 triangles, aspect ratios up to 47,756).
import sys

import numpy as np
import trimesh
from trimesh.creation import box, cylinder, icosphere
from trimesh.transformations import rotation_matrix, translation_matrix

part, out = sys.argv[1], sys.argv[2]
if part == 'bracket':
    m = box(extents=[120, 60, 3])
    for x in (-45, 0, 45):
        m = m.difference(cylinder(radius=6, height=10, sections=48,
                                  transform=translation_matrix([x, 15, 0])))
    for x in (-30, 30):
        m = m.union(cylinder(radius=4, height=12, sections=40,
                             transform=translation_matrix([x, -15, 4])))
elif part == 'finball':
    m = icosphere(subdivisions=3, radius=20).difference(
        box(extents=[15, 15, 50], transform=translation_matrix([12, 12, 0])))
    m = m.union(box(extents=[50, 1.2, 30]))
elif part == 'cross':
    m = cylinder(radius=8, height=60, sections=64).union(
        cylinder(radius=7, height=60, sections=56,
                 transform=rotation_matrix(np.radians(70), [1, 0, 0])))
elif part in ('drilled', 'drilled2'):
    m = icosphere(subdivisions=4, radius=15)
    seed, holes = (5, 6) if part == 'drilled' else (16, 2)
    rng = np.random.default_rng(seed)
    z = np.array([0, 0, 1.0])
    for _ in range(holes):
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        turn = rotation_matrix(np.arccos(np.clip(d @ z, -1, 1)), np.cross(z, d))
        m = m.difference(cylinder(radius=rng.uniform(0.8, 3), height=40,
                                  sections=int(rng.integers(12, 40)), transform=turn))
else:
    sys.exit(f'unknown part {part}: bracket, finball, cross, drilled or drilled2')
assert m.is_watertight
m.export(out)
print(f'{out}: {len(m.faces)} triangles, volume {m.volume:.6f}')
