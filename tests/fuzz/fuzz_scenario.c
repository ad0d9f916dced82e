/*
 * libFuzzer harness for the untrusted input of `coavoid plan`: scenario JSON text.
 *
 * Anything the parser accepts is sampled, checked by the core and planned both ways with
 * a small beta, so that every input the validation lets through also exercises the
 * geometry and the planner under the sanitizers. A crash, a sanitizer report, a leak or an
 * accepted scenario that the core then rejects as an invalid argument is a finding.
 */
#include <stdint.h>
#include <stdlib.h>

#include "coavoid/coavoid.h"
#include "scenario.h"

#define FUZZ_BETA 40u

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
            continue; /* 5^n children a node: keep each fuzz run fast */
        }
        const size_t size = coa_planner_workspace_size(searched, FUZZ_BETA);
        void *buffer = size ? aligned_alloc(COA_WORKSPACE_ALIGNMENT, (size + 7u) & ~(size_t)7u) : NULL;
        coa_planner_t *planner = buffer ? coa_planner_init(buffer, size, searched, FUZZ_BETA) : NULL;
        if (planner != NULL) {
            const int rc = (m == 1) ? coa_plan_decoupled(planner, problem, NULL, 4u, offsets, &result)
                                    : coa_plan_centralised(planner, problem, offsets, &result);
            if (rc == COA_ERR_ARGUMENT) {
                abort(); /* the app validated it: the core must accept it */
            }
        }
        free(buffer);
    }
    free(offsets);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    scenario_t s;
    char err[SCENARIO_ERROR_MAX];
    if (scenario_parse((const char *)data, size, &s, err, sizeof err) == 0 &&
        s.horizon <= 64u && scenario_sample(&s, err, sizeof err) == 0) {
        const coa_problem_t problem = scenario_problem(&s);
        if (coa_problem_check(&problem) == COA_OK) {
            plan_both(&problem);
        }
    }
    scenario_free(&s);
    return 0;
}
