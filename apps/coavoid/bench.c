/* SPDX-License-Identifier: MIT */
/*
 * coavoid bench predict: times the core's prediction cycle (coa_predict) on a random but
 * realistic airspace. See BENCH_PREDICT_USAGE below and docs/benchmarks.md.
 *
 * The airspace. UAVs fly at the density of 1,000 UAVs over 10 km x 10 km (10 per km^2:
 * a busy city), so the square's side grows as sqrt(N) and the traffic each UAV meets stays
 * the same whatever N is: that is what a ground station covering a bigger area sees, and
 * it measures how the predictor scales rather than how crowded one square can get
 * (--side-km fixes the square instead). They cruise at 8-20 m/s on four altitude layers
 * (60, 90, 120, 150 m, 30 m apart against 15 m of combined half-heights, so layers do not
 * conflict with each other) along routes of 2-3 legs of 300-1200 m that turn by up to 90
 * degrees; one in five changes to the next layer up or down on its second leg. Protected
 * volumes have a 25 m radius and a 7.5 m half-height. Plans are published unaligned, as
 * they arrive from the network: each starts within the last step before the cycle (t0 in
 * (-step, 0]), with a step of 0.5, 1 or 2 s, and has enough samples to cover the horizon.
 * N/50 non-cooperative tracks (light aircraft and helicopters: 30 m radius, 10 m
 * half-height, 20-50 m/s, 50-200 m) carry a one-sigma position error of 5-25 m
 * horizontally and 2-8 m vertically that grows by 0.5 and 0.1 m/s of look-ahead.
 *
 * Everything comes from our own PRNG (splitmix64) seeded by --seed, so a seed gives the
 * same airspace on every machine; only the times differ.
 *
 * What is timed: coa_predict alone (clock_gettime around the call), after one untimed
 * cycle that also sizes the workspace (max_pairs is doubled from a small guess until the
 * broad phase fits, so the pair set is as small as the traffic allows, as a deployment
 * would size it) and warms the caches.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "bench_support.h"
#include "cli.h"
#include "coavoid/coavoid.h"
#include "coavoid/predict.h"
#include "commands.h"
#include "output.h"

#define BENCH_DEFAULT_SEED 1u
#define BENCH_DEFAULT_REPEAT 21u
#define BENCH_MAX_REPEAT 100000u
#define BENCH_MAX_VEHICLES 65535u /* UAV ids are 16-bit */
/* UAVs per km^2 when --side-km is not given: 1,000 UAVs over 10 km x 10 km. */
#define BENCH_DENSITY_PER_KM2 10.0
#define BENCH_MAX_SIDE_KM 1000.0
/* The plans' samples are refused beyond this (N * H bounds them), before anything is
 * allocated: the benchmark should not page a machine to death. */
#define BENCH_MAX_SAMPLE_BYTES ((size_t)2u << 30)
/* And the predictor's workspace beyond this while it is being sized. */
#define BENCH_MAX_WORKSPACE_BYTES ((size_t)8u << 30)
#define BENCH_DT 1.0
#define BENCH_THRESHOLD 0.01
#define BENCH_TRACKS_PER_VEHICLE 50u /* one track per this many UAVs */
#define BENCH_TRACK_GROWTH_HORIZONTAL 0.5
#define BENCH_TRACK_GROWTH_VERTICAL 0.1

#define BENCH_USAGE                                                                         \
    "usage: coavoid bench predict --vehicles N --horizon H [--seed S] [--repeat R]\n"       \
    "                             [--side-km L] [--all-pairs] [--json]\n"                   \
    "\n"                                                                                    \
    "Builds a random airspace of N UAVs (%g per km^2, four altitude layers, 8-20 m/s,\n"    \
    "routes of 2-3 legs, plans published unaligned with steps of 0.5, 1 or 2 s) and N/%u\n" \
    "tracks with position uncertainty, then times the core's prediction cycle\n"            \
    "(coa_predict, dt = %g s over H steps, threshold %g) R times on one core.\n"            \
    "Prints the median, min and max time per cycle and the work done, one\n"                \
    "'key: value' per line (or a JSON object with --json). See docs/benchmarks.md.\n"       \
    "\n"                                                                                    \
    "options:\n"                                                                            \
    "  --vehicles N   UAVs, 1..%u\n"                                                        \
    "  --horizon H    steps predicted, 1..%u\n"                                             \
    "  --seed S       the airspace's random seed, an integer >= 0; default %u\n"            \
    "  --repeat R     timed cycles, 1..%u; default %u\n"                                    \
    "  --side-km L    fly in a fixed L km x L km square (0 < L <= %g) instead of\n"         \
    "                 one sized for %g UAVs per km^2\n"                                     \
    "  --all-pairs    skip the broad phase: every pair is tested (the reference)\n"         \
    "  --json         print a JSON object instead of 'key: value' lines\n"                  \
    "  -h, --help     show this help\n"                                                     \
    "\n"                                                                                    \
    "A benchmark is deterministic for a seed except for its times.\n"                       \
    "\n"                                                                                    \
    "exit status: 0 done, 2 invalid usage or a size beyond the benchmark's memory\n"        \
    "limits (one line on stderr naming the option and why), 3 internal error\n"

static void print_usage(void)
{
    printf(BENCH_USAGE, BENCH_DENSITY_PER_KM2, BENCH_TRACKS_PER_VEHICLE, BENCH_DT, BENCH_THRESHOLD,
           BENCH_MAX_VEHICLES, COA_MAX_HORIZON, BENCH_DEFAULT_SEED, BENCH_MAX_REPEAT,
           BENCH_DEFAULT_REPEAT, BENCH_MAX_SIDE_KM, BENCH_DENSITY_PER_KM2);
}

typedef struct {
    const char *vehicles_text;
    uint32_t vehicles;
    const char *horizon_text;
    uint32_t horizon;
    const char *seed_text;
    uint64_t seed;
    const char *repeat_text;
    uint32_t repeat;
    const char *side_text;
    double side_km;
    bool all_pairs;
    bool json;
} bench_options_t;

/* Returns CLI_CONTINUE, or the exit status (help printed: 0; a usage error: 2). */
static int parse_bench_options(int argc, char **argv, bench_options_t *o)
{
    memset(o, 0, sizeof *o);
    /* argv[2] is the benchmark's name, checked by the caller. */
    for (int i = 3; i < argc; i++) {
        const char *arg = argv[i];
        uint64_t value = 0;
        int status = CLI_CONTINUE;
        if (strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0) {
            print_usage();
            return CLI_EXIT_OK;
        } else if (coavoid_cli_option_is(arg, "--vehicles")) {
            status = coavoid_cli_count_option(argc, argv, &i, "--vehicles", NULL, false,
                                              BENCH_MAX_VEHICLES, &o->vehicles_text, &value);
            o->vehicles = (uint32_t)value;
        } else if (coavoid_cli_option_is(arg, "--horizon")) {
            status = coavoid_cli_count_option(argc, argv, &i, "--horizon", NULL, false,
                                              COA_MAX_HORIZON, &o->horizon_text, &value);
            o->horizon = (uint32_t)value;
        } else if (coavoid_cli_option_is(arg, "--seed")) {
            status = coavoid_cli_count_option(argc, argv, &i, "--seed", NULL, true, UINT64_MAX,
                                              &o->seed_text, &value);
            o->seed = value;
        } else if (coavoid_cli_option_is(arg, "--repeat")) {
            status = coavoid_cli_count_option(argc, argv, &i, "--repeat", NULL, false,
                                              BENCH_MAX_REPEAT, &o->repeat_text, &value);
            o->repeat = (uint32_t)value;
        } else if (coavoid_cli_option_is(arg, "--side-km")) {
            status = coavoid_cli_text_option(argc, argv, &i, "--side-km", "km, > 0", true,
                                             &o->side_text);
            if (status == CLI_CONTINUE && (!coavoid_cli_parse_real(o->side_text, &o->side_km) ||
                                           !(o->side_km > 0) || o->side_km > BENCH_MAX_SIDE_KM)) {
                return coavoid_cli_fail(CLI_EXIT_INVALID,
                                        "--side-km: must be a number with 0 < L <= %g, got '%.40s'",
                                        BENCH_MAX_SIDE_KM, o->side_text);
            }
        } else if (coavoid_cli_option_is(arg, "--all-pairs")) {
            status = coavoid_cli_flag_option(arg, "--all-pairs", &o->all_pairs);
        } else if (coavoid_cli_option_is(arg, "--json")) {
            status = coavoid_cli_flag_option(arg, "--json", &o->json);
        } else {
            return coavoid_cli_fail(
                CLI_EXIT_INVALID,
                "bench predict: unexpected argument '%.40s' (see 'coavoid bench "
                "predict --help')",
                arg);
        }
        if (status != CLI_CONTINUE) {
            return status;
        }
    }
    if (o->vehicles_text == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--vehicles: required (the number of UAVs, 1..%u)",
                                BENCH_MAX_VEHICLES);
    }
    if (o->horizon_text == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--horizon: required (steps to predict, 1..%u)",
                                COA_MAX_HORIZON);
    }
    if (o->seed_text == NULL) {
        o->seed = BENCH_DEFAULT_SEED;
    }
    if (o->repeat_text == NULL) {
        o->repeat = BENCH_DEFAULT_REPEAT;
    }
    if (o->side_text == NULL) {
        o->side_km = sqrt((double)o->vehicles / BENCH_DENSITY_PER_KM2);
    }
    return CLI_CONTINUE;
}

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

static void random_route(prng_t *r, double side, route_t *route)
{
    uint32_t layer = prng_below(r, BENCH_LAYER_COUNT);
    double heading = prng_uniform(r, 0.0, 2.0 * BENCH_PI);
    route->legs = 2u + prng_below(r, 2u);
    route->x[0] = prng_uniform(r, 0.0, side);
    route->y[0] = prng_uniform(r, 0.0, side);
    route->z[0] = BENCH_LAYERS[layer];
    bool changes_layer = prng_below(r, 5u) == 0;
    for (uint32_t j = 0; j < route->legs; j++) {
        double length = prng_uniform(r, 300.0, 1200.0);
        if (j > 0) {
            heading += prng_uniform(r, -0.5 * BENCH_PI, 0.5 * BENCH_PI);
        }
        if (j == 1 && changes_layer) {
            bool up = layer == 0 || (layer + 1u < BENCH_LAYER_COUNT && prng_below(r, 2u) == 0);
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
    return (size_t)ceil((double)horizon * BENCH_DT / step) + 2u;
}

/* Builds the airspace. Returns CLI_CONTINUE or the exit status after the message. */
static int build_airspace(const bench_options_t *o, airspace_t *a)
{
    memset(a, 0, sizeof *a);
    a->vehicles = o->vehicles;
    a->track_count = o->vehicles / BENCH_TRACKS_PER_VEHICLE;
    a->side_m = o->side_km * 1000.0;
    /* The worst case (every plan at the finest step) bounds the samples. */
    size_t per_plan = plan_samples(o->horizon, BENCH_STEPS[0]);
    size_t bytes_per_plan = per_plan * sizeof(coa_vec3_t);
    if (bytes_per_plan > BENCH_MAX_SAMPLE_BYTES / o->vehicles) {
        return coavoid_cli_fail(
            CLI_EXIT_INVALID,
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
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--vehicles, --horizon: out of memory for the plans");
    }

    prng_t r = {o->seed};
    size_t used = 0;
    for (uint32_t i = 0; i < o->vehicles; i++) {
        route_t route;
        random_route(&r, a->side_m, &route);
        double speed = prng_uniform(&r, 8.0, 20.0);
        double step = BENCH_STEPS[prng_below(&r, 3u)];
        double t0 = -prng_uniform(&r, 0.0, 1.0) * step;
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
        double speed = prng_uniform(&r, 20.0, 50.0);
        double heading = prng_uniform(&r, 0.0, 2.0 * BENCH_PI);
        t->id = j + 1u;
        t->volume.radius = (coa_real_t)30.0;
        t->volume.half_height = (coa_real_t)10.0;
        t->position.x = (coa_real_t)prng_uniform(&r, 0.0, a->side_m);
        t->position.y = (coa_real_t)prng_uniform(&r, 0.0, a->side_m);
        t->position.z = (coa_real_t)prng_uniform(&r, 50.0, 200.0);
        t->velocity.x = (coa_real_t)(speed * cos(heading));
        t->velocity.y = (coa_real_t)(speed * sin(heading));
        t->velocity.z = (coa_real_t)prng_uniform(&r, -1.0, 1.0);
        t->sigma_horizontal = (coa_real_t)prng_uniform(&r, 5.0, 25.0);
        t->sigma_vertical = (coa_real_t)prng_uniform(&r, 2.0, 8.0);
    }
    return CLI_CONTINUE;
}

/* ---- the run ---- */

typedef struct {
    double median_ms, min_ms, max_ms;
    coa_predict_result_t result;
    size_t workspace_bytes;
    size_t max_pairs;
} bench_result_t;

typedef struct {
    void *workspace;
    coa_predictor_t *predictor;
    size_t size;
    size_t max_pairs;
    coa_conflict_t *conflicts;
    size_t capacity;
} bench_memory_t;

/* (Re)builds the predictor for max_pairs. Returns CLI_CONTINUE or the exit status. */
static int size_predictor(const airspace_t *a, uint32_t horizon, bench_memory_t *m)
{
    free(m->workspace);
    m->workspace = NULL;
    m->size = coa_predictor_workspace_size(a->vehicles, a->track_count, horizon, m->max_pairs);
    if (m->size == 0 || m->size > BENCH_MAX_WORKSPACE_BYTES) {
        return coavoid_cli_fail(
            CLI_EXIT_INVALID,
            "--vehicles, --horizon: the predictor's workspace for %zu candidate "
            "pairs would exceed the benchmark's %zu MiB",
            m->max_pairs, BENCH_MAX_WORKSPACE_BYTES >> 20);
    }
    m->workspace = malloc(m->size);
    if (m->workspace == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "--vehicles, --horizon: out of memory for %zu bytes of workspace",
                                m->size);
    }
    m->predictor = coa_predictor_init(m->workspace, m->size, a->vehicles, a->track_count, horizon,
                                      m->max_pairs);
    if (m->predictor == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL,
                                "internal error: the predictor refused its workspace");
    }
    return CLI_CONTINUE;
}

static int predict_once(const airspace_t *a, const coa_predict_config_t *config, bench_memory_t *m,
                        coa_predict_result_t *result)
{
    memset(result, 0, sizeof *result);
    return coa_predict(m->predictor, config, a->plans, a->vehicles, NULL, 0, a->tracks,
                       a->track_count, m->conflicts, m->capacity, result);
}

/* The untimed first cycle: grows the pair set and the conflict array until the cycle
 * fits. Returns CLI_CONTINUE or the exit status. */
static int first_cycle(const airspace_t *a, const coa_predict_config_t *config, bench_memory_t *m,
                       coa_predict_result_t *result)
{
    for (;;) {
        int rc = predict_once(a, config, m, result);
        if (rc == COA_ERR_WORKSPACE && m->max_pairs <= SIZE_MAX / 2u) {
            m->max_pairs *= 2u;
            int status = size_predictor(a, config->horizon, m);
            if (status != CLI_CONTINUE) {
                return status;
            }
            continue;
        }
        if (rc != COA_OK) {
            return coavoid_cli_fail(CLI_EXIT_INTERNAL, "internal error: the predictor failed (%s)",
                                    coa_status_name(rc));
        }
        if (!result->overflow) {
            return CLI_CONTINUE;
        }
        free(m->conflicts);
        m->capacity = result->conflicts_found;
        m->conflicts = calloc(m->capacity, sizeof *m->conflicts);
        if (m->conflicts == NULL) {
            return coavoid_cli_fail(CLI_EXIT_INVALID, "--vehicles: out of memory for %zu conflicts",
                                    m->capacity);
        }
    }
}

static int run(const bench_options_t *o, const airspace_t *a, bench_result_t *out)
{
    coa_predict_config_t config;
    memset(&config, 0, sizeof config);
    config.t0 = 0;
    config.dt = (coa_real_t)BENCH_DT;
    config.horizon = o->horizon;
    config.track_sigma_rate_horizontal = (coa_real_t)BENCH_TRACK_GROWTH_HORIZONTAL;
    config.track_sigma_rate_vertical = (coa_real_t)BENCH_TRACK_GROWTH_VERTICAL;
    config.threshold = BENCH_THRESHOLD;
    config.all_pairs = o->all_pairs;

    bench_memory_t m;
    memset(&m, 0, sizeof m);
    /* A first guess a few times the UAVs: sparse traffic has a few neighbours each. */
    m.max_pairs = 4u * ((size_t)a->vehicles + a->track_count) + 64u;
    m.capacity = 1024u;
    m.conflicts = calloc(m.capacity, sizeof *m.conflicts);
    double *times = calloc(o->repeat, sizeof *times);
    int status = CLI_CONTINUE;
    if (m.conflicts == NULL || times == NULL) {
        status = coavoid_cli_fail(CLI_EXIT_INVALID, "--repeat: out of memory");
    }
    if (status == CLI_CONTINUE) {
        status = size_predictor(a, o->horizon, &m);
    }
    coa_predict_result_t first;
    if (status == CLI_CONTINUE) {
        status = first_cycle(a, &config, &m, &first);
    }
    for (uint32_t k = 0; status == CLI_CONTINUE && k < o->repeat; k++) {
        coa_predict_result_t result;
        struct timespec start, end;
        clock_gettime(CLOCK_MONOTONIC, &start);
        int rc = predict_once(a, &config, &m, &result);
        clock_gettime(CLOCK_MONOTONIC, &end);
        times[k] = bench_elapsed_ms(&start, &end);
        /* The same input must give the same answer every cycle. */
        if (rc != COA_OK || result.overflow || result.pair_tests != first.pair_tests ||
            result.candidate_pairs != first.candidate_pairs ||
            result.conflicts_found != first.conflicts_found) {
            status = coavoid_cli_fail(CLI_EXIT_INTERNAL,
                                      "internal error: cycle %lu differs from the first (%s)",
                                      (unsigned long)k + 1u, coa_status_name(rc));
        }
    }
    if (status == CLI_CONTINUE) {
        bench_summarise(times, o->repeat, &out->median_ms, &out->min_ms, &out->max_ms);
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

static int report(FILE *f, const bench_options_t *o, const airspace_t *a, const bench_result_t *b)
{
    const double all_pairs = (double)a->vehicles * ((double)a->vehicles - 1.0) / 2.0;
    const coa_predict_result_t *r = &b->result;
    struct {
        const char *key;
        double value;
        int decimals;
    } rows[] = {
        {"vehicles", a->vehicles, 0},
        {"tracks", a->track_count, 0},
        {"horizon", o->horizon, 0},
        {"dt_s", BENCH_DT, 3},
        {"seed", (double)o->seed, 0},
        {"repeat", o->repeat, 0},
        {"side_m", a->side_m, 1},
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
    if (!o->json) {
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

static int bench_predict(int argc, char **argv)
{
    bench_options_t options;
    int status = parse_bench_options(argc, argv, &options);
    if (status != CLI_CONTINUE) {
        return status;
    }
    airspace_t airspace;
    status = build_airspace(&options, &airspace);
    if (status != CLI_CONTINUE) {
        return status;
    }
    bench_result_t result;
    memset(&result, 0, sizeof result);
    status = run(&options, &airspace, &result);
    if (status == CLI_CONTINUE) {
        status = report(stdout, &options, &airspace, &result) == 0
                     ? CLI_EXIT_OK
                     : coavoid_cli_fail(CLI_EXIT_INTERNAL, "cannot write the result");
    }
    airspace_free(&airspace);
    return status;
}

int coavoid_command_bench(int argc, char **argv)
{
    if (argc < 3) {
        return coavoid_cli_fail(
            CLI_EXIT_INVALID,
            "bench: missing benchmark (predict or plan; see 'coavoid bench --help')");
    }
    const char *name = argv[2];
    if (strcmp(name, "-h") == 0 || strcmp(name, "--help") == 0) {
        /* Two benchmarks with their own options: name both, each one's help has the rest. */
        printf("usage: coavoid bench predict --vehicles N --horizon H [options]\n"
               "       coavoid bench plan [--vehicles N] [--count C] [options]\n"
               "\n"
               "  predict  times the conflict prediction cycle on a random airspace\n"
               "  plan     times the planner, centralised and decoupled, on the paper\n"
               "           scenario and random encounters\n"
               "\n"
               "Run 'coavoid bench predict --help' or 'coavoid bench plan --help' for the\n"
               "options. See docs/benchmarks.md.\n");
        return CLI_EXIT_OK;
    }
    if (strcmp(name, "predict") == 0) {
        return bench_predict(argc, argv);
    }
    if (strcmp(name, "plan") == 0) {
        return coavoid_bench_plan(argc, argv);
    }
    return coavoid_cli_fail(
        CLI_EXIT_INVALID,
        "bench: unknown benchmark '%.40s' (expected predict or plan; see 'coavoid bench "
        "--help')",
        name);
}
