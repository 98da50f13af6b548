"""ctypes declarations of the curvetet C ABI (include/curvetet.h) and the library loader.

This is the one place that mirrors the C structs in Python (the Gmsh wrapper,
bindings/gmsh/curvetet_gmsh.py, loads this file too): ``Options`` is
``struct curvetet_options`` and ``Quality`` is ``struct curvetet_quality``, field by field
in the header's order. ``load()`` checks the mirror against the library at load time (the
``struct_size`` that ``curvetet_options_default`` writes must equal ``ctypes.sizeof``), so a
header change that is not carried here fails loudly instead of corrupting memory.
"""

from __future__ import annotations

import ctypes
import glob
import os
from typing import Optional

# No import of numpy or of the package here: the Gmsh wrapper loads this file on its own,
# in a Python that may have neither.

# Status codes (enum curvetet_status).
OK = 0
ERR_INVALID_ARGUMENT = 1
ERR_IO = 2
ERR_PARSE = 3
ERR_INVALID_SURFACE = 4
ERR_MESHING_FAILED = 5
ERR_INVALID_MESH = 6
ERR_CANCELLED = 7
ERR_PANIC = 8

# Flags of curvetet_mesh_write_with_flags.
WRITE_BINARY = 1
WRITE_MSH22 = 2
WRITE_MEDIT_LINEAR = 4

# Flags of the curvetet_surface_*_with_flags functions.
SURFACE_STRICT = 1
SURFACE_NESTED_REGIONS = 2  # not taken by curvetet_surface_from_linear_with_flags

# enum curvetet_node_order.
ORDER_GMSH = 0
ORDER_VTK = 1

# int (*curvetet_progress_fn)(void *user_data, double fraction, const char *stage)
PROGRESS_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_double, ctypes.c_char_p)


class Options(ctypes.Structure):
    """``struct curvetet_options`` (include/curvetet.h), in the header's field order."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("alpha", ctypes.c_double),
        ("size", ctypes.c_double),
        ("optimize", ctypes.c_int32),
        ("threads", ctypes.c_uint32),
        ("progress", PROGRESS_FN),
        ("user_data", ctypes.c_void_p),
        ("uniform_size", ctypes.c_int32),
        ("thorough", ctypes.c_int32),
        ("pin_threads", ctypes.c_int32),
    ]


class Quality(ctypes.Structure):
    """``struct curvetet_quality`` (include/curvetet.h), in the header's field order."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("num_tets", ctypes.c_uint64),
        ("num_invalid", ctypes.c_uint64),
        ("min_scaled_jacobian", ctypes.c_double),
        ("mean_scaled_jacobian", ctypes.c_double),
        ("min_scaled_jacobian_certified", ctypes.c_double),
        ("max_skewness", ctypes.c_double),
        ("min_dihedral_deg", ctypes.c_double),
        ("max_dihedral_deg", ctypes.c_double),
    ]


_lib: Optional[ctypes.CDLL] = None
_lib_path: Optional[str] = None


def _candidates() -> list[str]:
    """The shared library shipped in the package first, then ``$CURVETET_LIBRARY``."""
    here = os.path.dirname(os.path.abspath(__file__))
    found = sorted(glob.glob(os.path.join(here, "libcurvetet.so*")))
    env = os.environ.get("CURVETET_LIBRARY")
    return found + ([env] if env else [])


def declare(lib: ctypes.CDLL) -> None:
    """Set the argument and result types of the C ABI's functions on ``lib`` (also used by
    bindings/gmsh/curvetet_gmsh.py, which loads the library its own way)."""
    c = ctypes
    dp, up, ip = c.POINTER(c.c_double), c.POINTER(c.c_uint32), c.POINTER(c.c_int32)
    vp, vpp = c.c_void_p, c.POINTER(c.c_void_p)
    sigs = {
        "curvetet_version": (c.c_char_p, []),
        "curvetet_last_error_message": (c.c_char_p, []),
        "curvetet_error_name": (c.c_char_p, [c.c_int]),
        "curvetet_options_default": (None, [c.POINTER(Options)]),
        "curvetet_options_init": (c.c_int, [c.POINTER(Options), c.c_size_t]),
        "curvetet_generate": (c.c_int, [vp, c.POINTER(Options), vpp]),
        "curvetet_mesh_free": (None, [vp]),
        "curvetet_mesh_num_nodes": (c.c_size_t, [vp]),
        "curvetet_mesh_nodes": (dp, [vp]),
        "curvetet_mesh_num_tets": (c.c_size_t, [vp]),
        "curvetet_mesh_tets": (c.c_int, [vp, c.c_int, up]),
        "curvetet_mesh_num_regions": (c.c_size_t, [vp]),
        "curvetet_mesh_tet_regions": (c.c_int, [vp, ip]),
        "curvetet_mesh_num_boundary_faces": (c.c_size_t, [vp]),
        "curvetet_mesh_boundary_faces": (c.c_int, [vp, up, ip]),
        "curvetet_mesh_quality": (c.c_int, [vp, c.POINTER(Quality)]),
        "curvetet_mesh_tet_quality": (c.c_int, [vp, dp, dp]),
        "curvetet_mesh_write": (c.c_int, [vp, c.c_char_p]),
        "curvetet_mesh_write_with_flags": (c.c_int, [vp, c.c_char_p, c.c_uint32]),
        "curvetet_mesh_report_json": (c.c_char_p, [vp]),
        "curvetet_mesh_target_size": (c.c_double, [vp]),
        "curvetet_surface_from_arrays": (c.c_int, [dp, c.c_size_t, up, c.c_size_t, ip, vpp]),
        "curvetet_surface_from_arrays_with_flags": (
            c.c_int, [dp, c.c_size_t, up, c.c_size_t, ip, c.c_uint32, vpp]),
        "curvetet_surface_from_linear": (
            c.c_int, [dp, c.c_size_t, up, c.c_size_t, ip, c.c_double, vpp]),
        "curvetet_surface_from_linear_with_flags": (
            c.c_int, [dp, c.c_size_t, up, c.c_size_t, ip, c.c_double, c.c_uint32, c.c_uint32,
                      vpp]),
        "curvetet_surface_read": (c.c_int, [c.c_char_p, vpp]),
        "curvetet_surface_read_with_flags": (c.c_int, [c.c_char_p, c.c_uint32, vpp]),
        "curvetet_surface_free": (None, [vp]),
        "curvetet_surface_num_nodes": (c.c_size_t, [vp]),
        "curvetet_surface_num_triangles": (c.c_size_t, [vp]),
        "curvetet_surface_nodes": (dp, [vp]),
        "curvetet_surface_triangles": (c.c_int, [vp, up, ip]),
        "curvetet_surface_num_regions": (c.c_size_t, [vp]),
        "curvetet_surface_num_warnings": (c.c_size_t, [vp]),
        "curvetet_surface_warning": (c.c_char_p, [vp, c.c_size_t]),
    }
    for name, (restype, argtypes) in sigs.items():
        f = getattr(lib, name)
        f.restype = restype
        f.argtypes = argtypes


def _check_layout(lib: ctypes.CDLL) -> None:
    """Fail when this mirror of ``curvetet_options`` disagrees with the library's."""
    opt = Options()
    lib.curvetet_options_default(ctypes.byref(opt))
    if opt.struct_size != ctypes.sizeof(Options):
        raise ImportError(
            "curvetet: the library's struct curvetet_options has %d bytes, this package's "
            "mirror (curvetet/_lib.py) %d: library and package do not match"
            % (opt.struct_size, ctypes.sizeof(Options))
        )


def load() -> ctypes.CDLL:
    """The loaded library (loaded and checked on first use)."""
    global _lib, _lib_path
    if _lib is not None:
        return _lib
    tried = []
    for path in _candidates():
        try:
            lib = ctypes.CDLL(path)
        except OSError as e:
            tried.append("%s (%s)" % (path, e))
            continue
        declare(lib)
        _check_layout(lib)
        _lib, _lib_path = lib, path
        return lib
    raise ImportError(
        "curvetet: no libcurvetet.so in the package and CURVETET_LIBRARY is not set to one"
        + (" (tried: %s)" % ", ".join(tried) if tried else "")
    )


def library_path() -> str:
    """The path of the loaded shared library."""
    load()
    assert _lib_path is not None
    return _lib_path


def default_options() -> Options:
    """``curvetet_options_default`` as an ``Options``."""
    opt = Options()
    load().curvetet_options_default(ctypes.byref(opt))
    return opt
