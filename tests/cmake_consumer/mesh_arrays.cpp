// A C++ user of the curvetet C API: RAII handles, a lambda progress callback, and the
// mesh's arrays copied into std::vectors (tets in VTK order).
#include <curvetet.h>

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

struct SurfaceFree {
    void operator()(curvetet_surface *s) const { curvetet_surface_free(s); }
};
struct MeshFree {
    void operator()(curvetet_mesh *m) const { curvetet_mesh_free(m); }
};
using Surface = std::unique_ptr<curvetet_surface, SurfaceFree>;
using Mesh = std::unique_ptr<curvetet_mesh, MeshFree>;

void check(curvetet_status st) {
    if (st != CURVETET_OK)
        throw std::runtime_error(std::string(curvetet_error_name(st)) + ": " +
                                 curvetet_last_error_message());
}

}  // namespace

int main(int argc, char **argv) try {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s SURFACE.msh\n", argv[0]);
        return 2;
    }
    curvetet_surface *raw_surface = nullptr;
    check(curvetet_surface_read(argv[1], &raw_surface));
    Surface surface(raw_surface);

    int calls = 0;
    curvetet_options opt;
    curvetet_options_default(&opt);
    opt.user_data = &calls;
    opt.progress = [](void *user, double, const char *) -> int {
        ++*static_cast<int *>(user);
        return 0;
    };
    curvetet_mesh *raw_mesh = nullptr;
    check(curvetet_generate(surface.get(), &opt, &raw_mesh));
    Mesh mesh(raw_mesh);

    const size_t n = curvetet_mesh_num_nodes(mesh.get());
    const double *xyz = curvetet_mesh_nodes(mesh.get());
    std::vector<double> nodes(xyz, xyz + 3 * n);
    std::vector<uint32_t> tets(10 * curvetet_mesh_num_tets(mesh.get()));
    check(curvetet_mesh_tets(mesh.get(), CURVETET_ORDER_VTK, tets.data()));
    std::vector<uint32_t> faces(6 * curvetet_mesh_num_boundary_faces(mesh.get()));
    std::vector<int32_t> tags(curvetet_mesh_num_boundary_faces(mesh.get()));
    check(curvetet_mesh_boundary_faces(mesh.get(), faces.data(), tags.data()));

    for (uint32_t v : tets)
        if (v >= n) throw std::runtime_error("node index out of range");
    std::printf("curvetet %s: %zu nodes, %zu tets, %zu boundary faces, %d progress calls\n",
                curvetet_version(), n, tets.size() / 10, faces.size() / 6, calls);
    return tets.empty() || calls == 0 ? 1 : 0;
} catch (const std::exception &e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
}
