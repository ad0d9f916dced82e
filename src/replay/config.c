/* SPDX-License-Identifier: MIT */
/* A vehicle's configuration in its record (replay.h): written by the recorder, read by
 * the replay into memory of its own. Every field in a fixed order; numbers in the core's
 * precision are written as doubles, so a record reads back exactly in the precision it was
 * written in. */
#include <string.h>

#include "replay_internal.h"

#define PUT_U(b, v, n) coavoid_replay_put_u((b), (uint64_t)(v), (n))
#define PUT_F(b, v) coavoid_replay_put_f((b), (double)(v))
#define GET_F(b) ((coa_real_t)coavoid_replay_get_f(b))

static void put_vec(coavoid_replay_buf_t *b, coa_vec3_t v)
{
    PUT_F(b, v.x);
    PUT_F(b, v.y);
    PUT_F(b, v.z);
}

static coa_vec3_t get_vec(coavoid_replay_buf_t *b)
{
    coa_vec3_t v;
    v.x = GET_F(b);
    v.y = GET_F(b);
    v.z = GET_F(b);
    return v;
}

static void put_common(coavoid_replay_buf_t *b, const coavoid_node_common_t *c)
{
    PUT_U(b, c->epoch_utime, 8u);
    PUT_F(b, c->dt);
    PUT_U(b, c->dt_us, 8u);
    PUT_U(b, c->horizon, 4u);
    PUT_F(b, c->threshold);
    PUT_F(b, c->vehicle_sigma_rate_horizontal);
    PUT_F(b, c->vehicle_sigma_rate_vertical);
    PUT_F(b, c->track_sigma_rate_horizontal);
    PUT_F(b, c->track_sigma_rate_vertical);
    PUT_F(b, c->stale_sigma_rate);
    PUT_U(b, c->stale_after_us, 8u);
    PUT_U(b, c->beta, 4u);
    PUT_U(b, c->has_floor, 1u);
    PUT_F(b, c->min_altitude);
    PUT_U(b, c->insecure, 1u);
    PUT_U(b, c->obstacle_count, 4u);
    for (size_t i = 0; i < c->obstacle_count; i++) {
        const coa_obstacle_t *o = &c->obstacles[i];
        PUT_U(b, o->kind, 1u);
        if (o->kind == COA_OBSTACLE_BOX) {
            put_vec(b, o->box.min);
            put_vec(b, o->box.max);
            continue;
        }
        PUT_U(b, o->polytope.count, 4u);
        for (size_t k = 0; k < o->polytope.count; k++) {
            put_vec(b, o->polytope.vertices[k]);
        }
    }
}

static void put_keys(coavoid_replay_buf_t *b, const coavoid_auth_signer_t *s,
                     const coavoid_auth_trust_t *t)
{
    const bool signs = s != NULL && t != NULL;
    PUT_U(b, signs, 1u);
    if (!signs) {
        return;
    }
    PUT_U(b, s->key_id, 4u);
    coavoid_replay_put(b, s->secret_key, sizeof s->secret_key);
    PUT_U(b, s->has_fleet_key, 1u);
    coavoid_replay_put(b, s->fleet_key, sizeof s->fleet_key);
    PUT_U(b, s->last_timestamp, 8u);
    PUT_U(b, s->sequence, 8u);
    PUT_U(b, t->has_fleet_key, 1u);
    coavoid_replay_put(b, t->fleet_key, sizeof t->fleet_key);
    PUT_U(b, t->count, 4u);
    for (size_t i = 0; i < t->count; i++) {
        PUT_U(b, t->keys[i].key_id, 4u);
        PUT_U(b, t->keys[i].role, 1u);
        PUT_U(b, t->keys[i].node_id, 2u);
        coavoid_replay_put(b, t->keys[i].public_key, sizeof t->keys[i].public_key);
    }
}

static void put_vehicle(coavoid_replay_buf_t *b, const coa_vehicle_t *v)
{
    PUT_U(b, v->id, 2u);
    PUT_U(b, v->priority, 4u);
    PUT_F(b, v->cruise_speed);
    PUT_F(b, v->climb_rate);
    PUT_U(b, v->steep_factor, 4u);
    PUT_F(b, v->volume.radius);
    PUT_F(b, v->volume.half_height);
    PUT_U(b, (uint32_t)v->initial_offset, 4u);
    PUT_U(b, (uint32_t)v->max_offset, 4u);
    PUT_U(b, v->route_count, 4u);
    for (size_t i = 0; i < v->route_count; i++) {
        put_vec(b, v->route[i]);
    }
}

static void put_node(coavoid_replay_buf_t *b, const coavoid_vehicle_node_config_t *c)
{
    PUT_U(b, c->mode, 1u);
    PUT_U(b, c->coordinator_timeout_us, 8u);
    PUT_U(b, c->priority_wait_us, 8u);
    PUT_F(b, c->sigma_horizontal);
    PUT_F(b, c->sigma_vertical);
    PUT_U(b, c->coordinator_id, 2u);
    PUT_U(b, c->resend_us, 8u);
    PUT_U(b, c->intent_copies, 4u);
    PUT_U(b, c->greedy_negotiation, 1u);
    PUT_U(b, c->answer_wait_us, 8u);
    PUT_U(b, c->joint_members, 4u);
    PUT_U(b, c->joint_beta, 4u);
    PUT_U(b, c->joint_work, 8u);
}

size_t coavoid_replay_write_config(const coavoid_vehicle_node_config_t *config, uint8_t *out,
                                   size_t capacity)
{
    coavoid_replay_buf_t b = {out, capacity, 0, 0, true};
    if (config->vehicle.route_count > COAVOID_REPLAY_MAX_ROUTE ||
        config->common.obstacle_count > COAVOID_NODE_MAX_CONFIGURED_OBSTACLES) {
        return 0u;
    }
    put_common(&b, &config->common);
    put_keys(&b, config->common.signer, config->common.trust);
    put_vehicle(&b, &config->vehicle);
    put_node(&b, config);
    return b.ok && b.length <= COAVOID_REPLAY_MAX_PAYLOAD ? b.length : 0u;
}

/* The obstacles into r, their vertices from r->vertices. */
static int get_obstacles(coavoid_replay_buf_t *b, coavoid_replay_t *r, size_t count)
{
    size_t used = 0;
    if (count > COAVOID_NODE_MAX_CONFIGURED_OBSTACLES) {
        return COAVOID_LCM_ERR_CAPACITY;
    }
    for (size_t i = 0; i < count && b->ok; i++) {
        coa_obstacle_t *o = &r->obstacles[i];
        memset(o, 0, sizeof *o);
        o->kind = coavoid_replay_get_u(b, 1u) == 0u ? COA_OBSTACLE_BOX : COA_OBSTACLE_POLYTOPE;
        if (o->kind == COA_OBSTACLE_BOX) {
            o->box.min = get_vec(b);
            o->box.max = get_vec(b);
            continue;
        }
        const size_t n = (size_t)coavoid_replay_get_u(b, 4u);
        if (n > COAVOID_REPLAY_MAX_VERTICES - used) {
            return COAVOID_LCM_ERR_CAPACITY;
        }
        for (size_t k = 0; k < n; k++) {
            r->vertices[used + k] = get_vec(b);
        }
        o->polytope.vertices = &r->vertices[used];
        o->polytope.count = n;
        used += n;
    }
    r->config.common.obstacles = count > 0u ? r->obstacles : NULL;
    r->config.common.obstacle_count = count;
    return COA_OK;
}

static int get_common(coavoid_replay_buf_t *b, coavoid_replay_t *r)
{
    coavoid_node_common_t *c = &r->config.common;
    c->epoch_utime = (int64_t)coavoid_replay_get_u(b, 8u);
    c->dt = GET_F(b);
    c->dt_us = (int64_t)coavoid_replay_get_u(b, 8u);
    c->horizon = (uint32_t)coavoid_replay_get_u(b, 4u);
    c->threshold = coavoid_replay_get_f(b);
    c->vehicle_sigma_rate_horizontal = GET_F(b);
    c->vehicle_sigma_rate_vertical = GET_F(b);
    c->track_sigma_rate_horizontal = GET_F(b);
    c->track_sigma_rate_vertical = GET_F(b);
    c->stale_sigma_rate = GET_F(b);
    c->stale_after_us = (int64_t)coavoid_replay_get_u(b, 8u);
    c->beta = (uint32_t)coavoid_replay_get_u(b, 4u);
    c->has_floor = coavoid_replay_get_u(b, 1u) != 0u;
    c->min_altitude = GET_F(b);
    c->insecure = coavoid_replay_get_u(b, 1u) != 0u;
    c->clock = &r->now;
    return get_obstacles(b, r, (size_t)coavoid_replay_get_u(b, 4u));
}

static int get_keys(coavoid_replay_buf_t *b, coavoid_replay_t *r)
{
    if (coavoid_replay_get_u(b, 1u) == 0u) {
        return COA_OK; /* an insecure vehicle's record */
    }
    coavoid_auth_signer_t *s = &r->signer;
    coavoid_auth_trust_t *t = &r->trust;
    s->key_id = (uint32_t)coavoid_replay_get_u(b, 4u);
    coavoid_replay_get(b, s->secret_key, sizeof s->secret_key);
    s->has_fleet_key = coavoid_replay_get_u(b, 1u) != 0u;
    coavoid_replay_get(b, s->fleet_key, sizeof s->fleet_key);
    s->last_timestamp = (int64_t)coavoid_replay_get_u(b, 8u);
    s->sequence = (int64_t)coavoid_replay_get_u(b, 8u);
    coavoid_auth_trust_init(t);
    t->has_fleet_key = coavoid_replay_get_u(b, 1u) != 0u;
    coavoid_replay_get(b, t->fleet_key, sizeof t->fleet_key);
    const size_t n = (size_t)coavoid_replay_get_u(b, 4u);
    for (size_t i = 0; i < n && b->ok; i++) {
        coavoid_auth_key_t k;
        memset(&k, 0, sizeof k);
        k.key_id = (uint32_t)coavoid_replay_get_u(b, 4u);
        k.role = (coavoid_auth_role_t)coavoid_replay_get_u(b, 1u);
        k.node_id = (uint16_t)coavoid_replay_get_u(b, 2u);
        coavoid_replay_get(b, k.public_key, sizeof k.public_key);
        if (b->ok && coavoid_auth_trust_add(t, &k) != COA_OK) {
            return COAVOID_LCM_ERR_CAPACITY;
        }
    }
    r->config.common.signer = s;
    r->config.common.trust = t;
    return COA_OK;
}

static int get_vehicle(coavoid_replay_buf_t *b, coavoid_replay_t *r)
{
    coa_vehicle_t *v = &r->config.vehicle;
    v->id = (uint16_t)coavoid_replay_get_u(b, 2u);
    v->priority = (uint32_t)coavoid_replay_get_u(b, 4u);
    v->cruise_speed = GET_F(b);
    v->climb_rate = GET_F(b);
    v->steep_factor = (uint32_t)coavoid_replay_get_u(b, 4u);
    v->volume.radius = GET_F(b);
    v->volume.half_height = GET_F(b);
    v->initial_offset = (int32_t)(uint32_t)coavoid_replay_get_u(b, 4u);
    v->max_offset = (int32_t)(uint32_t)coavoid_replay_get_u(b, 4u);
    v->route_count = (size_t)coavoid_replay_get_u(b, 4u);
    if (v->route_count > COAVOID_REPLAY_MAX_ROUTE) {
        return COAVOID_LCM_ERR_CAPACITY;
    }
    for (size_t i = 0; i < v->route_count; i++) {
        r->route[i] = get_vec(b);
    }
    v->route = r->route;
    return COA_OK;
}

static void get_node(coavoid_replay_buf_t *b, coavoid_vehicle_node_config_t *c)
{
    c->mode = coavoid_replay_get_u(b, 1u) == 0u ? COAVOID_NODE_CENTRALISED : COAVOID_NODE_DECOUPLED;
    c->coordinator_timeout_us = (int64_t)coavoid_replay_get_u(b, 8u);
    c->priority_wait_us = (int64_t)coavoid_replay_get_u(b, 8u);
    c->sigma_horizontal = GET_F(b);
    c->sigma_vertical = GET_F(b);
    c->coordinator_id = (uint16_t)coavoid_replay_get_u(b, 2u);
    c->resend_us = (int64_t)coavoid_replay_get_u(b, 8u);
    c->intent_copies = (uint32_t)coavoid_replay_get_u(b, 4u);
    c->greedy_negotiation = coavoid_replay_get_u(b, 1u) != 0u;
    c->answer_wait_us = (int64_t)coavoid_replay_get_u(b, 8u);
    c->joint_members = (size_t)coavoid_replay_get_u(b, 4u);
    c->joint_beta = (uint32_t)coavoid_replay_get_u(b, 4u);
    c->joint_work = coavoid_replay_get_u(b, 8u);
}

int coavoid_replay_config(coavoid_replay_t *r, const uint8_t *payload, size_t size)
{
    coavoid_replay_buf_t b = {(uint8_t *)(uintptr_t)payload, 0, size, 0, payload != NULL};
    memset(r, 0, sizeof *r);
    int rc = get_common(&b, r);
    if (rc == COA_OK) {
        rc = get_keys(&b, r);
    }
    if (rc == COA_OK) {
        rc = get_vehicle(&b, r);
    }
    if (rc != COA_OK) {
        return rc;
    }
    get_node(&b, &r->config);
    return b.ok && b.at == b.length ? COA_OK : COAVOID_REPLAY_ERR_FORMAT;
}
