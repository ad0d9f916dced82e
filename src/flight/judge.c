/* SPDX-License-Identifier: MIT */
/*
 * judge.c: a scenario's closed-loop run as a flight record, judged (judge.h).
 */
#include "judge.h"

#include <string.h>

int coavoid_judge_run(coavoid_judged_t *j, const coavoid_scenario_t *s, const char *mode,
                      uint32_t steps, uint32_t replans, coa_vec3_t *reference, int32_t *offsets,
                      bool *known)
{
    const size_t n = s->vehicle_count;
    const size_t row = (size_t)steps + 1u;
    memset(j, 0, sizeof *j);
    if (n > COA_MAX_VEHICLES) {
        return COA_ERR_ARGUMENT;
    }
    for (size_t i = 0; i < n; i++) {
        j->vehicles[i].vehicle = s->vehicles[i];
        j->vehicles[i].reference = reference + i * row;
        j->vehicles[i].offsets = offsets + i * row;
        j->vehicles[i].known = known != NULL ? known + i * row : NULL;
    }
    j->flight.scenario = s->name;
    j->flight.mode = mode;
    j->flight.dt = s->dt;
    j->flight.steps = steps;
    j->flight.vehicles = j->vehicles;
    j->flight.vehicle_count = n;
    j->flight.obstacles = s->obstacles;
    j->flight.obstacle_count = s->obstacle_count;
    j->flight.tracks = s->tracks;
    j->flight.track_count = s->track_count;
    j->flight.replans = replans;
    j->eval.vehicle_deviation = j->vehicle_deviation;
    j->eval.vehicle_effort = j->vehicle_effort;
    return coavoid_flight_evaluate(&j->flight, &j->eval);
}
