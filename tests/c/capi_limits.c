/*
 * The C ABI's promise that no call aborts, held under an address-space limit
 * (RLIMIT_AS, as `prlimit --as=800M`): a 30 MB .vtu of 10 million unclosed tags, a node
 * count of 2^32 + 1 and 100,000 threads are errors with a status, returned at once.
 * Also: curvetet_mesh_write replaces a file whole and leaves no temporary file, and a
 * write into a missing directory is CURVETET_ERR_IO.
 *
 * Not run under valgrind or ASan: both need more address space than the limit.
 *
 * usage: capi_limits DATA_DIR OUT_DIR
 */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <errno.h>
#include <stdint.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>

#include "test_util.h"

static double now_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

/* The number of entries of `dir` besides . and .. */
static int count_entries(const char *dir) {
    DIR *d = opendir(dir);
    REQUIRE(d != NULL);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) n++;
    }
    closedir(d);
    return n;
}

static void write_unclosed_tags(const char *path, long n) {
    FILE *f = fopen(path, "wb");
    REQUIRE(f != NULL);
    fputs("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\">", f);
    for (long i = 0; i < n; i++) fputs("<a>", f);
    REQUIRE(fclose(f) == 0);
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s DATA_DIR OUT_DIR\n", argv[0]);
        return 2;
    }
    const char *data = argv[1], *out = argv[2];
    if (mkdir(out, 0755) != 0 && errno != EEXIST) {
        perror(out);
        return 2;
    }
    char *tags = join_path(out, "tags.vtu");
    write_unclosed_tags(tags, 10000000L);

    struct rlimit r = {800ul << 20, 800ul << 20};
    REQUIRE(setrlimit(RLIMIT_AS, &r) == 0);

    double t = now_ms();
    curvetet_surface *s = NULL;
    EXPECT_STATUS(curvetet_surface_read(tags, &s), CURVETET_ERR_PARSE);
    EXPECT_MESSAGE("nested");
    CHECK(s == NULL);
    remove(tags);

    double xyz[3] = {0, 0, 0};
    uint32_t tri[6] = {0, 0, 0, 0, 0, 0};
    size_t big = (size_t)UINT32_MAX + 2;
    EXPECT_STATUS(curvetet_surface_from_arrays(xyz, big, tri, 1, NULL, &s),
                  CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_MESSAGE("num_nodes is 4294967297");
    CHECK(s == NULL);

    char *sphere = join_path(data, "sphere_p2.msh");
    EXPECT_STATUS(curvetet_surface_read(sphere, &s), CURVETET_OK);
    REQUIRE(s != NULL);
    curvetet_options o;
    curvetet_options_default(&o);
    o.threads = 100000;
    curvetet_mesh *m = NULL;
    EXPECT_STATUS(curvetet_generate(s, &o, &m), CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_MESSAGE("100000 threads");
    CHECK(m == NULL);
    double dt = now_ms() - t;
    CHECK(dt < 3000);
    printf("  refusals took %.0f ms\n", dt);

    /* Atomic writes: an old, longer file is replaced whole; no temporary is left. */
    o.threads = 1;
    o.optimize = 0;
    EXPECT_STATUS(curvetet_generate(s, &o, &m), CURVETET_OK);
    REQUIRE(m != NULL);
    char *dir = join_path(out, "write");
    REQUIRE(mkdir(dir, 0755) == 0 || errno == EEXIST);
    char *path = join_path(dir, "mesh.msh");
    FILE *f = fopen(path, "wb");
    REQUIRE(f != NULL);
    for (int i = 0; i < 4 << 20; i++) fputc('x', f);
    REQUIRE(fclose(f) == 0);
    EXPECT_STATUS(curvetet_mesh_write(m, path), CURVETET_OK);
    curvetet_surface *back = NULL;
    EXPECT_STATUS(curvetet_surface_read(path, &back), CURVETET_OK);
    CHECK(back != NULL && curvetet_surface_num_triangles(back) == curvetet_surface_num_triangles(s));
    CHECK(count_entries(dir) == 1);
    char *missing = join_path(dir, "no/such/dir/mesh.msh");
    EXPECT_STATUS(curvetet_mesh_write(m, missing), CURVETET_ERR_IO);
    EXPECT_MESSAGE("no/such/dir");
    CHECK(count_entries(dir) == 1);

    curvetet_surface_free(back);
    curvetet_mesh_free(m);
    curvetet_surface_free(s);
    free(missing);
    free(path);
    free(dir);
    free(sphere);
    free(tags);
    return finish("capi_limits");
}
