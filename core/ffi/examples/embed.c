/*
 * Embedding lucent from C: a flat patch of skin, uniformly lit, queried at its centre with
 * the edge-aware and the hierarchical method.
 *
 * On a flat, uniformly lit surface much larger than the diffusion length, the exitance is
 * E * Rd_total (docs/physics.md §12): the check below. The patch is 80 x 80 mm of skin1 at
 * 1 mm per unit; the longest diffusion length (red, 1/sigma_tr ~ 3.7 mm) fits 10.8 times
 * between the centre and the edge, so the light lost past the edge is of order e^-10.8, and
 * the 0.5 mm spacing is below every channel's mean free path (0.67-1.3 mm), so the sums
 * resolve the profile. Both methods come within 0.1 % of E * Rd_total at this point, and every
 * method within 0.21 % at the points of the same scene in the Rust test (tests/it/query.rs);
 * the check allows 0.5 %.
 *
 * Build and run (core/ffi/run-c-example.sh does this):
 *   cargo build --release -p lucent-ffi
 *   cc -std=c99 -Wall -Wextra -Werror -I core/ffi/include core/ffi/examples/embed.c \
 *      target/release/liblucent_ffi.a -lm -lpthread -ldl -o embed && ./embed
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "lucent.h"

#define HALF 40.0f
#define SPACING 0.5f
#define TOLERANCE 0.005f

/* Prints the failed call and its message, and exits. */
static void check(LucentStatus status, const char *call) {
    if (status != LUCENT_OK) {
        fprintf(stderr, "embed: %s failed (status %d): %s\n", call, (int)status,
                lucent_last_error_message());
        exit(1);
    }
}

int main(void) {
    const float irradiance[3] = {1.0f, 2.0f, 0.5f};

    LucentProfile *skin = NULL;
    check(lucent_profile_from_preset("skin1", 1.0f, &skin), "lucent_profile_from_preset");

    /* A square grid of samples in the plane z = 0, each standing for SPACING^2 of area. */
    const size_t n = (size_t)(2.0f * HALF / SPACING);
    LucentSample *samples = malloc(n * n * sizeof *samples);
    if (samples == NULL) {
        fprintf(stderr, "embed: out of memory\n");
        return 1;
    }
    for (size_t i = 0; i < n; i++) {
        for (size_t j = 0; j < n; j++) {
            LucentSample *s = &samples[i * n + j];
            s->position[0] = -HALF + ((float)i + 0.5f) * SPACING;
            s->position[1] = -HALF + ((float)j + 0.5f) * SPACING;
            s->position[2] = 0.0f;
            s->area = SPACING * SPACING;
            for (int c = 0; c < 3; c++) s->irradiance[c] = irradiance[c];
        }
    }
    LucentCache *cache = NULL;
    check(lucent_cache_build(samples, n * n, &cache), "lucent_cache_build");
    free(samples); /* the cache keeps its own copy */

    float rd_total[3];
    check(lucent_profile_total_reflectance(skin, rd_total), "lucent_profile_total_reflectance");

    const LucentShadingPoint point = {{0.1f, 0.2f, 0.0f}, {1.0f, 2.0f, 0.5f}};
    const LucentMethod methods[2] = {LUCENT_METHOD_EDGE_AWARE, LUCENT_METHOD_HIERARCHICAL};
    const char *names[2] = {"edge-aware", "hierarchical"};
    int failures = 0;
    for (int m = 0; m < 2; m++) {
        /* Smoothing radius 2 * sqrt(mean sample area) and K for it, computed once per plan. */
        LucentQueryOptions options;
        check(lucent_query_options_init(&options), "lucent_query_options_init");
        options.method = (uint32_t)methods[m];
        options.smoothing_factor = 2.0f;
        LucentQuery *query = NULL;
        check(lucent_query_new(skin, cache, &options, &query), "lucent_query_new");
        LucentExitance exitance;
        check(lucent_query_point(query, cache, &point, &exitance), "lucent_query_point");
        lucent_query_free(query);
        float radiance[3];
        check(lucent_profile_radiance(skin, exitance.total, cosf(0.5235988f), radiance),
              "lucent_profile_radiance");
        printf("%-12s exitance %.6f %.6f %.6f (E*Rd_total %.6f %.6f %.6f), "
               "radiance at 30 deg %.6f %.6f %.6f\n",
               names[m], exitance.total[0], exitance.total[1], exitance.total[2],
               irradiance[0] * rd_total[0], irradiance[1] * rd_total[1],
               irradiance[2] * rd_total[2], radiance[0], radiance[1], radiance[2]);
        for (int c = 0; c < 3; c++) {
            const float want = irradiance[c] * rd_total[c];
            const float error = fabsf(exitance.total[c] - want) / want;
            if (!(error < TOLERANCE)) {
                fprintf(stderr, "embed: %s channel %d: exitance %g, want %g (error %g > %g)\n",
                        names[m], c, exitance.total[c], want, error, TOLERANCE);
                failures++;
            }
        }
    }

    /* Errors come back as a status and a message, never as a crash. */
    LucentProfile *unknown = NULL;
    LucentStatus status = lucent_profile_from_preset("granite", 1.0f, &unknown);
    if (status != LUCENT_UNKNOWN_PRESET || unknown != NULL) {
        fprintf(stderr, "embed: an unknown preset gave status %d\n", (int)status);
        failures++;
    } else {
        printf("unknown preset: %s\n", lucent_last_error_message());
    }
    LucentExitance unused;
    status = lucent_query_point(NULL, cache, &point, &unused);
    if (status != LUCENT_NULL_POINTER) {
        fprintf(stderr, "embed: a NULL query gave status %d\n", (int)status);
        failures++;
    }

    lucent_cache_free(cache);
    lucent_profile_free(skin);
    if (failures != 0) {
        fprintf(stderr, "embed: %d check(s) failed\n", failures);
        return 1;
    }
    printf("embed: ok\n");
    return 0;
}
