/* SPDX-License-Identifier: MIT */
/*
 * judge.h: a closed-loop run of a scenario as a flight record (flight.h), judged. What
 * `coavoid sim` (from its nodes' states) and `coavoid summary` (from a log's intents) both
 * do with the samples they gathered, so that the two judge a run alike.
 */
#ifndef COAVOID_FLIGHT_JUDGE_H
#define COAVOID_FLIGHT_JUDGE_H

#include <stdbool.h>
#include <stdint.h>

#include "flight.h"
#include "scenario.h"

typedef struct {
    coavoid_flight_t flight;
    coavoid_flight_eval_t eval;
    coavoid_flight_vehicle_t vehicles[COA_MAX_VEHICLES];
    double vehicle_deviation[COA_MAX_VEHICLES];
    uint32_t vehicle_effort[COA_MAX_VEHICLES];
} coavoid_judged_t;

/* Records scenario s flown in `mode` over samples 0..steps, with `replans` planning calls,
 * in j->flight: UAV i (the scenario's order) flew row i of reference and offsets (n rows
 * of steps + 1), known as row i of `known` (NULL: every sample known); then evaluates it
 * into j->eval. Returns coavoid_flight_evaluate's status (COA_ERR_ARGUMENT also for more than
 * COA_MAX_VEHICLES UAVs). The record points into j, s and the arrays, which must outlive
 * it and not move. Cost: coavoid_flight_evaluate's; no memory beyond its scratch. */
int coavoid_judge_run(coavoid_judged_t *j, const coavoid_scenario_t *s, const char *mode,
                      uint32_t steps, uint32_t replans, coa_vec3_t *reference, int32_t *offsets,
                      bool *known);

#endif /* COAVOID_FLIGHT_JUDGE_H */
