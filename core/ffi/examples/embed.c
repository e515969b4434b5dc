/*
 * Embedding lucent from C: a flat patch of skin, uniformly lit, queried at its centre with
 * the edge-aware and the hierarchical method; then the same patch lit only where x > 0,
 * queried next to the shadow edge with the edge-refined method and an irradiance callback.
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
 * Near the shadow edge the exitance lies between the shadow's (0) and the lit side's
 * (E * Rd_total); the Rust test tests/it/refined.rs computes this query through lucent-core
 * step by step and gets REFINED_TOTAL below, which the check requires to 1e-4.
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

static const float REFINED_TOTAL[3] = {0.25488898f, 0.29473466f, 0.0476227f};

/* The renderer's side of the edge-refined method: the irradiance at a point of the patch, lit
 * only where x > 0 (a real renderer traces shadow rays to its lights here, ignoring occluders
 * closer than shadow_skip). `user` counts the calls. */
struct half_plane {
    float irradiance[3];
    int calls;
};

static int half_plane_irradiance(void *user, const float *position, const float *normal,
                                 float shadow_skip, float *irradiance) {
    struct half_plane *light = user;
    (void)normal;
    (void)shadow_skip;
    light->calls++;
    for (int c = 0; c < 3; c++) irradiance[c] = position[0] > 0.0f ? light->irradiance[c] : 0.0f;
    return 0;
}

/* Prints the failed call and its message, and exits. */
static void check(LucentStatus status, const char *call) {
    if (status != LUCENT_OK) {
        fprintf(stderr, "embed: %s failed (status %d): %s\n", call, (int)status,
                lucent_last_error_message());
        exit(1);
    }
}

/* A square grid of samples in the plane z = 0, each standing for SPACING^2 of area, lit by
 * `irradiance` (where x > 0 only, if `half_plane`). Exits on failure. */
static LucentCache *build_patch(const float irradiance[3], int half_plane) {
    const size_t n = (size_t)(2.0f * HALF / SPACING);
    LucentSample *samples = malloc(n * n * sizeof *samples);
    if (samples == NULL) {
        fprintf(stderr, "embed: out of memory\n");
        exit(1);
    }
    for (size_t i = 0; i < n; i++) {
        for (size_t j = 0; j < n; j++) {
            LucentSample *s = &samples[i * n + j];
            s->position[0] = -HALF + ((float)i + 0.5f) * SPACING;
            s->position[1] = -HALF + ((float)j + 0.5f) * SPACING;
            s->position[2] = 0.0f;
            s->area = SPACING * SPACING;
            const int lit = !half_plane || s->position[0] > 0.0f;
            for (int c = 0; c < 3; c++) s->irradiance[c] = lit ? irradiance[c] : 0.0f;
        }
    }
    LucentCache *cache = NULL;
    check(lucent_cache_build(samples, n * n, &cache), "lucent_cache_build");
    free(samples); /* the cache keeps its own copy */
    return cache;
}

int main(void) {
    const float irradiance[3] = {1.0f, 2.0f, 0.5f};

    LucentProfile *skin = NULL;
    check(lucent_profile_from_preset("skin1", 1.0f, &skin), "lucent_profile_from_preset");

    LucentCache *cache = build_patch(irradiance, 0);
    float rd_total[3];
    check(lucent_profile_total_reflectance(skin, rd_total), "lucent_profile_total_reflectance");

    const LucentShadingPoint point = {{0.1f, 0.2f, 0.0f}, {1.0f, 2.0f, 0.5f}};
    const LucentMethod methods[2] = {LUCENT_METHOD_EDGE_AWARE, LUCENT_METHOD_HIERARCHICAL};
    const char *names[2] = {"edge-aware", "hierarchical"};
    int failures = 0;
    LucentStatus status;
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

    /* Edge-refined next to a shadow edge: the query asks the callback for the irradiance at
     * its quadrature nodes around x (12 of them) where the samples within the smoothing
     * radius disagree with E(x). The seed turns the node pattern: vary it between pixels. */
    LucentCache *half_lit = build_patch(irradiance, 1);
    LucentQueryOptions options;
    check(lucent_query_options_init(&options), "lucent_query_options_init");
    options.method = (uint32_t)LUCENT_METHOD_EDGE_REFINED;
    LucentQuery *refined = NULL;
    check(lucent_query_new(skin, half_lit, &options, &refined), "lucent_query_new");
    const LucentShadingPoint near_edge = {{0.3f, 0.1f, 0.0f}, {1.0f, 2.0f, 0.5f}};
    const float normal[3] = {0.0f, 0.0f, 1.0f};
    struct half_plane light = {{1.0f, 2.0f, 0.5f}, 0};
    LucentExitance exitance;
    check(lucent_query_point_refined(refined, half_lit, &near_edge, normal, 7,
                                     half_plane_irradiance, &light, &exitance),
          "lucent_query_point_refined");
    printf("%-12s exitance %.6f %.6f %.6f next to the shadow edge (%d callback calls)\n",
           "edge-refined", exitance.total[0], exitance.total[1], exitance.total[2], light.calls);
    if (light.calls != 12) {
        fprintf(stderr, "embed: edge-refined called back %d times, want 12\n", light.calls);
        failures++;
    }
    for (int c = 0; c < 3; c++) {
        const float lit = irradiance[c] * rd_total[c];
        const float error = fabsf(exitance.total[c] - REFINED_TOTAL[c]) / REFINED_TOTAL[c];
        if (!(exitance.total[c] > 0.0f && exitance.total[c] < lit && error < 1e-4f)) {
            fprintf(stderr, "embed: edge-refined channel %d: exitance %g, want %g in (0, %g)\n",
                    c, exitance.total[c], REFINED_TOTAL[c], lit);
            failures++;
        }
    }
    /* Without a callback an edge-refined plan cannot be queried. */
    status = lucent_query_point(refined, half_lit, &near_edge, &exitance);
    if (status != LUCENT_UNSUPPORTED) {
        fprintf(stderr, "embed: edge-refined without a callback gave status %d\n", (int)status);
        failures++;
    }
    lucent_query_free(refined);
    lucent_cache_free(half_lit);

    /* Errors come back as a status and a message, never as a crash. */
    LucentProfile *unknown = NULL;
    status = lucent_profile_from_preset("granite", 1.0f, &unknown);
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
