#!/usr/bin/env python3
# Marching-cubes surfaces of implicit shapes (sphere, blob, peanut), raw, as an image
# segmentation pipeline gives them (needle and cap triangles):
#     scripts/marching-cubes.py N SHAPE out.off   (N grid points per axis; needs
#     scikit-image). tests/data/mc_blob.off is `22 blob`. Mesh them with --smooth 10
#     (docs/cli.md and docs/benchmarks.md, "Surfaces from image segmentation").
import sys, numpy as np
from skimage import measure
n, shape, out = int(sys.argv[1]), sys.argv[2], sys.argv[3]
x = np.linspace(-1.3, 1.3, n)
X, Y, Z = np.meshgrid(x, x, x, indexing='ij')
if shape == 'sphere':
    F = X**2 + Y**2 + Z**2 - 1.0
elif shape == 'blob':  # a "ventricle"-like lumpy blob
    F = (X/1.0)**2 + (Y/0.8)**2 + (Z/1.1)**2 - 1.0 + 0.25*np.sin(3*X)*np.cos(2*Y) + 0.15*np.sin(4*Z)
elif shape == 'peanut':
    F = np.minimum((X-0.45)**2 + Y**2 + Z**2 - 0.5, (X+0.45)**2 + Y**2 + Z**2 - 0.45)
verts, faces, _, _ = measure.marching_cubes(F, 0.0, spacing=(x[1]-x[0],)*3)
verts -= 1.3
# Orientation: skimage's normals point toward increasing F (outward here); OFF keeps it.
with open(out, 'w') as f:
    f.write('OFF\n%d %d 0\n' % (len(verts), len(faces)))
    for v in verts: f.write('%.10g %.10g %.10g\n' % tuple(v))
    for t in faces: f.write('3 %d %d %d\n' % tuple(t))
print(len(verts), len(faces))
