/* SPDX-License-Identifier: MIT */
/*
 * task.c: one UAV's collision-avoidance task (see firmware.h and docs/embedded.md). Plain
 * C on the core, nothing board-specific (that is main.c and startup.c).
 *
 * A cycle: our intent is our reference plus the plan in force; the predictor looks at it
 * together with the neighbours' intents and the tracks; when a conflict of ours is
 * predicted, we plan our own altitude offsets over the next N steps around the intents of
 * every higher-priority neighbour (fixed, as moving obstacles) and the tracks. Lower-
 * priority neighbours plan around us in their own cycles: the decoupled scheme, each UAV
 * solving a single-vehicle search, so the planner's workspace is sized for n = 1.
 */
#include <ccd/config.h>

#include "firmware.h"

#ifndef CCD_SINGLE
#error "the firmware needs libccd's single-precision build (cmake/libccd_arm.cmake)"
#endif
#ifndef COA_SINGLE_PRECISION
#error "the firmware needs the core in single precision (COA_SINGLE_PRECISION)"
#endif

/* The workspaces: static, aligned as the core asks. */
static _Alignas(COA_WORKSPACE_ALIGNMENT) unsigned char planner_buffer[FW_PLANNER_BYTES];
static _Alignas(COA_WORKSPACE_ALIGNMENT) unsigned char predictor_buffer[FW_PREDICTOR_BYTES];
static coa_planner_t *planner;
static coa_predictor_t *predictor;

fw_inputs_t fw_inputs;
fw_outputs_t fw_outputs;

/* Our airframe. The route and the current offset come from fw_inputs each cycle. */
static const coa_vehicle_t self_template = {
    .id = 7u,
    .priority = 2u,
    .cruise_speed = 20.0f,
    .climb_rate = 5.0f,
    .steep_factor = 2u,
    .volume = {.radius = 50.0f, .half_height = 15.0f},
    .route = NULL,
    .route_count = 0u,
    .initial_offset = 0,
    .max_offset = 40,
};

/* Per-cycle scratch, static so that the stack stays small. */
static coa_vec3_t reference[FW_SAMPLES];
static coa_intent_plan_t plans[FW_PLANS];
static coa_conflict_t conflicts[FW_MAX_CONFLICTS];
static coa_track_point_t paths[FW_NEIGHBOURS][FW_SAMPLES];
static coa_track_t obstacles[FW_NEIGHBOURS + FW_TRACKS];
static coa_vec3_t obstacle_samples[FW_NEIGHBOURS + FW_TRACKS][FW_SAMPLES];
static const coa_vec3_t *obstacle_rows[FW_NEIGHBOURS + FW_TRACKS];
static int32_t new_offsets[FW_SAMPLES];

int fw_task_init(void)
{
    coa_planner_config_t config = {.vehicles = 1u,
                                   .horizon = FW_HORIZON,
                                   .steep_factor = self_template.steep_factor,
                                   .max_offset = self_template.max_offset};
    uint32_t k;

    config.beta = coa_planner_max_beta(&config, sizeof planner_buffer);
    planner = coa_planner_init(planner_buffer, sizeof planner_buffer, &config);
    predictor = coa_predictor_init(predictor_buffer, sizeof predictor_buffer, FW_PLANS, FW_TRACKS,
                                   FW_HORIZON, FW_MAX_PAIRS);
    if (planner == NULL || predictor == NULL) {
        return COA_ERR_WORKSPACE;
    }
    fw_outputs.beta = config.beta;
    for (k = 0; k < FW_SAMPLES; ++k) {
        fw_outputs.offsets[k] = 0;
    }
    return COA_OK;
}

static bool outranks(const fw_intent_t *n, const coa_vehicle_t *self)
{
    return n->priority < self->priority || (n->priority == self->priority && n->id < self->id);
}

static fw_status_t finish(fw_status_t status, int error)
{
    fw_outputs.status = status;
    fw_outputs.error = error;
    fw_outputs.altitude_setpoint = fw_outputs.intent[1].z;
    return status;
}

static void write_intent(coa_real_t dh)
{
    uint32_t k;
    for (k = 0; k < FW_SAMPLES; ++k) {
        fw_outputs.intent[k] = reference[k];
        fw_outputs.intent[k].z += (coa_real_t)fw_outputs.offsets[k] * dh;
    }
}

/* Everything that must not be flown into: the higher-priority neighbours' intents as
 * tracks along their samples (times relative to now), then the tracks. */
static int collect_obstacles(const coa_vehicle_t *self, coa_real_t now, size_t *count)
{
    size_t m = 0;
    uint32_t i;
    uint32_t j;
    int rc;

    for (i = 0; i < FW_NEIGHBOURS; ++i) {
        const fw_intent_t *n = &fw_inputs.neighbours[i];
        if (!n->valid || !outranks(n, self) || n->count == 0u || n->count > FW_SAMPLES) {
            continue;
        }
        for (j = 0; j < n->count; ++j) {
            paths[m][j].t = n->t0 - now + (coa_real_t)j * n->step;
            paths[m][j].p = n->samples[j];
        }
        obstacles[m] = (coa_track_t){
            .id = n->id, .volume = n->volume, .path = paths[m], .path_count = n->count};
        ++m;
    }
    for (i = 0; i < fw_inputs.track_count && i < FW_TRACKS; ++i) {
        obstacles[m++] = fw_inputs.tracks[i];
    }
    for (j = 0; j < m; ++j) {
        rc = coa_track_sample(&obstacles[j], FW_DT, FW_HORIZON, obstacle_samples[j]);
        if (rc < 0) {
            return rc;
        }
        obstacle_rows[j] = obstacle_samples[j];
    }
    *count = m;
    return COA_OK;
}

/* 1. Prediction: our intent (plan 0) with the neighbours' and the tracks. */
static int predict_own(const coa_vehicle_t *self, coa_real_t now, coa_predict_result_t *predicted)
{
    coa_predict_config_t config = {
        .t0 = 0.0f, /* the predictor's clock is relative to now: floats stay small */
        .dt = FW_DT,
        .horizon = FW_HORIZON,
        .vehicle_sigma_rate_horizontal = 0.5f,
        .vehicle_sigma_rate_vertical = 0.2f,
        .track_sigma_rate_horizontal = 2.0f,
        .track_sigma_rate_vertical = 1.0f,
        .threshold = 1e-3,
        .all_pairs = false,
    };
    size_t n = 1;
    plans[0] = (coa_intent_plan_t){.id = self->id,
                                   .volume = self->volume,
                                   .t0 = 0.0f,
                                   .step = FW_DT,
                                   .samples = fw_outputs.intent,
                                   .count = FW_SAMPLES,
                                   .sigma_horizontal = 5.0f,
                                   .sigma_vertical = 2.0f};
    for (uint32_t i = 0; i < FW_NEIGHBOURS; ++i) {
        const fw_intent_t *nb = &fw_inputs.neighbours[i];
        if (nb->valid) {
            plans[n++] = (coa_intent_plan_t){.id = nb->id,
                                             .volume = nb->volume,
                                             .t0 = nb->t0 - now,
                                             .step = nb->step,
                                             .samples = nb->samples,
                                             .count = nb->count,
                                             .sigma_horizontal = 5.0f,
                                             .sigma_vertical = 2.0f};
        }
    }
    return coa_predict(predictor, &config, plans, n, NULL, 0u, fw_inputs.tracks,
                       fw_inputs.track_count, conflicts, FW_MAX_CONFLICTS, predicted);
}

/* Whether a predicted conflict is ours to solve (and counts ours). Plan 0 is always `a`. A
 * conflict with a lower-priority neighbour is its to solve; with a higher-priority one or
 * a track, ours. */
static bool ours_to_solve(const coa_vehicle_t *self, const coa_predict_result_t *predicted)
{
    bool replan = false;
    fw_outputs.conflicts = 0u;
    for (size_t c = 0; c < predicted->conflict_count; ++c) {
        const coa_conflict_t *cf = &conflicts[c];
        if (cf->a != 0u) {
            continue;
        }
        ++fw_outputs.conflicts;
        if (cf->kind != COA_CONFLICT_VEHICLE) {
            replan = true;
            continue;
        }
        for (uint32_t i = 0; i < FW_NEIGHBOURS; ++i) {
            const fw_intent_t *nb = &fw_inputs.neighbours[i];
            if (nb->valid && nb->id == plans[cf->b].id && outranks(nb, self)) {
                replan = true;
            }
        }
    }
    return replan;
}

/* 2. Planning: our offsets around what outranks us, at most beta expansions. */
static fw_status_t plan_own(coa_vehicle_t *self, coa_real_t now, coa_real_t dh)
{
    const coa_vec3_t *reference_rows[1] = {reference};
    coa_problem_t problem;
    size_t m = 0;
    int rc = collect_obstacles(self, now, &m);
    if (rc < 0) {
        return finish(FW_ERROR, rc);
    }
    problem = (coa_problem_t){.dt = FW_DT,
                              .horizon = FW_HORIZON,
                              .vehicles = self,
                              .vehicle_count = 1u,
                              .references = reference_rows,
                              .obstacles = NULL,
                              .obstacle_count = 0u,
                              .tracks = obstacles,
                              .track_count = m,
                              .track_samples = obstacle_rows};
    rc = coa_plan_decoupled(planner, &problem, NULL, 1u, new_offsets, &fw_outputs.plan);
    if (rc < 0) {
        return finish(FW_ERROR, rc);
    }
    if (fw_outputs.plan.status != COA_PLAN_SOLVED) {
        /* Budget exhausted or infeasible: the plan in force stays (it is what the
         * neighbours were told) and the autopilot's failsafe decides. */
        return finish(FW_NO_PLAN, COA_OK);
    }
    for (uint32_t k = 0; k < FW_SAMPLES; ++k) {
        fw_outputs.offsets[k] = new_offsets[k];
    }
    write_intent(dh);
    return finish(FW_REPLANNED, COA_OK);
}

fw_status_t fw_task_cycle(coa_real_t now)
{
    coa_vehicle_t self = self_template;
    coa_predict_result_t predicted;
    coa_real_t dh;
    int rc;

    self.route = fw_inputs.route;
    self.route_count = fw_inputs.route_count;
    self.initial_offset = fw_inputs.offset;
    rc = coa_reference_sample(&self, FW_DT, FW_HORIZON, reference);
    if (rc < 0) {
        return finish(FW_ERROR, rc);
    }
    dh = coa_climb_step(&self, FW_DT);
    /* The plan in force, moved on by the step flown since the last cycle, from the offset
     * we are actually at. */
    for (uint32_t k = 0; k + 1u < FW_SAMPLES; ++k) {
        fw_outputs.offsets[k] = fw_outputs.offsets[k + 1u];
    }
    fw_outputs.offsets[0] = fw_inputs.offset;
    write_intent(dh);
    rc = predict_own(&self, now, &predicted);
    if (rc < 0) {
        return finish(FW_ERROR, rc);
    }
    /* An overflowing list may hide one of ours: replan to be safe. */
    if (!ours_to_solve(&self, &predicted) && !predicted.overflow) {
        return finish(FW_CLEAR, COA_OK);
    }
    return plan_own(&self, now, dh);
}

void fw_example_inputs(void)
{
    static const coa_vec3_t route[2] = {{0.0f, 0.0f, 100.0f}, {4000.0f, 0.0f, 100.0f}};
    fw_intent_t *ahead = &fw_inputs.neighbours[0];
    fw_intent_t *behind = &fw_inputs.neighbours[1];
    uint32_t k;

    fw_inputs.route[0] = route[0];
    fw_inputs.route[1] = route[1];
    fw_inputs.route_count = 2u;
    fw_inputs.offset = 0;
    /* Head-on at our altitude, 600 m ahead, priority 1: we must give way. */
    *ahead = (fw_intent_t){.valid = true,
                           .id = 3u,
                           .priority = 1u,
                           .volume = {.radius = 50.0f, .half_height = 15.0f},
                           .t0 = 0.0f,
                           .step = FW_DT,
                           .count = FW_SAMPLES};
    /* Crossing 1.5 km behind us, priority 5: its problem, not ours. */
    *behind = (fw_intent_t){.valid = true,
                            .id = 9u,
                            .priority = 5u,
                            .volume = {.radius = 50.0f, .half_height = 15.0f},
                            .t0 = 0.0f,
                            .step = FW_DT,
                            .count = FW_SAMPLES};
    for (k = 0; k < FW_SAMPLES; ++k) {
        ahead->samples[k] = (coa_vec3_t){600.0f - 20.0f * (coa_real_t)k, 0.0f, 100.0f};
        behind->samples[k] = (coa_vec3_t){-1500.0f, -300.0f + 20.0f * (coa_real_t)k, 100.0f};
    }
    fw_inputs.tracks[0] = (coa_track_t){.id = 100u,
                                        .volume = {.radius = 150.0f, .half_height = 60.0f},
                                        .position = {3000.0f, 3000.0f, 400.0f},
                                        .velocity = {-30.0f, 0.0f, 0.0f},
                                        .sigma_horizontal = 20.0f,
                                        .sigma_vertical = 10.0f};
    fw_inputs.track_count = 1u;
}
