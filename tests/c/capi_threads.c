/*
 * Four threads run curvetet_generate at once on the same surface handle (each with a
 * different `threads` option); every result must equal, bit for bit, a sequential run.
 * Also checks that the last error message is per thread.
 *
 * usage: capi_threads DATA_DIR
 */
#include <pthread.h>
#include <stdint.h>

#include "test_util.h"

#define NTHREADS 4

typedef struct {
    const curvetet_surface *s;
    uint32_t threads;
    curvetet_status status;
    curvetet_mesh *mesh;
    int own_message_ok;
} job;

static void *run(void *arg) {
    job *j = (job *)arg;
    curvetet_options o;
    curvetet_options_default(&o);
    o.threads = j->threads;
    j->status = curvetet_generate(j->s, &o, &j->mesh);
    /* An error on this thread does not show on the others and vice versa. */
    curvetet_status bad = curvetet_mesh_tets(j->mesh, (curvetet_node_order)99, NULL);
    j->own_message_ok = bad == CURVETET_ERR_INVALID_ARGUMENT &&
                        strstr(curvetet_last_error_message(), "curvetet_mesh_tets") != NULL;
    return NULL;
}

typedef struct {
    size_t nn, nt, nb;
    double *xyz;
    uint32_t *tets;
    uint32_t *tri;
} flat;

static flat flatten(const curvetet_mesh *m) {
    flat f;
    f.nn = curvetet_mesh_num_nodes(m);
    f.nt = curvetet_mesh_num_tets(m);
    f.nb = curvetet_mesh_num_boundary_faces(m);
    f.xyz = (double *)xmalloc(3 * f.nn * sizeof(double));
    f.tets = (uint32_t *)xmalloc(10 * f.nt * sizeof(uint32_t));
    f.tri = (uint32_t *)xmalloc(6 * f.nb * sizeof(uint32_t));
    memcpy(f.xyz, curvetet_mesh_nodes(m), 3 * f.nn * sizeof(double));
    REQUIRE(curvetet_mesh_tets(m, CURVETET_ORDER_VTK, f.tets) == CURVETET_OK);
    REQUIRE(curvetet_mesh_boundary_faces(m, f.tri, NULL) == CURVETET_OK);
    return f;
}

static int same(const flat *a, const flat *b) {
    return a->nn == b->nn && a->nt == b->nt && a->nb == b->nb &&
           memcmp(a->xyz, b->xyz, 3 * a->nn * sizeof(double)) == 0 &&
           memcmp(a->tets, b->tets, 10 * a->nt * sizeof(uint32_t)) == 0 &&
           memcmp(a->tri, b->tri, 6 * a->nb * sizeof(uint32_t)) == 0;
}

static void free_flat(flat *f) {
    free(f->xyz);
    free(f->tets);
    free(f->tri);
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s DATA_DIR\n", argv[0]);
        return 2;
    }
    char *path = join_path(argv[1], "sphere_p2.msh");
    curvetet_surface *s = NULL;
    REQUIRE(curvetet_surface_read(path, &s) == CURVETET_OK);

    /* Sequential reference. */
    curvetet_mesh *ref = NULL;
    REQUIRE(curvetet_generate(s, NULL, &ref) == CURVETET_OK);
    flat fr = flatten(ref);

    /* Leave an error on the main thread: the workers must not disturb it. */
    CHECK(curvetet_mesh_quality(ref, NULL) == CURVETET_ERR_INVALID_ARGUMENT);
    const char *main_msg = curvetet_last_error_message();
    char saved[512];
    snprintf(saved, sizeof saved, "%s", main_msg);

    job jobs[NTHREADS];
    pthread_t th[NTHREADS];
    const uint32_t threads[NTHREADS] = {0, 1, 2, 3};
    for (int i = 0; i < NTHREADS; i++) {
        jobs[i].s = s;
        jobs[i].threads = threads[i];
        jobs[i].mesh = NULL;
        jobs[i].status = CURVETET_ERR_PANIC;
        jobs[i].own_message_ok = 0;
        REQUIRE(pthread_create(&th[i], NULL, run, &jobs[i]) == 0);
    }
    for (int i = 0; i < NTHREADS; i++) REQUIRE(pthread_join(th[i], NULL) == 0);
    CHECK(strcmp(curvetet_last_error_message(), saved) == 0);

    for (int i = 0; i < NTHREADS; i++) {
        CHECK(jobs[i].status == CURVETET_OK);
        CHECK(jobs[i].own_message_ok);
        if (jobs[i].mesh) {
            flat f = flatten(jobs[i].mesh);
            int ok = same(&f, &fr);
            if (!ok) fprintf(stderr, "thread %d (threads=%u) differs from the sequential run\n",
                             i, threads[i]);
            CHECK(ok);
            free_flat(&f);
        }
        curvetet_mesh_free(jobs[i].mesh);
    }
    printf("  %d concurrent generations: %zu nodes, %zu tets each, identical to sequential\n",
           NTHREADS, fr.nn, fr.nt);
    free_flat(&fr);
    curvetet_mesh_free(ref);
    curvetet_surface_free(s);
    free(path);
    return finish("capi_threads");
}
