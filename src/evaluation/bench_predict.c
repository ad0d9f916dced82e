/* SPDX-License-Identifier: MIT */
/*
 * bench_predict.c: the harness of `coavoid bench predict` (bench_predict.h): the random
 * airspace, the timed prediction cycles and their report.
 */
#define _POSIX_C_SOURCE 200809L

#include "bench_predict.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "coavoid/coavoid.h"
#include "coavoid/predict.h"
#include "evaluation_internal.h"
#include "output.h"
#include "run.h"
#include "prng.h"

/* The plans' samples are refused beyond this (N * H bounds them), before anything is
 * allocated: the benchmark should not page a machine to death. */
#define BENCH_MAX_SAMPLE_BYTES ((size_t)2u << 30)
/* And the predictor's workspace beyond this while it is being sized. */
#define BENCH_MAX_WORKSPACE_BYTES ((size_t)8u << 30)
#define BENCH_TRACK_GROWTH_HORIZONTAL 0.5
#define BENCH_TRACK_GROWTH_VERTICAL 0.1

/* ---- the airspace ---- */

#define BENCH_PI 3.14159265358979323846
#define BENCH_LAYER_COUNT 4u
#define BENCH_MAX_LEGS 3u
static const double BENCH_LAYERS[BENCH_LAYER_COUNT] = {60.0, 90.0, 120.0, 150.0};
static const double BENCH_STEPS[3] = {0.5, 1.0, 2.0};

/* A route: waypoints w[0..legs], flown from w[0] at t = 0 at constant horizontal speed. */
typedef struct {
    double x[BENCH_MAX_LEGS + 1u], y[BENCH_MAX_LEGS + 1u], z[BENCH_MAX_LEGS + 1u];
    double length[BENCH_MAX_LEGS]; /* horizontal */
    uint32_t legs;
} route_t;

static void random_route(coavoid_prng_t *r, double side, route_t *route)
{
    uint32_t layer = coavoid_prng_below(r, BENCH_LAYER_COUNT);
    double heading = coavoid_prng_uniform(r, 0.0, 2.0 * BENCH_PI);
    route->legs = 2u + coavoid_prng_below(r, 2u);
    route->x[0] = coavoid_prng_uniform(r, 0.0, side);
    route->y[0] = coavoid_prng_uniform(r, 0.0, side);
    route->z[0] = BENCH_LAYERS[layer];
    bool changes_layer = coavoid_prng_below(r, 5u) == 0;
    for (uint32_t j = 0; j < route->legs; j++) {
        double length = coavoid_prng_uniform(r, 300.0, 1200.0);
        if (j > 0) {
            heading += coavoid_prng_uniform(r, -0.5 * BENCH_PI, 0.5 * BENCH_PI);
        }
        if (j == 1 && changes_layer) {
            bool up =
                layer == 0 || (layer + 1u < BENCH_LAYER_COUNT && coavoid_prng_below(r, 2u) == 0);
            layer = up ? layer + 1u : layer - 1u;
        }
        route->length[j] = length;
        route->x[j + 1] = route->x[j] + length * cos(heading);
        route->y[j + 1] = route->y[j] + length * sin(heading);
        route->z[j + 1] = BENCH_LAYERS[layer];
    }
}

/* The point at horizontal distance s along the route; before its start and past its end
 * the first and last legs are extended. */
static coa_vec3_t route_at(const route_t *route, double s)
{
    uint32_t j = 0;
    while (j + 1u < route->legs && s > route->length[j]) {
        s -= route->length[j];
        j++;
    }
    double u = s / route->length[j];
    coa_vec3_t p;
    p.x = (coa_real_t)(route->x[j] + u * (route->x[j + 1] - route->x[j]));
    p.y = (coa_real_t)(route->y[j] + u * (route->y[j + 1] - route->y[j]));
    p.z = (coa_real_t)(route->z[j] + u * (route->z[j + 1] - route->z[j]));
    return p;
}

typedef struct {
    uint32_t vehicles;
    uint32_t track_count;
    double side_m;
    coa_intent_plan_t *plans;
    coa_vec3_t *samples;
    coa_track_t *tracks;
} airspace_t;

static void airspace_free(airspace_t *a)
{
    free(a->plans);
    free(a->samples);
    free(a->tracks);
}

/* Samples one plan needs to cover [t0, horizon * dt] with this step (t0 in (-step, 0]). */
static size_t plan_samples(uint32_t horizon, double step)
{
    return (size_t)ceil((double)horizon * COAVOID_BENCH_PREDICT_DT / step) + 2u;
}

/* Builds the airspace. Returns COAVOID_RUN_DONE, or an error with e set. */
static int build_airspace(const coavoid_bench_predict_config_t *o, airspace_t *a,
                          coavoid_run_error_t *e)
{
    memset(a, 0, sizeof *a);
    a->vehicles = o->vehicles;
    a->track_count = o->vehicles / COAVOID_BENCH_PREDICT_TRACKS_PER_VEHICLE;
    double side_km = o->side_km > 0
                         ? o->side_km
                         : sqrt((double)o->vehicles / COAVOID_BENCH_PREDICT_DENSITY_PER_KM2);
    a->side_m = side_km * 1000.0;
    /* The worst case (every plan at the finest step) bounds the samples. */
    size_t per_plan = plan_samples(o->horizon, BENCH_STEPS[0]);
    size_t bytes_per_plan = per_plan * sizeof(coa_vec3_t);
    if (bytes_per_plan > BENCH_MAX_SAMPLE_BYTES / o->vehicles) {
        return coavoid_run_fail(
            e, COAVOID_RUN_ERR_INPUT,
            "--vehicles, --horizon: %lu UAVs over %lu steps need up to %zu MiB of "
            "plans, more than the benchmark's %zu MiB",
            (unsigned long)o->vehicles, (unsigned long)o->horizon,
            bytes_per_plan / 1024u * o->vehicles / 1024u, BENCH_MAX_SAMPLE_BYTES >> 20);
    }
    a->plans = calloc(o->vehicles, sizeof *a->plans);
    a->samples = calloc((size_t)o->vehicles * per_plan, sizeof *a->samples);
    a->tracks = calloc(a->track_count + 1u, sizeof *a->tracks);
    if (a->plans == NULL || a->samples == NULL || a->tracks == NULL) {
        airspace_free(a);
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "--vehicles, --horizon: out of memory for the plans");
    }

    coavoid_prng_t r = {o->seed};
    size_t used = 0;
    for (uint32_t i = 0; i < o->vehicles; i++) {
        route_t route;
        random_route(&r, a->side_m, &route);
        double speed = coavoid_prng_uniform(&r, 8.0, 20.0);
        double step = BENCH_STEPS[coavoid_prng_below(&r, 3u)];
        double t0 = -coavoid_prng_uniform(&r, 0.0, 1.0) * step;
        size_t count = plan_samples(o->horizon, step);
        coa_vec3_t *samples = a->samples + used;
        for (size_t j = 0; j < count; j++) {
            samples[j] = route_at(&route, speed * (t0 + (double)j * step));
        }
        used += count;
        coa_intent_plan_t *p = &a->plans[i];
        p->id = (uint16_t)(i + 1u);
        p->volume.radius = (coa_real_t)25.0;
        p->volume.half_height = (coa_real_t)7.5;
        p->t0 = (coa_real_t)t0;
        p->step = (coa_real_t)step;
        p->samples = samples;
        p->count = count;
    }
    for (uint32_t j = 0; j < a->track_count; j++) {
        coa_track_t *t = &a->tracks[j];
        double speed = coavoid_prng_uniform(&r, 20.0, 50.0);
        double heading = coavoid_prng_uniform(&r, 0.0, 2.0 * BENCH_PI);
        t->id = j + 1u;
        t->volume.radius = (coa_real_t)30.0;
        t->volume.half_height = (coa_real_t)10.0;
        t->position.x = (coa_real_t)coavoid_prng_uniform(&r, 0.0, a->side_m);
        t->position.y = (coa_real_t)coavoid_prng_uniform(&r, 0.0, a->side_m);
        t->position.z = (coa_real_t)coavoid_prng_uniform(&r, 50.0, 200.0);
        t->velocity.x = (coa_real_t)(speed * cos(heading));
        t->velocity.y = (coa_real_t)(speed * sin(heading));
        t->velocity.z = (coa_real_t)coavoid_prng_uniform(&r, -1.0, 1.0);
        t->sigma_horizontal = (coa_real_t)coavoid_prng_uniform(&r, 5.0, 25.0);
        t->sigma_vertical = (coa_real_t)coavoid_prng_uniform(&r, 2.0, 8.0);
    }
    return COAVOID_RUN_DONE;
}

/* ---- the run ---- */

typedef struct {
    void *workspace;
    coa_predictor_t *predictor;
    size_t size;
    size_t max_pairs;
    coa_conflict_t *conflicts;
    size_t capacity;
} bench_memory_t;

/* (Re)builds the predictor for max_pairs. Returns COAVOID_RUN_DONE, or an error
 * with e set. */
static int size_predictor(const airspace_t *a, uint32_t horizon, bench_memory_t *m,
                          coavoid_run_error_t *e)
{
    free(m->workspace);
    m->workspace = NULL;
    m->size = coa_predictor_workspace_size(a->vehicles, a->track_count, horizon, m->max_pairs);
    if (m->size == 0 || m->size > BENCH_MAX_WORKSPACE_BYTES) {
        return coavoid_run_fail(
            e, COAVOID_RUN_ERR_INPUT,
            "--vehicles, --horizon: the predictor's workspace for %zu candidate "
            "pairs would exceed the benchmark's %zu MiB",
            m->max_pairs, BENCH_MAX_WORKSPACE_BYTES >> 20);
    }
    m->workspace = malloc(m->size);
    if (m->workspace == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "--vehicles, --horizon: out of memory for %zu bytes of workspace",
                                m->size);
    }
    m->predictor = coa_predictor_init(m->workspace, m->size, a->vehicles, a->track_count, horizon,
                                      m->max_pairs);
    if (m->predictor == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: the predictor refused its workspace");
    }
    return COAVOID_RUN_DONE;
}

static int predict_once(const airspace_t *a, const coa_predict_config_t *config, bench_memory_t *m,
                        coa_predict_result_t *result)
{
    memset(result, 0, sizeof *result);
    return coa_predict(m->predictor, config, a->plans, a->vehicles, NULL, 0, a->tracks,
                       a->track_count, m->conflicts, m->capacity, result);
}

/* The untimed first cycle: grows the pair set and the conflict array until the cycle
 * fits. Returns COAVOID_RUN_DONE, or an error with e set. */
static int first_cycle(const airspace_t *a, const coa_predict_config_t *config, bench_memory_t *m,
                       coa_predict_result_t *result, coavoid_run_error_t *e)
{
    for (;;) {
        int rc = predict_once(a, config, m, result);
        if (rc == COA_ERR_WORKSPACE && m->max_pairs <= SIZE_MAX / 2u) {
            m->max_pairs *= 2u;
            int status = size_predictor(a, config->horizon, m, e);
            if (status != COAVOID_RUN_DONE) {
                return status;
            }
            continue;
        }
        if (rc != COA_OK) {
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                    "internal error: the predictor failed (%s)",
                                    coa_status_name(rc));
        }
        if (!result->overflow) {
            return COAVOID_RUN_DONE;
        }
        free(m->conflicts);
        m->capacity = result->conflicts_found;
        m->conflicts = calloc(m->capacity, sizeof *m->conflicts);
        if (m->conflicts == NULL) {
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                    "--vehicles: out of memory for %zu conflicts", m->capacity);
        }
    }
}

static int run(const coavoid_bench_predict_config_t *o, const airspace_t *a,
               coavoid_bench_predict_result_t *out, coavoid_run_error_t *e)
{
    coa_predict_config_t config;
    memset(&config, 0, sizeof config);
    config.t0 = 0;
    config.dt = (coa_real_t)COAVOID_BENCH_PREDICT_DT;
    config.horizon = o->horizon;
    config.track_sigma_rate_horizontal = (coa_real_t)BENCH_TRACK_GROWTH_HORIZONTAL;
    config.track_sigma_rate_vertical = (coa_real_t)BENCH_TRACK_GROWTH_VERTICAL;
    config.threshold = COAVOID_BENCH_PREDICT_THRESHOLD;
    config.all_pairs = o->all_pairs;

    bench_memory_t m;
    memset(&m, 0, sizeof m);
    /* A first guess a few times the UAVs: sparse traffic has a few neighbours each. */
    m.max_pairs = 4u * ((size_t)a->vehicles + a->track_count) + 64u;
    m.capacity = 1024u;
    m.conflicts = calloc(m.capacity, sizeof *m.conflicts);
    double *times = calloc(o->repeat, sizeof *times);
    int status = COAVOID_RUN_DONE;
    if (m.conflicts == NULL || times == NULL) {
        status = coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--repeat: out of memory");
    }
    if (status == COAVOID_RUN_DONE) {
        status = size_predictor(a, o->horizon, &m, e);
    }
    coa_predict_result_t first;
    if (status == COAVOID_RUN_DONE) {
        status = first_cycle(a, &config, &m, &first, e);
    }
    for (uint32_t k = 0; status == COAVOID_RUN_DONE && k < o->repeat; k++) {
        coa_predict_result_t result;
        struct timespec start, end;
        clock_gettime(CLOCK_MONOTONIC, &start);
        int rc = predict_once(a, &config, &m, &result);
        clock_gettime(CLOCK_MONOTONIC, &end);
        times[k] = coavoid_timing_elapsed_ms(&start, &end);
        /* The same input must give the same answer every cycle. */
        if (rc != COA_OK || result.overflow || result.pair_tests != first.pair_tests ||
            result.candidate_pairs != first.candidate_pairs ||
            result.conflicts_found != first.conflicts_found) {
            status = coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                      "internal error: cycle %lu differs from the first (%s)",
                                      (unsigned long)k + 1u, coa_status_name(rc));
        }
    }
    if (status == COAVOID_RUN_DONE) {
        coavoid_timing_summarise(times, o->repeat, &out->median_ms, &out->min_ms, &out->max_ms);
        out->result = first;
        out->workspace_bytes = m.size;
        out->max_pairs = m.max_pairs;
    }
    free(times);
    free(m.conflicts);
    free(m.workspace);
    return status;
}

/* ---- the report ---- */

int coavoid_bench_predict_report(FILE *f, const coavoid_bench_predict_config_t *o,
                                 const coavoid_bench_predict_result_t *b, bool json)
{
    const double all_pairs = (double)b->vehicles * ((double)b->vehicles - 1.0) / 2.0;
    const coa_predict_result_t *r = &b->result;
    struct {
        const char *key;
        double value;
        int decimals;
    } rows[] = {
        {"vehicles", b->vehicles, 0},
        {"tracks", b->tracks, 0},
        {"horizon", o->horizon, 0},
        {"dt_s", COAVOID_BENCH_PREDICT_DT, 3},
        {"seed", (double)o->seed, 0},
        {"repeat", o->repeat, 0},
        {"side_m", b->side_m, 1},
        {"median_ms", b->median_ms, 3},
        {"min_ms", b->min_ms, 3},
        {"max_ms", b->max_ms, 3},
        {"pair_tests", (double)r->pair_tests, 0},
        {"candidate_pairs", (double)r->candidate_pairs, 0},
        {"all_pairs", all_pairs, 0},
        {"conflicts", (double)r->conflicts_found, 0},
        {"workspace_bytes", (double)b->workspace_bytes, 0},
        {"max_pairs", (double)b->max_pairs, 0},
    };
    const size_t row_count = sizeof rows / sizeof rows[0];
    const char *broad_phase = o->all_pairs ? "off" : "on";
    if (!json) {
        fprintf(f, "benchmark: predict\n");
        fprintf(f, "broad_phase: %s\n", broad_phase);
        for (size_t i = 0; i < row_count; i++) {
            if (strcmp(rows[i].key, "seed") == 0) {
                /* A 64-bit seed does not fit a double's 53 bits. */
                fprintf(f, "seed: %llu\n", (unsigned long long)o->seed);
            } else {
                fprintf(f, "%s: %.*f\n", rows[i].key, rows[i].decimals, rows[i].value);
            }
        }
        return fflush(f) == 0 && !ferror(f) ? 0 : -1;
    }
    cJSON *root = cJSON_CreateObject();
    bool ok = root != NULL && cJSON_AddStringToObject(root, "benchmark", "predict") != NULL &&
              cJSON_AddStringToObject(root, "broad_phase", broad_phase) != NULL;
    for (size_t i = 0; ok && i < row_count; i++) {
        if (strcmp(rows[i].key, "seed") == 0) {
            char seed[32];
            snprintf(seed, sizeof seed, "%llu", (unsigned long long)o->seed);
            /* A raw number keeps every digit of a 64-bit seed. */
            ok = cJSON_AddRawToObject(root, "seed", seed) != NULL;
        } else {
            ok = cJSON_AddNumberToObject(root, rows[i].key, rows[i].value) != NULL;
        }
    }
    if (!ok) {
        cJSON_Delete(root);
        return -1;
    }
    return coavoid_output_json(f, root, NULL, 0);
}

int coavoid_bench_predict_run(const coavoid_bench_predict_config_t *config,
                              coavoid_bench_predict_result_t *out, coavoid_run_error_t *e)
{
    memset(out, 0, sizeof *out);
    airspace_t airspace;
    int status = build_airspace(config, &airspace, e);
    if (status != COAVOID_RUN_DONE) {
        return status;
    }
    out->vehicles = airspace.vehicles;
    out->tracks = airspace.track_count;
    out->side_m = airspace.side_m;
    status = run(config, &airspace, out, e);
    airspace_free(&airspace);
    return status;
}
