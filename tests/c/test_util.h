/* Small helpers shared by the C tests of the curvetet ABI. */
#ifndef CURVETET_TEST_UTIL_H
#define CURVETET_TEST_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "curvetet.h"

static int g_failures = 0;
static int g_checks = 0;

#define CHECK(cond)                                                                    \
    do {                                                                               \
        g_checks++;                                                                    \
        if (!(cond)) {                                                                 \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);   \
            g_failures++;                                                              \
        }                                                                              \
    } while (0)

/* Call must return `expected`; a failure must leave a non-empty message, a success an
 * empty one. */
#define EXPECT_STATUS(call, expected)                                                  \
    do {                                                                               \
        curvetet_status st_ = (call);                                                  \
        const char *msg_ = curvetet_last_error_message();                              \
        g_checks++;                                                                    \
        if (st_ != (expected)) {                                                       \
            fprintf(stderr, "%s:%d: %s returned %s, expected %s (message: %s)\n",      \
                    __FILE__, __LINE__, #call, curvetet_error_name(st_),               \
                    curvetet_error_name(expected), msg_ ? msg_ : "(NULL)");            \
            g_failures++;                                                              \
        } else if (msg_ == NULL) {                                                     \
            fprintf(stderr, "%s:%d: last error message is NULL\n", __FILE__, __LINE__); \
            g_failures++;                                                              \
        } else if ((expected) != CURVETET_OK && msg_[0] == '\0') {                     \
            fprintf(stderr, "%s:%d: %s failed with an empty message\n", __FILE__,      \
                    __LINE__, #call);                                                  \
            g_failures++;                                                              \
        } else if ((expected) == CURVETET_OK && msg_[0] != '\0') {                     \
            fprintf(stderr, "%s:%d: %s succeeded but left a message: %s\n", __FILE__,  \
                    __LINE__, #call, msg_);                                            \
            g_failures++;                                                              \
        }                                                                              \
    } while (0)

/* The last error message mentions `needle`. */
#define EXPECT_MESSAGE(needle)                                                         \
    do {                                                                               \
        const char *m_ = curvetet_last_error_message();                                \
        g_checks++;                                                                    \
        if (strstr(m_, (needle)) == NULL) {                                            \
            fprintf(stderr, "%s:%d: message \"%s\" lacks \"%s\"\n", __FILE__, __LINE__, \
                    m_, (needle));                                                     \
            g_failures++;                                                              \
        }                                                                              \
    } while (0)

/* Abort the test: a precondition for the rest failed. */
#define REQUIRE(cond)                                                                  \
    do {                                                                               \
        if (!(cond)) {                                                                 \
            fprintf(stderr, "%s:%d: REQUIRE failed: %s (%s)\n", __FILE__, __LINE__,    \
                    #cond, curvetet_last_error_message());                             \
            exit(1);                                                                   \
        }                                                                              \
    } while (0)

static void *xmalloc(size_t n) {
    void *p = malloc(n ? n : 1);
    if (!p) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    return p;
}

static char *join_path(const char *dir, const char *name) {
    size_t n = strlen(dir) + strlen(name) + 2;
    char *p = (char *)xmalloc(n);
    snprintf(p, n, "%s/%s", dir, name);
    return p;
}

static int finish(const char *name) {
    if (g_failures) {
        fprintf(stderr, "%s: %d of %d checks FAILED\n", name, g_failures, g_checks);
        return 1;
    }
    printf("%s: all %d checks passed\n", name, g_checks);
    return 0;
}

#endif
