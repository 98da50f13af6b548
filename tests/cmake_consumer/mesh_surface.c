/* Mesh a closed P2 surface into a P2 tetrahedral mesh with the curvetet C API. */
#include <stdio.h>
#include <curvetet.h>

static int on_progress(void *user_data, double fraction, const char *stage) {
    (void)user_data;
    fprintf(stderr, "\r%s %3.0f%%", stage, 100 * fraction);
    return 0; /* nonzero cancels */
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s SURFACE.msh VOLUME.{msh,vtu,mesh}\n", argv[0]);
        return 2;
    }
    curvetet_surface *surface = NULL;
    curvetet_mesh *mesh = NULL;
    curvetet_status st = curvetet_surface_read(argv[1], &surface);
    if (st == CURVETET_OK) {
        curvetet_options opt;
        curvetet_options_default(&opt); /* alpha 1.5, graded size, optimize */
        opt.progress = on_progress;
        st = curvetet_generate(surface, &opt, &mesh);
        fprintf(stderr, "\n");
    }
    if (st == CURVETET_OK) {
        curvetet_quality q = {.struct_size = sizeof q};
        curvetet_mesh_quality(mesh, &q);
        printf("%zu nodes, %zu tets, min scaled Jacobian %.3f (certified %.3f)\n",
               curvetet_mesh_num_nodes(mesh), curvetet_mesh_num_tets(mesh),
               q.min_scaled_jacobian, q.min_scaled_jacobian_certified);
        st = curvetet_mesh_write(mesh, argv[2]);
    }
    if (st != CURVETET_OK)
        fprintf(stderr, "%s: %s\n", curvetet_error_name(st), curvetet_last_error_message());
    curvetet_mesh_free(mesh); /* NULL is fine */
    curvetet_surface_free(surface);
    return st == CURVETET_OK ? 0 : 1;
}
