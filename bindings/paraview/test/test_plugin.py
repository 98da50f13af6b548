"""ctest paraview_plugin: the curvetet plugin in pvpython.

    pvpython test_plugin.py <CurveTet.so> <closed linear .off> <output folder>

Loads the plugin, runs "curvetet: curved tetrahedra" on a Sphere() source (triangulated)
and on an STL reader (an ASCII .stl written here from the .off), and checks each output:
only quadratic tetrahedra (VTK cell type 24) with positive scaled Jacobians, the input
points first and bit-identical, and a boundary equal to the input surface (the faces used
by one tetrahedron only are exactly the input triangles; port 1 has one quadratic
triangle per input triangle). Also checks the progress ParaView receives reaches 1.
Exits non-zero (an AssertionError) on the first failed check.
"""

import os
import sys

# ParaView's Python modules unpacked beside a system VTK's (scripts/fetch-paraview-python):
# theirs first, or `vtkmodules` would be python3-vtk9's.
if os.environ.get("CURVETET_PARAVIEW_PYTHONPATH"):
    sys.path.insert(0, os.environ["CURVETET_PARAVIEW_PYTHONPATH"])

import numpy as np  # noqa: E402
from paraview import servermanager as sm  # noqa: E402
from paraview.simple import LoadPlugin, Sphere, STLReader, Triangulate  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

VTK_TRIANGLE = 5
VTK_QUADRATIC_TRIANGLE = 22
VTK_QUADRATIC_TETRA = 24
# Corner indices of the four faces of a VTK tetra (the mid nodes follow the corners).
TET_FACES = np.array([[0, 1, 2], [0, 1, 3], [1, 2, 3], [0, 2, 3]])


def read_off(path):
    """Vertices (n, 3) and triangles (m, 3) of a triangle-only OFF file."""
    with open(path) as f:
        words = [w for line in f for w in line.split("#", 1)[0].split()]
    assert words[0] == "OFF", f"{path}: not an OFF file"
    nv, nf = int(words[1]), int(words[2])
    pos = 4
    verts = np.array(words[pos : pos + 3 * nv], dtype=float).reshape(nv, 3)
    pos += 3 * nv
    tris = []
    for _ in range(nf):
        k = int(words[pos])
        assert k == 3, f"{path}: a face of {k} vertices"
        tris.append([int(w) for w in words[pos + 1 : pos + 4]])
        pos += 4
    return verts, np.array(tris)


def write_stl(path, verts, tris):
    with open(path, "w") as f:
        f.write("solid surface\n")
        for t in tris:
            a, b, c = verts[t]
            n = np.cross(b - a, c - a)
            n /= np.linalg.norm(n)
            f.write(f" facet normal {n[0]:.9g} {n[1]:.9g} {n[2]:.9g}\n  outer loop\n")
            for p in (a, b, c):
                f.write(f"   vertex {p[0]:.9g} {p[1]:.9g} {p[2]:.9g}\n")
            f.write("  endloop\n endfacet\n")
        f.write("endsolid surface\n")


def cells(grid):
    """Cell types (m,) and connectivity (m, k) of a grid or polydata of one cell size."""
    types = np.array([grid.GetCellType(i) for i in range(grid.GetNumberOfCells())])
    ids = [
        [grid.GetCell(i).GetPointId(j) for j in range(grid.GetCell(i).GetNumberOfPoints())]
        for i in range(grid.GetNumberOfCells())
    ]
    return types, np.array(ids)


def check(name, source, filt, expect_points=None, expect_triangles=None):
    surface = sm.Fetch(source)
    in_points = vtk_to_numpy(surface.GetPoints().GetData())
    in_types, in_tris = cells(surface)
    assert in_types.size > 0 and (in_types == VTK_TRIANGLE).all(), (
        f"{name}: the input is not triangles: {sorted(set(in_types))}")
    if expect_points is not None:
        assert len(in_points) == expect_points, (
            f"{name}: {len(in_points)} input points, expected {expect_points}")
    if expect_triangles is not None:
        assert len(in_tris) == expect_triangles, (
            f"{name}: {len(in_tris)} input triangles, expected {expect_triangles}")

    progress = []
    algo = filt.GetClientSideObject()
    algo.AddObserver("ProgressEvent", lambda obj, _event: progress.append(obj.GetProgress()))
    filt.UpdatePipeline()
    assert progress and max(progress) == 1.0, f"{name}: progress seen: {progress[-5:]}"

    volume = sm.Fetch(filt, idx=0)
    boundary = sm.Fetch(filt, idx=1)
    types, tets = cells(volume)
    assert types.size > 0, f"{name}: no tetrahedra"
    assert (types == VTK_QUADRATIC_TETRA).all(), (
        f"{name}: cell types {sorted(set(types))}, expected only {VTK_QUADRATIC_TETRA}")
    jac = vtk_to_numpy(volume.GetCellData().GetArray("ScaledJacobian"))
    assert len(jac) == len(tets) and jac.min() > 0, f"{name}: min scaled Jacobian {jac.min()}"
    for array in ("EquiangularSkewness", "Region"):
        assert volume.GetCellData().GetArray(array) is not None, f"{name}: no {array} array"

    # The input points come first, bit-identical.
    out_points = vtk_to_numpy(volume.GetPoints().GetData())
    assert len(out_points) > len(in_points), f"{name}: no interior or mid points"
    assert np.array_equal(out_points[: len(in_points)].astype(float), in_points.astype(float)), (
        f"{name}: the input points are not kept")

    # The boundary of the tetrahedra (faces of one tetrahedron) is the input surface.
    faces = np.sort(tets[:, :4][:, TET_FACES].reshape(-1, 3), axis=1)
    uniq, counts = np.unique(faces, axis=0, return_counts=True)
    assert counts.max() <= 2, f"{name}: a face shared by {counts.max()} tetrahedra"
    outer = uniq[counts == 1]
    expected = np.unique(np.sort(in_tris, axis=1), axis=0)
    assert len(outer) == len(in_tris) and np.array_equal(outer, expected), (
        f"{name}: {len(outer)} boundary faces, {len(in_tris)} input triangles, "
        f"equal sets: {np.array_equal(outer, expected) if len(outer) == len(expected) else False}")
    btypes, btris = cells(boundary)
    assert len(btris) == len(in_tris) and (btypes == VTK_QUADRATIC_TRIANGLE).all(), (
        f"{name}: boundary port: {len(btris)} cells of types {sorted(set(btypes))}")
    assert np.array_equal(np.unique(np.sort(btris[:, :3], axis=1), axis=0), expected), (
        f"{name}: the boundary port's triangles are not the input's")
    print(f"{name}: {len(in_tris)} input triangles, {len(tets)} quadratic tetrahedra, "
          f"min scaled Jacobian {jac.min():.3f}")


def main():
    plugin, off, out = sys.argv[1:4]
    LoadPlugin(plugin, ns=globals())
    make = globals().get("curvetetcurvedtetrahedra")
    assert make is not None, "the plugin did not define 'curvetet: curved tetrahedra'"

    sphere = Triangulate(Input=Sphere(ThetaResolution=16, PhiResolution=12))
    check("Sphere()", sphere, make(Input=sphere, Threads=2))

    verts, tris = read_off(off)
    stl = os.path.join(out, "surface.stl")
    write_stl(stl, verts, tris)
    reader = STLReader(FileNames=[stl])
    filt = make(Input=reader, Alpha=1.5, Size=0.0, Optimize=1, UniformSize=0, Thorough=0,
                Threads=2)
    check("STLReader", reader, filt, expect_points=len(verts), expect_triangles=len(tris))


if __name__ == "__main__":
    main()
