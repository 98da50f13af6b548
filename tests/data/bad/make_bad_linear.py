#!/usr/bin/env python3
"""Writes the linear part of the bad-input corpus: small linear surfaces (OFF and ASCII
STL, read by curvetet's own readers and curved by `Surface::from_linear`), one defect each,
and their lines in EXPECTED.txt ("filename kind-name"). Python 3 standard library only;
deterministic. make_bad.py runs this after writing the P2 files.

    python3 tests/data/bad/make_bad_linear.py   # rewrites the *_lin.* files beside it

Base shape: the tetrahedron with corners (0,0,0), (1,0,0), (0,1,0), (0,0,1), outward.
"""

import os

HERE = os.path.dirname(os.path.abspath(__file__))

TET_V = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
TET_F = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def shifted(vs, fs, d, off):
    return ([tuple(p[k] + d[k] for k in range(3)) for p in vs], [tuple(v + off for v in f) for f in fs])


def two_tets(d):
    """Two tetrahedra, the second moved by d, as one vertex/face list."""
    v2, f2 = shifted(TET_V, TET_F, d, len(TET_V))
    return TET_V + v2, TET_F + f2


def cases():
    # A hole: one face missing.
    yield "open_lin.off", "not-closed", TET_V, TET_F[:3]
    # Two tetrahedra sharing the edge (0,0,0)-(0,0,1): four triangles on one edge. The
    # second is the first turned by 180 degrees about z, its corners welded to the first's.
    v = TET_V + [(-1, 0, 0), (0, -1, 0)]
    f = TET_F + [(0, 5, 4), (0, 4, 3), (0, 3, 5), (4, 5, 3)]
    yield "nonmanifold_edge_lin.off", "non-manifold-edge", v, f
    # Two tetrahedra touching at the vertex (0,0,0) only.
    v = TET_V + [(-1, 0, 0), (0, -1, 0), (0, 0, -1)]
    f = TET_F + [(0, 4, 5), (0, 6, 4), (0, 5, 6), (4, 6, 5)]
    yield "nonmanifold_vertex_lin.off", "non-manifold-vertex", v, f
    # Two tetrahedra crossing each other.
    v, f = two_tets((0.25, 0.25, 0.25))
    yield "self_intersection_lin.off", "self-intersection", v, f
    yield "self_intersection_lin.stl", "self-intersection", v, f
    # One face turned the wrong way.
    f = TET_F[:3] + [(1, 3, 2)]
    yield "flipped_lin.off", "inconsistent-orientation", TET_V, f
    # A zero-area facet, triangle 4 (collinear corners): edge 0-1 is split at vertex 4 in
    # one face only, and the sliver (0, 1, 4) closes the surface.
    v = TET_V + [(0.5, 0, 0)]
    f = [(0, 2, 4), (4, 2, 1), (0, 1, 3), (0, 3, 2), (1, 0, 4), (1, 2, 3)]
    yield "degenerate_lin.off", "degenerate-triangle", v, f
    # An STL facet with two identical corners (after welding, triangle 2 repeats a vertex).
    f = TET_F[:2] + [(1, 1, 2)] + TET_F[2:]
    yield "degenerate_facet_lin.stl", "degenerate-triangle", TET_V, f
    # A vertex no face uses.
    yield "unused_vertex_lin.off", "unused-node", TET_V + [(5, 5, 5)], TET_F
    # No faces at all.
    yield "empty_lin.off", "empty", [], []


def fmt(x):
    return repr(float(x))


def write_off(path, v, f):
    with open(path, "w") as out:
        out.write("OFF\n# %s\n%d %d 0\n" % (os.path.basename(path), len(v), len(f)))
        for p in v:
            out.write(" ".join(fmt(x) for x in p) + "\n")
        for t in f:
            out.write("3 %d %d %d\n" % t)


def write_stl(path, v, f):
    with open(path, "w") as out:
        out.write("solid bad\n")
        for t in f:
            out.write("facet normal 0 0 0\n outer loop\n")
            for i in t:
                out.write("  vertex %s\n" % " ".join(fmt(x) for x in v[i]))
            out.write(" endloop\nendfacet\n")
        out.write("endsolid bad\n")


def main():
    path = os.path.join(HERE, "EXPECTED.txt")
    kept = []
    if os.path.exists(path):
        with open(path) as f:
            kept = [l.rstrip("\n") for l in f if l.strip() and "_lin." not in l.split()[0]]
    lines = []
    for name, kind, v, f in cases():
        (write_off if name.endswith(".off") else write_stl)(os.path.join(HERE, name), v, f)
        lines.append("%s %s" % (name, kind))
    with open(path, "w") as out:
        out.write("\n".join(kept + lines) + "\n")
    print("wrote %d linear files to %s" % (len(lines), HERE))


if __name__ == "__main__":
    main()
