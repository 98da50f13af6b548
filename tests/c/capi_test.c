/*
 * The curvetet C ABI, driven from C: meshes tests/data/sphere_p2.msh (read from the file
 * and rebuilt from arrays), checks counts, quality, node orders, the boundary, the round
 * trip through curvetet_mesh_write, and walks every error path.
 *
 * usage: capi_test DATA_DIR OUT_DIR
 * Environment: CURVETET_TEST_CANCEL_MS: how long cancellation may take (default 100 ms;
 * the valgrind run raises it, valgrind being ~50x slower).
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <sys/stat.h>
#include <time.h>

#include "test_util.h"

static const char *g_data;
static const char *g_out;

static double now_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

/* ---------------------------------------------------------------- surfaces */

typedef struct {
    size_t nn, nt;
    double *xyz;
    uint32_t *tri;
    int32_t *tags;
} arrays;

static arrays surface_arrays(const curvetet_surface *s) {
    arrays a;
    a.nn = curvetet_surface_num_nodes(s);
    a.nt = curvetet_surface_num_triangles(s);
    a.xyz = (double *)xmalloc(3 * a.nn * sizeof(double));
    a.tri = (uint32_t *)xmalloc(6 * a.nt * sizeof(uint32_t));
    a.tags = (int32_t *)xmalloc(a.nt * sizeof(int32_t));
    const double *p = curvetet_surface_nodes(s);
    REQUIRE(p != NULL);
    memcpy(a.xyz, p, 3 * a.nn * sizeof(double));
    EXPECT_STATUS(curvetet_surface_triangles(s, a.tri, a.tags), CURVETET_OK);
    return a;
}

static void free_arrays(arrays *a) {
    free(a->xyz);
    free(a->tri);
    free(a->tags);
}

/* A triangle as 18 coordinates and its tag, for comparing boundaries across files
 * (which renumber nodes). */
typedef struct {
    double x[18];
    int32_t tag;
} tri_rec;

static int cmp_rec(const void *pa, const void *pb) {
    const tri_rec *a = (const tri_rec *)pa, *b = (const tri_rec *)pb;
    for (int k = 0; k < 18; k++) {
        if (a->x[k] < b->x[k]) return -1;
        if (a->x[k] > b->x[k]) return 1;
    }
    return (a->tag > b->tag) - (a->tag < b->tag);
}

static tri_rec *records(const double *xyz, const uint32_t *tri, const int32_t *tags, size_t nt,
                        int with_tags) {
    tri_rec *r = (tri_rec *)xmalloc(nt * sizeof(tri_rec));
    memset(r, 0, nt * sizeof(tri_rec)); /* padding too: records are compared by memcmp */
    for (size_t t = 0; t < nt; t++) {
        for (int k = 0; k < 6; k++)
            for (int c = 0; c < 3; c++) r[t].x[3 * k + c] = xyz[3 * (size_t)tri[6 * t + k] + c];
        r[t].tag = with_tags ? tags[t] : 0;
    }
    qsort(r, nt, sizeof(tri_rec), cmp_rec);
    return r;
}

/* ------------------------------------------------------------- progress */

typedef struct {
    int calls;
    int cancel_at;        /* cancel at this call (1-based); 0 = never */
    double cancel_fraction; /* or when the fraction reaches this (> 1: never) */
    double last_fraction;
    int non_monotone;
    int out_of_range;
    int bad_stage;
    double cancelled_at_ms;
} progress_state;

static int progress_cb(void *user, double fraction, const char *stage) {
    progress_state *p = (progress_state *)user;
    p->calls++;
    if (!(fraction >= 0.0 && fraction <= 1.0)) p->out_of_range++;
    if (fraction < p->last_fraction) p->non_monotone++;
    if (stage == NULL || stage[0] == '\0') p->bad_stage++;
    p->last_fraction = fraction;
    if ((p->cancel_at && p->calls >= p->cancel_at) || fraction >= p->cancel_fraction) {
        p->cancelled_at_ms = now_ms();
        return 1;
    }
    return 0;
}

/* ------------------------------------------------------------- mesh checks */

static double det3(const double *a, const double *b, const double *c, const double *d) {
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = d[k] - a[k];
    }
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

/* Everything a mesh of surface `sa` must satisfy. */
static void check_mesh(const curvetet_mesh *m, const arrays *sa) {
    size_t nn = curvetet_mesh_num_nodes(m);
    size_t nt = curvetet_mesh_num_tets(m);
    size_t nb = curvetet_mesh_num_boundary_faces(m);
    const double *xyz = curvetet_mesh_nodes(m);
    CHECK(nn > sa->nn);
    CHECK(nt > 0);
    CHECK(nb == sa->nt);
    REQUIRE(xyz != NULL);
    /* The surface's nodes come first, bit-identical. */
    CHECK(memcmp(xyz, sa->xyz, 3 * sa->nn * sizeof(double)) == 0);

    /* Tets in both orders: VTK = Gmsh with the last two swapped. */
    uint32_t *gmsh = (uint32_t *)xmalloc(10 * nt * sizeof(uint32_t));
    uint32_t *vtk = (uint32_t *)xmalloc(10 * nt * sizeof(uint32_t));
    EXPECT_STATUS(curvetet_mesh_tets(m, CURVETET_ORDER_GMSH, gmsh), CURVETET_OK);
    EXPECT_STATUS(curvetet_mesh_tets(m, CURVETET_ORDER_VTK, vtk), CURVETET_OK);
    size_t swapped_ok = 0, in_range = 0, positive = 0, midpoints = 0;
    /* Gmsh's edges of mid nodes 4..9. */
    static const int edge[6][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}};
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *g = gmsh + 10 * t, *v = vtk + 10 * t;
        if (memcmp(g, v, 8 * sizeof(uint32_t)) == 0 && g[8] == v[9] && g[9] == v[8]) swapped_ok++;
        int ok = 1;
        for (int k = 0; k < 10; k++) ok &= g[k] < nn;
        in_range += ok;
        if (!ok) continue;
        if (det3(xyz + 3 * g[0], xyz + 3 * g[1], xyz + 3 * g[2], xyz + 3 * g[3]) > 0) positive++;
        /* An interior mid node (not a surface node) is its edge's midpoint. */
        int mid_ok = 1;
        for (int e = 0; e < 6; e++) {
            uint32_t mnode = g[4 + e];
            if (mnode < sa->nn) continue;
            for (int c = 0; c < 3; c++) {
                double mid = 0.5 * (xyz[3 * g[edge[e][0]] + c] + xyz[3 * g[edge[e][1]] + c]);
                if (fabs(xyz[3 * mnode + c] - mid) > 1e-12 * (1 + fabs(mid))) mid_ok = 0;
            }
        }
        midpoints += mid_ok;
    }
    CHECK(swapped_ok == nt);
    CHECK(in_range == nt);
    CHECK(positive == nt);
    (void)midpoints; /* the optimizer may move interior mid nodes: informative only */

    /* Boundary faces = the input triangles with their tags (same node indices). */
    uint32_t *btri = (uint32_t *)xmalloc(6 * nb * sizeof(uint32_t));
    int32_t *btag = (int32_t *)xmalloc(nb * sizeof(int32_t));
    EXPECT_STATUS(curvetet_mesh_boundary_faces(m, btri, btag), CURVETET_OK);
    EXPECT_STATUS(curvetet_mesh_boundary_faces(m, btri, NULL), CURVETET_OK);
    if (nb == sa->nt) {
        tri_rec *a = records(xyz, btri, btag, nb, 1);
        tri_rec *b = records(sa->xyz, sa->tri, sa->tags, sa->nt, 1);
        CHECK(memcmp(a, b, nb * sizeof(tri_rec)) == 0);
        free(a);
        free(b);
    }

    /* Quality. */
    curvetet_quality q;
    memset(&q, 0, sizeof q);
    q.struct_size = sizeof q;
    EXPECT_STATUS(curvetet_mesh_quality(m, &q), CURVETET_OK);
    CHECK(q.struct_size == sizeof q);
    CHECK(q.num_tets == nt);
    CHECK(q.num_invalid == 0);
    CHECK(q.min_scaled_jacobian > 0.0 && q.min_scaled_jacobian <= 1.0);
    CHECK(q.min_scaled_jacobian_certified > 0.0);
    CHECK(q.min_scaled_jacobian_certified <= q.min_scaled_jacobian + 1e-12);
    CHECK(q.mean_scaled_jacobian >= q.min_scaled_jacobian && q.mean_scaled_jacobian <= 1.0);
    CHECK(q.max_skewness >= 0.0 && q.max_skewness < 1.0);
    CHECK(q.min_dihedral_deg > 0.0 && q.min_dihedral_deg < 70.6);
    CHECK(q.max_dihedral_deg > 70.5 && q.max_dihedral_deg < 180.0);

    const char *json = curvetet_mesh_report_json(m);
    REQUIRE(json != NULL);
    char needle[64];
    snprintf(needle, sizeof needle, "\"num_tets\":%zu", nt);
    CHECK(json[0] == '{' && strstr(json, needle) != NULL);
    CHECK(json == curvetet_mesh_report_json(m)); /* owned by the mesh, made once */
    CHECK(curvetet_mesh_target_size(m) > 0.0);

    /* Per-element quality: agrees with the report's extremes. */
    double *sj = (double *)xmalloc(nt * sizeof(double));
    double *skew = (double *)xmalloc(nt * sizeof(double));
    EXPECT_STATUS(curvetet_mesh_tet_quality(m, sj, skew), CURVETET_OK);
    double sj_min = 2.0, skew_max = -1.0;
    for (size_t t = 0; t < nt; t++) {
        CHECK(sj[t] > 0.0 && sj[t] <= 1.0);
        CHECK(skew[t] >= 0.0 && skew[t] < 1.0);
        if (sj[t] < sj_min) sj_min = sj[t];
        if (skew[t] > skew_max) skew_max = skew[t];
    }
    CHECK(sj_min == q.min_scaled_jacobian);
    CHECK(skew_max == q.max_skewness);
    double *sj2 = (double *)xmalloc(nt * sizeof(double));
    EXPECT_STATUS(curvetet_mesh_tet_quality(m, sj2, NULL), CURVETET_OK);
    CHECK(memcmp(sj, sj2, nt * sizeof(double)) == 0);
    EXPECT_STATUS(curvetet_mesh_tet_quality(m, NULL, NULL), CURVETET_OK);
    EXPECT_STATUS(curvetet_mesh_tet_quality(NULL, sj, skew), CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_MESSAGE("m is NULL");
    free(sj);
    free(sj2);
    free(skew);

    printf("  mesh: %zu nodes, %zu tets, %zu boundary faces; SJ min %.3f (certified %.3f) "
           "mean %.3f; skewness max %.3f; dihedral %.1f..%.1f deg\n",
           nn, nt, nb, q.min_scaled_jacobian, q.min_scaled_jacobian_certified,
           q.mean_scaled_jacobian, q.max_skewness, q.min_dihedral_deg, q.max_dihedral_deg);
    free(gmsh);
    free(vtk);
    free(btri);
    free(btag);
}

/* Two meshes have the same nodes and tets, bit for bit. */
static int same_mesh(const curvetet_mesh *a, const curvetet_mesh *b) {
    size_t nn = curvetet_mesh_num_nodes(a), nt = curvetet_mesh_num_tets(a);
    if (nn != curvetet_mesh_num_nodes(b) || nt != curvetet_mesh_num_tets(b)) return 0;
    if (memcmp(curvetet_mesh_nodes(a), curvetet_mesh_nodes(b), 3 * nn * sizeof(double)))
        return 0;
    uint32_t *ta = (uint32_t *)xmalloc(10 * nt * sizeof(uint32_t));
    uint32_t *tb = (uint32_t *)xmalloc(10 * nt * sizeof(uint32_t));
    int same = curvetet_mesh_tets(a, CURVETET_ORDER_GMSH, ta) == CURVETET_OK &&
               curvetet_mesh_tets(b, CURVETET_ORDER_GMSH, tb) == CURVETET_OK &&
               memcmp(ta, tb, 10 * nt * sizeof(uint32_t)) == 0;
    free(ta);
    free(tb);
    return same;
}

/* Write `m` to OUT/name (with flags), read the file back as a surface, and compare its
 * boundary with the mesh's (by coordinates: files renumber nodes). */
static void round_trip(const curvetet_mesh *m, const char *name, uint32_t flags,
                       int check_tags) {
    char *path = join_path(g_out, name);
    EXPECT_STATUS(curvetet_mesh_write_with_flags(m, path, flags), CURVETET_OK);
    curvetet_surface *back = NULL;
    EXPECT_STATUS(curvetet_surface_read(path, &back), CURVETET_OK);
    if (back) {
        size_t nb = curvetet_mesh_num_boundary_faces(m);
        arrays ba = surface_arrays(back);
        CHECK(ba.nt == nb);
        uint32_t *btri = (uint32_t *)xmalloc(6 * nb * sizeof(uint32_t));
        int32_t *btag = (int32_t *)xmalloc(nb * sizeof(int32_t));
        EXPECT_STATUS(curvetet_mesh_boundary_faces(m, btri, btag), CURVETET_OK);
        if (ba.nt == nb) {
            tri_rec *a = records(curvetet_mesh_nodes(m), btri, btag, nb, check_tags);
            tri_rec *b = records(ba.xyz, ba.tri, ba.tags, ba.nt, check_tags);
            int same = memcmp(a, b, nb * sizeof(tri_rec)) == 0;
            if (!same) fprintf(stderr, "round trip through %s changed the boundary\n", name);
            CHECK(same);
            free(a);
            free(b);
        }
        free(btri);
        free(btag);
        free_arrays(&ba);
        curvetet_surface_free(back);
    }
    free(path);
}

/* ------------------------------------------------------------- the tests */

static void test_version_and_names(void) {
    CHECK(strcmp(curvetet_version(), CURVETET_VERSION) == 0);
    CHECK(strcmp(curvetet_last_error_message(), "") == 0);
    CHECK(strcmp(curvetet_error_name(CURVETET_OK), "CURVETET_OK") == 0);
    CHECK(strcmp(curvetet_error_name(CURVETET_ERR_CANCELLED), "CURVETET_ERR_CANCELLED") == 0);
    CHECK(strcmp(curvetet_error_name((curvetet_status)42), "CURVETET_UNKNOWN_STATUS") == 0);
    CHECK(CURVETET_VERSION_MAJOR >= 0 && CURVETET_VERSION_MINOR >= 0 &&
          CURVETET_VERSION_PATCH >= 0);
}

static void test_options(void) {
    curvetet_options o;
    memset(&o, 0xAB, sizeof o);
    curvetet_options_default(&o);
    CHECK(o.struct_size == sizeof o);
    CHECK(o.alpha == 1.5);
    CHECK(o.size == 0.0);
    CHECK(o.optimize == 1);
    CHECK(o.threads == 0);
    CHECK(o.progress == NULL && o.user_data == NULL);
    CHECK(o.uniform_size == 0);
    curvetet_options p;
    memset(&p, 0xAB, sizeof p);
    EXPECT_STATUS(curvetet_options_init(&p, sizeof p), CURVETET_OK);
    CHECK(memcmp(&o.alpha, &p.alpha, sizeof(double)) == 0 && p.struct_size == sizeof p);
    EXPECT_STATUS(curvetet_options_init(&p, 0), CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_MESSAGE("struct_size");
    EXPECT_STATUS(curvetet_options_init(NULL, sizeof p), CURVETET_ERR_INVALID_ARGUMENT);
    curvetet_options_default(NULL); /* ignored, with a message */
    CHECK(curvetet_last_error_message()[0] != '\0');
}

static void test_errors_without_mesh(void) {
    curvetet_surface *s = (curvetet_surface *)&g_failures; /* must be reset to NULL */
    char *missing = join_path(g_data, "does_not_exist.msh");
    char *open = join_path(g_data, "bad/open.msh");
    char *garbage = join_path(g_out, "garbage.msh");
    char *truncated = join_path(g_out, "truncated.msh");
    char *noext = join_path(g_out, "surface.unknown");

    /* NULL pointers. */
    EXPECT_STATUS(curvetet_surface_read(NULL, &s), CURVETET_ERR_INVALID_ARGUMENT);
    CHECK(s == NULL);
    EXPECT_MESSAGE("path is NULL");
    EXPECT_STATUS(curvetet_surface_read(missing, NULL), CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_MESSAGE("out is NULL");
    EXPECT_STATUS(curvetet_surface_read("", &s), CURVETET_ERR_INVALID_ARGUMENT);

    /* Missing file: IO. */
    s = (curvetet_surface *)&g_failures;
    EXPECT_STATUS(curvetet_surface_read(missing, &s), CURVETET_ERR_IO);
    CHECK(s == NULL);
    EXPECT_MESSAGE("does_not_exist.msh");

    /* Unknown extension. */
    EXPECT_STATUS(curvetet_surface_read(noext, &s), CURVETET_ERR_INVALID_ARGUMENT);

    /* Malformed files: PARSE, with the line. */
    FILE *f = fopen(garbage, "w");
    REQUIRE(f != NULL);
    fputs("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\nthis is not a number\n", f);
    fclose(f);
    EXPECT_STATUS(curvetet_surface_read(garbage, &s), CURVETET_ERR_PARSE);
    EXPECT_MESSAGE("garbage.msh:");
    char *sphere = join_path(g_data, "sphere_p2.msh");
    FILE *in = fopen(sphere, "rb");
    REQUIRE(in != NULL);
    char buf[4096];
    size_t n = fread(buf, 1, sizeof buf, in);
    fclose(in);
    f = fopen(truncated, "wb");
    REQUIRE(f != NULL);
    fwrite(buf, 1, n, f); /* cut inside $Nodes */
    fclose(f);
    EXPECT_STATUS(curvetet_surface_read(truncated, &s), CURVETET_ERR_PARSE);

    /* An open surface. */
    EXPECT_STATUS(curvetet_surface_read(open, &s), CURVETET_ERR_INVALID_SURFACE);
    CHECK(s == NULL);
    EXPECT_MESSAGE("not-closed");

    /* The whole bad-input corpus: each file gives INVALID_SURFACE naming its defect, in < 10 s,
       under CURVETET_SURFACE_STRICT; without it, unused nodes and orientation are repaired
       with a warning, and every other defect still gives the same status. */
    char *expected = join_path(g_data, "bad/EXPECTED.txt");
    FILE *ex = fopen(expected, "r");
    int corpus = 0;
    if (ex) {
        char file[256], kind[128];
        while (fscanf(ex, "%255s %127s", file, kind) == 2) {
            char rel[300];
            snprintf(rel, sizeof rel, "bad/%s", file);
            char *p = join_path(g_data, rel);
            curvetet_surface *b = NULL;
            double t0 = now_ms();
            curvetet_status st = curvetet_surface_read_with_flags(p, CURVETET_SURFACE_STRICT, &b);
            if (now_ms() - t0 > 10e3) { /* a hang guard: every case well under 10 s */
                fprintf(stderr, "%s: took %.0f ms\n", file, now_ms() - t0);
                g_failures++;
            }
            /* The file reader already refuses a reference to a missing node. */
            int parse_ok = st == CURVETET_ERR_PARSE && strcmp(kind, "index-out-of-range") == 0;
            if (!parse_ok && (st != CURVETET_ERR_INVALID_SURFACE ||
                              strstr(curvetet_last_error_message(), kind) == NULL)) {
                fprintf(stderr, "%s: %s: %s (expected %s)\n", file, curvetet_error_name(st),
                        curvetet_last_error_message(), kind);
                g_failures++;
            }
            CHECK(b == NULL);
            curvetet_surface_free(b);
            {
                int repairable = strcmp(kind, "unused-node") == 0 ||
                                 strcmp(kind, "inconsistent-orientation") == 0;
                curvetet_status lenient = curvetet_surface_read(p, &b);
                if (repairable) {
                    if (lenient != CURVETET_OK || curvetet_surface_num_warnings(b) != 1) {
                        fprintf(stderr, "%s: not repaired: %s: %s\n", file,
                                curvetet_error_name(lenient), curvetet_last_error_message());
                        g_failures++;
                    }
                } else {
                    CHECK(lenient == st && b == NULL);
                }
                curvetet_surface_free(b);
                b = NULL;
            }
            free(p);
            corpus++;
        }
        fclose(ex);
    }
    CHECK(corpus >= 20);

    /* Arrays: NULL with nonzero counts, out NULL, no triangles, bad index. */
    double xyz[18] = {0};
    uint32_t tri[6] = {0, 1, 2, 3, 4, 5};
    EXPECT_STATUS(curvetet_surface_from_arrays(NULL, 6, tri, 1, NULL, &s),
                  CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_MESSAGE("xyz is NULL");
    EXPECT_STATUS(curvetet_surface_from_arrays(xyz, 6, NULL, 1, NULL, &s),
                  CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_MESSAGE("tri6 is NULL");
    EXPECT_STATUS(curvetet_surface_from_arrays(xyz, 6, tri, 1, NULL, NULL),
                  CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_STATUS(curvetet_surface_from_arrays(xyz, 6, tri, (size_t)-1, NULL, &s),
                  CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_STATUS(curvetet_surface_from_arrays(NULL, 0, NULL, 0, NULL, &s),
                  CURVETET_ERR_INVALID_SURFACE);
    EXPECT_MESSAGE("empty");
    tri[5] = 99;
    EXPECT_STATUS(curvetet_surface_from_arrays(xyz, 6, tri, 1, NULL, &s),
                  CURVETET_ERR_INVALID_SURFACE);
    EXPECT_MESSAGE("index-out-of-range");
    CHECK(s == NULL);

    /* Accessors on NULL: 0 / NULL and a message. */
    CHECK(curvetet_surface_num_nodes(NULL) == 0);
    EXPECT_MESSAGE("s is NULL");
    CHECK(curvetet_surface_num_triangles(NULL) == 0);
    CHECK(curvetet_surface_nodes(NULL) == NULL);
    CHECK(curvetet_surface_num_warnings(NULL) == 0);
    CHECK(curvetet_surface_warning(NULL, 0) == NULL);
    EXPECT_STATUS(curvetet_surface_triangles(NULL, tri, NULL), CURVETET_ERR_INVALID_ARGUMENT);
    CHECK(curvetet_mesh_num_nodes(NULL) == 0);
    EXPECT_MESSAGE("m is NULL");
    CHECK(curvetet_mesh_num_tets(NULL) == 0);
    CHECK(curvetet_mesh_num_boundary_faces(NULL) == 0);
    CHECK(curvetet_mesh_nodes(NULL) == NULL);
    CHECK(curvetet_mesh_report_json(NULL) == NULL);
    CHECK(curvetet_mesh_target_size(NULL) == 0.0);
    EXPECT_STATUS(curvetet_mesh_tets(NULL, CURVETET_ORDER_GMSH, tri),
                  CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_STATUS(curvetet_mesh_boundary_faces(NULL, tri, NULL), CURVETET_ERR_INVALID_ARGUMENT);
    curvetet_quality q;
    memset(&q, 0, sizeof q);
    q.struct_size = sizeof q;
    EXPECT_STATUS(curvetet_mesh_quality(NULL, &q), CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_STATUS(curvetet_mesh_write(NULL, garbage), CURVETET_ERR_INVALID_ARGUMENT);
    curvetet_mesh *m = (curvetet_mesh *)&g_failures;
    EXPECT_STATUS(curvetet_generate(NULL, NULL, &m), CURVETET_ERR_INVALID_ARGUMENT);
    CHECK(m == NULL);
    EXPECT_MESSAGE("s is NULL");
    curvetet_surface_free(NULL);
    curvetet_mesh_free(NULL);

    free(missing);
    free(open);
    free(garbage);
    free(truncated);
    free(noext);
    free(sphere);
    free(expected);
}

/* uniform_size: the paper's uniform size (eq. 1) instead of the graded one; an explicit
 * size still wins. */
static void test_uniform_size(const curvetet_surface *s, double graded_size) {
    curvetet_options o;
    curvetet_options_default(&o);
    o.uniform_size = 1;
    o.optimize = 0;
    curvetet_mesh *u = NULL;
    EXPECT_STATUS(curvetet_generate(s, &o, &u), CURVETET_OK);
    REQUIRE(u != NULL);
    double hu = curvetet_mesh_target_size(u);
    CHECK(hu > 0.0 && hu != graded_size);
    CHECK(curvetet_mesh_num_tets(u) > 0);
    curvetet_mesh_free(u);
    o.size = 0.75 * hu;
    EXPECT_STATUS(curvetet_generate(s, &o, &u), CURVETET_OK);
    REQUIRE(u != NULL);
    CHECK(curvetet_mesh_target_size(u) == 0.75 * hu);
    curvetet_mesh_free(u);
}

static void test_errors_with_mesh(const curvetet_surface *s, const curvetet_mesh *m) {
    curvetet_mesh *out = (curvetet_mesh *)&g_failures;
    curvetet_options o;
    curvetet_options_default(&o);
    EXPECT_STATUS(curvetet_generate(s, &o, NULL), CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_MESSAGE("out is NULL");
    /* Bad sizes. */
    o.struct_size = 0;
    EXPECT_STATUS(curvetet_generate(s, &o, &out), CURVETET_ERR_INVALID_ARGUMENT);
    CHECK(out == NULL);
    EXPECT_MESSAGE("struct_size is 0");
    o.struct_size = 7;
    EXPECT_STATUS(curvetet_generate(s, &o, &out), CURVETET_ERR_INVALID_ARGUMENT);
    o.struct_size = 1u << 30;
    EXPECT_STATUS(curvetet_generate(s, &o, &out), CURVETET_ERR_INVALID_ARGUMENT);
    /* Bad values. */
    curvetet_options_default(&o);
    o.alpha = 0.0;
    EXPECT_STATUS(curvetet_generate(s, &o, &out), CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_MESSAGE("alpha");
    curvetet_options_default(&o);
    o.size = NAN;
    EXPECT_STATUS(curvetet_generate(s, &o, &out), CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_MESSAGE("size");
    CHECK(out == NULL);

    /* Output buffers and enums. */
    uint32_t one[10];
    EXPECT_STATUS(curvetet_mesh_tets(m, CURVETET_ORDER_GMSH, NULL), CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_STATUS(curvetet_mesh_tets(m, (curvetet_node_order)7, one),
                  CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_MESSAGE("order is 7");
    EXPECT_STATUS(curvetet_mesh_boundary_faces(m, NULL, NULL), CURVETET_ERR_INVALID_ARGUMENT);
    curvetet_quality q;
    memset(&q, 0, sizeof q); /* struct_size 0: not set */
    EXPECT_STATUS(curvetet_mesh_quality(m, &q), CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_MESSAGE("struct_size");
    EXPECT_STATUS(curvetet_mesh_quality(m, NULL), CURVETET_ERR_INVALID_ARGUMENT);

    /* Writing. */
    char *nodir = join_path(g_out, "no/such/dir/x.msh");
    char *unknown = join_path(g_out, "x.stl");
    char *vtk = join_path(g_out, "x.vtk");
    EXPECT_STATUS(curvetet_mesh_write(m, NULL), CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_STATUS(curvetet_mesh_write(m, nodir), CURVETET_ERR_IO);
    EXPECT_STATUS(curvetet_mesh_write(m, unknown), CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_MESSAGE("extension");
    EXPECT_STATUS(curvetet_mesh_write_with_flags(m, vtk, CURVETET_WRITE_BINARY),
                  CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_STATUS(curvetet_mesh_write_with_flags(m, vtk, 1u << 20), CURVETET_ERR_INVALID_ARGUMENT);
    free(nodir);
    free(unknown);
    free(vtk);
}

/* A linear octahedron (outward) curved by curvetet_surface_from_linear, then meshed. */
static void test_from_linear(void) {
    const double xyz[] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
    const uint32_t tri[] = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4,
                            2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    curvetet_surface *s = NULL;
    CHECK(curvetet_surface_from_linear(xyz, 6, tri, 8, NULL, 40.0, &s) == CURVETET_OK);
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK(curvetet_surface_num_triangles(s) == 8);
    CHECK(curvetet_surface_num_nodes(s) == 6 + 12); /* corners kept, one mid node per edge */
    CHECK(memcmp(curvetet_surface_nodes(s), xyz, sizeof xyz) == 0);
    curvetet_mesh *m = NULL;
    CHECK(curvetet_generate(s, NULL, &m) == CURVETET_OK);
    if (m) {
        curvetet_quality q = {.struct_size = sizeof q};
        CHECK(curvetet_mesh_quality(m, &q) == CURVETET_OK);
        CHECK(q.num_tets > 0 && q.num_invalid == 0);
    }
    curvetet_mesh_free(m);
    curvetet_surface_free(s);
    /* An open surface (one facet missing) is refused with the specific defect. */
    s = NULL;
    CHECK(curvetet_surface_from_linear(xyz, 6, tri, 7, NULL, 40.0, &s) ==
          CURVETET_ERR_INVALID_SURFACE);
    CHECK(s == NULL);
    CHECK(strstr(curvetet_last_error_message(), "not-closed") != NULL);
    CHECK(curvetet_surface_from_linear(NULL, 6, tri, 8, NULL, 40.0, &s) ==
          CURVETET_ERR_INVALID_ARGUMENT);
    /* Smoothed first: 0 iterations is the plain call; 2 move the vertices (the
     * octahedron's vertices all have four neighbours: it shrinks and inflates uniformly),
     * the result is still a valid surface that meshes. */
    s = NULL;
    CHECK(curvetet_surface_from_linear_smoothed(xyz, 6, tri, 8, NULL, 40.0, 0, &s) ==
          CURVETET_OK);
    CHECK(s && memcmp(curvetet_surface_nodes(s), xyz, sizeof xyz) == 0);
    curvetet_surface_free(s);
    s = NULL;
    CHECK(curvetet_surface_from_linear_smoothed(xyz, 6, tri, 8, NULL, 40.0, 2, &s) ==
          CURVETET_OK);
    if (s) {
        const double *x = curvetet_surface_nodes(s);
        CHECK(x[0] != 1.0 && x[0] > 0.5 && x[0] < 1.5 && x[1] == 0.0 && x[2] == 0.0);
        curvetet_mesh *m2 = NULL;
        CHECK(curvetet_generate(s, NULL, &m2) == CURVETET_OK);
        curvetet_mesh_free(m2);
    }
    curvetet_surface_free(s);
    s = NULL;
    CHECK(curvetet_surface_from_linear_smoothed(xyz, 6, tri, 7, NULL, 40.0, 2, &s) ==
          CURVETET_ERR_INVALID_SURFACE);
    CHECK(s == NULL);
}

static void test_cancel(const curvetet_surface *s, double limit_ms) {
    curvetet_options o;
    curvetet_options_default(&o);
    progress_state p;
    memset(&p, 0, sizeof p);
    p.cancel_at = 1;
    p.cancel_fraction = 2.0;
    o.progress = progress_cb;
    o.user_data = &p;
    curvetet_mesh *m = (curvetet_mesh *)&g_failures;
    EXPECT_STATUS(curvetet_generate(s, &o, &m), CURVETET_ERR_CANCELLED);
    CHECK(m == NULL);
    CHECK(p.calls == 1);
    EXPECT_MESSAGE("cancelled");

    /* Half way through: stops within limit_ms of the request. */
    memset(&p, 0, sizeof p);
    p.cancel_fraction = 0.5;
    EXPECT_STATUS(curvetet_generate(s, &o, &m), CURVETET_ERR_CANCELLED);
    double late = now_ms() - p.cancelled_at_ms;
    CHECK(m == NULL);
    CHECK(p.calls > 1);
    CHECK(p.last_fraction >= 0.5);
    printf("  cancel at %.0f%%: returned %.2f ms after the callback asked (limit %.0f ms)\n",
           100 * p.last_fraction, late, limit_ms);
    CHECK(late < limit_ms);
}

/* ---------------------------------------------------------------- regions */

/* Two unit boxes [0,1]x[0,1]^2 and [1,2]x[0,1]^2 sharing the wall x = 1 (given once),
 * two flat P2 triangles per unit square, in no particular orientation. */
static double g_rx[3 * 64];
static size_t g_rn;

static uint32_t region_node(double x, double y, double z) {
    for (size_t i = 0; i < g_rn; i++)
        if (g_rx[3 * i] == x && g_rx[3 * i + 1] == y && g_rx[3 * i + 2] == z) return (uint32_t)i;
    REQUIRE(g_rn < 64);
    g_rx[3 * g_rn] = x;
    g_rx[3 * g_rn + 1] = y;
    g_rx[3 * g_rn + 2] = z;
    return (uint32_t)g_rn++;
}

static uint32_t region_mid(uint32_t a, uint32_t b) {
    return region_node((g_rx[3 * a] + g_rx[3 * b]) / 2, (g_rx[3 * a + 1] + g_rx[3 * b + 1]) / 2,
                       (g_rx[3 * a + 2] + g_rx[3 * b + 2]) / 2);
}

/* The unit square at coordinate `at` of `axis`, spanning [u0, u0 + 1] x [0, 1] in the
 * next two axes. */
static void region_square(uint32_t *tri, size_t *nt, int axis, double at, double u0) {
    uint32_t c[4];
    const double uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int k = 0; k < 4; k++) {
        double p[3];
        p[axis] = at;
        p[(axis + 1) % 3] = uv[k][0] + ((axis + 1) % 3 == 0 ? u0 : 0);
        p[(axis + 2) % 3] = uv[k][1] + ((axis + 2) % 3 == 0 ? u0 : 0);
        c[k] = region_node(p[0], p[1], p[2]);
    }
    const int q[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (int h = 0; h < 2; h++) {
        uint32_t *t = tri + 6 * (*nt)++;
        t[0] = c[q[h][0]];
        t[1] = c[q[h][1]];
        t[2] = c[q[h][2]];
        t[3] = region_mid(t[0], t[1]);
        t[4] = region_mid(t[1], t[2]);
        t[5] = region_mid(t[2], t[0]);
    }
}

static int cmp_u32(const void *a, const void *b) {
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

static void test_two_regions(void) {
    uint32_t tri[6 * 22];
    size_t nt = 0;
    g_rn = 0;
    region_square(tri, &nt, 0, 0, 0);
    region_square(tri, &nt, 0, 1, 0); /* the wall, once */
    region_square(tri, &nt, 0, 2, 0);
    for (int b = 0; b < 2; b++) {
        region_square(tri, &nt, 1, 0, b); /* y = 0 and y = 1: x is the third axis */
        region_square(tri, &nt, 1, 1, b);
        region_square(tri, &nt, 2, 0, b); /* z = 0 and z = 1: x is the second axis */
        region_square(tri, &nt, 2, 1, b);
    }
    REQUIRE(nt == 22);
    curvetet_surface *s = NULL;
    EXPECT_STATUS(curvetet_surface_from_arrays(g_rx, g_rn, tri, nt, NULL, &s), CURVETET_OK);
    REQUIRE(s != NULL);
    CHECK(curvetet_surface_num_regions(s) == 2);
    CHECK(curvetet_surface_num_triangles(s) == 22);
    curvetet_options o;
    curvetet_options_default(&o);
    o.threads = 1;
    curvetet_mesh *m = NULL;
    EXPECT_STATUS(curvetet_generate(s, &o, &m), CURVETET_OK);
    REQUIRE(m != NULL);
    CHECK(curvetet_mesh_num_regions(m) == 2);
    size_t n = curvetet_mesh_num_tets(m);
    uint32_t *tets = (uint32_t *)xmalloc(10 * n * sizeof(uint32_t));
    int32_t *reg = (int32_t *)xmalloc(n * sizeof(int32_t));
    EXPECT_STATUS(curvetet_mesh_tets(m, CURVETET_ORDER_GMSH, tets), CURVETET_OK);
    EXPECT_STATUS(curvetet_mesh_tet_regions(m, reg), CURVETET_OK);
    /* Each region fills its box: linear volumes 1 and 1. */
    const double *x = curvetet_mesh_nodes(m);
    double vol[3] = {0, 0, 0};
    for (size_t t = 0; t < n; t++) {
        CHECK(reg[t] == 1 || reg[t] == 2);
        if (reg[t] != 1 && reg[t] != 2) continue;
        const double *a = x + 3 * tets[10 * t], *b = x + 3 * tets[10 * t + 1],
                     *c = x + 3 * tets[10 * t + 2], *d = x + 3 * tets[10 * t + 3];
        double u[3], v[3], w[3];
        for (int k = 0; k < 3; k++) {
            u[k] = b[k] - a[k];
            v[k] = c[k] - a[k];
            w[k] = d[k] - a[k];
        }
        vol[reg[t]] += (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                        u[2] * (v[0] * w[1] - v[1] * w[0])) /
                       6;
    }
    CHECK(fabs(vol[1] - 1) < 1e-10 && fabs(vol[2] - 1) < 1e-10);
    /* The wall's two triangles (input triangles 2 and 3) are each a face of one tet of
     * each region. */
    for (int w = 2; w < 4; w++) {
        uint32_t f[3] = {tri[6 * w], tri[6 * w + 1], tri[6 * w + 2]};
        qsort(f, 3, sizeof f[0], cmp_u32);
        int count[3] = {0, 0, 0};
        static const int faces[4][3] = {{0, 1, 2}, {0, 1, 3}, {1, 2, 3}, {0, 2, 3}};
        for (size_t t = 0; t < n; t++) {
            for (int k = 0; k < 4; k++) {
                uint32_t g[3] = {tets[10 * t + faces[k][0]], tets[10 * t + faces[k][1]],
                                 tets[10 * t + faces[k][2]]};
                qsort(g, 3, sizeof g[0], cmp_u32);
                if (memcmp(f, g, sizeof f) == 0 && (reg[t] == 1 || reg[t] == 2)) count[reg[t]]++;
            }
        }
        CHECK(count[1] == 1 && count[2] == 1);
    }
    /* The interface is kept once among the boundary triangles. */
    CHECK(curvetet_mesh_num_boundary_faces(m) == 22);
    EXPECT_STATUS(curvetet_mesh_tet_regions(m, NULL), CURVETET_ERR_INVALID_ARGUMENT);
    EXPECT_STATUS(curvetet_mesh_tet_regions(NULL, reg), CURVETET_ERR_INVALID_ARGUMENT);
    CHECK(curvetet_mesh_num_regions(NULL) == 0);
    CHECK(curvetet_surface_num_regions(NULL) == 0);
    {
        char *path = join_path(g_out, "two_regions.msh");
        EXPECT_STATUS(curvetet_mesh_write(m, path), CURVETET_OK);
        free(path);
    }
    free(tets);
    free(reg);
    curvetet_mesh_free(m);
    curvetet_surface_free(s);
    printf("  two regions: %zu tets, volumes %.12f + %.12f\n", n, vol[1], vol[2]);
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s DATA_DIR OUT_DIR\n", argv[0]);
        return 2;
    }
    g_data = argv[1];
    g_out = argv[2];
    if (mkdir(g_out, 0755) != 0 && errno != EEXIST) {
        perror(g_out);
        return 2;
    }
    double cancel_ms = 100;
    if (getenv("CURVETET_TEST_CANCEL_MS")) cancel_ms = atof(getenv("CURVETET_TEST_CANCEL_MS"));
    printf("curvetet %s (header %s)\n", curvetet_version(), CURVETET_VERSION);

    test_version_and_names();
    test_options();
    test_errors_without_mesh();
    test_from_linear();
    test_two_regions();

    /* The sphere, read from its file. */
    char *sphere = join_path(g_data, "sphere_p2.msh");
    curvetet_surface *s = NULL;
    EXPECT_STATUS(curvetet_surface_read(sphere, &s), CURVETET_OK);
    REQUIRE(s != NULL);
    arrays sa = surface_arrays(s);
    CHECK(sa.nn > 0 && sa.nt > 0);
    CHECK(curvetet_surface_num_warnings(s) == 0);
    CHECK(curvetet_surface_warning(s, 0) == NULL);
    printf("  surface: %zu nodes, %zu triangles\n", sa.nn, sa.nt);

    curvetet_mesh *m = NULL;
    EXPECT_STATUS(curvetet_generate(s, NULL, &m), CURVETET_OK);
    REQUIRE(m != NULL);
    check_mesh(m, &sa);

    /* The same surface rebuilt from arrays, meshed with explicit options and a progress
     * callback: the same mesh, bit for bit. */
    curvetet_surface *s2 = NULL;
    EXPECT_STATUS(curvetet_surface_from_arrays(sa.xyz, sa.nn, sa.tri, sa.nt, sa.tags, &s2),
                  CURVETET_OK);
    REQUIRE(s2 != NULL);
    CHECK(curvetet_surface_num_nodes(s2) == sa.nn);
    CHECK(curvetet_surface_num_triangles(s2) == sa.nt);
    curvetet_options o;
    curvetet_options_default(&o);
    progress_state p;
    memset(&p, 0, sizeof p);
    p.cancel_fraction = 2.0;
    o.progress = progress_cb;
    o.user_data = &p;
    o.threads = 1;
    curvetet_mesh *m2 = NULL;
    EXPECT_STATUS(curvetet_generate(s2, &o, &m2), CURVETET_OK);
    REQUIRE(m2 != NULL);
    CHECK(same_mesh(m, m2));
    CHECK(p.calls >= 10);
    CHECK(p.last_fraction == 1.0);
    CHECK(p.out_of_range == 0 && p.bad_stage == 0);
    printf("  progress: %d calls\n", p.calls);

    /* The surface flipped inside out: accepted with a warning, flipped back. */
    uint32_t *flipped = (uint32_t *)xmalloc(6 * sa.nt * sizeof(uint32_t));
    for (size_t t = 0; t < sa.nt; t++) {
        const uint32_t *a = sa.tri + 6 * t;
        uint32_t *b = flipped + 6 * t; /* corners 0,2,1; mids (0,2),(2,1),(1,0) */
        b[0] = a[0]; b[1] = a[2]; b[2] = a[1];
        b[3] = a[5]; b[4] = a[4]; b[5] = a[3];
    }
    curvetet_surface *s3 = NULL;
    EXPECT_STATUS(curvetet_surface_from_arrays(sa.xyz, sa.nn, flipped, sa.nt, NULL, &s3),
                  CURVETET_OK);
    REQUIRE(s3 != NULL);
    CHECK(curvetet_surface_num_warnings(s3) == 1);
    CHECK(curvetet_surface_warning(s3, 0) != NULL &&
          strstr(curvetet_surface_warning(s3, 0), "flipped") != NULL);
    curvetet_surface_free(s3);
    /* Only the first triangle flipped: reoriented with a warning, or refused when strict. */
    memcpy(flipped + 6, sa.tri + 6, 6 * (sa.nt - 1) * sizeof(uint32_t));
    s3 = NULL;
    EXPECT_STATUS(curvetet_surface_from_arrays_with_flags(sa.xyz, sa.nn, flipped, sa.nt, NULL,
                                                          0, &s3),
                  CURVETET_OK);
    REQUIRE(s3 != NULL);
    CHECK(curvetet_surface_num_warnings(s3) == 1);
    CHECK(curvetet_surface_warning(s3, 0) != NULL &&
          strstr(curvetet_surface_warning(s3, 0), "flipped 1 of") != NULL);
    curvetet_surface_free(s3);
    s3 = NULL;
    EXPECT_STATUS(curvetet_surface_from_arrays_with_flags(sa.xyz, sa.nn, flipped, sa.nt, NULL,
                                                          CURVETET_SURFACE_STRICT, &s3),
                  CURVETET_ERR_INVALID_SURFACE);
    CHECK(s3 == NULL);
    CHECK(strstr(curvetet_last_error_message(), "inconsistent-orientation") != NULL);
    free(flipped);

    /* Round trips through the writers. */
    round_trip(m, "sphere_volume.msh", 0, 1);
    round_trip(m, "sphere_volume_bin22.msh", CURVETET_WRITE_BINARY | CURVETET_WRITE_MSH22, 1);
    round_trip(m, "sphere_volume.vtu", 0, 1);
    round_trip(m, "sphere_volume_bin.vtu", CURVETET_WRITE_BINARY, 1);
    round_trip(m, "sphere_volume.vtk", 0, 1);
    round_trip(m, "sphere_volume.mesh", 0, 1);
    {
        char *path = join_path(g_out, "sphere_volume_plain.msh");
        EXPECT_STATUS(curvetet_mesh_write(m, path), CURVETET_OK);
        struct stat st;
        CHECK(stat(path, &st) == 0 && st.st_size > 1000);
        free(path);
    }

    test_errors_with_mesh(s, m);
    test_uniform_size(s, curvetet_mesh_target_size(m));
    test_cancel(s, cancel_ms);

    /* The surface outlives nothing: meshes stay valid after it is freed. */
    curvetet_surface_free(s);
    curvetet_surface_free(s2);
    CHECK(curvetet_mesh_num_tets(m) > 0 && same_mesh(m, m2));
    curvetet_mesh_free(m);
    curvetet_mesh_free(m2);
    free_arrays(&sa);
    free(sphere);
    return finish("capi_test");
}
