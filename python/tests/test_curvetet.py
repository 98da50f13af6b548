"""Tests of the installed curvetet package (scripts/python-test runs them against the wheel)."""

from __future__ import annotations

import importlib
import importlib.util
import math
import os
import signal
import warnings

import numpy as np
import pytest

import curvetet

SPHERE_VOLUME = 4.0 / 3.0 * math.pi


def optional(module: str):
    """An optional extra (meshio, pyvista, tqdm): skipped when missing, except under
    CURVETET_REQUIRE_TOOLS=1 (scripts/python-test installs them all: none may skip)."""
    if os.environ.get("CURVETET_REQUIRE_TOOLS") == "1":
        return importlib.import_module(module)
    return pytest.importorskip(module)


def icosphere(level: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """A unit icosphere: linear triangles, outward, vertices on the sphere."""
    t = (1.0 + 5.0**0.5) / 2.0
    pts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
           (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    tris = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
            (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
            (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    points = [np.array(p, dtype=float) / np.linalg.norm(p) for p in pts]
    for _ in range(level):
        mid: dict[tuple[int, int], int] = {}

        def middle(a: int, b: int) -> int:
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = points[a] + points[b]
                points.append(p / np.linalg.norm(p))
                mid[key] = len(points) - 1
            return mid[key]

        new = []
        for a, b, c in tris:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        tris = new
    return np.array(points), np.array(tris, dtype=np.int64)


def tet_volumes(nodes: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """Volumes of 10-node tets (Gmsh order) by 4-point Gauss quadrature of det J."""
    a, b = 0.5854101966249685, 0.1381966011250105
    pts = [(a, b, b), (b, a, b), (b, b, a), (b, b, b)]
    x = nodes[tets]  # (T, 10, 3)
    vol = np.zeros(len(tets))
    for (u, v, w) in pts:
        l0 = 1 - u - v - w
        # Gmsh order: 0..3 corners (l0, u, v, w), 4:(0,1) 5:(1,2) 6:(2,0) 7:(3,0) 8:(3,2) 9:(3,1)
        dn = np.zeros((10, 3))
        lam = [l0, u, v, w]
        dl = [(-1, -1, -1), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
        for i in range(4):
            dn[i] = (4 * lam[i] - 1) * np.array(dl[i])
        for k, (i, j) in zip(range(4, 10), [(0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1)]):
            dn[k] = 4 * (lam[i] * np.array(dl[j]) + lam[j] * np.array(dl[i]))
        jac = np.einsum("tna,nb->tab", x, dn)
        vol += np.linalg.det(jac) / 24.0
    return vol


@pytest.fixture(scope="module")
def sphere() -> tuple[np.ndarray, np.ndarray, curvetet.Mesh]:
    points, tris = icosphere(2)
    return points, tris, curvetet.mesh(points, tris, threads=2)


def test_sphere_from_numpy(sphere):
    points, tris, m = sphere
    assert m.tets.shape[1] == 10 and m.tets.dtype == np.int64 and len(m.tets) > 0
    assert m.nodes.shape[1] == 3 and m.nodes.dtype == np.float64
    assert m.tets.min() >= 0 and m.tets.max() < len(m.nodes)
    # The input vertices keep their indices and coordinates.
    assert np.array_equal(m.nodes[: len(points)], points)
    vol = tet_volumes(m.nodes, m.tets)
    assert (vol > 0).all()
    assert abs(vol.sum() - SPHERE_VOLUME) / SPHERE_VOLUME < 0.02, vol.sum()
    assert m.boundary_faces.shape == (len(tris), 6)
    assert len(m.boundary_tags) == len(tris)
    assert m.quality["num_tets"] == len(m.tets)
    assert m.quality["num_invalid"] == 0
    assert m.scaled_jacobian.shape == (len(m.tets),)
    # One closed surface: one region, the volume's tag 1 on every tet.
    assert m.num_regions == 1 and np.array_equal(m.tet_regions, np.ones(len(m.tets)))
    assert abs(m.scaled_jacobian.min() - m.quality["min_scaled_jacobian"]) < 1e-9
    assert isinstance(m.report, dict) and m.report
    assert m.target_size > 0
    # tets_vtk is Gmsh's order with the last two nodes swapped.
    assert np.array_equal(m.tets_vtk[:, 8], m.tets[:, 9])


def test_p2_surface_and_tags(sphere):
    points, tris, m = sphere
    tags = np.arange(len(tris)) % 3 + 1
    # The curved surface's own P2 triangles, with tags, mesh again.
    s = curvetet.surface(m.nodes, m.boundary_faces, tags)
    assert s.triangles.shape == (len(tris), 6)
    m2 = curvetet.mesh(s, threads=2)
    assert sorted(set(m2.boundary_tags.tolist())) == [1, 2, 3]
    assert len(m2.boundary_faces) == len(tris)


@pytest.mark.parametrize("ext", [".msh", ".vtu", ".vtk", ".mesh"])
def test_write_and_read_back(sphere, tmp_path, ext):
    _, tris, m = sphere
    path = tmp_path / ("sphere" + ext)
    m.write(path)
    assert path.stat().st_size > 0
    # curvetet reads back the boundary of the volume mesh it wrote.
    s = curvetet.read(path)
    assert len(s.triangles) == len(tris)
    want = np.unique(m.nodes[np.unique(m.boundary_faces)], axis=0)
    got = np.unique(s.nodes[np.unique(s.triangles)], axis=0)
    assert got.shape == want.shape and np.allclose(got, want, rtol=0, atol=1e-12)
    # The file was checked above; meshio (an optional extra) reads it too.
    if os.environ.get("CURVETET_REQUIRE_TOOLS") != "1" and importlib.util.find_spec("meshio") is None:
        return
    import meshio
    if ext == ".mesh":
        # meshio's medit reader has no P2 sections (TetrahedraP2): check the linear variant.
        path = tmp_path / "sphere_linear.mesh"
        m.write(path, medit_linear=True)
        back = meshio.read(path)
        assert len(back.get_cells_type("tetra")) == len(m.tets)
        assert np.array_equal(back.get_cells_type("tetra"), m.tets[:, :4])
        return
    back = meshio.read(path)
    assert np.array_equal(back.get_cells_type("tetra10")[:, :4], m.tets[:, :4])
    assert len(back.get_cells_type("tetra10")) == len(m.tets)
    assert np.allclose(back.points, m.nodes, rtol=0, atol=1e-12)


@pytest.mark.parametrize("ext,flags", [(".msh", {"binary": True}), (".msh", {"msh22": True}),
                                       (".vtu", {"binary": True})])
def test_write_flags(sphere, tmp_path, ext, flags):
    _, tris, m = sphere
    path = tmp_path / ("flags" + ext)
    m.write(path, **flags)
    assert len(curvetet.read(path).triangles) == len(tris)


def test_write_errors(sphere, tmp_path):
    _, _, m = sphere
    with pytest.raises(curvetet.CurvetetError) as err:
        m.write(tmp_path / "sphere.xyz")
    assert err.value.status == "CURVETET_ERR_INVALID_ARGUMENT"
    with pytest.raises(curvetet.CurvetetError) as err:
        m.write(tmp_path / "no" / "such" / "dir.vtu")
    assert err.value.status == "CURVETET_ERR_IO"


def test_meshio_round_trip(sphere, tmp_path):
    meshio = optional("meshio")
    _, tris, m = sphere
    mm = m.to_meshio()
    assert mm.get_cells_type("tetra10").shape == (len(m.tets), 10)
    path = tmp_path / "via_meshio.vtu"
    meshio.write(path, mm)
    back = meshio.read(path)
    assert np.array_equal(back.get_cells_type("tetra10"), m.tets_vtk)
    # A surface from meshio (triangle6 cells) meshes again with the same boundary.
    surf = meshio.Mesh(m.nodes, [("triangle6", m.boundary_faces)])
    s = curvetet.from_meshio(surf)
    assert len(s.triangles) == len(tris)
    m2 = curvetet.mesh(s, threads=2)
    assert len(m2.boundary_faces) == len(tris)
    # And a linear one (triangle cells).
    points, tris3 = icosphere(1)
    s3 = curvetet.from_meshio(meshio.Mesh(points, [("triangle", tris3)]))
    assert s3.triangles.shape == (len(tris3), 6)


def test_open_surface_raises():
    points, tris = icosphere(1)
    with pytest.raises(curvetet.CurvetetError) as err:
        curvetet.mesh(points, tris[1:])
    assert err.value.status == "CURVETET_ERR_INVALID_SURFACE"
    assert err.value.code == 4
    msg = err.value.message.lower()
    assert "closed" in msg or "boundary" in msg or "open" in msg, err.value.message


def test_read_missing_file_raises(tmp_path):
    with pytest.raises(curvetet.CurvetetError) as err:
        curvetet.read(tmp_path / "nope.stl")
    assert err.value.status == "CURVETET_ERR_IO"
    assert "nope.stl" in err.value.message


def test_progress_non_decreasing_per_stage():
    points, tris = icosphere(1)
    calls: list[tuple[float, str]] = []
    curvetet.mesh(points, tris, threads=2, progress=lambda f, s: calls.append((f, s)))
    assert calls
    stages = [s for _, s in calls]
    assert "front" in stages and "certify" in stages
    last: dict[str, float] = {}
    for f, s in calls:
        assert 0.0 <= f <= 1.0
        assert f >= last.get(s, 0.0), (s, f, last[s])
        last[s] = f


def test_progress_cancel():
    points, tris = icosphere(1)
    with pytest.raises(curvetet.CurvetetError) as err:
        curvetet.mesh(points, tris, threads=2, progress=lambda f, s: False)
    assert err.value.status == "CURVETET_ERR_CANCELLED"


def test_keyboard_interrupt_cancels():
    points, tris = icosphere(1)
    seen = []

    def interrupt(f: float, s: str) -> None:
        seen.append(s)
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        curvetet.mesh(points, tris, threads=2, progress=interrupt)
    assert len(seen) == 1  # the work stopped at the first call


def test_callback_exception_propagates():
    points, tris = icosphere(1)

    def bad(f: float, s: str) -> None:
        raise ValueError("from the callback")

    with pytest.raises(ValueError, match="from the callback"):
        curvetet.mesh(points, tris, threads=2, progress=bad)


def test_bad_shapes():
    with pytest.raises(ValueError):
        curvetet.surface(np.zeros((4, 2)), np.zeros((1, 3), dtype=int))
    with pytest.raises(ValueError):
        curvetet.surface(np.zeros((4, 3)), np.zeros((1, 4), dtype=int))
    with pytest.raises(ValueError):
        curvetet.surface(np.zeros((4, 3)), -np.ones((1, 3), dtype=int))


def test_to_pyvista(sphere):
    pyvista = optional("pyvista")
    _, _, m = sphere
    grid = m.to_pyvista()
    assert grid.n_cells == len(m.tets)
    assert set(np.unique(grid.celltypes)) == {pyvista.CellType.QUADRATIC_TETRA}
    assert np.array_equal(np.asarray(grid.cell_data["Region"]), m.tet_regions)


def test_tqdm_progress(capsys):
    optional("tqdm")
    points, tris = icosphere(1)
    m = curvetet.mesh(points, tris, threads=2, progress=True)
    assert len(m.tets) > 0
    err = capsys.readouterr().err
    assert "front" in err and "certify" in err


def test_ctrl_c_cancels():
    """A real SIGINT (Ctrl-C) during generate cancels it and raises KeyboardInterrupt."""
    points, tris = icosphere(1)
    calls = []

    def send_sigint_once(f: float, s: str) -> None:
        calls.append(s)
        if len(calls) == 1:
            signal.raise_signal(signal.SIGINT)

    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            curvetet.mesh(points, tris, threads=2, progress=send_sigint_once)
        # Cancelled at the next callback: the front had just started.
        assert calls == ["front"], calls
        # Python's handler is back.
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, old)


# --- Several regions -------------------------------------------------------------------

def data_file(name: str) -> str:
    """A file of the repository's tests/data ($CURVETET_TEST_DATA, which scripts/python-test
    sets since it runs the tests outside the tree, else found beside python/tests)."""
    root = os.environ.get("CURVETET_TEST_DATA") or os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "data")
    path = os.path.join(root, name)
    assert os.path.exists(path), "no %s: set CURVETET_TEST_DATA to tests/data" % path
    return path


def linear_volumes(nodes: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """Volumes of the straight tets of the corner nodes (which tile the polyhedron of the
    boundary's corner triangles exactly, curved or not)."""
    x = nodes[tets[:, :4]]
    return np.einsum("ti,ti->t", np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]),
                     x[:, 3] - x[:, 0]) / 6.0


def polyhedron_volume(nodes: np.ndarray, tris: np.ndarray) -> float:
    """Volume enclosed by closed, outward triangles (their corners), by the divergence
    theorem."""
    x = nodes[tris[:, :3]]
    return float(np.einsum("ti,ti->t", x[:, 0], np.cross(x[:, 1], x[:, 2])).sum() / 6.0)


def face_regions(m: curvetet.Mesh) -> dict[tuple[int, ...], list[int]]:
    """Each tet face (its sorted corners) -> the region ids of the tets having it."""
    faces: dict[tuple[int, ...], list[int]] = {}
    for tet, region in zip(m.tets[:, :4].tolist(), m.tet_regions.tolist()):
        for skip in range(4):
            key = tuple(sorted(tet[:skip] + tet[skip + 1:]))
            faces.setdefault(key, []).append(region)
    return faces


def p2_sphere(radius: float, level: int, first: int) -> tuple[np.ndarray, np.ndarray]:
    """An icosphere of 6-node triangles (outward) with its mid nodes on the sphere; node
    indices start at ``first``."""
    points, tris = icosphere(level)
    nodes = list(points)
    mids: dict[tuple[int, int], int] = {}
    tri6 = []
    for a, b, c in tris.tolist():
        row = [a, b, c]
        for i, j in ((a, b), (b, c), (c, a)):
            key = (min(i, j), max(i, j))
            if key not in mids:
                p = nodes[i] + nodes[j]
                nodes.append(p / np.linalg.norm(p))
                mids[key] = len(nodes) - 1
            row.append(mids[key])
        tri6.append(row)
    return radius * np.array(nodes), np.array(tri6, dtype=np.int64) + first


def nested_spheres() -> tuple[np.ndarray, np.ndarray, int]:
    """A unit sphere inside a sphere of radius 2 (P2): nodes, triangles, and the number of
    the inner sphere's triangles (first)."""
    inner_pts, inner = p2_sphere(1.0, 1, 0)
    outer_pts, outer = p2_sphere(2.0, 2, len(inner_pts))
    return np.vstack([inner_pts, outer_pts]), np.vstack([inner, outer]), len(inner)


def test_two_region_box_from_file():
    """tests/data/split_box_p2.msh: the box [0,2]x[0,1]x[0,1] with a wall at x = 1."""
    s = curvetet.read(data_file("split_box_p2.msh"))
    assert s.num_regions == 2, s
    m = curvetet.mesh(s, threads=2)
    assert m.num_regions == 2
    assert m.tet_regions.shape == (len(m.tets),) and m.tet_regions.dtype == np.int32
    assert set(m.tet_regions.tolist()) == {1, 2}
    assert m.quality["num_invalid"] == 0
    # Each region is one half: its tets on one side of the wall, a unit volume.
    x = m.nodes[m.tets[:, :4]].mean(axis=1)[:, 0]
    left = m.tet_regions[np.argmin(x)]
    right = 3 - left
    assert (x[m.tet_regions == left] < 1.0).all() and (x[m.tet_regions == right] > 1.0).all()
    vol = linear_volumes(m.nodes, m.tets)
    assert (vol > 0).all()
    for region in (left, right):
        assert abs(vol[m.tet_regions == region].sum() - 1.0) < 1e-9, region
    # The wall's triangles are among the boundary faces once, each shared by a tet of
    # each region; every other boundary triangle is the face of one tet.
    faces = face_regions(m)
    on_wall = np.all(m.nodes[m.boundary_faces[:, :3], 0] == 1.0, axis=1)
    assert on_wall.sum() > 0
    tri_x = m.nodes[m.boundary_faces[:, :3], 0].mean(axis=1)
    for tri, wall, cx in zip(m.boundary_faces[:, :3].tolist(), on_wall.tolist(), tri_x):
        regions = sorted(faces[tuple(sorted(tri))])
        assert regions == ([1, 2] if wall else [left if cx < 1.0 else right]), tri


def test_nested_spheres_two_regions(tmp_path):
    points, tris, n_inner = nested_spheres()
    # Without the flag the inner sphere is a cavity: one region.
    assert curvetet.surface(points, tris).num_regions == 1
    assert curvetet.surface(points, tris, nested_regions=True).num_regions == 2
    m = curvetet.mesh(points, tris, nested_regions=True, threads=2)
    assert m.num_regions == 2
    ids = set(m.tet_regions.tolist())
    assert len(ids) == 2 and min(ids) > 0
    assert m.quality["num_invalid"] == 0
    # The region of the tet nearest the centre is the ball; the other the shell.
    centre = np.linalg.norm(m.nodes[m.tets[:, :4]].mean(axis=1), axis=1)
    ball = int(m.tet_regions[np.argmin(centre)])
    (shell,) = ids - {ball}
    vol = linear_volumes(m.nodes, m.tets)
    assert (vol > 0).all()
    v_in = polyhedron_volume(points, tris[:n_inner])
    v_out = polyhedron_volume(points, tris[n_inner:])
    for region, want in ((ball, v_in), (shell, v_out - v_in)):
        got = vol[m.tet_regions == region].sum()
        assert abs(got - want) / want < 1e-9, (region, got, want)
    # The inner sphere is the interface: each of its triangles a face of a ball tet and a
    # shell tet; the outer sphere's triangles are faces of one shell tet.
    faces = face_regions(m)
    for tri in tris[:n_inner, :3].tolist():
        assert sorted(faces[tuple(sorted(tri))]) == sorted([ball, shell]), tri
    for tri in tris[n_inner:, :3].tolist():
        assert faces[tuple(sorted(tri))] == [shell], tri
    assert len(m.boundary_faces) == len(tris)
    # The written .msh puts each region in its own physical volume (read by meshio).
    path = tmp_path / "nested.msh"
    m.write(path)
    meshio = optional("meshio")
    back = meshio.read(path)
    got = set()
    for block, phys in zip(back.cells, back.cell_data["gmsh:physical"]):
        if block.type == "tetra10":
            got |= {(tuple(sorted(t)), int(r)) for t, r in zip(block.data[:, :4].tolist(), phys)}
    want = {(tuple(sorted(t)), r) for t, r in zip(m.tets[:, :4].tolist(), m.tet_regions.tolist())}
    assert got == want


def test_nested_regions_arguments():
    points, tris, _ = nested_spheres()
    s = curvetet.surface(points, tris, nested_regions=True)
    with pytest.raises(ValueError, match="nested_regions"):
        curvetet.mesh(s, nested_regions=True)
    lin_points, lin_tris = icosphere(1)
    with pytest.raises(ValueError, match="nested_regions"):
        curvetet.surface(lin_points, lin_tris, nested_regions=True)


@pytest.fixture(scope="module")
def split_box() -> curvetet.Mesh:
    return curvetet.mesh(curvetet.read(data_file("split_box_p2.msh")), threads=2)


@pytest.mark.parametrize("ext,fmt", [(".vtu", "vtu"), (".vtk", "vtk")])
def test_regions_meshio_round_trip(split_box, tmp_path, capfd, ext, fmt):
    meshio = optional("meshio")
    m = split_box
    mm = m.to_meshio()
    tet_block = [c.type for c in mm.cells].index("tetra10")
    assert np.array_equal(mm.cell_data["region"][tet_block], m.tet_regions)
    path = tmp_path / ("regions" + ext)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        meshio.write(path, mm, file_format=fmt)
    assert "warning" not in capfd.readouterr().err.lower()
    back = meshio.read(path)
    block = [c.type for c in back.cells].index("tetra10")
    assert np.array_equal(back.cells[block].data, m.tets_vtk)
    assert np.array_equal(np.asarray(back.cell_data["region"][block]), m.tet_regions)
    assert sorted(np.unique(back.cell_data["region"][block]).tolist()) == [1, 2]


def test_regions_to_pyvista(split_box):
    optional("pyvista")
    grid = split_box.to_pyvista()
    assert np.array_equal(np.asarray(grid.cell_data["Region"]), split_box.tet_regions)
    assert sorted(np.unique(grid.cell_data["Region"]).tolist()) == [1, 2]
