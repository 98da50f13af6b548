"""curvetet as the volume mesher of a Gmsh model (Python, on gmsh's own module).

    import gmsh, curvetet_gmsh
    gmsh.initialize()
    ...                                         # geometry
    gmsh.option.setNumber("Mesh.ElementOrder", 2)
    gmsh.model.mesh.generate(2)                 # a second-order (6-node) surface mesh
    curvetet_gmsh.generate()                    # 10-node tetrahedra in every volume
    gmsh.write("volume.msh")

Works with Debian's python3-gmsh (4.8) and PyPI's gmsh (4.15): it uses only API calls both
have. curvetet is called through its C ABI (libcurvetet, include/curvetet.h) with ctypes;
the library is found through, in order: the CURVETET_LIBRARY environment variable (the
library file), the install prefix this module was installed into
(<prefix>/share/curvetet/python -> <prefix>/lib*), the repository's cargo build
(target/release, or $CARGO_TARGET_DIR/release), then the system's library path. The
ctypes declarations (struct curvetet_options and the signatures) are the curvetet Python
package's (python/curvetet/_lib.py; see _load_ctypes_mirror).
"""

import ctypes
import ctypes.util
import glob
import importlib.util
import os
import re

import gmsh

__all__ = ["generate", "CurvetetError", "library_path", "version"]

TRI6 = 9  # Gmsh: 6-node second-order triangle
TET10 = 11  # Gmsh: 10-node second-order tetrahedron
_FLIP = (0, 2, 1, 5, 4, 3)  # a reversed 6-node triangle: [c0, c2, c1, m20, m12, m01]


class CurvetetError(RuntimeError):
    """curvetet could not mesh the model; the message says why. The model is unchanged."""


# --- the C library -------------------------------------------------------------------

def _load_ctypes_mirror():
    """The curvetet Python package's ``_lib`` module (python/curvetet/_lib.py): the one
    ctypes mirror of struct curvetet_options and of the C ABI's signatures. Loaded by file,
    not imported as ``curvetet._lib`` (the package's ``__init__`` needs numpy, which this
    module does not), from, in order: a copy installed beside this module
    (<prefix>/share/curvetet/python/curvetet_lib.py, by CMake), the repository's
    python/curvetet/_lib.py, an installed ``curvetet`` package (pip)."""
    here = os.path.dirname(os.path.realpath(__file__))
    paths = [os.path.join(here, "curvetet_lib.py"),
             os.path.join(here, "..", "..", "python", "curvetet", "_lib.py")]
    spec = importlib.util.find_spec("curvetet")  # finds the package without importing it
    if spec is not None and spec.submodule_search_locations:
        paths += [os.path.join(p, "_lib.py") for p in spec.submodule_search_locations]
    for path in paths:
        if os.path.exists(path):
            spec = importlib.util.spec_from_file_location("curvetet_gmsh_lib", path)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            return module
    raise ImportError("curvetet_gmsh: cannot find curvetet's ctypes declarations (tried: %s)"
                      % ", ".join(paths))


_ctypes_mirror = _load_ctypes_mirror()
_PROGRESS = _ctypes_mirror.PROGRESS_FN
_Options = _ctypes_mirror.Options


_lib = None
_lib_path = None


def _candidates():
    env = os.environ.get("CURVETET_LIBRARY")
    if env:
        yield env
        return
    here = os.path.dirname(os.path.realpath(__file__))
    # Installed: <prefix>/share/curvetet/python/curvetet_gmsh.py.
    prefix = os.path.normpath(os.path.join(here, "..", "..", ".."))
    for libdir in sorted(glob.glob(os.path.join(prefix, "lib*"))) + sorted(
        glob.glob(os.path.join(prefix, "lib", "*-linux-gnu"))
    ):
        yield os.path.join(libdir, "libcurvetet.so")
    # In the repository: bindings/gmsh/curvetet_gmsh.py, cargo's target/release.
    target = os.environ.get("CARGO_TARGET_DIR") or os.path.join(here, "..", "..", "target")
    yield os.path.join(target, "release", "libcurvetet.so")
    found = ctypes.util.find_library("curvetet")
    if found:
        yield found


def _load():
    global _lib, _lib_path
    if _lib is not None:
        return _lib
    tried = []
    for path in _candidates():
        if os.path.sep in path and not os.path.exists(path):
            tried.append(path)
            continue
        try:
            lib = ctypes.CDLL(path)
        except OSError as e:
            tried.append("%s (%s)" % (path, e))
            continue
        _declare(lib)
        _lib, _lib_path = lib, path
        return lib
    raise CurvetetError(
        "cannot find libcurvetet; set CURVETET_LIBRARY to the library file (tried: %s)"
        % ", ".join(tried)
    )


def _declare(lib):
    _ctypes_mirror.declare(lib)


def library_path():
    """The path of the libcurvetet that is (or will be) used."""
    _load()
    return _lib_path


def version():
    """The library's version string, e.g. "0.1.0"."""
    return _load().curvetet_version().decode()


def _error(lib, status):
    return "%s: %s" % (
        lib.curvetet_error_name(status).decode(),
        lib.curvetet_last_error_message().decode(errors="replace"),
    )


# --- the Gmsh side -------------------------------------------------------------------


def _tolist(a):
    return a.tolist() if hasattr(a, "tolist") else list(a)


def _fail(msg):
    raise CurvetetError("curvetet_gmsh: " + msg)


def _gather_boundary(volume):
    """[[surface tag, reversed, [6 node tags per triangle...], [element tags]]] of a
    volume's boundary."""
    if len(gmsh.model.mesh.getElementTypes(3, volume)) > 0:
        _fail("volume %d already has a 3D mesh; clear it (gmsh.model.mesh.clear) or "
              "generate only up to dimension 2" % volume)
    faces = gmsh.model.getBoundary([(3, volume)], combined=False, oriented=True,
                                   recursive=False)
    if not faces:
        _fail("volume %d has no boundary surface" % volume)
    out, seen = [], set()
    for _, s_signed in faces:
        s = abs(s_signed)
        if s in seen:
            continue  # listed twice (e.g. embedded): not a boundary
        seen.add(s)
        types = _tolist(gmsh.model.mesh.getElementTypes(2, s))
        if not types:
            _fail("surface %d (boundary of volume %d) has no mesh: call "
                  "gmsh.model.mesh.generate(2) first, with Mesh.ElementOrder = 2" % (s, volume))
        for t in types:
            if t != TRI6:
                name = gmsh.model.mesh.getElementProperties(t)[0]
                _fail("surface %d (boundary of volume %d) has elements of type %d (%s); curvetet "
                      "needs a second-order triangle mesh (6-node triangles, type 9): set "
                      "Mesh.ElementOrder = 2 before generate(2), or call "
                      "gmsh.model.mesh.setOrder(2)" % (s, volume, t, name))
        elems, nodes = gmsh.model.mesh.getElementsByType(TRI6, s)
        out.append([s, s_signed < 0, _tolist(nodes), _tolist(elems)])
    return out


def _orient(surfaces, coords):
    """Orient the boundary outward, as the C++ wrapper does (curvetet_gmsh.cpp: orient):
    Gmsh's signs are a first guess; surfaces sharing an edge must run through it in opposite
    directions; the shell enclosing the largest volume is made outward, the others (cavities)
    inward. curvetet checks the result again, exactly."""
    ns = len(surfaces)

    def corners(e, t):
        s = surfaces[e]
        n = s[2]
        idx = _FLIP if s[1] else range(6)
        return [n[6 * t + idx[k]] for k in range(3)]

    first, adj = {}, [[] for _ in range(ns)]
    for e in range(ns):
        for t in range(len(surfaces[e][2]) // 6):
            c = corners(e, t)
            for k in range(3):
                u, v = c[k], c[(k + 1) % 3]
                key = (min(u, v), max(u, v))
                use = first.setdefault(key, (e, u < v))
                if use[0] != e:
                    same = use[1] == (u < v)
                    adj[use[0]].append((e, same))
                    adj[e].append((use[0], same))
    shell, flip, nshells = [-1] * ns, [False] * ns, 0
    for r in range(ns):
        if shell[r] >= 0:
            continue
        shell[r], stack = nshells, [r]
        while stack:
            e = stack.pop()
            for o, same in adj[e]:
                if shell[o] < 0:
                    shell[o], flip[o] = nshells, flip[e] != same
                    stack.append(o)
        nshells += 1
    for e in range(ns):
        if flip[e]:
            surfaces[e][1] = not surfaces[e][1]
    vol = [0.0] * nshells
    o = coords[surfaces[0][2][0]]
    for e in range(ns):
        for t in range(len(surfaces[e][2]) // 6):
            p = [[x - y for x, y in zip(coords[n], o)] for n in corners(e, t)]
            vol[shell[e]] += (p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1])
                              - p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0])
                              + p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0]))
    outer = max(range(nshells), key=lambda s: abs(vol[s]))
    for e in range(ns):
        s = shell[e]
        if vol[s] != 0 and (vol[s] > 0) != (s == outer):
            surfaces[e][1] = not surfaces[e][1]


def _in_gmsh_numbers(msg, surfaces, node_tags):
    """curvetet's messages name triangles and nodes by their 0-based index in the arrays it
    was given; say which Gmsh elements and nodes these are."""
    tris = sorted({int(m) for m in re.findall(r"triangles? (\d+)", msg)})
    nodes = {int(m) for m in re.findall(r"nodes? (\d+)", msg)}
    for m in re.finditer(r"(corners|edge) \(?(\d+), (\d+)(, (\d+))?", msg):
        nodes.update(int(m.group(g)) for g in (2, 3, 5) if m.group(g) is not None)
    elements = [(e, s[0]) for s in surfaces for e in s[3]]
    out = ["triangle %d = element %d of surface %d" % ((t,) + elements[t])
           for t in tris if t < len(elements)][:8]
    out += ["node %d = node %d" % (i, node_tags[i]) for i in sorted(nodes)
            if i < len(node_tags)][:16 - len(out)]
    return " [in Gmsh's numbers: %s]" % "; ".join(out) if out else ""


def _mesh_volume(lib, volume, coords, opt):
    """Mesh one volume: (boundary node tags, new node coordinates, tets as local indices)."""
    surfaces = _gather_boundary(volume)
    if not any(s[2] for s in surfaces):
        _fail("volume %d has an empty boundary mesh" % volume)
    for s in surfaces:
        for n in s[2]:
            if n not in coords:
                _fail("volume %d: boundary node %d is not in the model" % (volume, n))
    _orient(surfaces, coords)

    local, tags_of, xyz, tri6, ttags = {}, [], [], [], []
    for s_tag, rev, nodes, _ in surfaces:
        idx = _FLIP if rev else range(6)
        for t in range(len(nodes) // 6):
            for k in range(6):
                n = nodes[6 * t + idx[k]]
                i = local.get(n)
                if i is None:
                    i = local[n] = len(tags_of)
                    tags_of.append(n)
                    xyz.extend(coords[n])
                tri6.append(i)
            ttags.append(s_tag)

    c = ctypes
    surface, mesh = c.c_void_p(), c.c_void_p()
    st = lib.curvetet_surface_from_arrays(
        (c.c_double * len(xyz))(*xyz), len(tags_of), (c.c_uint32 * len(tri6))(*tri6),
        len(ttags), (c.c_int32 * len(ttags))(*ttags), c.byref(surface))
    try:
        if st != 0:
            msg = _error(lib, st)
            _fail("volume %d: its boundary surface is not acceptable (%s)%s"
                  % (volume, msg, _in_gmsh_numbers(msg, surfaces, tags_of)))
        st = lib.curvetet_generate(surface, c.byref(opt), c.byref(mesh))
        if st != 0:
            msg = _error(lib, st)
            _fail("volume %d: %s%s" % (volume, msg, _in_gmsh_numbers(msg, surfaces, tags_of)))
        nb, nn = len(tags_of), lib.curvetet_mesh_num_nodes(mesh)
        if nn < nb:
            _fail("volume %d: curvetet returned fewer nodes than the surface has" % volume)
        new_xyz = lib.curvetet_mesh_nodes(mesh)[3 * nb:3 * nn]
        nt = lib.curvetet_mesh_num_tets(mesh)
        tets = (c.c_uint32 * (10 * nt))()
        st = lib.curvetet_mesh_tets(mesh, 0, tets)  # CURVETET_ORDER_GMSH
        if st != 0:
            _fail("volume %d: %s" % (volume, _error(lib, st)))
        return tags_of, new_xyz, list(tets)
    finally:
        lib.curvetet_mesh_free(mesh)
        lib.curvetet_surface_free(surface)


def generate(alpha=1.5, optimize=True, size=0.0, threads=0, progress=None, thorough=False):
    """Mesh every volume entity of the current Gmsh model with curvetet.

    The model needs a second-order surface mesh (6-node triangles, type 9) on the boundary
    of each volume, and no 3D mesh yet. For each volume, the triangles of its boundary
    surfaces are gathered (outward; a cavity's shell inward), meshed by curvetet, and the
    new interior nodes (classified on the volume) and 10-node tetrahedra (type 11, Gmsh
    node order) are added with gmsh.model.mesh.addNodes / addElementsByType. Boundary
    nodes are Gmsh's own, so a surface shared by two volumes stays conforming.

    alpha: search radius factor (paper's 1.5); optimize: quality improvement and
    high-order optimization; size: target edge length (<= 0: graded from the boundary);
    threads: worker threads (0: all cores); progress: optional callable(fraction, stage)
    returning True to cancel; thorough: more high-order rounds where some element starts
    poor (CAD parts), two to three times that stage's work there, for fewer elements left
    between the worst one and min J / max J 0.85.

    Raises CurvetetError with curvetet's message when a volume cannot be meshed; every
    volume is meshed before the model is touched, so the model is then unchanged.
    """
    lib = _load()
    opt = _Options()
    st = lib.curvetet_options_init(ctypes.byref(opt), ctypes.sizeof(opt))
    if st != 0:
        _fail(_error(lib, st))
    opt.alpha = float(alpha)
    opt.size = float(size)
    opt.optimize = 1 if optimize else 0
    opt.thorough = 1 if thorough else 0
    opt.threads = int(threads)
    raised = []
    if progress is not None:
        def on_progress(_user, fraction, stage):
            try:
                return 1 if progress(fraction, stage.decode()) else 0
            except BaseException as e:  # must not unwind through curvetet
                raised.append(e)
                return 1
        opt.progress = _PROGRESS(on_progress)

    volumes = [t for _, t in gmsh.model.getEntities(3)]
    if not volumes:
        _fail("the model has no volume")
    tags, xyz, _ = gmsh.model.mesh.getNodes(-1, -1, False, False)
    tags, xyz = _tolist(tags), _tolist(xyz)
    coords = {t: xyz[3 * i:3 * i + 3] for i, t in enumerate(tags)}

    # Mesh every volume first: a failure leaves the model unchanged.
    regions = []
    for v in volumes:
        try:
            regions.append((v,) + _mesh_volume(lib, v, coords, opt))
        except CurvetetError:
            if raised:
                raise raised[0]
            raise

    # Then add nodes and tetrahedra, with fresh tags after the model's largest ones.
    next_node = max(tags, default=0) + 1
    _, elem_tags, _ = gmsh.model.mesh.getElements()
    next_elem = max((max(_tolist(e)) for e in elem_tags if len(e)), default=0) + 1
    for v, boundary_tags, new_xyz, tets in regions:
        n_new = len(new_xyz) // 3
        new_tags = list(range(next_node, next_node + n_new))
        next_node += n_new
        node_tags = boundary_tags + new_tags
        nt = len(tets) // 10
        if new_tags:
            gmsh.model.mesh.addNodes(3, v, new_tags, new_xyz)
        gmsh.model.mesh.addElementsByType(v, TET10, list(range(next_elem, next_elem + nt)),
                                          [node_tags[i] for i in tets])
        next_elem += nt
