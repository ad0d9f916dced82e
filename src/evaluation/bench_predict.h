/* SPDX-License-Identifier: MIT */
/*
 * bench_predict.h: the harness of `coavoid bench predict`: times the core's prediction
 * cycle (coa_predict) on a random but realistic airspace (docs/benchmarks.md).
 *
 * The airspace. UAVs fly at the density of 1,000 UAVs over 10 km x 10 km (10 per km^2:
 * a busy city), so the square's side grows as sqrt(N) and the traffic each UAV meets stays
 * the same whatever N is: that is what a ground station covering a bigger area sees, and
 * it measures how the predictor scales rather than how crowded one square can get
 * (side_km fixes the square instead). They cruise at 8-20 m/s on four altitude layers
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
 * Everything comes from the seeded PRNG (prng.h), so a seed gives the same airspace on
 * every machine; only the times differ.
 *
 * What is timed: coa_predict alone (clock_gettime around the call), after one untimed
 * cycle that also sizes the workspace (max_pairs is doubled from a small guess until the
 * broad phase fits, so the pair set is as small as the traffic allows, as a deployment
 * would size it) and warms the caches. Every timed cycle must repeat the first's counts.
 */
#ifndef COAVOID_EVALUATION_BENCH_PREDICT_H
#define COAVOID_EVALUATION_BENCH_PREDICT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "coavoid/coavoid.h"
#include "coavoid/predict.h"
#include "run.h"

#define COAVOID_BENCH_PREDICT_MAX_VEHICLES 65535u /* UAV ids are 16-bit */
/* UAVs per km^2 when side_km is 0: 1,000 UAVs over 10 km x 10 km. */
#define COAVOID_BENCH_PREDICT_DENSITY_PER_KM2 10.0
#define COAVOID_BENCH_PREDICT_TRACKS_PER_VEHICLE 50u /* one track per this many UAVs */
#define COAVOID_BENCH_PREDICT_DT 1.0                 /* s per predicted step */
#define COAVOID_BENCH_PREDICT_THRESHOLD 0.01         /* conflict probability reported */

typedef struct {
    uint32_t vehicles; /* 1..COAVOID_BENCH_PREDICT_MAX_VEHICLES */
    uint32_t horizon;  /* steps predicted, 1..COA_MAX_HORIZON */
    uint64_t seed;
    uint32_t repeat; /* timed cycles, >= 1 */
    /* The square's side, km, > 0; 0: sized for COAVOID_BENCH_PREDICT_DENSITY_PER_KM2. */
    double side_km;
    bool all_pairs; /* skip the broad phase: every pair is tested (the reference) */
} coavoid_bench_predict_config_t;

typedef struct {
    uint32_t vehicles, tracks;
    double side_m;
    double median_ms, min_ms, max_ms; /* per cycle, over the timed cycles */
    coa_predict_result_t result;      /* the first cycle's counts, which every one repeats */
    size_t workspace_bytes;
    size_t max_pairs; /* the pair set the workspace was sized for */
} coavoid_bench_predict_result_t;

/* Builds the airspace and times the cycles. Returns COAVOID_RUN_DONE with *out filled,
 * or an error (evaluation.h, "Errors") with e set: COAVOID_RUN_ERR_INPUT when the plans
 * would pass 2 GiB or the predictor's workspace 8 GiB (before anything that size is
 * allocated: a benchmark should not page a machine to death) or memory is short,
 * COAVOID_RUN_ERR_INTERNAL when the predictor fails or a cycle differs from the first.
 * Memory: the plans (N x up to 2 H + 2 samples), the predictor's workspace and the
 * conflicts found, all freed before it returns. Cost: the sizing cycles and repeat + 1
 * cycles of coa_predict. */
int coavoid_bench_predict_run(const coavoid_bench_predict_config_t *config,
                              coavoid_bench_predict_result_t *out, coavoid_run_error_t *e);

/* Prints the config and the result on f, one "key: value" per line or, with json, a JSON
 * object (the keys of docs/benchmarks.md). Returns 0, or -1 when a write (or cJSON's
 * memory) failed. */
int coavoid_bench_predict_report(FILE *f, const coavoid_bench_predict_config_t *config,
                                 const coavoid_bench_predict_result_t *result, bool json);

#endif /* COAVOID_EVALUATION_BENCH_PREDICT_H */
