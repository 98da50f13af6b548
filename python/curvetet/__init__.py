"""curvetet: curved (quadratic, 10-node) tetrahedral meshes of closed surfaces, from Python.

A thin layer over the curvetet C ABI (``include/curvetet.h``; the shared library ships
inside this package). Arrays go in and come out as numpy arrays::

    import curvetet
    m = curvetet.mesh(points, triangles)      # (N, 3) floats; (M, 3) or (M, 6) node indices
    m.nodes, m.tets, m.boundary_faces, m.quality
    m.write("part.vtu")

A surface may bound several regions (materials sharing interfaces, each interface triangle
given once; or, with ``nested_regions=True``, closed shells nested in one another): the
mesh is then one conforming mesh with a region id per tet (``Mesh.tet_regions``).

Node orders: a 6-node triangle is its corners, then the mid nodes of edges (0,1), (1,2),
(2,0) (Gmsh's and VTK's order). ``Mesh.tets`` is in Gmsh's order (element type 11: corners,
mid nodes of (0,1), (1,2), (2,0), (3,0), (3,2), (3,1)); ``Mesh.tets_vtk`` is in VTK's order
(VTK_QUADRATIC_TETRA, the last two swapped), the one meshio and pyvista use.
"""

from __future__ import annotations

import contextlib
import ctypes
import json
import os
import signal
import threading
import weakref
from typing import Any, Callable, Iterator, Optional, Union

import numpy as np

from . import _lib

__all__ = [
    "CurvetetError",
    "Mesh",
    "Surface",
    "from_meshio",
    "library_version",
    "mesh",
    "read",
    "surface",
]

__version__ = "0.1.0"

ProgressFn = Callable[[float, str], Optional[bool]]
"""A progress callback: ``fn(fraction, stage)``; return ``False`` to cancel."""


class CurvetetError(Exception):
    """A failed curvetet call: ``status`` is the status name (e.g.
    ``"CURVETET_ERR_INVALID_SURFACE"``), ``code`` its number and ``message`` the library's
    message (which names the failing check and the element, line or path)."""

    def __init__(self, code: int, message: str) -> None:
        self.code = int(code)
        self.status = _lib.load().curvetet_error_name(self.code).decode()
        self.message = message
        super().__init__("%s: %s" % (self.status, message))


def _check(code: int) -> None:
    if code != _lib.OK:
        msg = _lib.load().curvetet_last_error_message().decode(errors="replace")
        raise CurvetetError(code, msg)


def library_version() -> str:
    """The version of the shipped C library, e.g. ``"0.1.0"``."""
    return _lib.load().curvetet_version().decode()


def _ptr(a: np.ndarray, ctype: Any) -> Any:
    return a.ctypes.data_as(ctypes.POINTER(ctype))


def _index_array(a: Any, what: str) -> np.ndarray:
    a = np.asarray(a)
    if a.dtype.kind not in "iu":
        raise ValueError("%s: node indices must be integers, not %s" % (what, a.dtype))
    if a.size and (a.min() < 0 or a.max() > 0xFFFFFFFF):
        raise ValueError("%s: node indices must be in 0..4294967295" % what)
    return np.ascontiguousarray(a, dtype=np.uint32)


class Surface:
    """A closed quadratic (6-node) triangle surface, checked by the library (closed,
    manifold, oriented, not self-intersecting), or a surface of several regions (each
    region's boundary checked). Build it with :func:`surface`, :func:`read` or
    :func:`from_meshio`.

    ``nodes`` is (N, 3) float64, ``triangles`` (M, 6) int64 (outward, after any flip the
    check made), ``tags`` (M,) int32, ``warnings`` the check's warnings (e.g. a flipped
    orientation), ``num_regions`` the number of regions it bounds (1 for a closed surface,
    with or without cavities)."""

    nodes: np.ndarray
    triangles: np.ndarray
    tags: np.ndarray
    warnings: list[str]
    num_regions: int

    def __init__(self, handle: ctypes.c_void_p) -> None:
        """Wrap a ``curvetet_surface *`` (owned from now on); use the factories instead."""
        lib = _lib.load()
        self._handle = handle
        self._finalizer = weakref.finalize(self, lib.curvetet_surface_free, handle)
        n = lib.curvetet_surface_num_nodes(handle)
        t = lib.curvetet_surface_num_triangles(handle)
        self.nodes = np.ctypeslib.as_array(lib.curvetet_surface_nodes(handle), (n, 3)).copy()
        tri = np.empty((t, 6), dtype=np.uint32)
        tags = np.empty(t, dtype=np.int32)
        _check(lib.curvetet_surface_triangles(handle, _ptr(tri, ctypes.c_uint32),
                                              _ptr(tags, ctypes.c_int32)))
        self.triangles = tri.astype(np.int64)
        self.tags = tags
        self.warnings = [
            lib.curvetet_surface_warning(handle, i).decode(errors="replace")
            for i in range(lib.curvetet_surface_num_warnings(handle))
        ]
        self.num_regions = int(lib.curvetet_surface_num_regions(handle))

    def __repr__(self) -> str:
        return "<curvetet.Surface: %d nodes, %d triangles, %d region%s>" % (
            len(self.nodes), len(self.triangles), self.num_regions,
            "" if self.num_regions == 1 else "s")


def surface(points: Any, triangles: Any, tags: Any = None, *,
            feature_angle: float = 40.0, nested_regions: bool = False) -> Surface:
    """A checked :class:`Surface` from arrays.

    ``points``: (N, 3) coordinates. ``triangles``: (M, 6) node indices (P2, Gmsh order,
    outward) or (M, 3) (linear: curved by the library, mid nodes appended after the input
    points; edges sharper than ``feature_angle`` degrees stay sharp). ``tags``: (M,)
    integers kept on the mesh boundary, or None for all 0. Raises :class:`CurvetetError`
    (status ``CURVETET_ERR_INVALID_SURFACE``) when the surface is not closed, not manifold,
    self-intersecting, ..., the message naming the check and the element.

    Several regions (P2 triangles only; the linear path takes one closed surface): triangles
    that bound several regions sharing interfaces (each interface triangle once, so edges
    where an interface meets the outer boundary have three or more triangles) make a
    surface of several regions. A closed shell nested in another is a cavity, unless
    ``nested_regions`` is True: then it bounds an inner region, meshed too
    (``CURVETET_SURFACE_NESTED_REGIONS``)."""
    lib = _lib.load()
    xyz = np.ascontiguousarray(points, dtype=np.float64)
    if xyz.ndim != 2 or xyz.shape[1] != 3:
        raise ValueError("points must have shape (N, 3), not %s" % (xyz.shape,))
    tri = _index_array(triangles, "triangles")
    if tri.ndim != 2 or tri.shape[1] not in (3, 6):
        raise ValueError("triangles must have shape (M, 6) or (M, 3), not %s" % (tri.shape,))
    tag_ptr = None
    if tags is not None:
        tag_arr = np.ascontiguousarray(tags, dtype=np.int32)
        if tag_arr.shape != (tri.shape[0],):
            raise ValueError("tags must have shape (%d,), not %s" % (tri.shape[0], tag_arr.shape))
        tag_ptr = _ptr(tag_arr, ctypes.c_int32)
    out = ctypes.c_void_p()
    if tri.shape[1] == 6:
        flags = _lib.SURFACE_NESTED_REGIONS if nested_regions else 0
        code = lib.curvetet_surface_from_arrays_with_flags(
            _ptr(xyz, ctypes.c_double), len(xyz), _ptr(tri, ctypes.c_uint32), len(tri),
            tag_ptr, flags, ctypes.byref(out))
    else:
        if nested_regions:
            raise ValueError("nested_regions needs quadratic (M, 6) triangles: linear "
                             "triangles are curved as one closed surface (curvetet.read "
                             "takes a linear file of several regions, uncurved)")
        code = lib.curvetet_surface_from_linear(
            _ptr(xyz, ctypes.c_double), len(xyz), _ptr(tri, ctypes.c_uint32), len(tri),
            tag_ptr, float(feature_angle), ctypes.byref(out))
    _check(code)
    return Surface(out)


def read(path: Union[str, os.PathLike], *, nested_regions: bool = False) -> Surface:
    """Read a surface file by its extension: P2 from Gmsh ``.msh``, ``.vtu``, ``.vtk``,
    medit ``.mesh``; linear from ``.stl``, ``.off``, ``.obj``, ``.ply`` (curved by the
    library). A file of several regions (interfaces shared; or a Gmsh MSH 4.1 surface
    whose entities list several volumes) gives a surface of several regions; with
    ``nested_regions`` a closed shell nested in another bounds an inner region instead of
    a cavity (see :func:`surface`). Raises :class:`CurvetetError` (IO, PARSE with
    file:line, INVALID_SURFACE)."""
    out = ctypes.c_void_p()
    flags = _lib.SURFACE_NESTED_REGIONS if nested_regions else 0
    _check(_lib.load().curvetet_surface_read_with_flags(os.fsencode(path), flags,
                                                        ctypes.byref(out)))
    return Surface(out)


class Mesh:
    """A certified quadratic tetrahedral mesh (from :func:`mesh`).

    - ``nodes``: (N, 3) float64; the surface's nodes come first, with the same indices.
    - ``tets``: (T, 10) int64, Gmsh order (element type 11); ``tets_vtk`` the VTK order.
      Positively oriented.
    - ``boundary_faces``: (B, 6) int64, the input surface's triangles (outward), with their
      tags in ``boundary_tags`` (B,) int32. With several regions, each interface triangle
      is there once.
    - ``tet_regions``: (T,) int32, the region id of each tet (positive: 1..n for a surface
      of several regions, the physical volume numbers of the written files; the volume's
      physical tag, usually 1, for one region); ``num_regions`` the number of distinct ids.
    - ``quality``: summary dict (``curvetet_mesh_quality``); ``scaled_jacobian`` and
      ``skewness``: per-tet (T,) arrays in the order of ``tets``.
    - ``report``: the library's full JSON report as a dict; ``target_size``.
    """

    def __init__(self, handle: ctypes.c_void_p) -> None:
        """Wrap a ``curvetet_mesh *`` (owned from now on); use :func:`mesh` instead."""
        lib = _lib.load()
        self._handle = handle
        self._finalizer = weakref.finalize(self, lib.curvetet_mesh_free, handle)
        n = lib.curvetet_mesh_num_nodes(handle)
        t = lib.curvetet_mesh_num_tets(handle)
        b = lib.curvetet_mesh_num_boundary_faces(handle)
        self.nodes: np.ndarray = np.ctypeslib.as_array(
            lib.curvetet_mesh_nodes(handle), (n, 3)).copy()
        tets = np.empty((t, 10), dtype=np.uint32)
        _check(lib.curvetet_mesh_tets(handle, _lib.ORDER_GMSH, _ptr(tets, ctypes.c_uint32)))
        self.tets: np.ndarray = tets.astype(np.int64)
        faces = np.empty((b, 6), dtype=np.uint32)
        tags = np.empty(b, dtype=np.int32)
        _check(lib.curvetet_mesh_boundary_faces(handle, _ptr(faces, ctypes.c_uint32),
                                                _ptr(tags, ctypes.c_int32)))
        self.boundary_faces: np.ndarray = faces.astype(np.int64)
        self.boundary_tags: np.ndarray = tags
        regions = np.empty(t, dtype=np.int32)
        _check(lib.curvetet_mesh_tet_regions(handle, _ptr(regions, ctypes.c_int32)))
        self.tet_regions: np.ndarray = regions
        self.num_regions: int = int(lib.curvetet_mesh_num_regions(handle))
        q = _lib.Quality()
        q.struct_size = ctypes.sizeof(_lib.Quality)
        _check(lib.curvetet_mesh_quality(handle, ctypes.byref(q)))
        self.quality: dict[str, float] = {
            name: getattr(q, name) for name, _ in _lib.Quality._fields_ if name != "struct_size"
        }
        sj = np.empty(t, dtype=np.float64)
        sk = np.empty(t, dtype=np.float64)
        _check(lib.curvetet_mesh_tet_quality(handle, _ptr(sj, ctypes.c_double),
                                             _ptr(sk, ctypes.c_double)))
        self.scaled_jacobian: np.ndarray = sj
        self.skewness: np.ndarray = sk
        self.report: dict[str, Any] = json.loads(lib.curvetet_mesh_report_json(handle))
        self.target_size: float = lib.curvetet_mesh_target_size(handle)

    @property
    def tets_vtk(self) -> np.ndarray:
        """The tetrahedra in VTK's node order (VTK_QUADRATIC_TETRA; meshio's tetra10)."""
        return self.tets[:, [0, 1, 2, 3, 4, 5, 6, 7, 9, 8]]

    def write(self, path: Union[str, os.PathLike], *, binary: bool = False,
              msh22: bool = False, medit_linear: bool = False) -> None:
        """Write tetrahedra and boundary triangles (with tags) to ``path``; the format comes
        from the extension: ``.msh`` (Gmsh 4.1), ``.vtu``, ``.vtk``, ``.mesh`` (medit, P2
        sections). ``binary``: binary .msh / base64 .vtu; ``msh22``: Gmsh MSH 2.2;
        ``medit_linear``: linear (corner) .mesh sections, for readers without P2 (meshio).
        Raises :class:`CurvetetError` (unknown extension, a flag the format does not take,
        IO error); a failed write leaves no half-written file."""
        flags = ((_lib.WRITE_BINARY if binary else 0) | (_lib.WRITE_MSH22 if msh22 else 0)
                 | (_lib.WRITE_MEDIT_LINEAR if medit_linear else 0))
        _check(_lib.load().curvetet_mesh_write_with_flags(self._handle, os.fsencode(path),
                                                          flags))

    def to_meshio(self) -> Any:
        """A ``meshio.Mesh``: ``tetra10`` and ``triangle6`` cells, with cell data
        ``boundary_tag`` (0 on tets), ``region`` (the tets' region ids, 0 on triangles)
        and ``scaled_jacobian`` (NaN on triangles)."""
        import meshio

        nt, nb = len(self.tets), len(self.boundary_faces)
        return meshio.Mesh(
            self.nodes,
            [("tetra10", self.tets_vtk), ("triangle6", self.boundary_faces)],
            cell_data={
                "boundary_tag": [np.zeros(nt, dtype=np.int32), self.boundary_tags],
                "region": [self.tet_regions, np.zeros(nb, dtype=np.int32)],
                "scaled_jacobian": [self.scaled_jacobian, np.full(nb, np.nan)],
            },
        )

    def to_pyvista(self) -> Any:
        """A ``pyvista.UnstructuredGrid`` of quadratic tetra (VTK cell type 24) with cell
        arrays ``Region`` (the region ids, as the VTK filter names them),
        ``scaled_jacobian`` and ``skewness``. Needs pyvista (ImportError otherwise)."""
        import pyvista

        grid = pyvista.UnstructuredGrid({pyvista.CellType.QUADRATIC_TETRA: self.tets_vtk},
                                        self.nodes)
        grid.cell_data["Region"] = self.tet_regions
        grid.cell_data["scaled_jacobian"] = self.scaled_jacobian
        grid.cell_data["skewness"] = self.skewness
        return grid

    def __repr__(self) -> str:
        return "<curvetet.Mesh: %d nodes, %d tets, %d boundary faces, %d region%s>" % (
            len(self.nodes), len(self.tets), len(self.boundary_faces), self.num_regions,
            "" if self.num_regions == 1 else "s")


def from_meshio(m: Any, *, feature_angle: float = 40.0,
                nested_regions: bool = False) -> Surface:
    """A :class:`Surface` from a ``meshio.Mesh`` with ``triangle6`` cells (P2) or, failing
    that, ``triangle`` cells (linear, curved by the library). The cell data
    ``gmsh:physical`` becomes the tags when present. ``nested_regions`` as in
    :func:`surface` (P2 only)."""
    for kind in ("triangle6", "triangle"):
        blocks = [i for i, c in enumerate(m.cells) if c.type == kind]
        if blocks:
            tri = np.concatenate([m.cells[i].data for i in blocks])
            tags = None
            phys = m.cell_data.get("gmsh:physical")
            if phys is not None:
                tags = np.concatenate([np.asarray(phys[i]) for i in blocks])
            return surface(np.asarray(m.points)[:, :3], tri, tags, feature_angle=feature_angle,
                           nested_regions=nested_regions)
    raise ValueError("the meshio mesh has no triangle6 or triangle cells (cells: %s)"
                     % ", ".join(c.type for c in m.cells))


class _Progress:
    """The C progress callback: calls the user's function, catches every Python exception
    (none may cross the C frames) and cancels; ``mesh`` raises it after generate.

    Ctrl-C: Python raises KeyboardInterrupt from its SIGINT handler at the next Python
    code it runs, which may be the entry of this callback, before any ``try`` (ctypes would
    then print and ignore it). So while generate runs, ``sigint_guard`` replaces Python's
    default SIGINT handler by one that only records the signal; the callback cancels on
    it and ``mesh`` raises KeyboardInterrupt once generate has returned."""

    def __init__(self, fn: Optional[ProgressFn]) -> None:
        self.fn = fn
        self.error: Optional[BaseException] = None
        self.interrupted = False
        self.c_fn = _lib.PROGRESS_FN(self._call)

    def _call(self, _user: Any, fraction: float, stage: bytes) -> int:
        try:
            if self.interrupted:
                return 1
            if self.fn is not None and self.fn(fraction, stage.decode(errors="replace")) is False:
                return 1
            return 0
        except BaseException as e:  # noqa: B036 - KeyboardInterrupt included, on purpose
            self.error = e
            return 1

    def _on_sigint(self, _signum: int, _frame: Any) -> None:
        self.interrupted = True

    @contextlib.contextmanager
    def sigint_guard(self) -> Iterator[None]:
        """Record SIGINT instead of raising, when Python's default handler is installed
        and this is the main thread (a program's own handler is left alone)."""
        if (threading.current_thread() is not threading.main_thread()
                or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
            yield
            return
        signal.signal(signal.SIGINT, self._on_sigint)
        try:
            yield
        finally:
            signal.signal(signal.SIGINT, signal.default_int_handler)


def _tqdm_progress() -> tuple[ProgressFn, Callable[[], None]]:
    from tqdm.auto import tqdm

    bar = tqdm(total=1.0, unit="", bar_format="{desc}: {percentage:3.0f}%|{bar}| {elapsed}")

    def fn(fraction: float, stage: str) -> None:
        if bar.desc != stage:
            bar.set_description_str(stage, refresh=False)
        bar.n = fraction
        bar.refresh()

    return fn, bar.close


def mesh(points: Union[Any, Surface], triangles: Any = None, *, tags: Any = None,
         size: Optional[float] = None, alpha: float = 1.5, optimize: bool = True,
         threads: int = 0, uniform_size: bool = False, thorough: bool = False,
         nested_regions: bool = False,
         progress: Union[ProgressFn, bool, None] = None) -> Mesh:
    """Mesh a closed surface into certified quadratic (10-node) tetrahedra.

    ``points``/``triangles``/``tags``/``nested_regions`` as in :func:`surface` (P2 (M, 6)
    or linear (M, 3) triangles), or ``points`` a :class:`Surface` (then ``triangles`` is
    None and ``nested_regions`` is given to :func:`surface` or :func:`read` instead). A
    surface of several regions gives one conforming mesh with a region id per tet
    (``Mesh.tet_regions``): each region is meshed on its own boundary, kept exactly.

    Options: ``size`` the target edge length (None: graded from the surface's triangle
    sizes, or uniform from the mean triangle area with ``uniform_size``); ``alpha`` the
    search radius factor; ``optimize`` quality and high-order optimization; ``threads``
    worker threads (0: one per CPU; the result does not depend on it); ``thorough`` more
    high-order rounds for poor elements.

    ``progress``: a callable ``fn(fraction, stage)`` called on this thread (fraction 0..1,
    non-decreasing within a stage; stages "front", "optimize", "certify", ...); return
    ``False`` to cancel (:class:`CurvetetError` with status ``CURVETET_ERR_CANCELLED``).
    ``True`` shows a tqdm bar (needs tqdm). An exception raised in the callback, and a
    KeyboardInterrupt (Ctrl-C) during meshing, stops the work and is raised again here.
    """
    if isinstance(points, Surface):
        if triangles is not None or tags is not None:
            raise ValueError("pass either a Surface or points and triangles, not both")
        if nested_regions:
            raise ValueError("nested_regions is decided when the Surface is built: pass it "
                             "to curvetet.surface() or curvetet.read()")
        surf = points
    else:
        if triangles is None:
            raise ValueError("triangles are required with points")
        surf = surface(points, triangles, tags, nested_regions=nested_regions)
    opt = _lib.default_options()
    if size is not None:
        opt.size = float(size)
    opt.alpha = float(alpha)
    opt.optimize = 1 if optimize else 0
    opt.threads = int(threads)
    opt.uniform_size = 1 if uniform_size else 0
    opt.thorough = 1 if thorough else 0
    close = None
    fn: Optional[ProgressFn]
    if progress is True:
        fn, close = _tqdm_progress()
    elif progress is False or progress is None:
        fn = None
    else:
        fn = progress
    # Always a callback, so that Ctrl-C (handled when Python code runs) cancels the work.
    cb = _Progress(fn)
    opt.progress = cb.c_fn
    out = ctypes.c_void_p()
    try:
        with cb.sigint_guard():
            code = _lib.load().curvetet_generate(surf._handle, ctypes.byref(opt),
                                                 ctypes.byref(out))
    finally:
        if close is not None:
            close()
    error = cb.error
    if error is None and cb.interrupted:
        error = KeyboardInterrupt()
    if error is not None:
        if out:
            _lib.load().curvetet_mesh_free(out)
        raise error
    _check(code)
    return Mesh(out)
