#!/usr/bin/env python3
"""Writes the bad-input corpus: small Gmsh MSH 4.1 ASCII surfaces of 6-node triangles
(type 9), one per surface defect, and EXPECTED.txt ("filename kind-name", the kind being
`SurfaceDefect::name()`). Python 3 standard library only; deterministic.

    python3 tests/data/bad/make_bad.py      # rewrites the files beside this script

Base shapes: a P2 octahedron (mid nodes projected on the unit sphere) and flat P2
tetrahedra (mid nodes at chord midpoints; dyadic coordinates where contact is exact).
Each file has one defect, so the first failing check is the intended one.
"""

import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


class P2:
    def __init__(self, nodes, tris):
        self.nodes = [list(p) for p in nodes]
        self.tris = [list(t) for t in tris]

    def copy(self):
        return P2(self.nodes, self.tris)

    def union(self, other):
        off = len(self.nodes)
        r = self.copy()
        r.nodes += [list(p) for p in other.nodes]
        r.tris += [[v + off for v in t] for t in other.tris]
        return r

    def flipped(self):
        r = self.copy()
        r.tris = [[t[0], t[2], t[1], t[5], t[4], t[3]] for t in r.tris]
        return r

    def moved(self, f):
        r = self.copy()
        r.nodes = [list(f(p)) for p in r.nodes]
        return r

    def compact(self):
        used = sorted({v for t in self.tris for v in t})
        new = {v: i for i, v in enumerate(used)}
        return P2([self.nodes[v] for v in used], [[new[v] for v in t] for t in self.tris])

    def mid_of_edge(self, a, b):
        for t in self.tris:
            for k in range(3):
                if {t[k], t[(k + 1) % 3]} == {a, b}:
                    return t[3 + k]
        raise KeyError((a, b))

    def set_mid(self, a, b, m):
        for t in self.tris:
            for k in range(3):
                if {t[k], t[(k + 1) % 3]} == {a, b}:
                    t[3 + k] = m


def build(verts, faces, mid_of):
    nodes = [list(v) for v in verts]
    mids = {}
    tris = []
    for f in faces:
        t = list(f) + [0, 0, 0]
        for k in range(3):
            a, b = f[k], f[(k + 1) % 3]
            key = (min(a, b), max(a, b))
            if key not in mids:
                nodes.append(mid_of(verts[a], verts[b]))
                mids[key] = len(nodes) - 1
            t[3 + k] = mids[key]
        tris.append(t)
    return P2(nodes, tris)


def chord_mid(a, b):
    return [(a[i] + b[i]) / 2 for i in range(3)]


def sphere_mid(a, b):
    m = chord_mid(a, b)
    n = math.sqrt(sum(x * x for x in m))
    r = math.sqrt(sum(x * x for x in a))
    return [r * x / n for x in m]


def octahedron(r=1.0):
    v = [[r, 0, 0], [-r, 0, 0], [0, r, 0], [0, -r, 0], [0, 0, r], [0, 0, -r]]
    v = [[float(x) for x in p] for p in v]
    faces = []
    for sx, X in ((1, 0), (-1, 1)):
        for sy, Y in ((1, 2), (-1, 3)):
            for sz, Z in ((1, 4), (-1, 5)):
                faces.append([X, Y, Z] if sx * sy * sz > 0 else [X, Z, Y])
    return build(v, faces, sphere_mid)


def tet(c):
    """Outward flat P2 surface of tetrahedron c (either orientation)."""
    d = [[c[k][i] - c[0][i] for i in range(3)] for k in (1, 2, 3)]
    det = (d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1])
           - d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0])
           + d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]))
    faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
    if det < 0:
        faces = [[f[0], f[2], f[1]] for f in faces]
    return build([[float(x) for x in p] for p in c], faces, chord_mid)


O, X, Y, Z = [0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]


def unit_tet():
    return tet([O, X, Y, Z])


def fmt(x):
    return repr(float(x))


def write_msh(name, s):
    finite = [x for p in s.nodes for x in p if math.isfinite(x)] or [0.0]
    lo, hi = min(finite), max(finite)
    n, m = len(s.nodes), len(s.tris)
    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$Entities"]
    if m:
        out += ["0 0 1 0", "1 %s %s %s %s %s %s 0 0" % (fmt(lo), fmt(lo), fmt(lo), fmt(hi), fmt(hi), fmt(hi))]
    else:
        out += ["0 0 0 0"]
    out += ["$EndEntities", "$Nodes"]
    if n:
        out += ["1 %d 1 %d" % (n, n), "2 1 0 %d" % n]
        out += [str(i + 1) for i in range(n)]
        out += [" ".join(fmt(x) for x in p) for p in s.nodes]
    else:
        out += ["0 0 0 0"]
    out += ["$EndNodes", "$Elements"]
    if m:
        out += ["1 %d 1 %d" % (m, m), "2 1 9 %d" % m]
        out += ["%d %s" % (i + 1, " ".join(str(v + 1) for v in t)) for i, t in enumerate(s.tris)]
    else:
        out += ["0 0 0 0"]
    out += ["$EndElements"]
    with open(os.path.join(HERE, name), "w") as f:
        f.write("\n".join(out) + "\n")


def cases():
    oc = octahedron()

    yield "empty.msh", "empty", P2([], [])

    s = oc.copy()
    s.tris[2][4] = len(s.nodes) + 4  # a node tag no $Nodes block defines
    yield "index_out_of_range.msh", "index-out-of-range", s

    s = oc.copy()
    s.tris[5][1] = s.tris[5][0]
    yield "repeated_node.msh", "repeated-node", s

    s = oc.copy()
    s.nodes[4][1] = float("nan")
    yield "nan_coordinate.msh", "non-finite-coordinate", s

    s = oc.copy()
    s.nodes[7][0] = float("inf")
    yield "inf_coordinate.msh", "non-finite-coordinate", s

    yield "huge_coordinates.msh", "coordinate-range", oc.moved(lambda p: [x * 1e300 for x in p])
    yield "tiny_model.msh", "coordinate-range", oc.moved(lambda p: [x * 1e-300 for x in p])

    s = oc.copy()
    s.nodes.append(list(s.nodes[0]))
    t = next(i for i, t in enumerate(s.tris) if t[0] == 0)
    s.tris[t][0] = len(s.nodes) - 1
    yield "duplicate_node.msh", "duplicate-node", s

    s = oc.copy()
    s.nodes.append([5.0, 5.0, 5.0])
    yield "unused_node.msh", "unused-node", s

    s = oc.copy()
    del s.tris[3]
    yield "open.msh", "not-closed", s

    # Half an equatorial membrane inside the octahedron: a fin whose two outer edges
    # have 3 triangles and whose edge through the centre is open. (A whole membrane
    # would split the octahedron into two regions: a valid surface of two regions.)
    s = oc.copy()
    s.nodes.append([0.0, 0.0, 0.0])
    d = len(s.nodes) - 1
    s.tris.append([0, 2, 1, s.mid_of_edge(0, 2), s.mid_of_edge(2, 1), d])
    yield "nonmanifold_edge.msh", "non-manifold-edge", s

    # Bowtie: two tetrahedra sharing only the origin.
    a = unit_tet()
    b = tet([O, [-1, 0, 0], [0, -1, 0], [0, 0, -1]])
    s = a.union(b)
    off = len(a.nodes)
    s.tris = [[0 if v == off else v for v in t] for t in s.tris]
    yield "nonmanifold_vertex.msh", "non-manifold-vertex", s.compact()

    s = oc.copy()
    t = s.tris[6]
    s.tris[6] = [t[0], t[2], t[1], t[5], t[4], t[3]]
    yield "flipped_triangle.msh", "inconsistent-orientation", s

    # A cavity facing out like its container.
    yield "shells_disagree.msh", "inconsistent-orientation", octahedron(2.0).union(octahedron(1.0))

    s = oc.copy()
    a, b, m = s.tris[0][0], s.tris[0][1], s.tris[0][3]
    s.nodes.append([1.01 * x for x in s.nodes[m]])
    s.tris[0][3] = len(s.nodes) - 1
    yield "mid_node_mismatch.msh", "mid-node-mismatch", s

    s = oc.copy()
    s.set_mid(0, 2, 1)  # the corner -x as the mid node of edge (+x, +y)
    yield "mid_node_as_corner.msh", "mid-node-mismatch", s.compact()

    # A tet whose edge O-X is split at E on one side, closed by the collinear (O, X, E).
    v = [O, [2, 0, 0], [0, 2, 0], [0, 0, 2], [0.5, 0, 0]]
    o, x, y, z, e = range(5)
    faces = [[o, y, x], [o, e, z], [e, x, z], [o, z, y], [x, y, z], [o, x, e]]
    yield "degenerate_triangle.msh", "degenerate-triangle", build([[float(c) for c in p] for p in v], faces, chord_mid)

    # Mid node pushed along its edge past the 3/4 point: the curved edge turns back.
    s = oc.copy()
    a, b, m = s.tris[0][0], s.tris[0][1], s.tris[0][3]
    pa, pb = s.nodes[a], s.nodes[b]
    s.nodes[m] = [pa[i] + 0.9 * (pb[i] - pa[i]) for i in range(3)]
    yield "folded_triangle.msh", "folded-triangle", s

    b = tet([[0.2, 0.2, 0.2], [-1, 0.1, 0.1], [0.1, -1, 0.1], [0.1, 0.1, -1]])
    yield "self_intersection_crossing.msh", "self-intersection", unit_tet().union(b)

    b = tet([[0.25, 0.25, 0], [0, 0, -1], [1, 0, -1], [0, 1, -1]])
    yield "self_intersection_touching.msh", "self-intersection", unit_tet().union(b)

    b = tet([[0.25, 0.25, 0], [1.25, 0.25, 0], [0.25, 1.25, 0], [0.25, 0.25, -1]])
    yield "self_intersection_coplanar.msh", "self-intersection", unit_tet().union(b)

    # Chords 0.1 apart, but a mid node of the upper tet bulges 0.2 down into the lower.
    a = unit_tet()
    b = tet([[0, 0, -0.1], [1, 0, -0.1], [0, 1, -0.1], [0, 0, -1.1]])
    s = a.union(b)
    s.nodes[s.mid_of_edge(0, 1)] = [0.5, 0.0, -0.2]
    yield "self_intersection_curved.msh", "self-intersection", s

    yield "shells_intersecting.msh", "self-intersection", oc.union(oc.moved(lambda p: [p[0] + 0.5, p[1] + 0.1, p[2] + 0.05]))


def main():
    expected = []
    for name, kind, s in cases():
        write_msh(name, s)
        expected.append("%s %s" % (name, kind))
    with open(os.path.join(HERE, "EXPECTED.txt"), "w") as f:
        f.write("\n".join(expected) + "\n")
    print("wrote %d files to %s" % (len(expected), HERE))
    # The linear files (make_bad_linear.py) add their lines to EXPECTED.txt.
    import make_bad_linear

    make_bad_linear.main()


if __name__ == "__main__":
    main()
