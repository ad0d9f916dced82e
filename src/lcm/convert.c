/* SPDX-License-Identifier: MIT */
/*
 * Validation of LCM messages and conversion to and from core types (coavoid_lcm.h).
 * Every rule is a REJECT(code, reason) with a reason naming the field, so a refusal
 * in a log says exactly what was wrong.
 */
#include "auth.h"
#include "coavoid_lcm.h"

#include <math.h>
#include <string.h>

#define REJECT(code, text)    \
    do {                      \
        if (reason != NULL) { \
            *reason = (text); \
        }                     \
        return (code);        \
    } while (0)

#define OK_REASON()           \
    do {                      \
        if (reason != NULL) { \
            *reason = "ok";   \
        }                     \
    } while (0)

/* 0 ok, COAVOID_LCM_ERR_NONFINITE, or COAVOID_LCM_ERR_VALUE when |x| > bound. */
static int number_rule(double x, double bound)
{
    if (!isfinite(x)) {
        return COAVOID_LCM_ERR_NONFINITE;
    }
    return (fabs(x) <= bound) ? COA_OK : COAVOID_LCM_ERR_VALUE;
}

/* Sizes and sigmas: finite, in (0, COAVOID_LCM_MAX_SIZE] when positive, else [0, COAVOID_LCM_MAX_SIZE]. */
static int size_rule(double x, bool positive)
{
    int rc = number_rule(x, COAVOID_LCM_MAX_SIZE);
    if (rc != COA_OK) {
        return rc;
    }
    return (positive ? x > 0.0 : x >= 0.0) ? COA_OK : COAVOID_LCM_ERR_VALUE;
}

static int vec_rule(const double v[3], double bound)
{
    int i;
    for (i = 0; i < 3; ++i) {
        int rc = number_rule(v[i], bound);
        if (rc != COA_OK) {
            return rc;
        }
    }
    return COA_OK;
}

static bool id_ok(int32_t id)
{
    return id >= 1 && id <= COAVOID_LCM_MAX_ID;
}

/* utime > 0 and, with a clock, neither stale nor in the future. */
static int utime_rule(int64_t utime, const coavoid_lcm_context_t *ctx)
{
    if (utime <= 0) {
        return COAVOID_LCM_ERR_TIME;
    }
    if (ctx != NULL && ctx->now_utime > 0) {
        if (ctx->max_future_us >= 0 && utime > ctx->now_utime &&
            utime - ctx->now_utime > ctx->max_future_us) {
            return COAVOID_LCM_ERR_TIME;
        }
        if (ctx->max_age_us >= 0 && utime < ctx->now_utime &&
            ctx->now_utime - utime > ctx->max_age_us) {
            return COAVOID_LCM_ERR_TIME;
        }
    }
    return COA_OK;
}

/* A time stamp that belongs to the message (plan start, estimate): > 0 and within the
 * age window of its utime in either direction, so a converted time stays small. */
static int related_time_rule(int64_t t, int64_t utime, const coavoid_lcm_context_t *ctx)
{
    int64_t window = (ctx != NULL && ctx->max_age_us > 0) ? ctx->max_age_us : INT64_C(3600000000);
    if (t <= 0) {
        return COAVOID_LCM_ERR_TIME;
    }
    if ((t > utime && t - utime > window) || (t < utime && utime - t > window)) {
        return COAVOID_LCM_ERR_TIME;
    }
    return COA_OK;
}

static coa_real_t core_time(int64_t utime, const coavoid_lcm_context_t *ctx)
{
    int64_t epoch = (ctx != NULL) ? ctx->epoch_utime : 0;
    /* Difference first, in integers, so that double keeps microseconds. */
    return (coa_real_t)((double)(utime - epoch) * 1e-6);
}

static int64_t utime_of(coa_real_t t, const coavoid_lcm_context_t *ctx)
{
    int64_t epoch = (ctx != NULL) ? ctx->epoch_utime : 0;
    double us = (double)t * 1e6;
    if (!isfinite(us) || fabs(us) > 9.0e18) {
        return 0; /* the check refuses it */
    }
    return epoch + (int64_t)llround(us);
}

static coa_vec3_t vec_of(const double v[3])
{
    coa_vec3_t out;
    out.x = (coa_real_t)v[0];
    out.y = (coa_real_t)v[1];
    out.z = (coa_real_t)v[2];
    return out;
}

static void vec_to(coa_vec3_t v, double out[3])
{
    out[0] = (double)v.x;
    out[1] = (double)v.y;
    out[2] = (double)v.z;
}

/* ---- sequence table ---- */

void coavoid_lcm_sequence_init(coavoid_lcm_sequence_table_t *table, coavoid_lcm_sender_t *entries,
                               size_t capacity)
{
    if (table == NULL) {
        return;
    }
    table->entries = entries;
    table->capacity = (entries != NULL) ? capacity : 0u;
    table->count = 0u;
}

int coavoid_lcm_sequence_accept(coavoid_lcm_sequence_table_t *table, uint32_t sender,
                                int64_t sequence, bool allow_equal)
{
    size_t i;
    if (table == NULL || table->count > table->capacity) {
        return COA_ERR_ARGUMENT;
    }
    for (i = 0; i < table->count; ++i) {
        if (table->entries[i].sender == sender) {
            int64_t last = table->entries[i].last;
            if (sequence < last || (sequence == last && !allow_equal)) {
                return COAVOID_LCM_ERR_SEQUENCE;
            }
            table->entries[i].last = sequence;
            return COA_OK;
        }
    }
    if (table->count == table->capacity) {
        return COAVOID_LCM_ERR_SENDERS;
    }
    table->entries[table->count].sender = sender;
    table->entries[table->count].last = sequence;
    table->count++;
    return COA_OK;
}

void coavoid_lcm_sequence_forget(coavoid_lcm_sequence_table_t *table, uint32_t sender)
{
    size_t i;
    if (table == NULL || table->count > table->capacity) {
        return;
    }
    for (i = 0; i < table->count; ++i) {
        if (table->entries[i].sender == sender) {
            table->entries[i] = table->entries[table->count - 1u];
            table->count--;
            return;
        }
    }
}

const char *coavoid_lcm_error_name(int status)
{
    switch (status) {
    case COAVOID_LCM_ERR_DECODE:
        return "message does not decode";
    case COAVOID_LCM_ERR_NONFINITE:
        return "non-finite number";
    case COAVOID_LCM_ERR_VALUE:
        return "number out of range";
    case COAVOID_LCM_ERR_COUNT:
        return "count out of range";
    case COAVOID_LCM_ERR_ENUM:
        return "unknown enum value";
    case COAVOID_LCM_ERR_ID:
        return "invalid id";
    case COAVOID_LCM_ERR_TIME:
        return "bad time stamp";
    case COAVOID_LCM_ERR_SEQUENCE:
        return "sequence went backwards";
    case COAVOID_LCM_ERR_SENDERS:
        return "too many senders";
    case COAVOID_LCM_ERR_CAPACITY:
        return "output too small";
    case COAVOID_AUTH_ERR_UNSIGNED:
        return "auth: not signed";
    case COAVOID_AUTH_ERR_KEY:
        return "auth: signed by a key not in the trust list";
    case COAVOID_AUTH_ERR_SIGNATURE:
        return "auth: the signature does not verify";
    case COAVOID_AUTH_ERR_ROLE:
        return "auth: the key may not send this message";
    case COAVOID_AUTH_ERR_REPLAY:
        return "auth: not newer than the last from that key (a copy or a replay)";
    case COAVOID_AUTH_ERR_CLOCK:
        return "auth: signed at a time outside the receiver's window";
    case COAVOID_AUTH_ERR_TAG:
        return "auth: the fleet tag does not match (not from the fleet)";
    default:
        return coa_status_name(status);
    }
}

/* The sequence rule after a message passed its check. */
static int sequence_rule(coavoid_lcm_sequence_table_t *seq, int32_t sender, int64_t sequence,
                         bool allow_equal, const char **reason, const char *backwards,
                         const char *full)
{
    int rc;
    if (seq == NULL) {
        return COA_OK;
    }
    rc = coavoid_lcm_sequence_accept(seq, (uint32_t)sender, sequence, allow_equal);
    if (rc == COAVOID_LCM_ERR_SEQUENCE) {
        REJECT(rc, backwards);
    }
    if (rc == COAVOID_LCM_ERR_SENDERS) {
        REJECT(rc, full);
    }
    if (rc != COA_OK) {
        REJECT(rc, "sequence table invalid");
    }
    return COA_OK;
}

/* ---- intent ---- */

/* The position of sample j as the planner computes it (plan.c, vehicle_sweep): the
 * reference in core precision plus the offset times the core's climb step. */
static coa_vec3_t intent_position(const coa_vec3_t *reference, int32_t offset, coa_real_t dh)
{
    coa_vec3_t p = *reference;
    p.z += (coa_real_t)offset * dh;
    return p;
}

/* The vehicle a receiver builds from an intent, over `route`. One function for the check
 * and for to_core, so that what the check judges is what the planner gets. */
static coa_vehicle_t intent_vehicle(const coavoid_intent_t *msg, const coa_vec3_t *route,
                                    size_t route_count, int32_t initial_offset)
{
    coa_vehicle_t v;
    memset(&v, 0, sizeof v);
    v.id = (uint16_t)msg->uav_id;
    v.priority = (uint32_t)msg->priority;
    v.cruise_speed = (coa_real_t)msg->cruise_speed;
    v.climb_rate = (coa_real_t)msg->climb_rate;
    v.steep_factor = (uint32_t)msg->steep_factor;
    v.volume.radius = (coa_real_t)msg->radius;
    v.volume.half_height = (coa_real_t)msg->half_height;
    v.route = route;
    v.route_count = route_count;
    v.initial_offset = initial_offset;
    v.max_offset = msg->max_offset;
    return v;
}

/* The numbers the double rules accepted must still be usable once in core precision: a
 * speed or size of 1e-50 is positive in double and 0 in float, and a product of two tiny
 * factors can vanish in either. The core's own rules judge it (coa_vehicle_check over a
 * two-point probe route, the planner's deviation weight, a positive climb step), so a
 * receiver never gets a vehicle its planner refuses. */
static bool intent_core_numbers_ok(const coavoid_intent_t *msg)
{
    static const coa_vec3_t probe[2] = {{0, 0, 0}, {1, 0, 0}};
    coa_vehicle_t v = intent_vehicle(msg, probe, 2u, 0);
    coa_real_t step = (coa_real_t)msg->step;
    uint64_t weight;
    int exponent;
    return coa_vehicle_check(&v) == COA_OK &&
           coa_deviation_weights(&v, 1u, step, &weight, &exponent) == COA_OK &&
           coa_climb_step(&v, step) > (coa_real_t)0;
}

/* Whether the leg a -> b (core precision) is one coa_vehicle_check accepts: judged by it
 * rather than by comparing coordinates, since two points that differ by 1e-200 have a
 * horizontal length of 0 once squared. */
static bool intent_leg_ok(const coavoid_intent_t *msg, coa_vec3_t a, coa_vec3_t b)
{
    coa_vec3_t leg[2];
    coa_vehicle_t v;
    leg[0] = a;
    leg[1] = b;
    v = intent_vehicle(msg, leg, 2u, 0);
    return coa_vehicle_check(&v) == COA_OK;
}

/* The intent's header: times, ids, mode, position and velocity. */
static int intent_header_check(const coavoid_intent_t *msg, const coavoid_lcm_context_t *ctx,
                               const char **reason)
{
    int rc;
    if ((rc = utime_rule(msg->utime, ctx)) != COA_OK) {
        REJECT(rc, "intent: utime stale, in the future or not positive");
    }
    if (!id_ok(msg->uav_id)) {
        REJECT(COAVOID_LCM_ERR_ID, "intent: uav_id not in 1..65535");
    }
    if (msg->sequence < 0) {
        REJECT(COAVOID_LCM_ERR_VALUE, "intent: sequence negative");
    }
    if (msg->priority < 1) {
        REJECT(COAVOID_LCM_ERR_VALUE, "intent: priority < 1");
    }
    if (msg->mode != COAVOID_INTENT_T_MODE_CENTRALISED &&
        msg->mode != COAVOID_INTENT_T_MODE_DECOUPLED &&
        msg->mode != COAVOID_INTENT_T_MODE_REFERENCE) {
        REJECT(COAVOID_LCM_ERR_ENUM, "intent: unknown mode");
    }
    if ((rc = vec_rule(msg->position, COAVOID_LCM_MAX_COORDINATE)) != COA_OK) {
        REJECT(rc, "intent: position non-finite or out of range");
    }
    if ((rc = vec_rule(msg->velocity, COAVOID_LCM_MAX_SPEED)) != COA_OK) {
        REJECT(rc, "intent: velocity non-finite or out of range");
    }
    return COA_OK;
}

/* The vehicle the intent describes: volume, speeds, manoeuvre limits, the plan's time and
 * step, and the sample count. */
static int intent_vehicle_check(const coavoid_intent_t *msg, const coavoid_lcm_context_t *ctx,
                                const char **reason)
{
    int rc;
    if ((rc = size_rule(msg->radius, true)) != COA_OK) {
        REJECT(rc, "intent: radius not in (0, 1e5] m");
    }
    if ((rc = size_rule(msg->half_height, true)) != COA_OK) {
        REJECT(rc, "intent: half_height not in (0, 1e5] m");
    }
    if ((rc = number_rule(msg->cruise_speed, COAVOID_LCM_MAX_SPEED)) != COA_OK ||
        !(msg->cruise_speed > 0.0)) {
        REJECT(rc != COA_OK ? rc : COAVOID_LCM_ERR_VALUE,
               "intent: cruise_speed not in (0, 1e4] m/s");
    }
    if ((rc = number_rule(msg->climb_rate, COAVOID_LCM_MAX_SPEED)) != COA_OK ||
        !(msg->climb_rate > 0.0)) {
        REJECT(rc != COA_OK ? rc : COAVOID_LCM_ERR_VALUE, "intent: climb_rate not in (0, 1e4] m/s");
    }
    if (msg->steep_factor < 2 || msg->steep_factor > (int32_t)COA_MAX_STEEP_FACTOR) {
        REJECT(COAVOID_LCM_ERR_VALUE, "intent: steep_factor not in 2..10");
    }
    if (msg->max_offset < -1 || msg->max_offset > COA_MAX_OFFSET) {
        REJECT(COAVOID_LCM_ERR_VALUE, "intent: max_offset not in -1..32767");
    }
    if ((rc = related_time_rule(msg->plan_utime, msg->utime, ctx)) != COA_OK) {
        REJECT(rc, "intent: plan_utime not positive or too far from utime");
    }
    if ((rc = number_rule(msg->step, COAVOID_LCM_MAX_STEP)) != COA_OK || !(msg->step > 0.0)) {
        REJECT(rc != COA_OK ? rc : COAVOID_LCM_ERR_VALUE, "intent: step not in (0, 3600] s");
    }
    if (!intent_core_numbers_ok(msg)) {
        REJECT(COAVOID_LCM_ERR_VALUE,
               "intent: cruise_speed, climb_rate, step, radius or half_height "
               "vanishes in the core's precision");
    }
    if (msg->sample_count < 2 || msg->sample_count > COAVOID_INTENT_T_MAX_SAMPLES) {
        REJECT(COAVOID_LCM_ERR_COUNT, "intent: sample_count not in 2..MAX_SAMPLES");
    }
    return COA_OK;
}

/* The samples: reference points, offsets and the positions they plan. Positions and the
 * route rule are judged in the core's precision, as the planner and coa_vehicle_check
 * will see them. */
static int intent_samples_check(const coavoid_intent_t *msg, const char **reason)
{
    coa_vehicle_t v = intent_vehicle(msg, NULL, 0u, 0);
    coa_real_t dh = coa_climb_step(&v, (coa_real_t)msg->step);
    int32_t bound = (msg->max_offset >= 0) ? msg->max_offset : COA_MAX_OFFSET;
    coa_vec3_t previous = {0, 0, 0};
    int rc;
    for (int32_t j = 0; j < msg->sample_count; ++j) {
        coa_vec3_t r;
        coa_vec3_t p;
        int32_t o = msg->offsets[j];
        if ((rc = vec_rule(msg->reference[j], COAVOID_LCM_MAX_COORDINATE)) != COA_OK) {
            REJECT(rc, "intent: a reference point non-finite or out of range");
        }
        r = vec_of(msg->reference[j]);
        if (j > 0 && !intent_leg_ok(msg, previous, r)) {
            REJECT(COAVOID_LCM_ERR_VALUE,
                   "intent: consecutive reference points without horizontal separation");
        }
        if (o < -bound || o > bound) {
            REJECT(COAVOID_LCM_ERR_VALUE, "intent: an offset beyond max_offset or 32767");
        }
        if (j > 0) {
            int32_t d = o - msg->offsets[j - 1];
            if (d != 0 && d != 1 && d != -1 && d != msg->steep_factor && d != -msg->steep_factor) {
                REJECT(COAVOID_LCM_ERR_VALUE, "intent: consecutive offsets differ by no action");
            }
        }
        p = intent_position(&r, o, dh);
        if (!isfinite((double)p.z) || fabs((double)p.z) > COAVOID_LCM_MAX_COORDINATE) {
            REJECT(COAVOID_LCM_ERR_VALUE, "intent: a planned position out of range");
        }
        previous = r;
    }
    return COA_OK;
}

int coavoid_lcm_intent_check(const coavoid_intent_t *msg, const coavoid_lcm_context_t *ctx,
                             const char **reason)
{
    int rc;
    if (msg == NULL) {
        REJECT(COA_ERR_ARGUMENT, "intent: NULL");
    }
    if ((rc = intent_header_check(msg, ctx, reason)) != COA_OK ||
        (rc = intent_vehicle_check(msg, ctx, reason)) != COA_OK ||
        (rc = intent_samples_check(msg, reason)) != COA_OK) {
        return rc;
    }
    if ((rc = size_rule(msg->sigma_horizontal, false)) != COA_OK) {
        REJECT(rc, "intent: sigma_horizontal not in [0, 1e5] m");
    }
    if ((rc = size_rule(msg->sigma_vertical, false)) != COA_OK) {
        REJECT(rc, "intent: sigma_vertical not in [0, 1e5] m");
    }
    if (msg->rank < 0 || msg->rank > COAVOID_INTENT_T_MAX_RANK) {
        REJECT(COAVOID_LCM_ERR_VALUE, "intent: rank not in 0..MAX_RANK");
    }
    OK_REASON();
    return COA_OK;
}

int coavoid_lcm_intent_to_core(const coavoid_intent_t *msg, const coavoid_lcm_context_t *ctx,
                               coavoid_lcm_sequence_table_t *seq, coavoid_lcm_intent_info_t *info,
                               coa_vehicle_t *vehicle, coa_intent_plan_t *plan,
                               coavoid_lcm_intent_arrays_t *arrays, const char **reason)
{
    int rc;
    int32_t j;
    coa_real_t dh;
    if (info == NULL || vehicle == NULL || plan == NULL || arrays == NULL) {
        REJECT(COA_ERR_ARGUMENT, "intent: NULL output");
    }
    if ((rc = coavoid_lcm_intent_check(msg, ctx, reason)) != COA_OK) {
        return rc;
    }
    if (msg->sample_count > (int32_t)COAVOID_LCM_MAX_SAMPLES) {
        REJECT(COAVOID_LCM_ERR_CAPACITY, "intent: more samples than this receiver keeps");
    }
    if ((rc = sequence_rule(seq, msg->uav_id, msg->sequence, false, reason,
                            "intent: sequence not after the last one from this UAV",
                            "intent: sequence table full")) != COA_OK) {
        return rc;
    }
    *vehicle = intent_vehicle(msg, arrays->reference, (size_t)msg->sample_count, msg->offsets[0]);
    dh = coa_climb_step(vehicle, (coa_real_t)msg->step);
    for (j = 0; j < msg->sample_count; ++j) {
        arrays->reference[j] = vec_of(msg->reference[j]);
        arrays->offsets[j] = msg->offsets[j];
        arrays->samples[j] = intent_position(&arrays->reference[j], msg->offsets[j], dh);
    }
    memset(plan, 0, sizeof *plan);
    plan->id = (uint16_t)msg->uav_id;
    plan->volume = vehicle->volume;
    plan->t0 = core_time(msg->plan_utime, ctx);
    plan->step = (coa_real_t)msg->step;
    plan->samples = arrays->samples;
    plan->count = (size_t)msg->sample_count;
    plan->sigma_horizontal = (coa_real_t)msg->sigma_horizontal;
    plan->sigma_vertical = (coa_real_t)msg->sigma_vertical;
    info->utime = msg->utime;
    info->sequence = msg->sequence;
    info->mode = msg->mode;
    info->position = vec_of(msg->position);
    info->velocity = vec_of(msg->velocity);
    info->plan_utime = msg->plan_utime;
    info->step = (coa_real_t)msg->step;
    info->sigma_horizontal = plan->sigma_horizontal;
    info->sigma_vertical = plan->sigma_vertical;
    info->rank = msg->rank;
    OK_REASON();
    return COA_OK;
}

int coavoid_lcm_intent_from_core(const coa_vehicle_t *vehicle,
                                 const coavoid_lcm_intent_info_t *info, const coa_vec3_t *reference,
                                 const int32_t *offsets, size_t count,
                                 const coavoid_lcm_context_t *ctx, coavoid_intent_t *msg,
                                 const char **reason)
{
    size_t j;
    if (vehicle == NULL || info == NULL || msg == NULL || reference == NULL || offsets == NULL) {
        REJECT(COA_ERR_ARGUMENT, "intent: NULL argument");
    }
    if (count < 2u || count > (size_t)COAVOID_INTENT_T_MAX_SAMPLES) {
        REJECT(COAVOID_LCM_ERR_COUNT, "intent: sample count not in 2..MAX_SAMPLES");
    }
    if (vehicle->priority > (uint32_t)INT32_MAX || vehicle->steep_factor > (uint32_t)INT32_MAX) {
        REJECT(COAVOID_LCM_ERR_VALUE, "intent: priority or steep factor too large");
    }
    memset(msg, 0, sizeof *msg);
    msg->utime = info->utime;
    msg->uav_id = vehicle->id;
    msg->sequence = info->sequence;
    msg->priority = (int32_t)vehicle->priority;
    msg->mode = info->mode;
    vec_to(info->position, msg->position);
    vec_to(info->velocity, msg->velocity);
    msg->radius = (double)vehicle->volume.radius;
    msg->half_height = (double)vehicle->volume.half_height;
    msg->cruise_speed = (double)vehicle->cruise_speed;
    msg->climb_rate = (double)vehicle->climb_rate;
    msg->steep_factor = (int32_t)vehicle->steep_factor;
    msg->max_offset = (vehicle->max_offset < 0) ? -1 : vehicle->max_offset;
    msg->plan_utime = info->plan_utime;
    msg->step = (double)info->step;
    msg->sample_count = (int32_t)count;
    for (j = 0; j < count; ++j) {
        vec_to(reference[j], msg->reference[j]);
        msg->offsets[j] = offsets[j];
    }
    msg->sigma_horizontal = (double)info->sigma_horizontal;
    msg->sigma_vertical = (double)info->sigma_vertical;
    msg->rank = info->rank;
    return coavoid_lcm_intent_check(msg, ctx, reason);
}

/* ---- plan ---- */

/* The plan's header: times, ids, horizon, mode, status and its costs. */
static int plan_header_check(const coavoid_plan_t *msg, const coavoid_lcm_context_t *ctx,
                             const char **reason)
{
    int rc;
    if ((rc = utime_rule(msg->utime, ctx)) != COA_OK) {
        REJECT(rc, "plan: utime stale, in the future or not positive");
    }
    if (!id_ok(msg->coordinator_id)) {
        REJECT(COAVOID_LCM_ERR_ID, "plan: coordinator_id not in 1..65535");
    }
    if (msg->plan_id < 0) {
        REJECT(COAVOID_LCM_ERR_VALUE, "plan: plan_id negative");
    }
    if ((rc = related_time_rule(msg->valid_from_utime, msg->utime, ctx)) != COA_OK) {
        REJECT(rc, "plan: valid_from_utime not positive or too far from utime");
    }
    if (msg->valid_until_utime <= msg->valid_from_utime ||
        related_time_rule(msg->valid_until_utime, msg->utime, ctx) != COA_OK) {
        REJECT(COAVOID_LCM_ERR_TIME,
               "plan: valid_until_utime not after valid_from_utime or too far");
    }
    if ((rc = number_rule(msg->dt, COAVOID_LCM_MAX_STEP)) != COA_OK || !(msg->dt > 0.0)) {
        REJECT(rc != COA_OK ? rc : COAVOID_LCM_ERR_VALUE, "plan: dt not in (0, 3600] s");
    }
    if (msg->horizon < 1 || msg->horizon > COAVOID_PLAN_T_MAX_SAMPLES - 1) {
        REJECT(COAVOID_LCM_ERR_COUNT, "plan: horizon not in 1..MAX_SAMPLES-1");
    }
    if (msg->mode != COAVOID_PLAN_T_MODE_CENTRALISED &&
        msg->mode != COAVOID_PLAN_T_MODE_DECOUPLED) {
        REJECT(COAVOID_LCM_ERR_ENUM, "plan: unknown mode");
    }
    if (msg->status != COAVOID_PLAN_T_STATUS_SOLVED &&
        msg->status != COAVOID_PLAN_T_STATUS_INFEASIBLE &&
        msg->status != COAVOID_PLAN_T_STATUS_BUDGET_EXHAUSTED &&
        msg->status != COAVOID_PLAN_T_STATUS_ABANDONED) {
        REJECT(COAVOID_LCM_ERR_ENUM, "plan: unknown status");
    }
    if ((rc = number_rule(msg->deviation, 1.0e300)) != COA_OK || msg->deviation < 0.0) {
        REJECT(rc != COA_OK ? rc : COAVOID_LCM_ERR_VALUE, "plan: deviation negative or non-finite");
    }
    if (msg->effort < 0) {
        REJECT(COAVOID_LCM_ERR_VALUE, "plan: effort negative");
    }
    if (msg->nodes_expanded < 0) {
        REJECT(COAVOID_LCM_ERR_VALUE, "plan: nodes_expanded negative");
    }
    return COA_OK;
}

/* The plan's vehicles: counts and ids (each once). */
static int plan_vehicles_check(const coavoid_plan_t *msg, const char **reason)
{
    int32_t i;
    int32_t j;
    if (msg->vehicle_count < 1 || msg->vehicle_count > COAVOID_PLAN_T_MAX_VEHICLES) {
        REJECT(COAVOID_LCM_ERR_COUNT, "plan: vehicle_count not in 1..MAX_VEHICLES");
    }
    if (msg->planned_count < 0 || msg->planned_count > msg->vehicle_count ||
        (msg->status == COAVOID_PLAN_T_STATUS_SOLVED && msg->planned_count != msg->vehicle_count) ||
        (msg->status == COAVOID_PLAN_T_STATUS_ABANDONED && msg->planned_count != 0)) {
        REJECT(
            COAVOID_LCM_ERR_COUNT,
            "plan: planned_count not in 0..vehicle_count (all when solved, none when abandoned)");
    }
    for (i = 0; i < msg->vehicle_count; ++i) {
        if (!id_ok(msg->uav_ids[i])) {
            REJECT(COAVOID_LCM_ERR_ID, "plan: a uav_id not in 1..65535");
        }
        for (j = 0; j < i; ++j) {
            if (msg->uav_ids[j] == msg->uav_ids[i]) {
                REJECT(COAVOID_LCM_ERR_ID, "plan: a uav_id repeated");
            }
        }
    }
    return COA_OK;
}

/* Where the row's UAV is in uav_ids, or -1. */
static int32_t plan_row_index(const coavoid_plan_t *msg)
{
    int32_t i;
    for (i = 0; i < msg->vehicle_count && i < COAVOID_PLAN_T_MAX_VEHICLES; ++i) {
        if (msg->uav_ids[i] == msg->row_uav_id) {
            return i;
        }
    }
    return -1;
}

/* The message's row: a listed UAV; a plan's offsets each within the bound and each step
 * one that some action makes; no offsets at all when its UAV has no plan. */
static int plan_row_check(const coavoid_plan_t *msg, const char **reason)
{
    int32_t k;
    const int32_t row = plan_row_index(msg);
    if (row < 0) {
        REJECT(COAVOID_LCM_ERR_ID, "plan: row_uav_id is not one of uav_ids");
    }
    for (k = 0; k < COAVOID_PLAN_T_MAX_SAMPLES; ++k) {
        int32_t o = msg->offsets[k];
        if (row >= msg->planned_count || k > msg->horizon) {
            if (o != 0) {
                REJECT(COAVOID_LCM_ERR_VALUE,
                       "plan: offsets where there is no plan (a UAV not planned, past horizon)");
            }
            continue;
        }
        if (o > COA_MAX_OFFSET || o < -COA_MAX_OFFSET) {
            REJECT(COAVOID_LCM_ERR_VALUE, "plan: an offset beyond COA_MAX_OFFSET");
        }
        /* No action moves more than the largest steep factor in one step. */
        if (k > 0) {
            int32_t d = o - msg->offsets[k - 1];
            if (d > (int32_t)COA_MAX_STEEP_FACTOR || d < -(int32_t)COA_MAX_STEEP_FACTOR) {
                REJECT(COAVOID_LCM_ERR_VALUE, "plan: an offset step no action makes");
            }
        }
    }
    return COA_OK;
}

int coavoid_lcm_plan_check(const coavoid_plan_t *msg, const coavoid_lcm_context_t *ctx,
                           const char **reason)
{
    int rc;
    if (msg == NULL) {
        REJECT(COA_ERR_ARGUMENT, "plan: NULL");
    }
    if ((rc = plan_header_check(msg, ctx, reason)) != COA_OK ||
        (rc = plan_vehicles_check(msg, reason)) != COA_OK ||
        (rc = plan_row_check(msg, reason)) != COA_OK) {
        return rc;
    }
    OK_REASON();
    return COA_OK;
}

void coavoid_lcm_plan_rows_init(coavoid_lcm_plan_rows_t *rows, coavoid_lcm_plan_slot_t *slots,
                                size_t capacity)
{
    size_t i;
    rows->slots = slots;
    rows->capacity = capacity;
    for (i = 0; i < capacity; ++i) {
        slots[i].used = false;
        slots[i].have = 0u;
    }
}

/* Whether two rows' messages say the same of their plan (everything but utime, the row
 * and auth). */
static bool plan_same_header(const coavoid_plan_t *a, const coavoid_plan_t *b)
{
    int32_t i;
    if (a->coordinator_id != b->coordinator_id || a->plan_id != b->plan_id ||
        a->valid_from_utime != b->valid_from_utime ||
        a->valid_until_utime != b->valid_until_utime || a->dt != b->dt ||
        a->horizon != b->horizon || a->mode != b->mode || a->status != b->status ||
        a->deviation != b->deviation || a->effort != b->effort ||
        a->nodes_expanded != b->nodes_expanded || a->vehicle_count != b->vehicle_count ||
        a->planned_count != b->planned_count) {
        return false;
    }
    for (i = 0; i < a->vehicle_count; ++i) {
        if (a->uav_ids[i] != b->uav_ids[i]) {
            return false;
        }
    }
    return true;
}

/* The slot collecting msg's plan (coordinator, plan_id, valid_from); else a free one; else
 * the one with the oldest plan (valid_from, then plan_id), which is dropped. */
static coavoid_lcm_plan_slot_t *plan_slot(coavoid_lcm_plan_rows_t *rows, const coavoid_plan_t *msg)
{
    size_t i;
    coavoid_lcm_plan_slot_t *free_slot = NULL;
    coavoid_lcm_plan_slot_t *oldest = &rows->slots[0];
    for (i = 0; i < rows->capacity; ++i) {
        coavoid_lcm_plan_slot_t *s = &rows->slots[i];
        if (!s->used) {
            free_slot = (free_slot == NULL) ? s : free_slot;
            continue;
        }
        if (s->first.coordinator_id == msg->coordinator_id && s->first.plan_id == msg->plan_id &&
            s->first.valid_from_utime == msg->valid_from_utime) {
            return s;
        }
        if (oldest->used && (s->first.valid_from_utime < oldest->first.valid_from_utime ||
                             (s->first.valid_from_utime == oldest->first.valid_from_utime &&
                              s->first.plan_id < oldest->first.plan_id))) {
            oldest = s;
        }
    }
    return (free_slot != NULL) ? free_slot : oldest;
}

/* A complete plan in the core's terms, as one message of the whole cluster would give it. */
static void plan_complete(const coavoid_lcm_plan_slot_t *s, const coavoid_lcm_context_t *ctx,
                          coavoid_lcm_plan_info_t *info, coa_plan_result_t *result,
                          int32_t *offsets)
{
    const coavoid_plan_t *msg = &s->first;
    const size_t n = (size_t)msg->vehicle_count;
    const size_t samples = (size_t)msg->horizon + 1u;
    size_t i;
    size_t k;
    memset(info, 0, sizeof *info);
    memset(result, 0, sizeof *result);
    info->utime = msg->utime;
    info->coordinator_id = (uint32_t)msg->coordinator_id;
    info->plan_id = msg->plan_id;
    info->valid_from = core_time(msg->valid_from_utime, ctx);
    info->valid_until = core_time(msg->valid_until_utime, ctx);
    info->dt = (coa_real_t)msg->dt;
    info->horizon = (uint32_t)msg->horizon;
    info->mode = msg->mode;
    info->vehicle_count = n;
    for (i = 0; i < n; ++i) {
        info->uav_ids[i] = (uint16_t)msg->uav_ids[i];
        result->order[i] = i;
        for (k = 0; k < samples; ++k) {
            offsets[i * samples + k] = s->offsets[i][k];
        }
    }
    info->abandoned = msg->status == COAVOID_PLAN_T_STATUS_ABANDONED;
    result->status = info->abandoned ? COA_PLAN_BUDGET_EXHAUSTED : (coa_plan_status_t)msg->status;
    result->deviation = msg->deviation;
    result->effort = (uint32_t)msg->effort;
    result->nodes_expanded = (uint64_t)msg->nodes_expanded;
    result->planned_count = (size_t)msg->planned_count;
    result->failed_vehicle = (result->planned_count < n) ? result->planned_count : COA_NO_VEHICLE;
}

int coavoid_lcm_plan_collect(coavoid_lcm_plan_rows_t *rows, const coavoid_plan_t *msg,
                             const coavoid_lcm_context_t *ctx, const coavoid_plan_t **whole,
                             coavoid_lcm_plan_info_t *info, coa_plan_result_t *result,
                             int32_t *offsets, size_t capacity, const char **reason)
{
    int rc;
    int32_t row;
    coavoid_lcm_plan_slot_t *s;
    if (rows == NULL || rows->slots == NULL || rows->capacity == 0u || whole == NULL ||
        info == NULL || result == NULL || offsets == NULL) {
        REJECT(COA_ERR_ARGUMENT, "plan: NULL output");
    }
    *whole = NULL;
    if ((rc = coavoid_lcm_plan_check(msg, ctx, reason)) != COA_OK) {
        return rc;
    }
    if ((size_t)msg->vehicle_count * ((size_t)msg->horizon + 1u) > capacity) {
        REJECT(COAVOID_LCM_ERR_CAPACITY, "plan: more offsets than the caller's array holds");
    }
    if (msg->vehicle_count > (int32_t)COAVOID_LCM_PLAN_ROWS) {
        REJECT(COAVOID_LCM_ERR_CAPACITY, "plan: more UAVs than this receiver collects");
    }
    if (msg->horizon >= (int32_t)COAVOID_LCM_MAX_SAMPLES) {
        REJECT(COAVOID_LCM_ERR_CAPACITY, "plan: a longer horizon than this receiver keeps");
    }
    s = plan_slot(rows, msg);
    if (s->used && s->first.plan_id == msg->plan_id &&
        s->first.coordinator_id == msg->coordinator_id &&
        s->first.valid_from_utime == msg->valid_from_utime && !plan_same_header(&s->first, msg)) {
        REJECT(COAVOID_LCM_ERR_VALUE, "plan: a row that disagrees with its plan's other rows");
    }
    if (!s->used || s->first.plan_id != msg->plan_id ||
        s->first.coordinator_id != msg->coordinator_id ||
        s->first.valid_from_utime != msg->valid_from_utime) {
        s->used = true;
        s->first = *msg;
        s->have = 0u;
    }
    row = plan_row_index(msg);
    memcpy(s->offsets[row], msg->offsets, sizeof s->offsets[row]);
    s->have |= UINT32_C(1) << (uint32_t)row;
    if (s->have == (UINT32_MAX >> (32u - (uint32_t)msg->vehicle_count))) {
        plan_complete(s, ctx, info, result, offsets);
        s->used = false;
        *whole = &s->first;
    }
    OK_REASON();
    return COA_OK;
}

int coavoid_lcm_plan_from_core(const coavoid_lcm_plan_info_t *info, const coa_plan_result_t *result,
                               const int32_t *offsets, size_t row, const coavoid_lcm_context_t *ctx,
                               coavoid_plan_t *msg, const char **reason)
{
    size_t i;
    size_t k;
    size_t n;
    size_t samples;
    if (info == NULL || result == NULL || offsets == NULL || msg == NULL) {
        REJECT(COA_ERR_ARGUMENT, "plan: NULL argument");
    }
    n = info->vehicle_count;
    if (n < 1u || n > (size_t)COAVOID_PLAN_T_MAX_VEHICLES || result->planned_count > n ||
        row >= n) {
        REJECT(COAVOID_LCM_ERR_COUNT, "plan: vehicle_count not in 1..MAX_VEHICLES, or no such row");
    }
    if (info->horizon < 1u || info->horizon > (uint32_t)COAVOID_PLAN_T_MAX_SAMPLES - 1u) {
        REJECT(COAVOID_LCM_ERR_COUNT, "plan: horizon not in 1..MAX_SAMPLES-1");
    }
    if (result->effort > (uint32_t)INT32_MAX || result->nodes_expanded > (uint64_t)INT64_MAX ||
        info->coordinator_id > (uint32_t)COAVOID_LCM_MAX_ID) {
        REJECT(COAVOID_LCM_ERR_VALUE, "plan: a number too large for the message");
    }
    samples = (size_t)info->horizon + 1u;
    memset(msg, 0, sizeof *msg);
    msg->utime = info->utime;
    msg->coordinator_id = (int32_t)info->coordinator_id;
    msg->plan_id = info->plan_id;
    msg->valid_from_utime = utime_of(info->valid_from, ctx);
    msg->valid_until_utime = utime_of(info->valid_until, ctx);
    msg->dt = (double)info->dt;
    msg->horizon = (int32_t)info->horizon;
    msg->mode = info->mode;
    msg->status = info->abandoned ? COAVOID_PLAN_T_STATUS_ABANDONED : (int8_t)result->status;
    msg->deviation = result->deviation;
    msg->effort = (int32_t)result->effort;
    msg->nodes_expanded = (int64_t)result->nodes_expanded;
    msg->vehicle_count = (int32_t)n;
    msg->planned_count = info->abandoned ? 0 : (int32_t)result->planned_count;
    for (i = 0; i < n; ++i) {
        size_t v = result->order[i];
        if (v >= n) {
            REJECT(COA_ERR_ARGUMENT, "plan: result order names no vehicle");
        }
        msg->uav_ids[i] = info->uav_ids[v];
        if (i == row) {
            msg->row_uav_id = msg->uav_ids[i];
            for (k = 0; i < (size_t)msg->planned_count && k < samples; ++k) {
                msg->offsets[k] = offsets[v * samples + k];
            }
        }
    }
    return coavoid_lcm_plan_check(msg, ctx, reason);
}

/* ---- track ---- */

int coavoid_lcm_track_check(const coavoid_track_t *msg, const coavoid_lcm_context_t *ctx,
                            const char **reason)
{
    int rc;
    int32_t j;
    if (msg == NULL) {
        REJECT(COA_ERR_ARGUMENT, "track: NULL");
    }
    if ((rc = utime_rule(msg->utime, ctx)) != COA_OK) {
        REJECT(rc, "track: utime stale, in the future or not positive");
    }
    if (!id_ok(msg->source_id)) {
        REJECT(COAVOID_LCM_ERR_ID, "track: source_id not in 1..65535");
    }
    if (msg->sequence < 0) {
        REJECT(COAVOID_LCM_ERR_VALUE, "track: sequence negative");
    }
    if (msg->track_id < 1) {
        REJECT(COAVOID_LCM_ERR_ID, "track: track_id < 1");
    }
    if ((rc = related_time_rule(msg->estimate_utime, msg->utime, ctx)) != COA_OK) {
        REJECT(rc, "track: estimate_utime not positive or too far from utime");
    }
    if ((rc = vec_rule(msg->position, COAVOID_LCM_MAX_COORDINATE)) != COA_OK) {
        REJECT(rc, "track: position non-finite or out of range");
    }
    if ((rc = vec_rule(msg->velocity, COAVOID_LCM_MAX_SPEED)) != COA_OK) {
        REJECT(rc, "track: velocity non-finite or out of range");
    }
    if ((rc = size_rule(msg->radius, true)) != COA_OK) {
        REJECT(rc, "track: radius not in (0, 1e5] m");
    }
    if ((rc = size_rule(msg->half_height, true)) != COA_OK) {
        REJECT(rc, "track: half_height not in (0, 1e5] m");
    }
    if (msg->path_count < 0 || msg->path_count > COAVOID_TRACK_T_MAX_PATH) {
        REJECT(COAVOID_LCM_ERR_COUNT, "track: path_count not in 0..MAX_PATH");
    }
    for (j = 0; j < msg->path_count; ++j) {
        if (related_time_rule(msg->path_utime[j], msg->utime, ctx) != COA_OK) {
            REJECT(COAVOID_LCM_ERR_TIME, "track: a path time not positive or too far from utime");
        }
        if (j > 0 && msg->path_utime[j] <= msg->path_utime[j - 1]) {
            REJECT(COAVOID_LCM_ERR_TIME, "track: path times not strictly ascending");
        }
        if ((rc = vec_rule(msg->path[j], COAVOID_LCM_MAX_COORDINATE)) != COA_OK) {
            REJECT(rc, "track: a path point non-finite or out of range");
        }
    }
    if ((rc = size_rule(msg->sigma_horizontal, false)) != COA_OK) {
        REJECT(rc, "track: sigma_horizontal not in [0, 1e5] m");
    }
    if ((rc = size_rule(msg->sigma_vertical, false)) != COA_OK) {
        REJECT(rc, "track: sigma_vertical not in [0, 1e5] m");
    }
    OK_REASON();
    return COA_OK;
}

int coavoid_lcm_track_to_core(const coavoid_track_t *msg, const coavoid_lcm_context_t *ctx,
                              coavoid_lcm_sequence_table_t *seq, coavoid_lcm_track_info_t *info,
                              coa_track_t *track, coa_track_point_t *path, size_t capacity,
                              const char **reason)
{
    int rc;
    int32_t j;
    double tau;
    if (info == NULL || track == NULL || (path == NULL && capacity > 0u)) {
        REJECT(COA_ERR_ARGUMENT, "track: NULL output");
    }
    if ((rc = coavoid_lcm_track_check(msg, ctx, reason)) != COA_OK) {
        return rc;
    }
    if ((size_t)msg->path_count > capacity) {
        REJECT(COAVOID_LCM_ERR_CAPACITY, "track: more path points than the caller's array holds");
    }
    /* The core predicts from position at t = 0 of its clock: move the estimate there.
     * Both the epoch and the estimate are caller-bounded, so this stays finite. */
    tau = (double)core_time(msg->estimate_utime, ctx);
    {
        double p[3];
        int a;
        for (a = 0; a < 3; ++a) {
            p[a] = msg->position[a] - msg->velocity[a] * tau;
            if (!isfinite(p[a])) {
                REJECT(COAVOID_LCM_ERR_VALUE, "track: position at the core epoch overflows");
            }
        }
        track->position = vec_of(p);
    }
    if ((rc = sequence_rule(seq, msg->source_id, msg->sequence, false, reason,
                            "track: sequence not after the last one from this source",
                            "track: sequence table full")) != COA_OK) {
        return rc;
    }
    for (j = 0; j < msg->path_count; ++j) {
        path[j].t = core_time(msg->path_utime[j], ctx);
        path[j].p = vec_of(msg->path[j]);
    }
    track->id = (uint32_t)msg->track_id;
    track->volume.radius = (coa_real_t)msg->radius;
    track->volume.half_height = (coa_real_t)msg->half_height;
    track->velocity = vec_of(msg->velocity);
    track->path = (msg->path_count > 0) ? path : NULL;
    track->path_count = (size_t)msg->path_count;
    track->sigma_horizontal = (coa_real_t)msg->sigma_horizontal;
    track->sigma_vertical = (coa_real_t)msg->sigma_vertical;
    info->utime = msg->utime;
    info->source_id = (uint32_t)msg->source_id;
    info->sequence = msg->sequence;
    OK_REASON();
    return COA_OK;
}

int coavoid_lcm_track_from_core(const coa_track_t *track, const coavoid_lcm_track_info_t *info,
                                const coavoid_lcm_context_t *ctx, coavoid_track_t *msg,
                                const char **reason)
{
    size_t j;
    if (track == NULL || info == NULL || msg == NULL ||
        (track->path == NULL && track->path_count > 0u)) {
        REJECT(COA_ERR_ARGUMENT, "track: NULL argument");
    }
    if (track->path_count > (size_t)COAVOID_TRACK_T_MAX_PATH) {
        REJECT(COAVOID_LCM_ERR_COUNT, "track: path_count not in 0..MAX_PATH");
    }
    if (track->id > (uint32_t)INT32_MAX || info->source_id > (uint32_t)COAVOID_LCM_MAX_ID) {
        REJECT(COAVOID_LCM_ERR_ID, "track: id too large for the message");
    }
    memset(msg, 0, sizeof *msg);
    msg->utime = info->utime;
    msg->source_id = (int32_t)info->source_id;
    msg->sequence = info->sequence;
    msg->track_id = (int32_t)track->id;
    /* The core's position is at its t = 0: publish it as an estimate at the epoch. */
    msg->estimate_utime = (ctx != NULL) ? ctx->epoch_utime : 0;
    vec_to(track->position, msg->position);
    vec_to(track->velocity, msg->velocity);
    msg->radius = (double)track->volume.radius;
    msg->half_height = (double)track->volume.half_height;
    msg->path_count = (int32_t)track->path_count;
    for (j = 0; j < track->path_count; ++j) {
        msg->path_utime[j] = utime_of(track->path[j].t, ctx);
        vec_to(track->path[j].p, msg->path[j]);
    }
    msg->sigma_horizontal = (double)track->sigma_horizontal;
    msg->sigma_vertical = (double)track->sigma_vertical;
    return coavoid_lcm_track_check(msg, ctx, reason);
}

/* ---- obstacle map ---- */

/* One tile's polytopes: counts within the tile's capacity, every vertex finite and within
 * range. */
static int map_polytopes_check(const coavoid_obstacle_map_t *msg, const char **reason)
{
    int32_t i;
    int32_t j;
    int32_t used = 0;
    int rc;
    if (msg->polytope_count < 0 || msg->polytope_count > COAVOID_OBSTACLE_MAP_T_MAX_POLYTOPES) {
        REJECT(COAVOID_LCM_ERR_COUNT, "obstacle_map: polytope_count not in 0..MAX_POLYTOPES");
    }
    for (i = 0; i < msg->polytope_count; ++i) {
        if (msg->vertex_count[i] < 4 ||
            msg->vertex_count[i] > COAVOID_OBSTACLE_MAP_T_MAX_VERTICES - used) {
            REJECT(COAVOID_LCM_ERR_COUNT,
                   "obstacle_map: a vertex_count below 4, or the tile's beyond MAX_VERTICES");
        }
        used += msg->vertex_count[i];
    }
    for (j = 0; j < used; ++j) {
        if ((rc = vec_rule(msg->vertices[j], COAVOID_LCM_MAX_COORDINATE)) != COA_OK) {
            REJECT(rc, "obstacle_map: a vertex non-finite or out of range");
        }
    }
    return COA_OK;
}

int coavoid_lcm_obstacle_map_check(const coavoid_obstacle_map_t *msg,
                                   const coavoid_lcm_context_t *ctx, const char **reason)
{
    int rc;
    int32_t i;
    int a;
    if (msg == NULL) {
        REJECT(COA_ERR_ARGUMENT, "obstacle_map: NULL");
    }
    /* A map is latched and long-lived: only positivity, not age, applies to utime. */
    if (msg->utime <= 0) {
        REJECT(COAVOID_LCM_ERR_TIME, "obstacle_map: utime not positive");
    }
    if (ctx != NULL && ctx->now_utime > 0 && ctx->max_future_us >= 0 &&
        msg->utime > ctx->now_utime && msg->utime - ctx->now_utime > ctx->max_future_us) {
        REJECT(COAVOID_LCM_ERR_TIME, "obstacle_map: utime in the future");
    }
    if (!id_ok(msg->map_id)) {
        REJECT(COAVOID_LCM_ERR_ID, "obstacle_map: map_id not in 1..65535");
    }
    if (msg->version < 0) {
        REJECT(COAVOID_LCM_ERR_VALUE, "obstacle_map: version negative");
    }
    if (msg->tile_count < 1 || msg->tile_count > COAVOID_OBSTACLE_MAP_T_MAX_TILES) {
        REJECT(COAVOID_LCM_ERR_COUNT, "obstacle_map: tile_count not in 1..MAX_TILES");
    }
    if (msg->tile_index < 0 || msg->tile_index >= msg->tile_count) {
        REJECT(COAVOID_LCM_ERR_COUNT, "obstacle_map: tile_index not in 0..tile_count-1");
    }
    if (msg->box_count < 0 || msg->box_count > COAVOID_OBSTACLE_MAP_T_MAX_BOXES) {
        REJECT(COAVOID_LCM_ERR_COUNT, "obstacle_map: box_count not in 0..MAX_BOXES");
    }
    for (i = 0; i < msg->box_count; ++i) {
        if ((rc = vec_rule(msg->box_min[i], COAVOID_LCM_MAX_COORDINATE)) != COA_OK ||
            (rc = vec_rule(msg->box_max[i], COAVOID_LCM_MAX_COORDINATE)) != COA_OK) {
            REJECT(rc, "obstacle_map: a box corner non-finite or out of range");
        }
        for (a = 0; a < 3; ++a) {
            if (msg->box_min[i][a] > msg->box_max[i][a]) {
                REJECT(COAVOID_LCM_ERR_VALUE, "obstacle_map: a box with min > max");
            }
        }
    }
    if ((rc = map_polytopes_check(msg, reason)) != COA_OK) {
        return rc;
    }
    OK_REASON();
    return COA_OK;
}

int coavoid_lcm_obstacle_map_accept(const coavoid_obstacle_map_t *msg,
                                    const coavoid_lcm_context_t *ctx,
                                    coavoid_lcm_sequence_table_t *seq, const char **reason)
{
    int rc;
    if ((rc = coavoid_lcm_obstacle_map_check(msg, ctx, reason)) != COA_OK) {
        return rc;
    }
    if ((rc = sequence_rule(seq, msg->map_id, msg->version, true, reason,
                            "obstacle_map: version lower than one already seen",
                            "obstacle_map: sequence table full")) != COA_OK) {
        return rc;
    }
    OK_REASON();
    return COA_OK;
}

/* Whether tiles[0..n) are tiles 0..n-1 of one map version of n tiles, within the map's
 * capacity and the caller's. */
static int map_tiles_check(const coavoid_obstacle_map_t *tiles, size_t n,
                           const coavoid_lcm_context_t *ctx, size_t capacity,
                           size_t vertex_capacity, const char **reason)
{
    size_t t;
    int32_t i;
    int rc;
    size_t boxes = 0;
    size_t polytopes = 0;
    size_t vertices = 0;
    if (n < 1u || n > (size_t)COAVOID_OBSTACLE_MAP_T_MAX_TILES) {
        REJECT(COAVOID_LCM_ERR_COUNT, "obstacle_map: tile_count not in 1..MAX_TILES");
    }
    for (t = 0; t < n; ++t) {
        if ((rc = coavoid_lcm_obstacle_map_check(&tiles[t], ctx, reason)) != COA_OK) {
            return rc;
        }
        if (tiles[t].tile_index != (int32_t)t || tiles[t].tile_count != (int32_t)n ||
            tiles[t].map_id != tiles[0].map_id || tiles[t].version != tiles[0].version) {
            REJECT(COAVOID_LCM_ERR_COUNT,
                   "obstacle_map: tiles not 0..tile_count-1 of one map_id and version");
        }
        boxes += (size_t)tiles[t].box_count;
        polytopes += (size_t)tiles[t].polytope_count;
        for (i = 0; i < tiles[t].polytope_count; ++i) {
            vertices += (size_t)tiles[t].vertex_count[i];
        }
    }
    if (boxes > (size_t)COAVOID_OBSTACLE_MAP_T_MAX_MAP_BOXES ||
        polytopes > (size_t)COAVOID_OBSTACLE_MAP_T_MAX_MAP_POLYTOPES) {
        REJECT(COAVOID_LCM_ERR_COUNT,
               "obstacle_map: more than MAX_MAP_BOXES boxes or MAX_MAP_POLYTOPES polytopes");
    }
    if (boxes + polytopes > capacity || vertices > vertex_capacity) {
        REJECT(COAVOID_LCM_ERR_CAPACITY,
               "obstacle_map: more obstacles than the caller's arrays hold");
    }
    return COA_OK;
}

int coavoid_lcm_obstacle_map_to_core(const coavoid_obstacle_map_t *tiles, size_t tile_count,
                                     const coavoid_lcm_context_t *ctx, coa_obstacle_t *obstacles,
                                     size_t capacity, size_t *count, coa_vec3_t *vertices,
                                     size_t vertex_capacity, const char **reason)
{
    int rc;
    size_t t;
    int32_t i;
    int32_t j;
    size_t n = 0;
    size_t used = 0;
    if (tiles == NULL || obstacles == NULL || count == NULL ||
        (vertices == NULL && vertex_capacity > 0u)) {
        REJECT(COA_ERR_ARGUMENT, "obstacle_map: NULL argument");
    }
    if ((rc = map_tiles_check(tiles, tile_count, ctx, capacity, vertex_capacity, reason)) !=
        COA_OK) {
        return rc;
    }
    /* Every box, then every polytope, in tile order: the order the world's list had. */
    for (t = 0; t < tile_count; ++t) {
        for (i = 0; i < tiles[t].box_count; ++i, ++n) {
            memset(&obstacles[n], 0, sizeof obstacles[n]);
            obstacles[n].kind = COA_OBSTACLE_BOX;
            obstacles[n].box.min = vec_of(tiles[t].box_min[i]);
            obstacles[n].box.max = vec_of(tiles[t].box_max[i]);
        }
    }
    for (t = 0; t < tile_count; ++t) {
        int32_t k = 0;
        for (i = 0; i < tiles[t].polytope_count; ++i, ++n) {
            memset(&obstacles[n], 0, sizeof obstacles[n]);
            obstacles[n].kind = COA_OBSTACLE_POLYTOPE;
            obstacles[n].polytope.vertices = &vertices[used];
            obstacles[n].polytope.count = (size_t)tiles[t].vertex_count[i];
            for (j = 0; j < tiles[t].vertex_count[i]; ++j) {
                vertices[used++] = vec_of(tiles[t].vertices[k++]);
            }
        }
    }
    *count = n;
    OK_REASON();
    return COA_OK;
}

/* The tiling of a list of obstacles: box b goes to tile b / MAX_BOXES (b counting boxes
 * only); polytopes fill tiles in order, the next tile when MAX_POLYTOPES or MAX_VERTICES
 * would be passed. So the boxes, then the polytopes, of tiles 0, 1, ... are the list's in
 * its order. *tile_of[i] is obstacle i's tile. Returns the tile count (>= 1), or a
 * negative refusal. */
static int map_tiling(const coa_obstacle_t *obstacles, size_t count, int32_t *tile_of,
                      const char **reason)
{
    size_t i;
    int32_t boxes = 0;
    int32_t polys = 0;
    int32_t poly_tile = 0;
    int32_t poly_in_tile = 0;
    int32_t vertices_in_tile = 0;
    int32_t tiles = 1;
    for (i = 0; i < count; ++i) {
        const coa_obstacle_t *o = &obstacles[i];
        if (o->kind == COA_OBSTACLE_BOX) {
            tile_of[i] = boxes++ / COAVOID_OBSTACLE_MAP_T_MAX_BOXES;
        } else if (o->kind == COA_OBSTACLE_POLYTOPE) {
            if (o->polytope.count > (size_t)COAVOID_OBSTACLE_MAP_T_MAX_VERTICES ||
                o->polytope.vertices == NULL) {
                REJECT(COAVOID_LCM_ERR_COUNT, "obstacle_map: a polytope beyond MAX_VERTICES");
            }
            if (poly_in_tile == COAVOID_OBSTACLE_MAP_T_MAX_POLYTOPES ||
                vertices_in_tile + (int32_t)o->polytope.count >
                    COAVOID_OBSTACLE_MAP_T_MAX_VERTICES) {
                poly_tile++;
                poly_in_tile = 0;
                vertices_in_tile = 0;
            }
            tile_of[i] = poly_tile;
            poly_in_tile++;
            vertices_in_tile += (int32_t)o->polytope.count;
            polys++;
        } else {
            REJECT(COAVOID_LCM_ERR_ENUM, "obstacle_map: unknown obstacle kind");
        }
        tiles = (tile_of[i] + 1 > tiles) ? tile_of[i] + 1 : tiles;
    }
    if (boxes > COAVOID_OBSTACLE_MAP_T_MAX_MAP_BOXES ||
        polys > COAVOID_OBSTACLE_MAP_T_MAX_MAP_POLYTOPES ||
        tiles > COAVOID_OBSTACLE_MAP_T_MAX_TILES) {
        REJECT(COAVOID_LCM_ERR_COUNT,
               "obstacle_map: more than MAX_MAP_BOXES boxes, MAX_MAP_POLYTOPES polytopes or "
               "MAX_TILES tiles");
    }
    return tiles;
}

int coavoid_lcm_obstacle_map_tiles(const coa_obstacle_t *obstacles, size_t count,
                                   size_t *tile_count, const char **reason)
{
    int32_t tile_of[COAVOID_LCM_MAP_MAX_OBSTACLES];
    int rc;
    if ((obstacles == NULL && count > 0u) || tile_count == NULL) {
        REJECT(COA_ERR_ARGUMENT, "obstacle_map: NULL argument");
    }
    if (count > COAVOID_LCM_MAP_MAX_OBSTACLES) {
        REJECT(COAVOID_LCM_ERR_COUNT,
               "obstacle_map: more than MAX_MAP_BOXES boxes and MAX_MAP_POLYTOPES polytopes");
    }
    if ((rc = map_tiling(obstacles, count, tile_of, reason)) < 0) {
        return rc;
    }
    *tile_count = (size_t)rc;
    OK_REASON();
    return COA_OK;
}

int coavoid_lcm_obstacle_map_from_core(const coa_obstacle_t *obstacles, size_t count, int64_t utime,
                                       uint32_t map_id, int64_t version, size_t tile_index,
                                       const coavoid_lcm_context_t *ctx,
                                       coavoid_obstacle_map_t *msg, const char **reason)
{
    int32_t tile_of[COAVOID_LCM_MAP_MAX_OBSTACLES];
    size_t i;
    size_t j;
    int tiles;
    int32_t used = 0;
    if ((obstacles == NULL && count > 0u) || msg == NULL) {
        REJECT(COA_ERR_ARGUMENT, "obstacle_map: NULL argument");
    }
    if (map_id > (uint32_t)COAVOID_LCM_MAX_ID) {
        REJECT(COAVOID_LCM_ERR_ID, "obstacle_map: map_id not in 1..65535");
    }
    if (count > COAVOID_LCM_MAP_MAX_OBSTACLES) {
        REJECT(COAVOID_LCM_ERR_COUNT,
               "obstacle_map: more than MAX_MAP_BOXES boxes and MAX_MAP_POLYTOPES polytopes");
    }
    if ((tiles = map_tiling(obstacles, count, tile_of, reason)) < 0) {
        return tiles;
    }
    if (tile_index >= (size_t)tiles) {
        REJECT(COAVOID_LCM_ERR_COUNT, "obstacle_map: tile_index not in 0..tile_count-1");
    }
    memset(msg, 0, sizeof *msg);
    msg->utime = utime;
    msg->map_id = (int32_t)map_id;
    msg->version = version;
    msg->tile_index = (int32_t)tile_index;
    msg->tile_count = tiles;
    for (i = 0; i < count; ++i) {
        const coa_obstacle_t *o = &obstacles[i];
        if (tile_of[i] != (int32_t)tile_index) {
            continue;
        }
        if (o->kind == COA_OBSTACLE_BOX) {
            vec_to(o->box.min, msg->box_min[msg->box_count]);
            vec_to(o->box.max, msg->box_max[msg->box_count]);
            msg->box_count++;
        } else {
            msg->vertex_count[msg->polytope_count++] = (int32_t)o->polytope.count;
            for (j = 0; j < o->polytope.count; ++j) {
                vec_to(o->polytope.vertices[j], msg->vertices[used++]);
            }
        }
    }
    return coavoid_lcm_obstacle_map_check(msg, ctx, reason);
}

/* ---- conflict report ---- */

int coavoid_lcm_conflict_report_check(const coavoid_conflict_report_t *msg,
                                      const coavoid_lcm_context_t *ctx, const char **reason)
{
    int rc;
    int32_t i;
    if (msg == NULL) {
        REJECT(COA_ERR_ARGUMENT, "conflict_report: NULL");
    }
    if ((rc = utime_rule(msg->utime, ctx)) != COA_OK) {
        REJECT(rc, "conflict_report: utime stale, in the future or not positive");
    }
    if (!id_ok(msg->reporter_id)) {
        REJECT(COAVOID_LCM_ERR_ID, "conflict_report: reporter_id not in 1..65535");
    }
    if (msg->sequence < 0) {
        REJECT(COAVOID_LCM_ERR_VALUE, "conflict_report: sequence negative");
    }
    if ((rc = related_time_rule(msg->prediction_utime, msg->utime, ctx)) != COA_OK) {
        REJECT(rc, "conflict_report: prediction_utime not positive or too far from utime");
    }
    if ((rc = number_rule(msg->dt, COAVOID_LCM_MAX_STEP)) != COA_OK || !(msg->dt > 0.0)) {
        REJECT(rc != COA_OK ? rc : COAVOID_LCM_ERR_VALUE, "conflict_report: dt not in (0, 3600] s");
    }
    if (msg->horizon < 1 || msg->horizon > (int32_t)COA_MAX_HORIZON) {
        REJECT(COAVOID_LCM_ERR_COUNT, "conflict_report: horizon not in 1..COA_MAX_HORIZON");
    }
    if (msg->conflict_count < 0 || msg->conflict_count > COAVOID_CONFLICT_REPORT_T_MAX_CONFLICTS ||
        msg->conflicts_found < msg->conflict_count) {
        REJECT(COAVOID_LCM_ERR_COUNT,
               "conflict_report: conflict_count not in 0..MAX_CONFLICTS or > conflicts_found");
    }
    for (i = 0; i < msg->conflict_count; ++i) {
        int8_t kind = msg->kind[i];
        if (kind != COAVOID_CONFLICT_REPORT_T_KIND_VEHICLE &&
            kind != COAVOID_CONFLICT_REPORT_T_KIND_TRACK &&
            kind != COAVOID_CONFLICT_REPORT_T_KIND_OBSTACLE) {
            REJECT(COAVOID_LCM_ERR_ENUM, "conflict_report: unknown kind");
        }
        if (!id_ok(msg->a_id[i])) {
            REJECT(COAVOID_LCM_ERR_ID, "conflict_report: an a_id not in 1..65535");
        }
        if (msg->b_id[i] < 0 || (kind == COAVOID_CONFLICT_REPORT_T_KIND_VEHICLE &&
                                 (!id_ok(msg->b_id[i]) || msg->b_id[i] == msg->a_id[i]))) {
            REJECT(COAVOID_LCM_ERR_ID, "conflict_report: a b_id invalid for its kind");
        }
        if (msg->first_step[i] < 0 || msg->first_step[i] >= msg->horizon) {
            REJECT(COAVOID_LCM_ERR_VALUE, "conflict_report: a first_step not in 0..horizon-1");
        }
        if ((rc = number_rule(msg->min_horizontal[i], COAVOID_LCM_MAX_COORDINATE * 4.0)) !=
                COA_OK ||
            (rc = number_rule(msg->min_vertical[i], COAVOID_LCM_MAX_COORDINATE * 4.0)) != COA_OK ||
            msg->min_horizontal[i] < 0.0 || msg->min_vertical[i] < 0.0) {
            REJECT(rc != COA_OK ? rc : COAVOID_LCM_ERR_VALUE,
                   "conflict_report: a distance negative or non-finite");
        }
        if (!isfinite(msg->probability[i])) {
            REJECT(COAVOID_LCM_ERR_NONFINITE, "conflict_report: a probability non-finite");
        }
        if (msg->probability[i] < 0.0 || msg->probability[i] > 1.0) {
            REJECT(COAVOID_LCM_ERR_VALUE, "conflict_report: a probability outside [0, 1]");
        }
        /* A label numbers a cluster of UAVs, fewer than there are UAV ids. */
        if (msg->cluster[i] < -1 || msg->cluster[i] >= COAVOID_LCM_MAX_ID) {
            REJECT(COAVOID_LCM_ERR_VALUE, "conflict_report: a cluster label out of range");
        }
    }
    OK_REASON();
    return COA_OK;
}

int coavoid_lcm_conflict_report_from_core(const coa_conflict_t *conflicts, size_t count,
                                          size_t conflicts_found, const uint16_t *plan_ids,
                                          size_t plan_count, const uint32_t *track_ids,
                                          size_t track_count, const uint32_t *cluster,
                                          int64_t utime, uint32_t reporter_id, int64_t sequence,
                                          int64_t prediction_utime, coa_real_t dt, uint32_t horizon,
                                          const coavoid_lcm_context_t *ctx,
                                          coavoid_conflict_report_t *msg, const char **reason)
{
    size_t i;
    size_t n;
    if ((conflicts == NULL && count > 0u) || msg == NULL || (plan_ids == NULL && plan_count > 0u) ||
        (track_ids == NULL && track_count > 0u)) {
        REJECT(COA_ERR_ARGUMENT, "conflict_report: NULL argument");
    }
    if (reporter_id > (uint32_t)COAVOID_LCM_MAX_ID || horizon > (uint32_t)INT32_MAX) {
        REJECT(COAVOID_LCM_ERR_VALUE, "conflict_report: reporter_id or horizon too large");
    }
    if (conflicts_found < count) {
        conflicts_found = count;
    }
    n = count < (size_t)COAVOID_CONFLICT_REPORT_T_MAX_CONFLICTS
            ? count
            : (size_t)COAVOID_CONFLICT_REPORT_T_MAX_CONFLICTS;
    memset(msg, 0, sizeof *msg);
    msg->utime = utime;
    msg->reporter_id = (int32_t)reporter_id;
    msg->sequence = sequence;
    msg->prediction_utime = prediction_utime;
    msg->dt = (double)dt;
    msg->horizon = (int32_t)horizon;
    msg->conflicts_found =
        conflicts_found > (size_t)INT32_MAX ? INT32_MAX : (int32_t)conflicts_found;
    msg->conflict_count = (int32_t)n;
    for (i = 0; i < n; ++i) {
        const coa_conflict_t *c = &conflicts[i];
        if (c->a >= plan_count) {
            REJECT(COA_ERR_ARGUMENT, "conflict_report: a names no plan");
        }
        msg->kind[i] = (int8_t)c->kind;
        msg->a_id[i] = plan_ids[c->a];
        if (c->kind == COA_CONFLICT_VEHICLE) {
            if (c->b >= plan_count) {
                REJECT(COA_ERR_ARGUMENT, "conflict_report: b names no plan");
            }
            msg->b_id[i] = plan_ids[c->b];
        } else if (c->kind == COA_CONFLICT_TRACK) {
            if (c->b >= track_count || track_ids[c->b] > (uint32_t)INT32_MAX) {
                REJECT(COA_ERR_ARGUMENT, "conflict_report: b names no track");
            }
            msg->b_id[i] = (int32_t)track_ids[c->b];
        } else {
            msg->b_id[i] = (c->b > (uint32_t)INT32_MAX) ? -1 : (int32_t)c->b;
        }
        msg->first_step[i] = (c->first_step > (uint32_t)INT32_MAX) ? -1 : (int32_t)c->first_step;
        msg->min_horizontal[i] = (double)c->min_horizontal;
        msg->min_vertical[i] = (double)c->min_vertical;
        msg->probability[i] = c->probability;
        msg->cluster[i] = (cluster == NULL || cluster[c->a] == COA_NO_CLUSTER ||
                           cluster[c->a] > (uint32_t)INT32_MAX)
                              ? -1
                              : (int32_t)cluster[c->a];
    }
    return coavoid_lcm_conflict_report_check(msg, ctx, reason);
}

int coavoid_lcm_conflict_report_accept(const coavoid_conflict_report_t *msg,
                                       const coavoid_lcm_context_t *ctx,
                                       coavoid_lcm_sequence_table_t *seq, const char **reason)
{
    int rc = coavoid_lcm_conflict_report_check(msg, ctx, reason);
    if (rc != COA_OK) {
        return rc;
    }
    return sequence_rule(seq, msg->reporter_id, msg->sequence, false, reason,
                         "conflict_report: sequence not after the last one from this reporter",
                         "conflict_report: sequence table full");
}

/* ---- status ---- */

coavoid_auth_role_t coavoid_lcm_status_role(int8_t node_kind)
{
    return node_kind == COAVOID_STATUS_T_NODE_COORDINATOR ? COAVOID_AUTH_COORDINATOR
                                                          : COAVOID_AUTH_VEHICLE;
}

int8_t coavoid_lcm_health_of(int32_t reasons)
{
    const int32_t fatal =
        COAVOID_STATUS_T_REASON_INTERNAL_ERROR | COAVOID_STATUS_T_REASON_DUPLICATE_ID;
    return (reasons & fatal) != 0 ? COAVOID_STATUS_T_HEALTH_FAULT
           : reasons != 0         ? COAVOID_STATUS_T_HEALTH_DEGRADED
                                  : COAVOID_STATUS_T_HEALTH_OK;
}

/* Known REASON_* bits only, and the health they give. */
static bool status_reasons_ok(const coavoid_status_t *msg)
{
    const int32_t known = 2 * COAVOID_STATUS_T_REASON_INBOX_FLOOD - 1;
    const int32_t r = msg->reasons;
    return r >= 0 && (r & ~known) == 0 && msg->health == coavoid_lcm_health_of(r);
}

int coavoid_lcm_status_check(const coavoid_status_t *msg, const coavoid_lcm_context_t *ctx,
                             const char **reason)
{
    int rc;
    if (msg == NULL) {
        REJECT(COA_ERR_ARGUMENT, "status: NULL");
    }
    if ((rc = utime_rule(msg->utime, ctx)) != COA_OK) {
        REJECT(rc, "status: utime stale, in the future or not positive");
    }
    if (!id_ok(msg->node_id)) {
        REJECT(COAVOID_LCM_ERR_ID, "status: node_id not in 1..65535");
    }
    if (msg->node_kind != COAVOID_STATUS_T_NODE_COORDINATOR &&
        msg->node_kind != COAVOID_STATUS_T_NODE_VEHICLE) {
        REJECT(COAVOID_LCM_ERR_ENUM, "status: unknown node_kind");
    }
    if (msg->sequence < 0) {
        REJECT(COAVOID_LCM_ERR_VALUE, "status: sequence negative");
    }
    if (msg->health != COAVOID_STATUS_T_HEALTH_OK &&
        msg->health != COAVOID_STATUS_T_HEALTH_DEGRADED &&
        msg->health != COAVOID_STATUS_T_HEALTH_FAULT) {
        REJECT(COAVOID_LCM_ERR_ENUM, "status: unknown health");
    }
    if (msg->mode != COAVOID_STATUS_T_MODE_CENTRALISED &&
        msg->mode != COAVOID_STATUS_T_MODE_DECOUPLED &&
        msg->mode != COAVOID_STATUS_T_MODE_REFERENCE) {
        REJECT(COAVOID_LCM_ERR_ENUM, "status: unknown mode");
    }
    if (msg->outcome != COAVOID_STATUS_T_OUTCOME_SOLVED &&
        msg->outcome != COAVOID_STATUS_T_OUTCOME_INFEASIBLE &&
        msg->outcome != COAVOID_STATUS_T_OUTCOME_BUDGET_EXHAUSTED &&
        msg->outcome != COAVOID_STATUS_T_OUTCOME_NONE) {
        REJECT(COAVOID_LCM_ERR_ENUM, "status: unknown outcome");
    }
    if (msg->last_plan_utime < 0 || msg->last_plan_utime > msg->utime) {
        REJECT(COAVOID_LCM_ERR_TIME, "status: last_plan_utime negative or after utime");
    }
    if (msg->last_plan_duration_us < 0 || msg->nodes_expanded < 0 || msg->conflicts < 0 ||
        msg->plans_run < 0) {
        REJECT(COAVOID_LCM_ERR_VALUE,
               "status: a negative duration, node count, conflict count or plans_run");
    }
    if (msg->messages_received < 0 || msg->messages_rejected < 0 ||
        msg->messages_rejected > msg->messages_received) {
        REJECT(COAVOID_LCM_ERR_COUNT, "status: messages_rejected not in 0..messages_received");
    }
    if (msg->last_reject_code > 0) {
        REJECT(COAVOID_LCM_ERR_VALUE, "status: last_reject_code positive");
    }
    if (msg->messages_dropped < 0 || msg->inbox_rate < 0) {
        REJECT(COAVOID_LCM_ERR_COUNT, "status: messages_dropped or inbox_rate negative");
    }
    if (!status_reasons_ok(msg)) {
        REJECT(COAVOID_LCM_ERR_VALUE, "status: reasons unknown, or not what its health says");
    }
    OK_REASON();
    return COA_OK;
}

int coavoid_lcm_status_accept(const coavoid_status_t *msg, const coavoid_lcm_context_t *ctx,
                              coavoid_lcm_sequence_table_t *seq, const char **reason)
{
    int rc = coavoid_lcm_status_check(msg, ctx, reason);
    if (rc != COA_OK) {
        return rc;
    }
    return sequence_rule(seq, msg->node_id, msg->sequence, false, reason,
                         "status: sequence not after the last one from this node",
                         "status: sequence table full");
}

/* ---- agreement on a plan ---- */

static bool agreement_from_coordinator(int8_t kind)
{
    return kind == COAVOID_AGREEMENT_T_KIND_COMMIT || kind == COAVOID_AGREEMENT_T_KIND_ABORT;
}

coavoid_auth_role_t coavoid_lcm_agreement_role(int8_t kind)
{
    return agreement_from_coordinator(kind) ? COAVOID_AUTH_COORDINATOR : COAVOID_AUTH_VEHICLE;
}

int coavoid_lcm_agreement_check(const coavoid_agreement_t *msg, const coavoid_lcm_context_t *ctx,
                                const char **reason)
{
    int rc;
    if (msg == NULL) {
        REJECT(COA_ERR_ARGUMENT, "agreement: NULL");
    }
    if ((rc = utime_rule(msg->utime, ctx)) != COA_OK) {
        REJECT(rc, "agreement: utime stale, in the future or not positive");
    }
    if (msg->kind < COAVOID_AGREEMENT_T_KIND_ACCEPT || msg->kind > COAVOID_AGREEMENT_T_KIND_ABORT) {
        REJECT(COAVOID_LCM_ERR_ENUM, "agreement: unknown kind");
    }
    if (!id_ok(msg->node_id) || !id_ok(msg->coordinator_id)) {
        REJECT(COAVOID_LCM_ERR_ID, "agreement: node_id or coordinator_id not in 1..65535");
    }
    if (agreement_from_coordinator(msg->kind) && msg->node_id != msg->coordinator_id) {
        REJECT(COAVOID_LCM_ERR_ID, "agreement: a commit or abort not from the plan's coordinator");
    }
    if (msg->plan_id < 0 || msg->valid_from_utime <= 0) {
        REJECT(COAVOID_LCM_ERR_VALUE,
               "agreement: plan_id negative or valid_from_utime not positive");
    }
    OK_REASON();
    return COA_OK;
}

/* ---- counting what arrives ---- */

void coavoid_lcm_rx_init(coavoid_lcm_rx_stats_t *stats)
{
    if (stats == NULL) {
        return;
    }
    stats->received = 0;
    stats->rejected = 0;
    stats->last_reject_code = 0;
    stats->last_reason = "none";
}

void coavoid_lcm_rx_count(coavoid_lcm_rx_stats_t *stats, int rc, const char *reason)
{
    if (stats == NULL) {
        return;
    }
    if (stats->received < INT64_MAX) {
        stats->received++;
    }
    /* Only a negative rc is a refusal: a decoder's byte count is a success, and a
     * positive last_reject_code would make the status message itself refused. */
    if (rc < 0) {
        if (stats->rejected < stats->received) {
            stats->rejected++;
        }
        stats->last_reject_code = rc;
        stats->last_reason = (reason != NULL) ? reason : coavoid_lcm_error_name(rc);
    }
}
