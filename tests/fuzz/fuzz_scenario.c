/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness for the untrusted input of `coavoid plan`: scenario JSON text.
 *
 * Anything the parser accepts is sampled, checked by the core, planned both ways with a
 * small beta and predicted, so that every input the validation lets through also
 * exercises the geometry, the planner and the predictor under the sanitizers. A crash, a sanitizer report, a leak or an
 * accepted scenario that the core then rejects as an invalid argument is a finding.
 */
#include <stdint.h>
#include <stdlib.h>

#include "coavoid/coavoid.h"
#include "scenario.h"

#define FUZZ_BETA 40u
#define FUZZ_MAX_WORKSPACE ((size_t)64u << 20)

static void plan_both(const coa_problem_t *problem)
{
    const size_t n = problem->vehicle_count;
    int32_t *offsets = calloc(n * (problem->horizon + 1u), sizeof *offsets);
    if (offsets == NULL) {
        return;
    }
    coa_plan_result_t result;
    for (size_t m = 1; m <= 2; ++m) {
        const size_t searched = (m == 1) ? 1u : n;
        if (searched > 3u) {
            continue; /* joint searches of more: keep each fuzz run fast */
        }
        coa_planner_config_t config;
        size_t size = 0u;
        if (coa_planner_config_of(problem, searched, FUZZ_BETA, &config) == COA_OK) {
            size = coa_planner_workspace_size(&config);
        }
        if (size > FUZZ_MAX_WORKSPACE) {
            continue; /* tables of a long unbounded horizon: gigabytes, not a bug */
        }
        void *buffer =
            size ? aligned_alloc(COA_WORKSPACE_ALIGNMENT, (size + 7u) & ~(size_t)7u) : NULL;
        coa_planner_t *planner = buffer ? coa_planner_init(buffer, size, &config) : NULL;
        if (planner != NULL) {
            const int rc = (m == 1)
                               ? coa_plan_decoupled(planner, problem, NULL, 4u, offsets, &result)
                               : coa_plan_centralised(planner, problem, offsets, &result);
            if (rc == COA_ERR_ARGUMENT) {
                abort(); /* the app validated it: the core must accept it */
            }
        }
        free(buffer);
    }
    free(offsets);
}

/* One prediction cycle over every UAV at its reference and initial offset, as
 * `coavoid predict` runs it, with the pair set and the conflict array sized for every pair
 * so that only a bug can make it fail. */
static void predict_all(const coa_problem_t *problem)
{
    const size_t n = problem->vehicle_count;
    const size_t pairs =
        n * (n - 1u) / 2u + n * (problem->track_count + problem->obstacle_count) + 1u;
    const size_t size =
        coa_predictor_workspace_size(n, problem->track_count, problem->horizon, pairs);
    coa_intent_plan_t *plans = calloc(n, sizeof *plans);
    coa_vec3_t *samples = calloc(n * (problem->horizon + 1u), sizeof *samples);
    coa_conflict_t *conflicts = calloc(pairs, sizeof *conflicts);
    uint32_t *cluster = calloc(n, sizeof *cluster);
    void *buffer = size ? aligned_alloc(COA_WORKSPACE_ALIGNMENT, (size + 7u) & ~(size_t)7u) : NULL;
    coa_predictor_t *predictor =
        buffer ? coa_predictor_init(buffer, size, n, problem->track_count, problem->horizon, pairs)
               : NULL;
    if (plans != NULL && samples != NULL && conflicts != NULL && cluster != NULL &&
        predictor != NULL) {
        for (size_t i = 0; i < n; ++i) {
            const coa_vehicle_t *v = &problem->vehicles[i];
            const coa_real_t lift = (coa_real_t)v->initial_offset * coa_climb_step(v, problem->dt);
            for (uint32_t k = 0; k <= problem->horizon; ++k) {
                samples[i * (problem->horizon + 1u) + k] = problem->references[i][k];
                samples[i * (problem->horizon + 1u) + k].z += lift;
            }
            plans[i] = (coa_intent_plan_t){.id = v->id,
                                           .volume = v->volume,
                                           .step = problem->dt,
                                           .samples = &samples[i * (problem->horizon + 1u)],
                                           .count = problem->horizon + 1u};
        }
        const coa_predict_config_t config = {.dt = problem->dt,
                                             .horizon = problem->horizon,
                                             .track_sigma_rate_horizontal = 0.5,
                                             .track_sigma_rate_vertical = 0.5,
                                             .threshold = 0.01};
        coa_predict_result_t result;
        size_t clusters = 0;
        const int rc =
            coa_predict(predictor, &config, plans, n, problem->obstacles, problem->obstacle_count,
                        problem->tracks, problem->track_count, conflicts, pairs, &result);
        if (rc != COA_OK || result.overflow ||
            coa_predict_clusters(conflicts, result.conflict_count, n, cluster, &clusters) !=
                COA_OK) {
            abort(); /* sized for every pair and validated: the predictor must succeed */
        }
    }
    free(buffer);
    free(cluster);
    free(conflicts);
    free(samples);
    free(plans);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    coavoid_scenario_t s;
    char err[COAVOID_SCENARIO_ERROR_MAX];
    if (coavoid_scenario_parse((const char *)data, size, &s, err, sizeof err) == 0 &&
        s.horizon <= 64u && coavoid_scenario_sample(&s, err, sizeof err) == 0) {
        const coa_problem_t problem = coavoid_scenario_problem(&s);
        if (coa_problem_check(&problem) == COA_OK) {
            plan_both(&problem);
            predict_all(&problem);
        }
    }
    coavoid_scenario_free(&s);
    return 0;
}
