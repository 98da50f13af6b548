#!/usr/bin/env python3
# Marching-cubes surfaces of implicit shapes, raw, as an image segmentation pipeline
# gives them (needle and cap triangles):
#     scripts/marching-cubes.py N SHAPE out.off   (N grid points per axis; needs
#     scikit-image and its scipy). tests/data/mc_blob.off is `22 blob`. Mesh them
#     with --smooth 10 (docs/cli.md and docs/benchmarks.md, "Surfaces from image
#     segmentation").
# SHAPE: sphere, blob, peanut; and, kept out of the tests as an unseen check of the
# mesher on raw surfaces (the largest component is kept): gyroball (a thickened gyroid
# sheet in a ball, genus > 10), twotori (two crossing tori blended), holeybox (a cube
# with three orthogonal holes through it).
import sys, numpy as np
from skimage import measure
n, shape, out = int(sys.argv[1]), sys.argv[2], sys.argv[3]
x = np.linspace(-1.3, 1.3, n)
X, Y, Z = np.meshgrid(x, x, x, indexing='ij')
def torus(X, Y, Z, R=0.75, r=0.28):
    return (np.sqrt(X**2 + Y**2) - R)**2 + Z**2 - r**2
if shape == 'gyroball':
    G = np.sin(2.4*X)*np.cos(2.4*Y) + np.sin(2.4*Y)*np.cos(2.4*Z) + np.sin(2.4*Z)*np.cos(2.4*X)
    F = np.maximum(np.abs(G) - 0.6, X**2 + Y**2 + Z**2 - 1.2)
elif shape == 'twotori':
    F = np.minimum(torus(X - 0.4, Y, Z), torus(X + 0.4, Z, Y))
elif shape == 'holeybox':
    box = np.maximum(np.abs(X), np.maximum(np.abs(Y), np.abs(Z))) - 1.0
    holes = np.minimum(np.minimum(Y**2 + Z**2, X**2 + Z**2), X**2 + Y**2) - 0.25
    F = np.maximum(box, -holes)
elif shape == 'sphere':
    F = X**2 + Y**2 + Z**2 - 1.0
elif shape == 'blob':  # a "ventricle"-like lumpy blob
    F = (X/1.0)**2 + (Y/0.8)**2 + (Z/1.1)**2 - 1.0 + 0.25*np.sin(3*X)*np.cos(2*Y) + 0.15*np.sin(4*Z)
elif shape == 'peanut':
    F = np.minimum((X-0.45)**2 + Y**2 + Z**2 - 0.5, (X+0.45)**2 + Y**2 + Z**2 - 0.45)
if shape in ('gyroball', 'twotori', 'holeybox'):
    # Outside on the grid's faces, so that the surface closes.
    F[0, :, :] = F[-1, :, :] = F[:, 0, :] = F[:, -1, :] = F[:, :, 0] = F[:, :, -1] = 1.0
verts, faces, _, _ = measure.marching_cubes(F, 0.0, spacing=(x[1]-x[0],)*3)
verts -= 1.3
# The largest edge-connected component only.
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
_, label = connected_components(
    coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(len(verts),) * 2),
    directed=False)
comp = label[faces[:, 0]]
faces = faces[comp == np.bincount(comp).argmax()]
used = np.unique(faces)
renum = np.full(len(verts), -1)
renum[used] = np.arange(len(used))
verts, faces = verts[used], renum[faces]
# Orientation: skimage's normals point toward increasing F (outward here); OFF keeps it.
with open(out, 'w') as f:
    f.write('OFF\n%d %d 0\n' % (len(verts), len(faces)))
    for v in verts: f.write('%.10g %.10g %.10g\n' % tuple(v))
    for t in faces: f.write('3 %d %d %d\n' % tuple(t))
print(len(verts), len(faces))
