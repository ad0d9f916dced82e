/* SPDX-License-Identifier: MIT */
/*
 * sim.c: the one-process closed loop of sim.h. The nodes handle each message as soon as
 * it is published (LCM's memq provider, drained after every step of a node), as on a
 * quiet network, and the clock jumps from deadline to deadline.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <lcm/lcm.h>

#include "flight.h"
#include "judge.h"
#include "net.h"
#include "node.h"
#include "sim.h"
#include "record.h"
#include "sim_internal.h"

/* Cycle 0's utime: a fixed constant (2001-09-09), never the wall clock, so that every
 * run stamps its messages alike and prints the same result. */
#define SIM_EPOCH_UTIME INT64_C(1000000000000000)

/* The nodes' numbers on the network (net.h): the world, the coordinator, then the UAVs in
 * priority order. */
#define SIM_NET_WORLD 0u
#define SIM_NET_COORDINATOR 1u
#define SIM_NET_VEHICLE(j) (2u + (j))
/* Messages a node publishes in a cycle at most, for the network's queue: a UAV its
 * intent and heartbeat with their copies, and its answers on plans (each answer again
 * when a plan comes again, every resend_us: dt/20); the coordinator its report, heartbeat
 * and copies, and the rows of at most three plans per UAV (its clusters', the regrouped
 * one's, the whole fleet's) or their abandonment, each sent again while unanswered, and
 * its commits (32 per UAV + 32, with margin); the world every tile and track. More would
 * be a queue overflow: an error of the run, never a loss. */
#define SIM_NET_VEHICLE_MESSAGES 32u
/* A run's own memo of failed joint searches (a group fails a problem or two a cycle). */
#define SIM_JOINT_MEMO_KEYS 256u
#define SIM_NET_COORDINATOR_MESSAGES(n) (32u * (n) + 32u)
typedef struct {
    /* The run's parameters (sim_check, sim_planner_sizes). */
    const coavoid_sim_config_t *o;
    coavoid_run_error_t *err;
    FILE *out;
    const coavoid_scenario_t *s;
    const char *file;
    size_t n;       /* UAVs */
    uint32_t steps; /* samples 0..steps are flown */
    size_t samples; /* steps + 1 */
    int64_t now;    /* the nodes' clock (common.clock points here) */
    coavoid_node_common_t common;
    int64_t collect_us; /* the coordinator plans this long after each cycle start */
    uint32_t vehicle_beta;
    uint32_t coordinator_beta;
    size_t max_centralised;
    uint32_t coordinator_plans; /* plans the coordinator ran, when it stopped or at the end */
    coavoid_coordinator_state_t coordinator_final; /* its state then */
    uint64_t coordinator_sent; /* its messages out at the start of the cycle (config's record) */
    uint32_t stop_cycle_sent;  /* --coordinator-stops: its messages out in the cycle it stopped */
    bool replaying;            /* config's tape replayed in the coordinator's place */
    /* The vehicles' memo of failed joint searches when config has none. */
    coavoid_node_joint_memo_t own_memo;
    uint64_t own_keys[SIM_JOINT_MEMO_KEYS];
    size_t coordinator_calls; /* its calls so far, recorded or replayed */
    /* What the run holds (sim_run_free releases it). */
    coavoid_sim_net_t *net;
    int net_error; /* the network's first error (coavoid_sim_net_pump) */
    coavoid_world_t *world;
    coavoid_coordinator_t *coordinator;
    coavoid_vehicle_node_t **vehicles; /* in priority order: the order they run in */
    size_t *index;                     /* index[j]: scenario index of vehicles[j] */
    coa_vec3_t *references;            /* by scenario index, rows of K + 1 */
    int32_t *offsets;
    coa_track_t *tracks; /* the world's copy when the scenario's ids do not fit */
    coavoid_judged_t judged;
    FILE *svg;
    /* The fleet's keys (sim_keys): every node trusts every key; signers by key, the
     * coordinator's, the world's, then each UAV's in scenario order. */
    coavoid_auth_trust_t trust;
    coavoid_auth_signer_t *signers;
    /* With record_path: the record of one UAV, vehicles[recorded] (n: none). */
    coavoid_sim_record_t record;
    size_t recorded;
} sim_run_t;

static void sim_run_free(sim_run_t *r, size_t n)
{
    coavoid_coordinator_destroy(r->coordinator);
    if (r->vehicles != NULL) {
        for (size_t j = 0; j < n; j++) {
            coavoid_vehicle_node_destroy(r->vehicles[j]);
        }
    }
    coavoid_world_destroy(r->world);
    (void)coavoid_sim_record_close(&r->record);
    coavoid_sim_net_destroy(r->net);
    free(r->vehicles);
    free(r->index);
    free(r->references);
    free(r->offsets);
    free(r->tracks);
    if (r->signers != NULL) {
        for (size_t j = 0; j < n + 2u; j++) {
            coavoid_auth_signer_clear(&r->signers[j]);
        }
    }
    free(r->signers);
    if (r->svg != NULL) {
        fclose(r->svg);
    }
}

/* ---- what the messages can carry ----
 *
 * The nodes talk in messages whose numbers have bounds (coavoid_lcm.h, COAVOID_LCM_MAX_*) that
 * a scenario's do not: coavoid plan takes a radius of 1e300 m. A node that cannot publish
 * its intent, or a world that cannot publish a track, would stop the run as a failed node,
 * so the whole run is checked before it starts, and the field is named. "The whole run":
 * every sample a message of it carries, t_0 .. t_{K+N} (the intent of cycle K reaches N
 * samples beyond the last flown one), as the nodes compute them. */

#define SIM_INTENT "an intent"
#define SIM_TRACK "a track message"
#define SIM_MAP "an obstacle map"

static bool beyond(double x, double limit)
{
    return !isfinite(x) || fabs(x) > limit;
}

/* The first coordinate of p that is beyond COAVOID_LCM_MAX_COORDINATE, as 'x', 'y' or 'z'
 * with *value set; or 0. */
static char far_axis(coa_vec3_t p, double *value)
{
    const double c[3] = {(double)p.x, (double)p.y, (double)p.z};
    for (int a = 0; a < 3; a++) {
        if (beyond(c[a], COAVOID_LCM_MAX_COORDINATE)) {
            *value = c[a];
            return (char)('x' + a);
        }
    }
    return 0;
}

/* A vehicle's intents over samples 0..last: its volume, speeds and priority, and every
 * reference point and the positions and velocities its offsets can give there. An offset
 * at sample j is at most initial_offset + steep_factor * j climb steps from the reference
 * (and within max_offset), whatever is planned. */
/* Vehicle i's volume, speeds and priority within what an intent carries; *climb is the
 * vertical speed its largest change of offset in one step adds. */
static int check_vehicle_sizes(coavoid_run_error_t *err, const char *file, size_t i,
                               const coa_vehicle_t *v, double *climb)
{
    if (beyond((double)v->volume.radius, COAVOID_LCM_MAX_SIZE)) {
        return coavoid_run_fail(err, COAVOID_RUN_ERR_INPUT,
                                "%s: vehicles[%zu].radius: %g m is beyond what " SIM_INTENT
                                " carries (%g m)",
                                file, i, (double)v->volume.radius, COAVOID_LCM_MAX_SIZE);
    }
    if (beyond((double)v->volume.half_height, COAVOID_LCM_MAX_SIZE)) {
        return coavoid_run_fail(err, COAVOID_RUN_ERR_INPUT,
                                "%s: vehicles[%zu].half_height: %g m is beyond what " SIM_INTENT
                                " carries (%g m)",
                                file, i, (double)v->volume.half_height, COAVOID_LCM_MAX_SIZE);
    }
    if (beyond((double)v->cruise_speed, COAVOID_LCM_MAX_SPEED)) {
        return coavoid_run_fail(err, COAVOID_RUN_ERR_INPUT,
                                "%s: vehicles[%zu].cruise_speed: %g m/s is beyond what " SIM_INTENT
                                " carries (%g m/s)",
                                file, i, (double)v->cruise_speed, COAVOID_LCM_MAX_SPEED);
    }
    uint32_t max_change = v->steep_factor;
    if (v->max_offset >= 0 && (uint64_t)2u * (uint32_t)v->max_offset < max_change) {
        max_change = 2u * (uint32_t)v->max_offset;
    }
    *climb = (double)max_change * (double)v->climb_rate;
    if (beyond(*climb, COAVOID_LCM_MAX_SPEED)) {
        return coavoid_run_fail(err, COAVOID_RUN_ERR_INPUT,
                                "%s: vehicles[%zu].climb_rate: %g m/s, %g m/s in a steep climb, is "
                                "beyond what " SIM_INTENT " carries (%g m/s)",
                                file, i, (double)v->climb_rate, *climb, COAVOID_LCM_MAX_SPEED);
    }
    if (v->priority > (uint32_t)INT32_MAX) {
        return coavoid_run_fail(err, COAVOID_RUN_ERR_INPUT,
                                "%s: vehicles[%zu].priority: %lu is beyond what " SIM_INTENT
                                " carries (%ld)",
                                file, i, (unsigned long)v->priority, (long)INT32_MAX);
    }
    return SIM_GO_ON;
}

/* The step from sample `previous` to r (at t): the intent's velocity is that step, and
 * consecutive reference points must differ horizontally in the core's precision, as the
 * intent's check judges them (a route far out flown very slowly does not). */
static int check_vehicle_step(coavoid_run_error_t *err, const char *file, size_t i,
                              const coa_vehicle_t *v, coa_real_t dt, coa_real_t t,
                              coa_vec3_t previous, coa_vec3_t r, double climb)
{
    const double vx = (double)((r.x - previous.x) / dt);
    const double vy = (double)((r.y - previous.y) / dt);
    const double vz = fabs((double)((r.z - previous.z) / dt)) + climb;
    if (beyond(vx, COAVOID_LCM_MAX_SPEED) || beyond(vy, COAVOID_LCM_MAX_SPEED) ||
        beyond(vz, COAVOID_LCM_MAX_SPEED)) {
        return coavoid_run_fail(err, COAVOID_RUN_ERR_INPUT,
                                "%s: vehicles[%zu].route: its reference moves at (%g, %g) m/s "
                                "horizontally and %g m/s vertically with its steepest climb at t = "
                                "%g s, beyond what " SIM_INTENT " carries (%g m/s each)",
                                file, i, vx, vy, vz, (double)t, COAVOID_LCM_MAX_SPEED);
    }
    const coa_vec3_t leg[2] = {previous, r};
    coa_vehicle_t probe = *v;
    probe.route = leg;
    probe.route_count = 2u;
    probe.initial_offset = 0;
    if (coa_vehicle_check(&probe) != COA_OK) {
        return coavoid_run_fail(err, COAVOID_RUN_ERR_INPUT,
                                "%s: vehicles[%zu].cruise_speed: %g m/s moves it too little in a "
                                "step to tell its position at t = %g s from the one before "
                                "(%.10g, %.10g m), as " SIM_INTENT " must",
                                file, i, (double)v->cruise_speed, (double)t, (double)r.x,
                                (double)r.y);
    }
    return SIM_GO_ON;
}

static int check_vehicle_limits(coavoid_run_error_t *err, const char *file, size_t i,
                                const coa_vehicle_t *v, coa_real_t dt, uint64_t last)
{
    double climb = 0.0;
    int status = check_vehicle_sizes(err, file, i, v, &climb);
    if (status != SIM_GO_ON) {
        return status;
    }
    const double dh = (double)coa_climb_step(v, dt);
    const int64_t bound = v->max_offset >= 0 ? v->max_offset : COA_MAX_OFFSET;
    const int64_t initial =
        v->initial_offset < 0 ? -(int64_t)v->initial_offset : (int64_t)v->initial_offset;
    coa_vec3_t previous = coa_reference_at(v, (coa_real_t)0);
    for (uint64_t j = 0; j <= last; j++) {
        const coa_real_t t = (coa_real_t)j * dt;
        const coa_vec3_t r = j == 0u ? previous : coa_reference_at(v, t);
        double value = 0.0;
        char axis = far_axis(r, &value);
        if (axis != 0) {
            return coavoid_run_fail(
                err, COAVOID_RUN_ERR_INPUT,
                "%s: vehicles[%zu].route: its reference reaches %c = %.10g m at t "
                "= %g s, beyond what " SIM_INTENT " carries (%g m; this run's "
                "intents reach t = %g s)",
                file, i, axis, value, (double)t, COAVOID_LCM_MAX_COORDINATE,
                (double)last * (double)dt);
        }
        const int64_t reach_steps = initial + (int64_t)v->steep_factor * (int64_t)j;
        const int64_t reach = reach_steps < bound ? reach_steps : bound;
        const double top = fabs((double)r.z) + (double)reach * dh;
        if (beyond(top, COAVOID_LCM_MAX_COORDINATE)) {
            return coavoid_run_fail(
                err, COAVOID_RUN_ERR_INPUT,
                "%s: vehicles[%zu]: at t = %g s its reference is at z = %.10g m, "
                "and the %lld climb steps of %g m it may have taken by then take "
                "|z| to %.10g m: beyond what " SIM_INTENT " carries (%g m)",
                file, i, (double)t, (double)r.z, (long long)reach, dh, top,
                COAVOID_LCM_MAX_COORDINATE);
        }
        if (j > 0u) {
            status = check_vehicle_step(err, file, i, v, dt, t, previous, r, climb);
            if (status != SIM_GO_ON) {
                return status;
            }
        }
        previous = r;
    }
    return SIM_GO_ON;
}

/* A track's messages over cycles 0..steps (world.c): its volume and sigmas, and at each
 * cycle its velocity (a path track's: that of the leg in use) and position; a path track's
 * message also carries its path over the next horizon, so its points and positions up to
 * sample `last` too. */
/* Track i's speeds within what a track message carries: its velocity, or the speed of the
 * leg in use at each step t_k, as coa_track_at and the world choose it (the first one
 * before path[1], the last one from path[last - 1] on). */
static int check_track_speeds(coavoid_run_error_t *err, const char *file, size_t i,
                              const coa_track_t *tr, coa_real_t dt, uint64_t steps)
{
    if (tr->path_count == 0u) {
        double value = 0.0;
        const coa_vec3_t v = tr->velocity;
        if (beyond((double)v.x, COAVOID_LCM_MAX_SPEED) ||
            beyond((double)v.y, COAVOID_LCM_MAX_SPEED) ||
            beyond((double)v.z, COAVOID_LCM_MAX_SPEED)) {
            value = beyond((double)v.x, COAVOID_LCM_MAX_SPEED)   ? (double)v.x
                    : beyond((double)v.y, COAVOID_LCM_MAX_SPEED) ? (double)v.y
                                                                 : (double)v.z;
            return coavoid_run_fail(err, COAVOID_RUN_ERR_INPUT,
                                    "%s: tracks[%zu].velocity: %g m/s is beyond what " SIM_TRACK
                                    " carries (%g m/s)",
                                    file, i, value, COAVOID_LCM_MAX_SPEED);
        }
    } else if (tr->path_count > 1u) {
        const size_t final = tr->path_count - 1u;
        size_t leg = 0;
        for (uint64_t k = 0; k <= steps; k++) {
            const coa_real_t t = (coa_real_t)k * dt;
            while (leg + 1u < final && !(t < tr->path[leg + 1u].t)) {
                leg++;
            }
            const coa_track_point_t *a = &tr->path[leg];
            const coa_track_point_t *b = &tr->path[leg + 1u];
            const coa_real_t span = b->t - a->t;
            const double v[3] = {(double)((b->p.x - a->p.x) / span),
                                 (double)((b->p.y - a->p.y) / span),
                                 (double)((b->p.z - a->p.z) / span)};
            for (int c = 0; c < 3; c++) {
                if (beyond(v[c], COAVOID_LCM_MAX_SPEED)) {
                    return coavoid_run_fail(
                        err, COAVOID_RUN_ERR_INPUT,
                        "%s: tracks[%zu].path[%zu]: the leg to it is flown at %g m/s, "
                        "beyond what " SIM_TRACK " carries (%g m/s)",
                        file, i, leg + 1u, v[c], COAVOID_LCM_MAX_SPEED);
                }
            }
        }
    }
    return SIM_GO_ON;
}

static int check_track_limits(coavoid_run_error_t *err, const char *file, size_t i,
                              const coa_track_t *tr, coa_real_t dt, uint64_t steps, uint64_t last)
{
    const struct {
        const char *name;
        coa_real_t value;
    } sizes[4] = {{"radius", tr->volume.radius},
                  {"half_height", tr->volume.half_height},
                  {"sigma[0]", tr->sigma_horizontal},
                  {"sigma[1]", tr->sigma_vertical}};
    for (size_t f = 0; f < 4u; f++) {
        if (beyond((double)sizes[f].value, COAVOID_LCM_MAX_SIZE)) {
            return coavoid_run_fail(
                err, COAVOID_RUN_ERR_INPUT,
                "%s: tracks[%zu].%s: %g m is beyond what " SIM_TRACK " carries (%g m)", file, i,
                sizes[f].name, (double)sizes[f].value, COAVOID_LCM_MAX_SIZE);
        }
    }
    int status = check_track_speeds(err, file, i, tr, dt, steps);
    if (status != SIM_GO_ON) {
        return status;
    }
    const uint64_t sampled = tr->path_count > 0u ? last : steps;
    const coa_real_t end = (coa_real_t)sampled * dt;
    for (size_t j = 0; j < tr->path_count; j++) {
        double value = 0.0;
        char axis = far_axis(tr->path[j].p, &value);
        if (axis != 0 && tr->path[j].t > (coa_real_t)0 && tr->path[j].t < end) {
            return coavoid_run_fail(
                err, COAVOID_RUN_ERR_INPUT,
                "%s: tracks[%zu].path[%zu]: %c = %.10g m is beyond what " SIM_TRACK
                " carries (%g m)",
                file, i, j, axis, value, COAVOID_LCM_MAX_COORDINATE);
        }
    }
    for (uint64_t j = 0; j <= sampled; j++) {
        const coa_real_t t = (coa_real_t)j * dt;
        double value = 0.0;
        char axis = far_axis(coa_track_at(tr, t), &value);
        if (axis != 0) {
            return coavoid_run_fail(
                err, COAVOID_RUN_ERR_INPUT,
                "%s: tracks[%zu]: at t = %g s it is at %c = %.10g m, beyond what " SIM_TRACK
                " carries (%g m; this run's track messages reach t = %g "
                "s)",
                file, i, (double)t, axis, value, COAVOID_LCM_MAX_COORDINATE, (double)end);
        }
    }
    return SIM_GO_ON;
}

static int check_obstacle_limits(coavoid_run_error_t *err, const char *file, size_t i,
                                 const coa_obstacle_t *o)
{
    double value = 0.0;
    char axis = 0;
    if (o->kind == COA_OBSTACLE_BOX) {
        const char *corner = "min";
        axis = far_axis(o->box.min, &value);
        if (axis == 0) {
            corner = "max";
            axis = far_axis(o->box.max, &value);
        }
        if (axis != 0) {
            return coavoid_run_fail(err, COAVOID_RUN_ERR_INPUT,
                                    "%s: obstacles[%zu].%s: %c = %.10g m is beyond what " SIM_MAP
                                    " carries (%g m)",
                                    file, i, corner, axis, value, COAVOID_LCM_MAX_COORDINATE);
        }
        return SIM_GO_ON;
    }
    for (size_t j = 0; j < o->polytope.count; j++) {
        axis = far_axis(o->polytope.vertices[j], &value);
        if (axis != 0) {
            return coavoid_run_fail(
                err, COAVOID_RUN_ERR_INPUT,
                "%s: obstacles[%zu].vertices[%zu]: %c = %.10g m is beyond what " SIM_MAP
                " carries (%g m)",
                file, i, j, axis, value, COAVOID_LCM_MAX_COORDINATE);
        }
    }
    return SIM_GO_ON;
}

/* Every check above, over a run of `steps` cycles. Cost O((steps + N) * (vehicles * route +
 * tracks * path) + obstacle vertices), no memory. */
static int check_message_limits(coavoid_run_error_t *err, const char *file,
                                const coavoid_scenario_t *s, uint32_t steps)
{
    const uint64_t last = (uint64_t)steps + s->horizon;
    int rc = SIM_GO_ON;
    for (size_t i = 0; i < s->vehicle_count && rc == SIM_GO_ON; i++) {
        rc = check_vehicle_limits(err, file, i, &s->vehicles[i], s->dt, last);
    }
    for (size_t i = 0; i < s->track_count && rc == SIM_GO_ON; i++) {
        rc = check_track_limits(err, file, i, &s->tracks[i], s->dt, steps, last);
    }
    for (size_t i = 0; i < s->obstacle_count && rc == SIM_GO_ON; i++) {
        rc = check_obstacle_limits(err, file, i, &s->obstacles[i]);
    }
    return rc;
}

/* --coordinator-stops: once the network has cut the coordinator's link (sim_stop_cycle),
 * it is gone; checked after every pump, so that it makes no further call whichever of its
 * calls published its last message. */
static void sim_stop_if_cut(sim_run_t *r)
{
    if ((r->coordinator == NULL && !r->replaying) ||
        !coavoid_sim_net_cut(r->net, SIM_NET_COORDINATOR)) {
        return;
    }
    if (r->coordinator != NULL) {
        r->coordinator_plans = coavoid_coordinator_state(r->coordinator)->plans_run;
        r->coordinator_final = *coavoid_coordinator_state(r->coordinator);
    }
    coavoid_coordinator_destroy(r->coordinator);
    r->coordinator = NULL;
    r->replaying = false;
    coavoid_sim_net_stop(r->net, SIM_NET_COORDINATOR);
}

/* Hands the nodes what they published and what is due by now. false when the network
 * failed (r->net_error says how). */
static bool drain(sim_run_t *r)
{
    int rc = coavoid_sim_net_pump(r->net, r->now);
    r->net_error = r->net_error != COA_OK ? r->net_error : rc;
    sim_stop_if_cut(r);
    return rc == COA_OK;
}

/* The network's settings (the program checks them too, but the library trusts no caller):
 * a message at most less than a cycle late. */
static int check_network(sim_run_t *r)
{
    const coavoid_sim_config_t *o = r->o;
    if (!(o->loss >= 0.0 && o->loss < 1.0)) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "--loss: must be a probability from 0 to below 1, got %g", o->loss);
    }
    if (!(o->delay >= 0.0 && o->delay <= COAVOID_LCM_MAX_STEP) ||
        !(o->jitter >= 0.0 && o->jitter <= COAVOID_LCM_MAX_STEP)) {
        return coavoid_run_fail(
            r->err, COAVOID_RUN_ERR_INPUT, "--%s: must be a time in seconds, 0 or more, got %g",
            o->delay >= 0.0 && o->delay <= COAVOID_LCM_MAX_STEP ? "jitter" : "delay",
            o->delay >= 0.0 && o->delay <= COAVOID_LCM_MAX_STEP ? o->jitter : o->delay);
    }
    if (llround(o->delay * 1e6) + llround(o->jitter * 1e6) >= r->common.dt_us) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "--delay: %g s plus --jitter %g s must be less than the "
                                "scenario's dt (%g s): a message may be at most a cycle late",
                                o->delay, o->jitter, (double)r->s->dt);
    }
    return SIM_GO_ON;
}

/* The scenario's limits for a simulation, then its samples and the nodes' common config. */
static int sim_check(sim_run_t *r, coavoid_scenario_t *s)
{
    const char *file = r->file;
    const size_t n = r->n;
    if (s->horizon > COAVOID_NODE_MAX_HORIZON) {
        return coavoid_run_fail(
            r->err, COAVOID_RUN_ERR_INPUT,
            "%s: horizon: %lu steps, at most %u in a simulation (an intent carries "
            "N + 1 samples)",
            file, (unsigned long)s->horizon, COAVOID_NODE_MAX_HORIZON);
    }
    if (n > COA_MAX_VEHICLES || n > COAVOID_NODE_MAX_PEERS) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: vehicles: %zu UAVs, at most %u in a simulation", file, n,
                                COA_MAX_VEHICLES < COAVOID_NODE_MAX_PEERS ? COA_MAX_VEHICLES
                                                                          : COAVOID_NODE_MAX_PEERS);
    }
    if (s->track_count > COAVOID_NODE_MAX_TRACKS) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: tracks: %zu tracks, at most %u in a simulation", file,
                                s->track_count, COAVOID_NODE_MAX_TRACKS);
    }
    r->recorded = n;
    bool known = r->o->record_path == NULL;
    for (size_t i = 0; i < n && !known; i++) {
        known = s->vehicles[i].id == r->o->record_uav;
    }
    if (!known) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT, "--record-vehicle: %s has no UAV %u",
                                file, (unsigned)r->o->record_uav);
    }
    r->steps = r->o->has_steps ? r->o->steps : 2u * s->horizon;
    r->samples = (size_t)r->steps + 1u;
    if (r->o->has_stop && r->o->stop_step > r->steps) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "--coordinator-stops: step %lu is after the last, %lu",
                                (unsigned long)r->o->stop_step, (unsigned long)r->steps);
    }
    char sample_err[COAVOID_SCENARIO_ERROR_MAX];
    if (coavoid_scenario_sample(s, sample_err, sizeof sample_err) != 0) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT, "%s: %s", file, sample_err);
    }
    r->now = SIM_EPOCH_UTIME;
    if (coavoid_node_common_defaults(&r->common, SIM_EPOCH_UTIME, s->dt, s->horizon, &r->now) !=
        COA_OK) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: dt: %g s cannot be a cycle (whole microseconds, at most %g s)",
                                file, (double)s->dt, COAVOID_LCM_MAX_STEP);
    }
    r->collect_us = r->common.dt_us / 4 > 0 ? r->common.dt_us / 4 : 1;
    int rc = check_network(r);
    return rc == SIM_GO_ON ? check_message_limits(r->err, file, s, r->steps) : rc;
}

/* Planner sizes: each UAV plans alone; the coordinator searches up to max_centralised UAVs
 * together, fewer when the scenario's beta would not fit the cap otherwise. */
static int sim_planner_sizes(sim_run_t *r)
{
    const coavoid_scenario_t *s = r->s;
    coa_planner_config_t vehicle_shape =
        coavoid_node_planner_config(s->horizon, 1u, COAVOID_DEFAULT_BETA);
    r->vehicle_beta = s->has_beta ? s->beta : coavoid_default_beta(&vehicle_shape);
    vehicle_shape.beta = r->vehicle_beta;
    if (r->vehicle_beta == 0 || !coavoid_workspace_fits(&vehicle_shape)) {
        return coavoid_run_fail(
            r->err, COAVOID_RUN_ERR_INPUT,
            "%s: beta: %lu is too large: a UAV's planner would not fit in 1 GiB", r->file,
            (unsigned long)r->vehicle_beta);
    }
    r->max_centralised = r->n < COA_MAX_CENTRALISED ? r->n : COA_MAX_CENTRALISED;
    coa_planner_config_t coordinator_shape =
        coavoid_node_planner_config(s->horizon, r->max_centralised, COAVOID_DEFAULT_BETA);
    r->coordinator_beta = s->has_beta ? s->beta : coavoid_default_beta(&coordinator_shape);
    coordinator_shape.beta = r->coordinator_beta;
    while (r->max_centralised > 1u && !coavoid_workspace_fits(&coordinator_shape)) {
        coordinator_shape.vehicles = --r->max_centralised;
    }
    return SIM_GO_ON;
}

/* A node's id from its number on the network (net.h). */
static uint32_t sim_node_id(const sim_run_t *r, size_t index)
{
    if (index == SIM_NET_WORLD) {
        return COAVOID_NODE_WORLD_ID;
    }
    if (index == SIM_NET_COORDINATOR) {
        return COAVOID_NODE_COORDINATOR_ID;
    }
    return r->s->vehicles[r->index[index - SIM_NET_VEHICLE(0)]].id;
}

/* The caller's script of losses (coavoid_sim_config_t.drop), asked with node ids. */
static bool sim_drop(void *user, const char *channel, size_t from, size_t to, const void *data,
                     size_t size, int64_t now)
{
    const sim_run_t *r = user;
    return r->o->drop(r->o->drop_user, channel, sim_node_id(r, from), sim_node_id(r, to), data,
                      size, now);
}

/* The network between the nodes (net.h), on LCM's in-process provider: its queue holds
 * two cycles of every node's messages, as a message is less than a cycle late. */
static int sim_net(sim_run_t *r)
{
    const coavoid_sim_config_t *o = r->o;
    const size_t n = r->n;
    coavoid_sim_net_config_t c;
    memset(&c, 0, sizeof c);
    c.loss = o->loss;
    c.delay_us = (int64_t)llround(o->delay * 1e6);
    c.jitter_us = (int64_t)llround(o->jitter * 1e6);
    c.seed = o->seed;
    c.drop = o->drop != NULL ? sim_drop : NULL;
    c.drop_user = r;
    if (c.delay_us > 0 || c.jitter_us > 0) {
        /* The world's first cycle sends twice the copies. */
        const size_t per_cycle = (COAVOID_OBSTACLE_MAP_T_MAX_TILES + r->s->track_count) *
                                     (1u + 2u * COAVOID_NODE_DEFAULT_COPIES) +
                                 SIM_NET_VEHICLE_MESSAGES * n + SIM_NET_COORDINATOR_MESSAGES(n);
        c.message_capacity = 2u * per_cycle;
        c.copy_capacity = 2u * per_cycle * (n + 1u);
    }
    bool receives[COAVOID_NODE_MAX_PEERS + 2u];
    receives[SIM_NET_WORLD] = false;
    receives[SIM_NET_COORDINATOR] = !o->decoupled;
    for (size_t j = 0; j < n; j++) {
        receives[SIM_NET_VEHICLE(j)] = true;
    }
    int error = COA_OK;
    r->net_error = COA_OK;
    r->net = coavoid_sim_net_create(&c, n + 2u, receives, &error);
    if (r->net == NULL) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: no simulated network (%s: LCM's memq provider "
                                "or memory)",
                                coa_status_name(error));
    }
    return SIM_GO_ON;
}

/* The flight record, the figure's file and the network. */
static int sim_open(sim_run_t *r)
{
    const size_t n = r->n;
    r->vehicles = calloc(n, sizeof *r->vehicles);
    r->index = calloc(n, sizeof *r->index);
    r->references = calloc(n * r->samples, sizeof *r->references);
    r->offsets = calloc(n * r->samples, sizeof *r->offsets);
    if (r->vehicles == NULL || r->index == NULL || r->references == NULL || r->offsets == NULL) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: cannot allocate the record of %lu steps", r->file,
                                (unsigned long)r->steps);
    }
    if (r->o->svg_path != NULL) {
        r->svg = fopen(r->o->svg_path, "w");
        if (r->svg == NULL) {
            return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT, "--svg: cannot write '%.200s'",
                                    r->o->svg_path);
        }
    }
    return sim_net(r);
}

/* One node's key of the simulation into signer and the trust list: its seed is a fixed text
 * and the key id, so every run signs alike; it tags with the trust list's fleet key. */
static int sim_key(sim_run_t *r, coavoid_auth_signer_t *signer, uint32_t key_id,
                   coavoid_auth_role_t role, uint16_t node)
{
    unsigned char seed[COAVOID_AUTH_SEED_BYTES] = "coavoid simulation key";
    seed[COAVOID_AUTH_SEED_BYTES - 4u] = (unsigned char)(key_id >> 24);
    seed[COAVOID_AUTH_SEED_BYTES - 3u] = (unsigned char)(key_id >> 16);
    seed[COAVOID_AUTH_SEED_BYTES - 2u] = (unsigned char)(key_id >> 8);
    seed[COAVOID_AUTH_SEED_BYTES - 1u] = (unsigned char)key_id;
    coavoid_auth_key_t key = {key_id, role, node, {0}};
    memset(signer, 0, sizeof *signer);
    signer->key_id = key_id;
    coavoid_auth_signer_use_fleet(signer, &r->trust);
    if (coavoid_auth_keypair_seed(seed, key.public_key, signer->secret_key) != COA_OK ||
        coavoid_auth_trust_add(&r->trust, &key) != COA_OK) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: no simulation key (libsodium)");
    }
    return SIM_GO_ON;
}

/* The fleet's keys, as coavoid keygen numbers them, and a fixed fleet key, unless the run
 * is insecure. */
static int sim_keys(sim_run_t *r)
{
    r->common.insecure = r->o->insecure;
    if (r->o->insecure) {
        return SIM_GO_ON;
    }
    r->signers = calloc(r->n + 2u, sizeof *r->signers);
    if (r->signers == NULL) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: out of memory for the keys");
    }
    coavoid_auth_trust_init(&r->trust);
    r->common.trust = &r->trust;
    const unsigned char fleet_key[COAVOID_AUTH_FLEET_KEY_BYTES] = "coavoid sim key";
    (void)coavoid_auth_trust_set_fleet_key(&r->trust, fleet_key);
    int rc = sim_key(r, &r->signers[0], COAVOID_AUTH_KEY_ID_COORDINATOR, COAVOID_AUTH_COORDINATOR,
                     (uint16_t)COAVOID_NODE_COORDINATOR_ID);
    if (rc == SIM_GO_ON) {
        rc = sim_key(r, &r->signers[1], COAVOID_AUTH_KEY_ID_WORLD, COAVOID_AUTH_WORLD,
                     (uint16_t)COAVOID_NODE_WORLD_ID);
    }
    for (size_t i = 0; i < r->n && rc == SIM_GO_ON; i++) {
        const uint16_t id = r->s->vehicles[i].id;
        rc = sim_key(r, &r->signers[2u + i], COAVOID_AUTH_KEY_ID_VEHICLE_BASE + id,
                     COAVOID_AUTH_VEHICLE, id);
    }
    return rc;
}

/* A node's signer: NULL when insecure; else the coordinator's (0), the world's (1) or the
 * UAV's of scenario index i (2 + i). */
static const coavoid_auth_signer_t *sim_signer(const sim_run_t *r, size_t which)
{
    return r->signers != NULL ? &r->signers[which] : NULL;
}

/* The world node. A track message numbers tracks 1..2^31-1, once each; the scenario may
 * use any integer, so then the world's tracks are numbered by position instead (the ids
 * only name tracks in the messages: the flight is judged on the scenario's own tracks). */
static int sim_world(sim_run_t *r)
{
    const coavoid_scenario_t *s = r->s;
    const coa_track_t *world_tracks = s->tracks;
    bool ids_fit = true;
    for (size_t i = 0; i < s->track_count; i++) {
        ids_fit = ids_fit && s->tracks[i].id >= 1u && s->tracks[i].id <= (uint32_t)INT32_MAX;
        for (size_t j = 0; j < i; j++) {
            ids_fit = ids_fit && s->tracks[j].id != s->tracks[i].id;
        }
    }
    if (!ids_fit) {
        r->tracks = calloc(s->track_count, sizeof *r->tracks);
        if (r->tracks == NULL) {
            return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT, "%s: cannot allocate the tracks",
                                    r->file);
        }
        for (size_t i = 0; i < s->track_count; i++) {
            r->tracks[i] = s->tracks[i];
            r->tracks[i].id = (uint32_t)i + 1u;
        }
        world_tracks = r->tracks;
    }
    int error = COA_OK;
    coavoid_world_config_t world;
    memset(&world, 0, sizeof world);
    world.common = r->common;
    world.common.signer = sim_signer(r, 1u);
    world.id = COAVOID_NODE_WORLD_ID;
    world.obstacles = s->obstacles;
    world.obstacle_count = s->obstacle_count;
    world.tracks = world_tracks;
    world.track_count = s->track_count;
    world.copies = COAVOID_NODE_DEFAULT_COPIES;
    r->world = coavoid_world_create(&world, coavoid_sim_net_tx(r->net, SIM_NET_WORLD), &error);
    if (r->world == NULL && error == COA_ERR_ARGUMENT) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: obstacles: more than an obstacle map holds (%d boxes, "
                                "%d polytopes of at most %d vertices)",
                                r->file, COAVOID_OBSTACLE_MAP_T_MAX_MAP_BOXES,
                                COAVOID_OBSTACLE_MAP_T_MAX_MAP_POLYTOPES,
                                COAVOID_OBSTACLE_MAP_T_MAX_VERTICES);
    }
    if (r->world == NULL) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: out of memory for the world node");
    }
    /* The UAVs and the coordinator keep the scenario's obstacles as their own (they fit:
     * the world's map holds them all); the world's map adds to them. */
    r->common.obstacles = s->obstacles;
    r->common.obstacle_count = s->obstacle_count;
    r->common.has_floor = s->has_floor;
    r->common.min_altitude = s->min_altitude;
    return SIM_GO_ON;
}

/* The UAVs' nodes, in priority order (ascending priority, ties by ascending id), whatever
 * the file's order or their ids: the order in which a real fleet's decisions settle. A UAV
 * that has not yet heard a peer cannot wait for it (cycle 0, before anyone has published),
 * so a lower priority stepped first would decide around nothing there. */
static int sim_vehicles(sim_run_t *r)
{
    const coavoid_scenario_t *s = r->s;
    if (coa_priority_order(s->vehicles, r->n, r->index) != COA_OK) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: no priority order of %zu UAVs", r->n);
    }
    for (size_t j = 0; j < r->n; j++) {
        size_t i = r->index[j];
        int error = COA_OK;
        coavoid_vehicle_node_config_t config;
        memset(&config, 0, sizeof config);
        config.common = r->common;
        config.common.beta = r->vehicle_beta;
        config.common.signer = sim_signer(r, 2u + i);
        config.vehicle = s->vehicles[i];
        config.mode = r->o->decoupled ? COAVOID_NODE_DECOUPLED : COAVOID_NODE_CENTRALISED;
        config.intent_copies = COAVOID_NODE_DEFAULT_COPIES;
        config.joint_members = r->o->has_joint_members
                                   ? r->o->joint_members
                                   : coavoid_node_joint_members(config.mode, r->n);
        config.joint_memo = r->o->joint_memo != NULL ? r->o->joint_memo : &r->own_memo;
        const bool recorded = r->o->record_path != NULL && config.vehicle.id == r->o->record_uav;
        if (recorded) {
            config.joint_memo = NULL; /* a replay searches on its own: so does the record */
            if (!coavoid_sim_record_open(&r->record, r->o->record_path, &config)) {
                return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                        "--record-vehicle: cannot write '%.200s'",
                                        r->o->record_path);
            }
        }
        r->vehicles[j] =
            coavoid_vehicle_node_create(&config, coavoid_sim_net_tx(r->net, SIM_NET_VEHICLE(j)),
                                        coavoid_sim_net_rx(r->net, SIM_NET_VEHICLE(j)), &error);
        if (recorded && r->vehicles[j] != NULL) {
            coavoid_vehicle_node_tap(r->vehicles[j], coavoid_sim_record_tap, &r->record);
            r->recorded = j;
        }
        if (r->vehicles[j] == NULL && error == COA_ERR_ARGUMENT) {
            return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                    "%s: vehicles[%zu]: cannot run as a node (%s)", r->file, i,
                                    coavoid_lcm_error_name(error));
        }
        if (r->vehicles[j] == NULL) {
            return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                    "%s: vehicles[%zu]: cannot allocate its node (beta %lu)",
                                    r->file, i, (unsigned long)r->vehicle_beta);
        }
    }
    return SIM_GO_ON;
}

/* The coordinator's node (centralised runs). */
static int sim_coordinator(sim_run_t *r)
{
    if (r->o->decoupled) {
        return SIM_GO_ON;
    }
    int error = COA_OK;
    coavoid_coordinator_config_t config;
    memset(&config, 0, sizeof config);
    config.common = r->common;
    config.common.beta = r->coordinator_beta;
    config.common.signer = sim_signer(r, 0u);
    config.id = COAVOID_NODE_COORDINATOR_ID;
    config.max_centralised = r->max_centralised;
    config.collect_us = r->collect_us;
    config.heartbeat_copies = COAVOID_NODE_DEFAULT_COPIES;
    if (config.collect_us >= r->common.dt_us) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: dt: %g s leaves the coordinator no time within a cycle",
                                r->file, (double)r->s->dt);
    }
    if (r->o->tape != NULL && r->o->replay) {
        /* Replayed (sim_coordinator_cycle): the node itself is never needed. */
        r->replaying = r->o->has_stop;
        return r->replaying ? SIM_GO_ON
                            : coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                               "internal error: a replay without a stop");
    }
    if (r->o->tape != NULL) {
        coavoid_sim_tape_clear(r->o->tape);
        coavoid_sim_net_tap(r->net, SIM_NET_COORDINATOR, coavoid_sim_tape_message, r->o->tape);
    }
    r->coordinator =
        coavoid_coordinator_create(&config, coavoid_sim_net_tx(r->net, SIM_NET_COORDINATOR),
                                   coavoid_sim_net_rx(r->net, SIM_NET_COORDINATOR), &error);
    if (r->coordinator == NULL && error == COA_ERR_ARGUMENT) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: beta: %lu cannot size the coordinator's planner", r->file,
                                (unsigned long)r->coordinator_beta);
    }
    if (r->coordinator == NULL) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: cannot allocate the coordinator's planner (beta %lu, %zu UAVs "
                                "together)",
                                r->file, (unsigned long)r->coordinator_beta, r->max_centralised);
    }
    return SIM_GO_ON;
}

/* The UAVs' waits, and the network's deliveries in time order with them: poll until
 * nobody moves on, then the clock jumps to the first deadline or delivery, until no
 * deadline is left and no delivery is due by `until` (one due later but before a UAV's
 * deadline comes first: the clock never goes back). Keeps the first node error in
 * *node_error. False when the network failed. */
static int64_t sim_coordinator_deadline(const sim_run_t *r);
static int sim_coordinator_poll(sim_run_t *r);

/* Vehicle j's cycle (or poll) at r->now, recorded when it is the recorded one. */
static int sim_vehicle_call(sim_run_t *r, size_t j, bool cycle)
{
    if (j == r->recorded) {
        return coavoid_sim_record_call(&r->record, r->vehicles[j], cycle, r->now);
    }
    return cycle ? coavoid_vehicle_node_cycle(r->vehicles[j], r->now)
                 : coavoid_vehicle_node_poll(r->vehicles[j], r->now);
}

/* Polls every node once at r->now, draining what each published. True when one did. */
static bool sim_poll(sim_run_t *r, int *node_error, bool *lcm_ok)
{
    bool changed = false;
    for (size_t j = 0; j <= r->n && *lcm_ok; j++) {
        int rc = 0;
        if (j < r->n) {
            rc = sim_vehicle_call(r, j, false);
        } else if (r->coordinator != NULL || r->replaying) {
            rc = sim_coordinator_poll(r);
        }
        if (rc < 0) {
            *node_error = *node_error != COA_OK ? *node_error : rc;
        } else if (rc > 0) {
            changed = true;
            *lcm_ok = drain(r);
        }
    }
    return changed;
}

static bool sim_waits(sim_run_t *r, int64_t until, int *node_error)
{
    bool lcm_ok = true;
    for (;;) {
        while (lcm_ok && sim_poll(r, node_error, &lcm_ok)) {
        }
        int64_t deadline = INT64_MAX;
        for (size_t j = 0; j < r->n; j++) {
            int64_t d = coavoid_vehicle_node_deadline(r->vehicles[j]);
            deadline = d < deadline ? d : deadline;
        }
        const int64_t d = sim_coordinator_deadline(r);
        deadline = d < deadline ? d : deadline;
        /* The nodes' deadlines and the deliveries in time order (a delivery first on a
         * tie), up to `until`: what is due later comes after the caller's event at `until`
         * (the coordinator's cycle), and a node polled after its deadline's cycle ended
         * would not act on it. */
        deadline = deadline <= until ? deadline : INT64_MAX;
        const int64_t due = coavoid_sim_net_next(r->net);
        if (due <= until && due <= deadline) {
            deadline = due;
        }
        if (deadline == INT64_MAX || !lcm_ok) {
            return lcm_ok;
        }
        r->now = deadline > r->now ? deadline : r->now;
        lcm_ok = drain(r);
    }
}

/* The coordinator's messages of the cycle that ends now (config's record). */
static void sim_count_coordinator(sim_run_t *r, uint32_t ended)
{
    const uint64_t sent = coavoid_sim_net_sent_by(r->net, SIM_NET_COORDINATOR);
    const uint32_t count = (uint32_t)(sent - r->coordinator_sent);
    if (r->o->coordinator_messages != NULL && ended < r->o->coordinator_messages_size) {
        r->o->coordinator_messages[ended] = count;
    }
    if (r->o->has_stop && ended == r->o->stop_step) {
        r->stop_cycle_sent = count;
    }
    r->coordinator_sent = sent;
}

/* At cycle k's start: the last cycle's count; then, from cycle STEP of --coordinator-stops
 * STEP[:M], the coordinator's link is cut after M more messages (after none past STEP:
 * it is gone by the next cycle whatever it sent), and it is gone once it is cut. */
static void sim_stop_cycle(sim_run_t *r, uint32_t k)
{
    if (k > 0u) {
        sim_count_coordinator(r, k - 1u);
    }
    if ((r->coordinator == NULL && !r->replaying) || !r->o->has_stop || k < r->o->stop_step) {
        return;
    }
    coavoid_sim_net_stop_after(r->net, SIM_NET_COORDINATOR,
                               k == r->o->stop_step ? r->o->stop_messages : 0u);
    sim_stop_if_cut(r);
}

/* When the coordinator's next poll is due: its deadline, or replaying, the time of the
 * tape's next call when that is a poll. INT64_MAX: none. */
static int64_t sim_coordinator_deadline(const sim_run_t *r)
{
    if (r->replaying) {
        int64_t at = INT64_MAX;
        bool poll = false;
        return coavoid_sim_tape_next(r->o->tape, r->coordinator_calls, &at, &poll) && poll
                   ? at
                   : INT64_MAX;
    }
    return r->coordinator != NULL ? coavoid_coordinator_deadline(r->coordinator) : INT64_MAX;
}

/* The coordinator's poll when it is due (its agreement steps: docs/protocol.md), recorded
 * on or replayed from the tape as its cycles are. 1 when it published, 0 when nothing was
 * due, or a negative error. */
static int sim_coordinator_poll(sim_run_t *r)
{
    const coavoid_sim_config_t *o = r->o;
    if (sim_coordinator_deadline(r) > r->now) {
        return 0;
    }
    const uint64_t digest = coavoid_sim_net_digest(r->net);
    if (r->replaying) {
        int rc = coavoid_sim_tape_play(o->tape, r->coordinator_calls++, digest,
                                       coavoid_sim_net_tx(r->net, SIM_NET_COORDINATOR),
                                       &r->coordinator_plans);
        return rc != COA_OK ? rc : 1;
    }
    if (o->tape != NULL && !coavoid_sim_tape_begin(o->tape, digest, r->now, true)) {
        return COA_ERR_WORKSPACE;
    }
    int rc = coavoid_coordinator_poll(r->coordinator, r->now);
    if (o->tape != NULL) {
        coavoid_sim_tape_end(o->tape, coavoid_coordinator_state(r->coordinator)->plans_run);
    }
    return rc < 0 ? rc : 1;
}

/* The coordinator's cycle, or with a tape (config's) recorded or replayed: its messages
 * of the call as the tape has them. */
static int sim_coordinator_cycle(sim_run_t *r)
{
    const coavoid_sim_config_t *o = r->o;
    const uint64_t digest = coavoid_sim_net_digest(r->net);
    if (r->replaying) {
        return coavoid_sim_tape_play(o->tape, r->coordinator_calls++, digest,
                                     coavoid_sim_net_tx(r->net, SIM_NET_COORDINATOR),
                                     &r->coordinator_plans);
    }
    if (o->tape != NULL && !coavoid_sim_tape_begin(o->tape, digest, r->now, false)) {
        return COA_ERR_WORKSPACE;
    }
    int rc = coavoid_coordinator_cycle(r->coordinator, r->now);
    if (o->tape != NULL) {
        coavoid_sim_tape_end(o->tape, coavoid_coordinator_state(r->coordinator)->plans_run);
    }
    return rc;
}

/* Cycle k of the loop of node.h: what the network still carries up to its start, then
 * the world, the UAVs in priority order, their waits, then the coordinator at cycle start
 * + collect; each message reaches its receivers when the network says (at once, with
 * neither delay nor jitter, as on a quiet network). False when the network failed. */
static bool sim_cycle(sim_run_t *r, uint32_t k, int *node_error)
{
    const int64_t cycle_start = coavoid_node_cycle_utime(&r->common, (int64_t)k);
    bool lcm_ok = k == 0u || sim_waits(r, cycle_start, node_error);
    sim_stop_cycle(r, k);
    r->now = cycle_start;
    int rc = coavoid_world_cycle(r->world, r->now);
    *node_error = *node_error != COA_OK ? *node_error : rc;
    lcm_ok = lcm_ok && drain(r);
    for (size_t j = 0; j < r->n && lcm_ok; j++) {
        rc = sim_vehicle_call(r, j, true);
        *node_error = *node_error != COA_OK ? *node_error : rc;
        lcm_ok = drain(r);
    }
    lcm_ok = lcm_ok && sim_waits(r, cycle_start + r->collect_us, node_error);
    /* The coordinator plans cycles 0..K-1: cycle K only flies the last sample. */
    if ((r->coordinator != NULL || r->replaying) && k < r->steps && lcm_ok) {
        r->now = cycle_start + r->collect_us > r->now ? cycle_start + r->collect_us : r->now;
        rc = sim_coordinator_cycle(r);
        *node_error = *node_error != COA_OK ? *node_error : rc;
        lcm_ok = drain(r);
    }
    for (size_t j = 0; j < r->n; j++) {
        const coavoid_vehicle_node_state_t *st = coavoid_vehicle_node_state(r->vehicles[j]);
        size_t i = r->index[j];
        r->references[i * r->samples + k] = st->reference;
        r->offsets[i * r->samples + k] = st->offset;
    }
    return lcm_ok;
}

/* Flies samples 0..steps. */
static int sim_fly(sim_run_t *r)
{
    int node_error = COA_OK;
    bool lcm_ok = true;
    for (uint32_t k = 0; k <= r->steps && lcm_ok; k++) {
        lcm_ok = sim_cycle(r, k, &node_error);
    }
    sim_count_coordinator(r, r->steps);
    if (r->coordinator != NULL) {
        r->coordinator_plans = coavoid_coordinator_state(r->coordinator)->plans_run;
        r->coordinator_final = *coavoid_coordinator_state(r->coordinator);
    }
    if (!lcm_ok && r->net_error == COA_ERR_WORKSPACE) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: the simulated network's queue overflowed (more "
                                "messages in flight than two cycles of the fleet's)");
    }
    if (!lcm_ok) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: LCM failed while handling messages");
    }
    if (node_error != COA_OK) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: a node failed (%s)",
                                coavoid_lcm_error_name(node_error));
    }
    return SIM_GO_ON;
}

/* The network's settings and counts: a JSON object, or (json false) a line of text. */
static void network_text(const sim_run_t *r, bool json, char *buf, size_t size)
{
    const coavoid_sim_config_t *o = r->o;
    const coavoid_sim_net_stats_t st = coavoid_sim_net_stats(r->net);
    snprintf(buf, size,
             json ? "{\"loss\": %.15g, \"delay\": %.15g, \"jitter\": %.15g, \"seed\": %llu, "
                    "\"sent\": %llu, \"delivered\": %llu, \"dropped\": %llu, \"in_flight\": "
                    "%llu}"
                  : "network: loss %.15g, delay %.15g s, jitter %.15g s, seed %llu: %llu messages "
                    "sent, copies to other nodes %llu delivered, %llu dropped, %llu in flight\n",
             o->loss, o->delay, o->jitter, (unsigned long long)o->seed, (unsigned long long)st.sent,
             (unsigned long long)st.delivered, (unsigned long long)st.dropped,
             (unsigned long long)st.in_flight);
}

/* Writes the result (text or JSON) to r->out. COA_OK or an error. */
static int sim_write(const sim_run_t *r, uint32_t fallbacks)
{
    const coavoid_sim_config_t *o = r->o;
    const coavoid_flight_t *flight = &r->judged.flight;
    const coavoid_flight_eval_t *eval = &r->judged.eval;
    char network[512];
    network_text(r, o->json, network, sizeof network);
    const unsigned long cut = (unsigned long)coavoid_sim_net_stats(r->net).cut;
    int rc = COA_OK;
    if (o->json) {
        char fallbacks_text[16];
        char stopped_text[16], after_text[16], sent_text[16], cut_text[24];
        snprintf(fallbacks_text, sizeof fallbacks_text, "%lu", (unsigned long)fallbacks);
        snprintf(stopped_text, sizeof stopped_text, "%lu", (unsigned long)o->stop_step);
        snprintf(after_text, sizeof after_text, "%lu", (unsigned long)o->stop_messages);
        snprintf(sent_text, sizeof sent_text, "%lu", (unsigned long)r->stop_cycle_sent);
        snprintf(cut_text, sizeof cut_text, "%lu", cut);
        coavoid_flight_extra_t extra[6] = {{"fallbacks", fallbacks_text}};
        size_t count = 1u;
        if (o->has_stop) {
            extra[count++] = (coavoid_flight_extra_t){"coordinator_stopped_at", stopped_text};
        }
        if (o->has_stop && o->has_stop_messages) {
            extra[count++] = (coavoid_flight_extra_t){"coordinator_stopped_after", after_text};
            extra[count++] = (coavoid_flight_extra_t){"coordinator_messages_sent", sent_text};
            extra[count++] = (coavoid_flight_extra_t){"coordinator_messages_cut", cut_text};
        }
        if (o->network) {
            extra[count++] = (coavoid_flight_extra_t){"network", network};
        }
        rc = coavoid_flight_json_extra(flight, eval, extra, count, r->out);
    } else {
        rc = coavoid_flight_text(flight, eval, r->out);
        if (rc == COA_OK && (fprintf(r->out, "fallbacks: %lu\n", (unsigned long)fallbacks) < 0 ||
                             (o->network && fputs(network, r->out) < 0))) {
            rc = COA_ERR_WORKSPACE;
        }
        if (rc == COA_OK && o->has_stop && o->has_stop_messages &&
            fprintf(r->out,
                    "coordinator: stopped in cycle %lu after %lu of its messages (%lu went out "
                    "in it, %lu more were cut)\n",
                    (unsigned long)o->stop_step, (unsigned long)o->stop_messages,
                    (unsigned long)r->stop_cycle_sent, cut) < 0) {
            rc = COA_ERR_WORKSPACE;
        }
        rc = rc == COA_OK && fflush(r->out) != 0 ? COA_ERR_WORKSPACE : rc;
    }
    return rc;
}

/* The agreement counts of the run (the coordinator's, the UAVs' sums). */
static void sim_agreement_counts(const sim_run_t *r, coavoid_sim_outcome_t *outcome)
{
    const coavoid_coordinator_state_t *c = &r->coordinator_final;
    outcome->plans_proposed = c->plans_proposed;
    outcome->plans_committed = c->plans_committed;
    outcome->plans_aborted = c->plans_aborted;
    outcome->plans_replanned = c->plans_replanned;
    outcome->plans_resent = c->plans_resent;
    outcome->plans_switched = 0;
    outcome->plans_in_doubt = 0;
    outcome->plans_standby = 0;
    outcome->joint_plans = 0;
    for (size_t j = 0; j < r->n; j++) {
        const coavoid_vehicle_node_state_t *st = coavoid_vehicle_node_state(r->vehicles[j]);
        outcome->plans_switched += st->plans_switched;
        outcome->plans_in_doubt += st->plans_in_doubt;
        outcome->plans_standby += st->plans_standby;
        outcome->joint_plans += st->joint_plans;
    }
}

/* Judges the flight and writes the figure and the result (unless there is no r->out);
 * the exit status, and *outcome when not NULL. */
static int sim_report(sim_run_t *r, coavoid_sim_outcome_t *outcome)
{
    const coavoid_sim_config_t *o = r->o;
    uint32_t replans = r->coordinator_plans;
    uint32_t fallbacks = 0;
    for (size_t j = 0; j < r->n; j++) {
        const coavoid_vehicle_node_state_t *st = coavoid_vehicle_node_state(r->vehicles[j]);
        replans += st->plans_run;
        fallbacks += st->fallbacks;
        if (st->protocol_faults > 0u) {
            /* An event its state machines do not allow: a bug of the protocol library. */
            return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                    "internal error: UAV %u made %lu transitions its state "
                                    "machines do not allow",
                                    (unsigned)r->s->vehicles[r->index[j]].id,
                                    (unsigned long)st->protocol_faults);
        }
    }
    if (!coavoid_sim_record_close(&r->record)) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                "--record-vehicle: writing '%.200s' failed", o->record_path);
    }
    int rc = coavoid_judge_run(&r->judged, r->s, o->mode, r->steps, replans, r->references,
                               r->offsets, NULL);
    const coavoid_flight_eval_t *eval = &r->judged.eval;
    if (rc != COA_OK) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: the flight cannot be judged (%s)",
                                coa_status_name(rc));
    }
    if (r->svg != NULL) {
        rc = coavoid_flight_svg(&r->judged.flight, eval, r->svg);
        int closed = fclose(r->svg);
        r->svg = NULL;
        if (rc != COA_OK || closed != 0) {
            return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                    "--svg: writing '%.200s' failed", o->svg_path);
        }
    }
    if (r->out != NULL && sim_write(r, fallbacks) != COA_OK) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: the result could not be written");
    }
    if (outcome != NULL) {
        const coavoid_sim_net_stats_t st = coavoid_sim_net_stats(r->net);
        outcome->loss_of_separation = eval->loss_of_separation;
        outcome->fallbacks = fallbacks;
        outcome->sent = st.sent;
        outcome->delivered = st.delivered;
        outcome->dropped = st.dropped;
        outcome->in_flight = st.in_flight;
        sim_agreement_counts(r, outcome);
    }
    return eval->loss_of_separation ? COAVOID_SIM_LOSS : COAVOID_SIM_SEPARATED;
}

int coavoid_sim_run(const coavoid_sim_config_t *c, coavoid_scenario_t *s, FILE *out,
                    coavoid_run_error_t *e)
{
    return coavoid_sim_fly(c, s, out, NULL, e);
}

int coavoid_sim_fly(const coavoid_sim_config_t *c, coavoid_scenario_t *s, FILE *out,
                    coavoid_sim_outcome_t *outcome, coavoid_run_error_t *e)
{
    sim_run_t r;
    memset(&r, 0, sizeof r);
    e->text[0] = '\0';
    r.o = c;
    r.err = e;
    r.out = out;
    r.s = s;
    r.file = c->scenario_path;
    r.n = s->vehicle_count;
    (void)coavoid_node_joint_memo_init(&r.own_memo, r.own_keys, SIM_JOINT_MEMO_KEYS);
    int rc = sim_check(&r, s);
    if (rc == SIM_GO_ON) {
        rc = sim_planner_sizes(&r);
    }
    if (rc == SIM_GO_ON) {
        rc = sim_open(&r);
    }
    if (rc == SIM_GO_ON) {
        rc = sim_keys(&r);
    }
    if (rc == SIM_GO_ON) {
        rc = sim_world(&r);
    }
    if (rc == SIM_GO_ON) {
        rc = sim_vehicles(&r);
    }
    if (rc == SIM_GO_ON) {
        rc = sim_coordinator(&r);
    }
    if (rc == SIM_GO_ON) {
        rc = sim_fly(&r);
    }
    if (rc == SIM_GO_ON) {
        rc = sim_report(&r, outcome);
    }
    sim_run_free(&r, r.n);
    return rc;
}
