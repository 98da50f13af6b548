"""What the C ABI alone does with a linear OFF surface: the reference the filter must match.

capi_reference.py LIBCURVETET.so SURFACE.off

Calls curvetet_surface_from_linear (no tags, 40 degrees) and curvetet_generate with
curvetet_options_default, as the filter does with its default parameters, through ctypes.
Prints the status name and, on failure, curvetet's message; exit code 0 on success, 1 on
failure.
"""
import ctypes as C
import sys


class Options(C.Structure):
    _fields_ = [("struct_size", C.c_uint32), ("alpha", C.c_double), ("size", C.c_double),
                ("optimize", C.c_int32), ("threads", C.c_uint32), ("progress", C.c_void_p),
                ("user_data", C.c_void_p), ("uniform_size", C.c_int32),
                ("thorough", C.c_int32), ("pin_threads", C.c_int32)]


def main():
    lib = C.CDLL(sys.argv[1])
    toks = []
    for line in open(sys.argv[2]):
        toks += line.split("#")[0].split()
    nv, nf = int(toks[1]), int(toks[2])
    xyz = [float(t) for t in toks[4:4 + 3 * nv]]
    rest, tri, k = toks[4 + 3 * nv:], [], 0
    for _ in range(nf):
        assert rest[k] == "3", "triangles only"
        tri += [int(t) for t in rest[k + 1:k + 4]]
        k += 4
    lib.curvetet_surface_from_linear.argtypes = [C.c_void_p, C.c_size_t, C.c_void_p, C.c_size_t,
                                                 C.c_void_p, C.c_double, C.c_void_p]
    lib.curvetet_generate.argtypes = [C.c_void_p, C.c_void_p, C.c_void_p]
    lib.curvetet_last_error_message.restype = C.c_char_p
    lib.curvetet_error_name.restype = C.c_char_p
    lib.curvetet_surface_free.argtypes = [C.c_void_p]
    lib.curvetet_mesh_free.argtypes = [C.c_void_p]
    surface, mesh = C.c_void_p(), C.c_void_p()
    st = lib.curvetet_surface_from_linear((C.c_double * len(xyz))(*xyz), nv,
                                          (C.c_uint32 * len(tri))(*tri), nf, None, 40.0,
                                          C.byref(surface))
    if st == 0:
        opt = Options()
        lib.curvetet_options_default(C.byref(opt))
        assert opt.struct_size == C.sizeof(Options), "curvetet_options grew: update this script"
        st = lib.curvetet_generate(surface, C.byref(opt), C.byref(mesh))
    print(lib.curvetet_error_name(st).decode())
    if st != 0:
        print(lib.curvetet_last_error_message().decode())
    lib.curvetet_mesh_free(mesh)
    lib.curvetet_surface_free(surface)
    return 0 if st == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
