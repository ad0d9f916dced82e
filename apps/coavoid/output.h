/*
 * output.h: the plan result object of SCENARIO_FORMAT.md ("Plan result"), printed as JSON.
 */
#ifndef COAVOID_APP_OUTPUT_H
#define COAVOID_APP_OUTPUT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "coavoid/coavoid.h"
#include "scenario.h"

typedef struct {
    const scenario_t *scenario;
    bool decoupled;                  /* mode: decoupled, else centralised */
    const coa_plan_result_t *result;
    const int32_t *offsets;          /* vehicle_count rows of horizon+1, row i is vehicle i */
    int64_t time_us;                 /* wall time of the planning call */
    uint32_t beta;                   /* the closed-set bound the planner ran with */
} output_plan_t;

/* Writes the result object (and a newline) to `out`. Returns 0, or -1 with the reason in
 * err: out of memory, a write error, or a result the core should never produce (a step
 * that is no action, a failed vehicle index out of range). */
int output_plan(FILE *out, const output_plan_t *plan, char *err, size_t err_size);

/* The contract's name of a plan status ("solved", "infeasible", "budget_exhausted"). */
const char *output_status_name(coa_plan_status_t status);

#endif /* COAVOID_APP_OUTPUT_H */
