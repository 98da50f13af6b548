"""Tests of curvetet_gmsh.generate (Python) on Gmsh models (ctest: gmsh_py).

Environment: CURVETET_LIBRARY (libcurvetet), CURVETET_CLI (the curvetet tool, for
`curvetet check`), CURVETET_TEST_OUT (output folder); PYTHONPATH holding curvetet_gmsh.py.
Run: python3 bindings/gmsh/tests/test_gmsh.py -v   (with Debian's python3-gmsh: /usr/bin/python3)
"""

import math
import os
import struct
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

import gmsh  # noqa: E402
import curvetet_gmsh  # noqa: E402

ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
CLI = os.environ.get("CURVETET_CLI") or os.path.join(ROOT, "target", "release", "curvetet")
OUT = os.environ.get("CURVETET_TEST_OUT") or tempfile.mkdtemp(prefix="curvetet_gmsh_py_")

# Faces of a 10-node tet in Gmsh order (corners, then edges (0,1)=4 (1,2)=5 (2,0)=6 (3,0)=7
# (3,2)=8 (3,1)=9).
FACES = ((0, 1, 2, 4, 5, 6), (0, 1, 3, 4, 9, 7), (1, 2, 3, 5, 8, 9), (0, 2, 3, 6, 8, 7))


def tolist(a):
    return a.tolist() if hasattr(a, "tolist") else list(a)


def all_nodes():
    tags, xyz, _ = gmsh.model.mesh.getNodes(-1, -1, False, False)
    tags, xyz = tolist(tags), tolist(xyz)
    return {t: tuple(xyz[3 * i:3 * i + 3]) for i, t in enumerate(tags)}


def surface_triangles(surface=-1):
    elems, nodes = gmsh.model.mesh.getElementsByType(9, surface)
    nodes = tolist(nodes)
    return {tuple(sorted(nodes[6 * e:6 * e + 6])): int(t) for e, t in enumerate(tolist(elems))}


def tets_of(volume=-1):
    elems, nodes = gmsh.model.mesh.getElementsByType(11, volume)
    return tolist(elems), tolist(nodes)


def face_counts(tets):
    counts = {}
    for t in range(len(tets) // 10):
        n = tets[10 * t:10 * t + 10]
        for f in FACES:
            k = tuple(sorted(n[i] for i in f))
            counts[k] = counts.get(k, 0) + 1
    return counts


def tet_volume(volume=-1):
    # The Jacobian determinant of a 10-node tet is cubic: "Gauss3" is exact (Gmsh 4.8's
    # "Gauss4" weights sum to 1/6 only to 3e-12).
    local, weights = gmsh.model.mesh.getIntegrationPoints(11, "Gauss3")
    _, dets, _ = gmsh.model.mesh.getJacobians(11, local, volume)
    weights, dets = tolist(weights), tolist(dets)
    return math.fsum(d * weights[i % len(weights)] for i, d in enumerate(dets))


def bits(xyz):
    return struct.pack("<3d", *xyz)


def count_elements():
    _, elems, _ = gmsh.model.mesh.getElements()
    return sum(len(e) for e in elems)


class GmshCase(unittest.TestCase):
    def setUp(self):
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)

    def tearDown(self):
        gmsh.finalize()

    def surface_mesh_order2(self, h):
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        gmsh.option.setNumber("Mesh.ElementOrder", 2)
        gmsh.model.mesh.generate(2)

    def check_volume_mesh(self, surface_tris):
        self.assertEqual(tolist(gmsh.model.mesh.getElementTypes(3)), [11])
        elems, tets = tets_of()
        self.assertGreater(len(elems), 0)
        counts = face_counts(tets)
        self.assertLessEqual(max(counts.values()), 2, "a face is used by more than two tets")
        boundary = {k for k, n in counts.items() if n == 1}
        self.assertEqual(boundary, set(surface_tris), "tets' boundary != surface triangles")


class TestTorus(GmshCase):
    def test_torus(self):
        R, r = 1.0, 0.35
        gmsh.model.occ.addTorus(0, 0, 0, R, r)
        gmsh.model.occ.synchronize()
        self.surface_mesh_order2(0.12)
        before = all_nodes()
        tris = surface_triangles()
        stages = []
        curvetet_gmsh.generate(alpha=1.5, optimize=True,
                               progress=lambda f, s: stages.append(s) and False)
        self.assertIn("front", stages)
        self.check_volume_mesh(tris)
        exact = 2 * math.pi ** 2 * R * r * r
        self.assertAlmostEqual(tet_volume() / exact, 1.0, delta=1e-3)

        path = os.path.join(OUT, "torus.msh")
        os.makedirs(OUT, exist_ok=True)
        gmsh.option.setNumber("Mesh.Binary", 1)
        gmsh.write(path)
        gmsh.clear()
        gmsh.open(path)
        self.check_volume_mesh(tris)
        self.assertEqual(surface_triangles(), tris)
        after = all_nodes()
        self.assertGreater(len(after), len(before))
        changed = [t for t, x in before.items() if t not in after or bits(after[t]) != bits(x)]
        self.assertEqual(changed, [], "surface nodes not bit-identical after write + open")
        run = subprocess.run([CLI, "check", path], capture_output=True, text=True)
        print(run.stdout, run.stderr)
        self.assertEqual(run.returncode, 0, "curvetet check failed")
        self.assertIn("valid P2 volume mesh", run.stdout)


class TestTwoVolumes(GmshCase):
    def test_box_with_ball(self):
        c, rad = 1.0, 0.5
        gmsh.model.occ.addBox(0, 0, 0, 2, 2, 2)
        gmsh.model.occ.addSphere(c, c, c, rad)
        gmsh.model.occ.fragment([(3, 1)], [(3, 2)])
        gmsh.model.occ.synchronize()
        self.surface_mesh_order2(0.25)
        before = all_nodes()
        tris = surface_triangles()
        vols = [t for _, t in gmsh.model.getEntities(3)]
        self.assertEqual(len(vols), 2)
        bnd = {v: gmsh.model.getBoundary([(3, v)], combined=False) for v in vols}
        ball = next(v for v in vols if len(bnd[v]) == 1)
        shell = next(v for v in vols if v != ball)
        sphere_surface = abs(bnd[ball][0][1])
        sphere_tris = surface_triangles(sphere_surface)

        curvetet_gmsh.generate()

        self.check_volume_mesh({k: e for k, e in tris.items() if k not in sphere_tris})
        nodes_of = {}
        for v, own in ((ball, sphere_tris), (shell, tris)):
            elems, tets = tets_of(v)
            self.assertGreater(len(elems), 0)
            counts = face_counts(tets)
            self.assertEqual({k for k, n in counts.items() if n == 1}, set(own),
                             "volume %d: boundary != its surfaces" % v)
            nodes_of[v] = set(tets)
        # The ball's tets are inside the ball (corners are; it is convex).
        nodes = all_nodes()
        _, tets = tets_of(ball)
        for t in range(len(tets) // 10):
            g = [sum(nodes[tets[10 * t + k]][d] for k in range(4)) / 4 for d in range(3)]
            self.assertLessEqual(math.dist(g, (c, c, c)), rad)
        # Interface nodes shared (reused), nothing else.
        interface = set(n for k in sphere_tris for n in k)
        self.assertEqual(nodes_of[ball] & nodes_of[shell], interface)
        moved = [t for t, x in before.items() if bits(nodes[t]) != bits(x)]
        self.assertEqual(moved, [])
        vb, vs = tet_volume(ball), tet_volume(shell)
        print("ball %.12f, box minus ball %.12f, sum %.15f" % (vb, vs, vb + vs))
        self.assertLess(abs(vb + vs - 8.0), 1e-12 * 8)
        self.assertAlmostEqual(vb / (4 / 3 * math.pi * rad ** 3), 1.0, delta=2e-3)


class TestCavity(GmshCase):
    def test_box_minus_ball(self):
        # One volume with two shells: Gmsh 4.8's oriented boundary gives the cavity's
        # sphere a positive sign; the wrapper must turn it inward.
        gmsh.model.occ.addBox(0, 0, 0, 2, 2, 2)
        gmsh.model.occ.addSphere(1, 1, 1, 0.5)
        gmsh.model.occ.cut([(3, 1)], [(3, 2)])
        gmsh.model.occ.synchronize()
        self.assertEqual(len(gmsh.model.getEntities(3)), 1)
        self.surface_mesh_order2(0.25)
        tris = surface_triangles()
        curvetet_gmsh.generate()
        self.check_volume_mesh(tris)
        exact = 8 - 4 / 3 * math.pi * 0.5 ** 3
        self.assertAlmostEqual(tet_volume() / exact, 1.0, delta=1e-4)
        # Gmsh's own tools work on the result: Jacobians at nodes and Gauss points are
        # positive; its high-order optimizer runs.
        _, _, _, _, nodal, _ = gmsh.model.mesh.getElementProperties(11)
        local, _ = gmsh.model.mesh.getIntegrationPoints(11, "Gauss6")
        _, dets, _ = gmsh.model.mesh.getJacobians(11, tolist(nodal) + tolist(local))
        self.assertGreater(min(tolist(dets)), 0)
        gmsh.model.mesh.optimize("HighOrder")
        self.assertEqual(tolist(gmsh.model.mesh.getElementTypes(3)), [11])


class TestFailures(GmshCase):
    def expect_failure(self, needle):
        n, e = len(all_nodes()), count_elements()
        with self.assertRaises(curvetet_gmsh.CurvetetError) as cm:
            curvetet_gmsh.generate()
        print(cm.exception)
        self.assertIn(needle, str(cm.exception))
        self.assertEqual((len(all_nodes()), count_elements()), (n, e), "the model changed")

    def test_no_volume(self):
        gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
        gmsh.model.occ.synchronize()
        self.surface_mesh_order2(0.3)
        self.expect_failure("no volume")

    def test_first_order_and_no_mesh(self):
        gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.ElementOrder", 1)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
        gmsh.model.mesh.generate(2)
        self.expect_failure("6-node triangles")
        gmsh.model.mesh.clear()
        self.expect_failure("no mesh")

    def test_open_surface(self):
        # A discrete volume bounded by three of the four faces of a P2 tetrahedron.
        s = gmsh.model.addDiscreteEntity(2)
        gmsh.model.addDiscreteEntity(3, -1, [s])
        p = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
        tags, xyz, mid = [1, 2, 3, 4], [x for q in p for x in q], {}
        for i in range(4):
            for j in range(i + 1, 4):
                tags.append(len(tags) + 1)
                mid[i, j] = mid[j, i] = tags[-1]
                xyz += [(a + b) / 2 for a, b in zip(p[i], p[j])]
        gmsh.model.mesh.addNodes(2, s, tags, xyz)
        tri = []
        for f in ((0, 2, 1), (0, 1, 3), (1, 2, 3)):  # face (0, 3, 2) missing
            tri += [f[0] + 1, f[1] + 1, f[2] + 1] + [mid[f[k], f[(k + 1) % 3]] for k in range(3)]
        gmsh.model.mesh.addElementsByType(s, 9, [1, 2, 3], tri)
        self.expect_failure("CURVETET_ERR_INVALID_SURFACE")
        # The message also names the Gmsh element and nodes.
        self.expect_failure("[in Gmsh's numbers: triangle 0 = element 1 of surface %d; node 0 = node 1" % s)

    def test_already_meshed(self):
        gmsh.model.occ.addSphere(0, 0, 0, 1)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.4)
        gmsh.model.mesh.generate(3)
        self.expect_failure("already has a 3D mesh")

    def test_cancel(self):
        gmsh.model.occ.addSphere(0, 0, 0, 1)
        gmsh.model.occ.synchronize()
        self.surface_mesh_order2(0.3)
        n = count_elements()
        with self.assertRaises(curvetet_gmsh.CurvetetError) as cm:
            curvetet_gmsh.generate(progress=lambda f, s: True)
        self.assertIn("CURVETET_ERR_CANCELLED", str(cm.exception))
        self.assertEqual(count_elements(), n)


class TestOptions(GmshCase):
    def test_options_struct_is_the_headers(self):
        # curvetet_options_default writes this library's sizeof(curvetet_options) into
        # struct_size: the Python mirror must have every field of the header.
        import ctypes
        lib = curvetet_gmsh._load()
        buf = ctypes.create_string_buffer(4096)
        lib.curvetet_options_default.argtypes = [ctypes.c_void_p]
        lib.curvetet_options_default.restype = None
        lib.curvetet_options_default(buf)
        size = struct.unpack_from("I", buf.raw, 0)[0]
        self.assertEqual(size, ctypes.sizeof(curvetet_gmsh._Options))
        opt = curvetet_gmsh._Options.from_buffer_copy(buf.raw[:size])
        self.assertEqual((opt.optimize, opt.uniform_size, opt.thorough), (1, 0, 0))

    def test_thorough_reaches_curvetet(self):
        # The flag curvetet_generate receives (a sphere starts fair, so the meshes
        # themselves would not tell).
        def sphere():
            gmsh.clear()
            gmsh.model.occ.addSphere(0, 0, 0, 1)
            gmsh.model.occ.synchronize()
            self.surface_mesh_order2(0.3)
            return surface_triangles()

        lib = curvetet_gmsh._load()
        real = lib.curvetet_generate
        seen = []

        def spy(surface, opt, mesh):
            seen.append(opt._obj.thorough)
            return real(surface, opt, mesh)

        lib.curvetet_generate = spy
        try:
            for flag in (True, False):
                tris = sphere()
                curvetet_gmsh.generate(thorough=flag)
                self.check_volume_mesh(tris)
        finally:
            lib.curvetet_generate = real
        self.assertEqual(seen, [1, 0])


if __name__ == "__main__":
    print("libcurvetet:", curvetet_gmsh.library_path(), "version", curvetet_gmsh.version())
    unittest.main()
