/* SPDX-License-Identifier: MIT */
/*
 * What the nodes share (node.h, node_internal.h): the clock arithmetic, the inbox that
 * decodes, validates, counts and stores what arrives, the view of one cycle, the
 * planner's track list, prediction and publishing.
 */
#include "node_internal.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A generous queue per subscription: a cycle publishes one intent and one heartbeat per
 * UAV and one estimate per track, all handled before the next cycle. LCM's default (30)
 * would drop messages of a large fleet without a word. */
#define COAVOID_NODE_QUEUE_CAPACITY \
    ((int)(4u * COAVOID_NODE_MAX_PEERS + 2u * COAVOID_NODE_MAX_TRACKS + 16u))

int coavoid_node_common_defaults(coavoid_node_common_t *c, int64_t epoch_utime, coa_real_t dt,
                                 uint32_t horizon, const int64_t *clock)
{
    if (c == NULL || clock == NULL || epoch_utime <= 0 || !isfinite((double)dt) ||
        !(dt > (coa_real_t)0) || (double)dt > COAVOID_LCM_MAX_STEP || horizon < 1u ||
        horizon > COAVOID_NODE_MAX_HORIZON) {
        return COA_ERR_ARGUMENT;
    }
    int64_t dt_us = (int64_t)llround((double)dt * 1e6);
    if (dt_us < 1) {
        return COA_ERR_ARGUMENT;
    }
    memset(c, 0, sizeof *c);
    c->epoch_utime = epoch_utime;
    c->dt = dt;
    c->dt_us = dt_us;
    c->horizon = horizon;
    c->clock = clock;
    c->stopwatch_us = NULL;
    c->stopwatch_user = NULL;
    c->threshold = 0.01;
    c->stale_after_us = (int64_t)llround(2.5 * (double)dt_us);
    c->stale_sigma_rate = (coa_real_t)1;
    c->beta = 20000u;
    return COA_OK;
}

static bool rate_ok(coa_real_t r)
{
    return isfinite((double)r) && r >= (coa_real_t)0;
}

int coavoid_node_common_check(const coavoid_node_common_t *c)
{
    if (c == NULL || c->clock == NULL || c->epoch_utime <= 0 || !isfinite((double)c->dt) ||
        !(c->dt > (coa_real_t)0) || (double)c->dt > COAVOID_LCM_MAX_STEP || c->horizon < 1u ||
        c->horizon > COAVOID_NODE_MAX_HORIZON || c->dt_us < 1 ||
        c->dt_us != (int64_t)llround((double)c->dt * 1e6)) {
        return COA_ERR_ARGUMENT;
    }
    if (!(c->threshold > 0.0) || !(c->threshold <= 1.0) ||
        !rate_ok(c->vehicle_sigma_rate_horizontal) || !rate_ok(c->vehicle_sigma_rate_vertical) ||
        !rate_ok(c->track_sigma_rate_horizontal) || !rate_ok(c->track_sigma_rate_vertical) ||
        !rate_ok(c->stale_sigma_rate) || c->stale_after_us < 1 || c->beta < 1u) {
        return COA_ERR_ARGUMENT;
    }
    if (!c->insecure && c->signer == NULL) {
        return COA_ERR_ARGUMENT;
    }
    if (c->obstacle_count > COAVOID_NODE_MAX_CONFIGURED_OBSTACLES ||
        (c->obstacle_count > 0u && c->obstacles == NULL)) {
        return COA_ERR_ARGUMENT;
    }
    for (size_t i = 0; i < c->obstacle_count; i++) {
        if (coa_obstacle_check(&c->obstacles[i]) != COA_OK) {
            return COA_ERR_ARGUMENT;
        }
    }
    /* Cycle arithmetic stays far from overflow for any run a node can make. */
    if (c->epoch_utime > INT64_MAX / 4) {
        return COA_ERR_ARGUMENT;
    }
    return COA_OK;
}

int64_t coavoid_node_cycle_utime(const coavoid_node_common_t *c, int64_t k)
{
    return c->epoch_utime + k * c->dt_us;
}

int64_t coavoid_node_cycle_of(const coavoid_node_common_t *c, int64_t utime)
{
    int64_t d = utime - c->epoch_utime;
    int64_t k = d / c->dt_us;
    if (d % c->dt_us != 0 && d < 0) {
        k -= 1; /* floor, not truncation */
    }
    return k;
}

int64_t coavoid_node_stopwatch(const coavoid_node_common_t *c)
{
    return (c->stopwatch_us != NULL) ? c->stopwatch_us(c->stopwatch_user) : 0;
}

bool coavoid_node_outranks(uint32_t priority_a, uint16_t id_a, uint32_t priority_b, uint16_t id_b)
{
    return priority_a < priority_b || (priority_a == priority_b && id_a < id_b);
}

bool coavoid_node_precedes(int32_t rank_a, uint32_t priority_a, uint16_t id_a, int32_t rank_b,
                           uint32_t priority_b, uint16_t id_b)
{
    return rank_a > rank_b ||
           (rank_a == rank_b && coavoid_node_outranks(priority_a, id_a, priority_b, id_b));
}

/* ---- senders ---- */

static void senders_init(coavoid_node_senders_t *s)
{
    coavoid_lcm_sequence_init(&s->table, s->entries, COAVOID_NODE_MAX_SENDERS);
    s->heard_count = 0;
}

static void senders_heard(coavoid_node_senders_t *s, uint32_t sender, int64_t now)
{
    for (size_t i = 0; i < s->heard_count; i++) {
        if (s->heard_sender[i] == sender) {
            s->heard_utime[i] = now;
            return;
        }
    }
    if (s->heard_count < COAVOID_NODE_MAX_SENDERS) {
        s->heard_sender[s->heard_count] = sender;
        s->heard_utime[s->heard_count] = now;
        s->heard_count++;
    }
}

/* Forgets every sender not heard for longer than limit, so its numbering may restart. */
static void senders_expire(coavoid_node_senders_t *s, int64_t now, int64_t limit)
{
    size_t i = 0;
    while (i < s->heard_count) {
        if (now - s->heard_utime[i] > limit) {
            coavoid_lcm_sequence_forget(&s->table, s->heard_sender[i]);
            s->heard_count--;
            s->heard_sender[i] = s->heard_sender[s->heard_count];
            s->heard_utime[i] = s->heard_utime[s->heard_count];
        } else {
            i++;
        }
    }
}

/* ---- the inbox ---- */

coavoid_lcm_context_t coavoid_node_context(const coavoid_node_inbox_t *in, int64_t now,
                                           int64_t epoch)
{
    coavoid_lcm_context_t ctx;
    ctx.now_utime = now;
    ctx.max_age_us = in->max_age_us;
    ctx.max_future_us = in->common.dt_us;
    ctx.epoch_utime = epoch;
    return ctx;
}

/* The bytes of one received message, or false when they cannot be a message. */
static bool received_size(const lcm_recv_buf_t *rbuf, int *size)
{
    if (rbuf == NULL || rbuf->data == NULL || rbuf->data_size > (uint32_t)INT_MAX) {
        return false;
    }
    *size = (int)rbuf->data_size;
    return true;
}

static void count_undecodable(coavoid_node_inbox_t *in, const char *reason)
{
    coavoid_lcm_rx_count(in->rx, COAVOID_LCM_ERR_DECODE, reason);
}

/* A whole budget for cycle `cycle`, nothing checked or taken in yet. */
static void budget_start(coavoid_node_inbox_t *in, int64_t cycle)
{
    in->budget_cycle = cycle;
    memset(in->checks, 0, sizeof in->checks);
    in->cycle_checks = 0u;
    in->cycle_datagrams = 0u;
}

/* Brings the inbox budget to the cycle of `now`: a new cycle starts it afresh. */
static void budget_roll(coavoid_node_inbox_t *in, int64_t now)
{
    const int64_t cycle = coavoid_node_cycle_of(&in->common, now);
    if (cycle != in->budget_cycle) {
        in->last_cycle_datagrams = cycle == in->budget_cycle + 1 ? in->cycle_datagrams : 0u;
        budget_start(in, cycle);
    }
}

/* An inbox budget of no cycle yet, nothing dropped. */
static void budget_init(coavoid_node_inbox_t *in)
{
    budget_start(in, INT64_MIN);
    in->last_cycle_datagrams = 0u;
    in->dropped = 0;
    in->dropped_at_heartbeat = 0;
}

/* Whether the cycle's budget has a signature check left for key on stream; then it is
 * spent. Otherwise the datagram is counted as dropped. */
static bool budget_check(coavoid_node_inbox_t *in, size_t key, size_t stream)
{
    const uint16_t limit = in->trust.keys[key].role == COAVOID_AUTH_VEHICLE
                               ? COAVOID_NODE_CHECKS_PER_VEHICLE
                               : COAVOID_NODE_CHECKS_PER_KEY;
    if (in->checks[key][stream] >= limit || in->cycle_checks >= COAVOID_NODE_CHECKS_PER_CYCLE) {
        in->dropped++;
        return false;
    }
    in->checks[key][stream]++;
    in->cycle_checks++;
    return true;
}

/* A received datagram's auth tail, fleet tag and signature, over its raw bytes before
 * anything decodes them (a secure inbox only): first what the tail and the tag say (a
 * known key of the channel's role, fresh on its stream, from the fleet: a copy, a replay
 * or an outsider's datagram ends here), then, within the cycle's budget (node.h,
 * COAVOID_NODE_CHECKS_PER_*), the signature. True with the key's index in *key, else
 * counted as refused or dropped. Every datagram counts towards the cycle's inbox rate. */
static bool signature_ok(coavoid_node_inbox_t *in, const lcm_recv_buf_t *rbuf, size_t stream,
                         coavoid_auth_role_t role, size_t *key)
{
    *key = 0;
    budget_roll(in, *in->common.clock);
    if (in->cycle_datagrams < UINT32_MAX) {
        in->cycle_datagrams++;
    }
    if (!in->secure) {
        return true;
    }
    const coavoid_auth_expect_t expect = {stream, role, *in->common.clock, in->max_age_us,
                                          in->common.dt_us};
    int rc = coavoid_auth_precheck(&in->trust, rbuf->data, rbuf->data_size, &expect, key);
    if (rc == COA_OK && !budget_check(in, *key, stream)) {
        return false;
    }
    if (rc == COA_OK) {
        rc = coavoid_auth_verify(&in->trust, rbuf->data, rbuf->data_size, key);
    }
    if (rc != COA_OK) {
        coavoid_lcm_rx_count(in->rx, rc, coavoid_lcm_error_name(rc));
        return false;
    }
    return true;
}

/* The decoded sender of a verified message: key may speak as role for node `id`, and the
 * message is newer than the last of its stream from that key, within the window. True,
 * or counted as refused. Always true in an insecure inbox. */
static bool sender_ok(coavoid_node_inbox_t *in, size_t key, size_t stream, coavoid_auth_role_t role,
                      int32_t id, const coavoid_auth_t *auth)
{
    if (!in->secure) {
        return true;
    }
    const int rc =
        coavoid_auth_accept(&in->trust, key, stream, role, id, auth->timestamp_us, auth->sequence,
                            *in->common.clock, in->max_age_us, in->common.dt_us);
    if (rc != COA_OK) {
        coavoid_lcm_rx_count(in->rx, rc, coavoid_lcm_error_name(rc));
        return false;
    }
    return true;
}

/* The sequence table of a stream: none in a secure inbox, where freshness is the
 * signature's (and a restarted sender is accepted at once). */
static coavoid_lcm_sequence_table_t *sequence_table(coavoid_node_inbox_t *in,
                                                    coavoid_node_senders_t *s)
{
    return in->secure ? NULL : &s->table;
}

uint64_t coavoid_node_fnv(uint64_t h, const void *data, size_t size)
{
    const uint8_t *p = data;
    for (size_t i = 0; i < size; i++) {
        h = (h ^ p[i]) * UINT64_C(1099511628211);
    }
    return h;
}

/* FNV-1a (64 bits) of a message's bytes. */
static uint64_t fingerprint(const void *data, size_t size)
{
    return coavoid_node_fnv(COAVOID_NODE_FNV_OFFSET, data, size);
}

static bool sent_by_self(const coavoid_node_inbox_t *in, const void *data, size_t size)
{
    const uint64_t h = fingerprint(data, size);
    for (size_t i = 0; i < COAVOID_NODE_OWN_INTENTS; i++) {
        if (in->own_size[i] > 0 && (size_t)in->own_size[i] == size && in->own_hash[i] == h) {
            return true;
        }
    }
    return false;
}

/* Stores a UAV's new intent in its slot, keeping its last one of an earlier cycle. */
static void peer_keep(coavoid_node_peer_t *peer, const coavoid_intent_t *msg)
{
    if (peer->used && peer->msg.plan_utime < msg->plan_utime) {
        peer->has_prev = true; /* its last word on the cycle before */
        peer->prev = peer->msg;
    } else if (!peer->used) {
        peer->has_prev = false;
    }
    peer->used = true;
    peer->forgotten = false;
    peer->msg = *msg;
}

static void on_intent(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    coavoid_node_inbox_t *in = user;
    coavoid_intent_t *msg = &in->rx_msg.intent;
    int size = 0;
    size_t key = 0;
    (void)channel;
    if (!received_size(rbuf, &size)) {
        return;
    }
    /* Its own, looped back, byte for byte: nothing to check (a copy of it changes nothing). */
    if (in->self_uav != 0u && sent_by_self(in, rbuf->data, (size_t)size)) {
        return;
    }
    if (!signature_ok(in, rbuf, COAVOID_AUTH_STREAM_INTENT, COAVOID_AUTH_VEHICLE, &key)) {
        return;
    }
    if (coavoid_intent_t_decode(rbuf->data, 0, size, msg) < 0) {
        count_undecodable(in, "intent: does not decode");
        return;
    }
    /* Before a twin is recognised: a forged intent under its id must not pass for a twin
     * (a fault) when it is not even signed by that UAV's key. */
    if (!sender_ok(in, key, COAVOID_AUTH_STREAM_INTENT, COAVOID_AUTH_VEHICLE, msg->uav_id,
                   &msg->auth)) {
        return;
    }
    if (in->self_uav != 0u && msg->uav_id == (int32_t)in->self_uav) {
        /* Two UAVs flying under one id: each would ignore the other as its own echo. */
        if (in->foreign_intents < UINT32_MAX) {
            in->foreign_intents++;
        }
        coavoid_lcm_rx_count(in->rx, COAVOID_LCM_ERR_ID, "intent: another UAV uses this node's id");
        return;
    }
    const int64_t now = *in->common.clock;
    /* A place to keep it before the sequence rule, so that a full table does not
     * swallow a sequence number it then drops. */
    size_t slot = COAVOID_NODE_MAX_PEERS;
    size_t used = 0;
    for (size_t i = 0; i < COAVOID_NODE_MAX_PEERS; i++) {
        if (in->peers[i].used) {
            used++;
            if (in->peers[i].msg.uav_id == msg->uav_id) {
                slot = i;
            }
        }
    }
    if (slot == COAVOID_NODE_MAX_PEERS && used < in->peer_capacity) {
        for (size_t i = 0; i < COAVOID_NODE_MAX_PEERS; i++) {
            if (!in->peers[i].used) {
                slot = i;
                break;
            }
        }
    }
    if (slot == COAVOID_NODE_MAX_PEERS) {
        coavoid_lcm_rx_count(in->rx, COAVOID_LCM_ERR_SENDERS,
                             "intent: more UAVs than the node holds");
        return;
    }
    coavoid_lcm_context_t ctx = coavoid_node_context(in, now, now);
    coavoid_lcm_intent_info_t info;
    coa_vehicle_t vehicle;
    coa_intent_plan_t plan;
    const char *reason = NULL;
    int rc = coavoid_lcm_intent_to_core(msg, &ctx, sequence_table(in, &in->intent_seq), &info,
                                        &vehicle, &plan, &in->rx_arrays, &reason);
    coavoid_lcm_rx_count(in->rx, rc, reason);
    if (rc != COA_OK) {
        return;
    }
    senders_heard(&in->intent_seq, (uint32_t)msg->uav_id, now);
    peer_keep(&in->peers[slot], msg);
}

static void on_track(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    coavoid_node_inbox_t *in = user;
    coavoid_track_t *msg = &in->rx_msg.track;
    int size = 0;
    size_t key = 0;
    (void)channel;
    if (!received_size(rbuf, &size) ||
        !signature_ok(in, rbuf, COAVOID_AUTH_STREAM_TRACK, COAVOID_AUTH_WORLD, &key)) {
        return;
    }
    if (coavoid_track_t_decode(rbuf->data, 0, size, msg) < 0) {
        count_undecodable(in, "track: does not decode");
        return;
    }
    if (!sender_ok(in, key, COAVOID_AUTH_STREAM_TRACK, COAVOID_AUTH_WORLD, msg->source_id,
                   &msg->auth)) {
        return;
    }
    const int64_t now = *in->common.clock;
    size_t slot = COAVOID_NODE_MAX_TRACKS;
    for (size_t i = 0; i < COAVOID_NODE_MAX_TRACKS; i++) {
        if (in->tracks[i].used && in->tracks[i].msg.source_id == msg->source_id &&
            in->tracks[i].msg.track_id == msg->track_id) {
            slot = i;
            break;
        }
    }
    if (slot == COAVOID_NODE_MAX_TRACKS) {
        for (size_t i = 0; i < COAVOID_NODE_MAX_TRACKS; i++) {
            if (!in->tracks[i].used) {
                slot = i;
                break;
            }
        }
    }
    if (slot == COAVOID_NODE_MAX_TRACKS) {
        coavoid_lcm_rx_count(in->rx, COAVOID_LCM_ERR_CAPACITY,
                             "track: more tracks than the node holds");
        return;
    }
    coavoid_lcm_context_t ctx = coavoid_node_context(in, now, now);
    coavoid_lcm_track_info_t info;
    coa_track_t track;
    coa_track_point_t path[COAVOID_TRACK_T_MAX_PATH];
    const char *reason = NULL;
    int rc = coavoid_lcm_track_to_core(msg, &ctx, sequence_table(in, &in->track_seq), &info, &track,
                                       path, COAVOID_TRACK_T_MAX_PATH, &reason);
    coavoid_lcm_rx_count(in->rx, rc, reason);
    if (rc != COA_OK) {
        return;
    }
    senders_heard(&in->track_seq, (uint32_t)msg->source_id, now);
    in->world_news += in->tracks[slot].used ? 0u : 1u;
    in->tracks[slot].used = true;
    in->tracks[slot].msg = *msg;
}

static bool same_vec3(coa_vec3_t a, coa_vec3_t b)
{
    return a.x == b.x && a.y == b.y && a.z == b.z;
}

static bool same_obstacle(const coa_obstacle_t *a, const coa_obstacle_t *b)
{
    if (a->kind != b->kind) {
        return false;
    }
    if (a->kind == COA_OBSTACLE_BOX) {
        return same_vec3(a->box.min, b->box.min) && same_vec3(a->box.max, b->box.max);
    }
    if (a->polytope.count != b->polytope.count) {
        return false;
    }
    for (size_t i = 0; i < a->polytope.count; i++) {
        if (!same_vec3(a->polytope.vertices[i], b->polytope.vertices[i])) {
            return false;
        }
    }
    return true;
}

/* The configured obstacles, then the map's that are not one of them: a map adds terrain
 * and never takes any away, and the world's copy of the same database adds nothing (so
 * an honest run avoids exactly the configured obstacles, in their order). O(configured x
 * map x vertices), at most once per map received. */
static void obstacles_merge(coavoid_node_inbox_t *in)
{
    const size_t own = in->common.obstacle_count;
    for (size_t i = 0; i < own; i++) {
        in->obstacles[i] = in->common.obstacles[i];
    }
    size_t count = own;
    for (size_t j = 0; j < in->map_obstacle_count; j++) {
        bool known = false;
        for (size_t i = 0; i < own && !known; i++) {
            known = same_obstacle(&in->map_obstacles[j], &in->obstacles[i]);
        }
        if (!known) {
            in->obstacles[count++] = in->map_obstacles[j];
        }
    }
    in->obstacle_count = count;
}

/* Keeps an accepted tile; when it completes a version other than the one in use, that
 * version replaces it (the conversion checks the whole before it writes, so a version
 * that does not convert leaves the map in use untouched). Returns COA_OK or the refusal
 * that counts against this tile. */
static int map_tile_keep(coavoid_node_inbox_t *in, const coavoid_obstacle_map_t *msg,
                         const coavoid_lcm_context_t *ctx, const char **reason)
{
    if (in->have_map && msg->map_id == in->map_id && msg->version == in->map_version) {
        return COA_OK; /* the map in use, republished */
    }
    const coavoid_obstacle_map_t *first = &in->map_tiles[0];
    bool same = false;
    for (size_t i = 0; i < COAVOID_OBSTACLE_MAP_T_MAX_TILES && !same; i++) {
        const coavoid_obstacle_map_t *t = &in->map_tiles[i];
        same = (in->map_tiles_have & (UINT32_C(1) << i)) != 0u && t->map_id == msg->map_id &&
               t->version == msg->version;
        first = same ? t : first;
    }
    if (same && first->tile_count != msg->tile_count) {
        *reason = "obstacle_map: tile_count differs from the other tiles of its version";
        return COAVOID_LCM_ERR_COUNT;
    }
    if (!same) {
        in->map_tiles_have = 0u; /* a newer version, or another map: start over */
    }
    in->map_tiles[msg->tile_index] = *msg;
    in->map_tiles_have |= UINT32_C(1) << (uint32_t)msg->tile_index;
    if (in->map_tiles_have != UINT32_MAX >> (32u - (uint32_t)msg->tile_count)) {
        return COA_OK;
    }
    in->map_tiles_have = 0u;
    size_t count = 0;
    int rc = coavoid_lcm_obstacle_map_to_core(
        in->map_tiles, (size_t)msg->tile_count, ctx, in->map_obstacles,
        COAVOID_NODE_MAX_MAP_OBSTACLES, &count, in->vertices, COAVOID_NODE_MAX_VERTICES, reason);
    if (rc != COA_OK) {
        return rc;
    }
    in->map_obstacle_count = count;
    in->map_id = msg->map_id;
    in->map_version = msg->version;
    in->have_map = true;
    in->world_news++;
    obstacles_merge(in);
    return COA_OK;
}

static void on_map(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    coavoid_node_inbox_t *in = user;
    coavoid_obstacle_map_t *msg = &in->rx_msg.map;
    int size = 0;
    size_t key = 0;
    (void)channel;
    if (!received_size(rbuf, &size) ||
        !signature_ok(in, rbuf, COAVOID_AUTH_STREAM_MAP, COAVOID_AUTH_WORLD, &key)) {
        return;
    }
    if (coavoid_obstacle_map_t_decode(rbuf->data, 0, size, msg) < 0) {
        count_undecodable(in, "obstacle_map: does not decode");
        return;
    }
    if (!sender_ok(in, key, COAVOID_AUTH_STREAM_MAP, COAVOID_AUTH_WORLD, msg->map_id, &msg->auth)) {
        return;
    }
    const int64_t now = *in->common.clock;
    coavoid_lcm_context_t ctx = coavoid_node_context(in, now, now);
    const char *reason = NULL;
    int rc = coavoid_lcm_obstacle_map_accept(msg, &ctx, sequence_table(in, &in->map_seq), &reason);
    if (rc == COA_OK) {
        senders_heard(&in->map_seq, (uint32_t)msg->map_id, now);
        rc = map_tile_keep(in, msg, &ctx, &reason);
    }
    coavoid_lcm_rx_count(in->rx, rc, reason);
}

/* Any message its coordinator signed (or, insecure, sent) shows that it is alive: with
 * loss, a heartbeat alone may not come for a while when its plans and commits do. */
static void coordinator_heard(coavoid_node_inbox_t *in, int64_t now)
{
    in->heard_coordinator = true;
    in->coordinator_utime = now;
}

static void on_status(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    coavoid_node_inbox_t *in = user;
    coavoid_status_t *msg = &in->rx_msg.status;
    int size = 0;
    size_t key = 0;
    (void)channel;
    if (!received_size(rbuf, &size) ||
        !signature_ok(in, rbuf, COAVOID_AUTH_STREAM_STATUS, COAVOID_AUTH_ANY_ROLE, &key)) {
        return;
    }
    if (coavoid_status_t_decode(rbuf->data, 0, size, msg) < 0) {
        count_undecodable(in, "status: does not decode");
        return;
    }
    if (msg->node_id == (int32_t)in->self_node) {
        return;
    }
    if (!sender_ok(in, key, COAVOID_AUTH_STREAM_STATUS, coavoid_lcm_status_role(msg->node_kind),
                   msg->node_id, &msg->auth)) {
        return;
    }
    /* Before the sequence rule, so that impostors take no room in its table. */
    if (msg->node_kind == COAVOID_STATUS_T_NODE_COORDINATOR &&
        msg->node_id != (int32_t)in->coordinator_id) {
        coavoid_lcm_rx_count(in->rx, COAVOID_LCM_ERR_ID,
                             "status: a coordinator that is not this UAV's");
        return;
    }
    const int64_t now = *in->common.clock;
    coavoid_lcm_context_t ctx = coavoid_node_context(in, now, now);
    const char *reason = NULL;
    int rc = coavoid_lcm_status_accept(msg, &ctx, sequence_table(in, &in->status_seq), &reason);
    coavoid_lcm_rx_count(in->rx, rc, reason);
    if (rc != COA_OK) {
        return;
    }
    senders_heard(&in->status_seq, (uint32_t)msg->node_id, now);
    /* A coordinator that reports a fault is not one to follow. */
    if (msg->node_kind == COAVOID_STATUS_T_NODE_COORDINATOR &&
        msg->health != COAVOID_STATUS_T_HEALTH_FAULT) {
        coordinator_heard(in, now);
    }
}

static void on_plan(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    coavoid_node_inbox_t *in = user;
    coavoid_plan_t *msg = &in->rx_msg.plan;
    int size = 0;
    size_t key = 0;
    (void)channel;
    if (!received_size(rbuf, &size) ||
        !signature_ok(in, rbuf, COAVOID_AUTH_STREAM_PLAN, COAVOID_AUTH_COORDINATOR, &key)) {
        return;
    }
    if (coavoid_plan_t_decode(rbuf->data, 0, size, msg) < 0) {
        count_undecodable(in, "plan: does not decode");
        return;
    }
    if (msg->coordinator_id != (int32_t)in->coordinator_id) {
        coavoid_lcm_rx_count(in->rx, COAVOID_LCM_ERR_ID,
                             "plan: from a coordinator that is not this UAV's");
        return;
    }
    if (!sender_ok(in, key, COAVOID_AUTH_STREAM_PLAN, COAVOID_AUTH_COORDINATOR, msg->coordinator_id,
                   &msg->auth)) {
        return;
    }
    const int64_t now = *in->common.clock;
    coordinator_heard(in, now);
    if (in->on_plan_row != NULL && in->on_plan_row(in->owner, msg)) {
        coavoid_lcm_rx_count(in->rx, COA_OK, NULL); /* a plan it holds, sent again */
        return;
    }
    coavoid_lcm_context_t ctx = coavoid_node_context(in, now, now);
    coavoid_lcm_plan_info_t info;
    coa_plan_result_t result;
    const char *reason = NULL;
    /* No sequence rule across cycles: a plan is only ever adopted in the cycle its
     * valid_from names, and the vehicle orders the plans of one cycle itself. A table
     * remembering plan_ids would let one forged INT64_MAX, or a coordinator restarted
     * while its heartbeat kept the entry alive, lock every later plan out. A plan is
     * decided on only once all its rows (one message per UAV) have come. */
    const coavoid_plan_t *whole = NULL;
    int rc =
        coavoid_lcm_plan_collect(&in->plan_rows, msg, &ctx, &whole, &info, &result, in->rx_offsets,
                                 sizeof in->rx_offsets / sizeof in->rx_offsets[0], &reason);
    if (rc != COA_OK || whole == NULL) {
        coavoid_lcm_rx_count(in->rx, rc, reason); /* refused, or a row kept */
        return;
    }
    in->on_plan(in->owner, whole, &info, &result, in->rx_offsets);
}

static void on_agreement(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    coavoid_node_inbox_t *in = user;
    coavoid_agreement_t *msg = &in->rx_msg.agreement;
    int size = 0;
    size_t key = 0;
    (void)channel;
    if (!received_size(rbuf, &size) ||
        !signature_ok(in, rbuf, COAVOID_AUTH_STREAM_AGREEMENT, COAVOID_AUTH_ANY_ROLE, &key)) {
        return;
    }
    if (coavoid_agreement_t_decode(rbuf->data, 0, size, msg) < 0) {
        count_undecodable(in, "agreement: does not decode");
        return;
    }
    if (msg->node_id == (int32_t)in->self_node) {
        return; /* its own, back */
    }
    if (msg->coordinator_id != (int32_t)in->coordinator_id) {
        coavoid_lcm_rx_count(in->rx, COAVOID_LCM_ERR_ID,
                             "agreement: on a plan of a coordinator that is not this node's");
        return;
    }
    if (!sender_ok(in, key, COAVOID_AUTH_STREAM_AGREEMENT, coavoid_lcm_agreement_role(msg->kind),
                   msg->node_id, &msg->auth)) {
        return;
    }
    const int64_t now = *in->common.clock;
    coavoid_lcm_context_t ctx = coavoid_node_context(in, now, now);
    const char *reason = NULL;
    int rc = coavoid_lcm_agreement_check(msg, &ctx, &reason);
    if (rc == COA_OK && coavoid_lcm_agreement_role(msg->kind) == COAVOID_AUTH_COORDINATOR) {
        coordinator_heard(in, now);
    }
    if (rc == COA_OK) {
        rc = in->on_agreement(in->owner, msg);
    }
    coavoid_lcm_rx_count(in->rx, rc, rc == COA_OK ? NULL : reason);
}

static int subscribe(coavoid_node_inbox_t *in, const char *channel, lcm_msg_handler_t handler)
{
    lcm_subscription_t *sub = lcm_subscribe(in->rx_lcm, channel, handler, in);
    if (sub == NULL) {
        return COA_ERR_ARGUMENT;
    }
    lcm_subscription_set_queue_capacity(sub, COAVOID_NODE_QUEUE_CAPACITY);
    in->subs[in->sub_count++] = sub;
    return COA_OK;
}

int coavoid_node_inbox_init(coavoid_node_inbox_t *in, const coavoid_node_common_t *common,
                            uint16_t self_uav, uint16_t self_node, uint16_t coordinator_id,
                            size_t peer_capacity, lcm_t *lcm, coavoid_lcm_rx_stats_t *rx,
                            bool want_status, coavoid_node_plan_handler_t plan_handler, void *owner)
{
    in->common = *common;
    in->self_uav = self_uav;
    in->self_node = self_node;
    in->coordinator_id = coordinator_id;
    in->rx = rx;
    in->peer_capacity =
        peer_capacity > COAVOID_NODE_MAX_PEERS ? COAVOID_NODE_MAX_PEERS : peer_capacity;
    /* Old enough to still extrapolate a silent UAV for a horizon, and wide enough for a
     * track's path and a plan's samples around their stamps. */
    int64_t horizon_us = ((int64_t)common->horizon + 2) * common->dt_us;
    in->max_age_us = common->stale_after_us + horizon_us;
    coavoid_node_tx_init(&in->tx, lcm, common);
    in->rx_lcm = common->rx_lcm != NULL ? common->rx_lcm : lcm;
    in->sub_count = 0;
    in->secure = !common->insecure;
    if (in->secure && common->trust == NULL) {
        coavoid_node_tx_fini(&in->tx);
        return COA_ERR_ARGUMENT;
    }
    if (in->secure) {
        in->trust = *common->trust;
    } else {
        coavoid_auth_trust_init(&in->trust);
    }
    in->common.signer = NULL; /* copied: the caller's may go */
    in->common.trust = NULL;
    coavoid_lcm_rx_init(in->rx);
    senders_init(&in->intent_seq);
    senders_init(&in->track_seq);
    senders_init(&in->map_seq);
    senders_init(&in->status_seq);
    memset(in->peers, 0, sizeof in->peers);
    memset(in->tracks, 0, sizeof in->tracks);
    in->have_map = false;
    in->map_id = 0;
    in->map_version = 0;
    in->map_tiles_have = 0u;
    in->map_obstacle_count = 0;
    in->world_news = 0u;
    coavoid_lcm_plan_rows_init(&in->plan_rows, in->plan_slots, COAVOID_NODE_PLAN_SLOTS);
    obstacles_merge(in);
    memset(in->own_hash, 0, sizeof in->own_hash);
    memset(in->own_size, 0, sizeof in->own_size);
    in->own_next = 0;
    in->foreign_intents = 0;
    in->rejected_at_heartbeat = 0;
    budget_init(in);
    in->heard_coordinator = false;
    in->coordinator_utime = 0;
    in->on_plan = plan_handler;
    in->on_agreement = NULL;
    in->on_plan_row = NULL;
    in->owner = owner;
    int rc = subscribe(in, COAVOID_CHANNEL_INTENT, on_intent);
    if (rc == COA_OK) {
        rc = subscribe(in, COAVOID_CHANNEL_TRACK, on_track);
    }
    if (rc == COA_OK) {
        rc = subscribe(in, COAVOID_CHANNEL_OBSTACLES, on_map);
    }
    if (rc == COA_OK && want_status) {
        rc = subscribe(in, COAVOID_CHANNEL_STATUS, on_status);
    }
    if (rc == COA_OK && plan_handler != NULL) {
        rc = subscribe(in, COAVOID_CHANNEL_PLAN, on_plan);
    }
    if (rc != COA_OK) {
        coavoid_node_inbox_fini(in);
    }
    return rc;
}

int coavoid_node_inbox_agreements(coavoid_node_inbox_t *in,
                                  coavoid_node_agreement_handler_t handler)
{
    in->on_agreement = handler;
    return subscribe(in, COAVOID_CHANNEL_AGREEMENT, on_agreement);
}

void coavoid_node_inbox_fini(coavoid_node_inbox_t *in)
{
    for (size_t i = 0; i < in->sub_count; i++) {
        lcm_unsubscribe(in->rx_lcm, in->subs[i]);
    }
    in->sub_count = 0;
    coavoid_node_tx_fini(&in->tx);
}

static int64_t drop_after(const coavoid_node_inbox_t *in)
{
    return in->common.stale_after_us +
           (int64_t)COAVOID_NODE_DROP_HORIZONS * (int64_t)in->common.horizon * in->common.dt_us;
}

void coavoid_node_inbox_expire(coavoid_node_inbox_t *in, int64_t now)
{
    const int64_t stale = in->common.stale_after_us;
    const int64_t drop = drop_after(in);
    for (size_t i = 0; i < COAVOID_NODE_MAX_PEERS; i++) {
        coavoid_node_peer_t *p = &in->peers[i];
        if (!p->used) {
            continue;
        }
        int64_t age = now - p->msg.utime;
        if (age > stale && !p->forgotten) {
            /* A UAV that comes back after a restart numbers from 0 again. */
            coavoid_lcm_sequence_forget(&in->intent_seq.table, (uint32_t)p->msg.uav_id);
            p->forgotten = true;
        }
        if (age > drop) {
            p->used = false;
        }
    }
    for (size_t i = 0; i < COAVOID_NODE_MAX_TRACKS; i++) {
        if (in->tracks[i].used && now - in->tracks[i].msg.utime > stale) {
            in->tracks[i].used = false;
        }
    }
    senders_expire(&in->intent_seq, now, stale);
    senders_expire(&in->track_seq, now, stale);
    senders_expire(&in->map_seq, now, stale);
    senders_expire(&in->status_seq, now, stale);
}

/* ---- the view ---- */

static bool vec_finite(coa_vec3_t v)
{
    return isfinite((double)v.x) && isfinite((double)v.y) && isfinite((double)v.z);
}

/* A stale UAV as a track: constant velocity from the state of its last intent, moved to
 * t = 0 at cycle_start, its sigma grown with the silence. */
static bool stale_track(const coavoid_intent_t *msg, const coavoid_node_common_t *c,
                        int64_t cycle_start, int64_t now, coa_track_t *tr)
{
    double lead = (double)(cycle_start - msg->utime) * 1e-6;
    double silence = (double)(now - msg->utime) * 1e-6;
    double p[3];
    for (int a = 0; a < 3; a++) {
        p[a] = msg->position[a] + msg->velocity[a] * lead;
    }
    memset(tr, 0, sizeof *tr);
    tr->id = (uint32_t)msg->uav_id;
    tr->volume.radius = (coa_real_t)msg->radius;
    tr->volume.half_height = (coa_real_t)msg->half_height;
    tr->position.x = (coa_real_t)p[0];
    tr->position.y = (coa_real_t)p[1];
    tr->position.z = (coa_real_t)p[2];
    tr->velocity.x = (coa_real_t)msg->velocity[0];
    tr->velocity.y = (coa_real_t)msg->velocity[1];
    tr->velocity.z = (coa_real_t)msg->velocity[2];
    tr->path = NULL;
    tr->path_count = 0;
    double grow = (double)c->stale_sigma_rate * (silence > 0.0 ? silence : 0.0);
    tr->sigma_horizontal = (coa_real_t)(msg->sigma_horizontal + grow);
    tr->sigma_vertical = (coa_real_t)(msg->sigma_vertical + grow);
    return vec_finite(tr->position) && isfinite((double)tr->sigma_horizontal) &&
           isfinite((double)tr->sigma_vertical) && coa_track_check(tr) == COA_OK;
}

/* A stale UAV's track along the last plan it announced: its intent's positions at their
 * own times (a UAV that has gone silent most likely flies what it said), then the
 * velocity of the plan's last leg (coa_track_t's rule), with stale_track's volume and
 * sigma. False when the intent no longer converts on this clock, or the path is refused:
 * then the caller keeps stale_track's straight line. O(samples); no memory. */
static bool stale_plan_track(const coavoid_intent_t *msg, const coavoid_lcm_context_t *ctx,
                             coavoid_lcm_intent_arrays_t *scratch, coa_track_point_t *path,
                             coa_track_t *tr)
{
    coavoid_lcm_intent_info_t info;
    coa_vehicle_t vehicle;
    coa_intent_plan_t plan;
    if (coavoid_lcm_intent_to_core(msg, ctx, NULL, &info, &vehicle, &plan, scratch, NULL) !=
            COA_OK ||
        plan.count > COAVOID_NODE_MAX_SAMPLES) {
        return false;
    }
    for (size_t j = 0; j < plan.count; j++) {
        path[j].t = plan.t0 + (coa_real_t)j * plan.step;
        path[j].p = plan.samples[j];
    }
    coa_track_t planned = *tr;
    planned.position = plan.samples[0];
    planned.path = path;
    planned.path_count = plan.count;
    if (coa_track_check(&planned) != COA_OK) {
        return false;
    }
    *tr = planned;
    return true;
}

/* Peer i's latest intent of a cycle that began before `before`: its latest, or the one
 * before it; NULL when it has none. O(1). */
static const coavoid_intent_t *peer_intent(const coavoid_node_inbox_t *in, size_t i, int64_t before)
{
    const coavoid_node_peer_t *p = &in->peers[i];
    if (p->msg.plan_utime < before) {
        return &p->msg;
    }
    return p->has_prev && p->prev.plan_utime < before ? &p->prev : NULL;
}

/* The UAVs heard, by ascending id, so that plan indices (and the clusters' order) do not
 * depend on the order intents arrived in. Returns how many. */
static size_t peers_by_id(const coavoid_node_inbox_t *in, size_t *order)
{
    size_t n = 0;
    for (size_t i = 0; i < COAVOID_NODE_MAX_PEERS; i++) {
        if (!in->peers[i].used) {
            continue;
        }
        size_t j = n++;
        while (j > 0 && in->peers[order[j - 1]].msg.uav_id > in->peers[i].msg.uav_id) {
            order[j] = order[j - 1];
            j--;
        }
        order[j] = i;
    }
    return n;
}

/* The live tracks heard, by (source, id). Returns how many. */
static size_t tracks_by_id(const coavoid_node_inbox_t *in, int64_t now, size_t *torder)
{
    size_t m = 0;
    for (size_t i = 0; i < COAVOID_NODE_MAX_TRACKS; i++) {
        const coavoid_node_track_slot_t *t = &in->tracks[i];
        if (!t->used || now - t->msg.utime > in->common.stale_after_us) {
            continue;
        }
        size_t j = m++;
        while (j > 0) {
            const coavoid_track_t *prev = &in->tracks[torder[j - 1]].msg;
            if (prev->source_id < t->msg.source_id ||
                (prev->source_id == t->msg.source_id && prev->track_id < t->msg.track_id)) {
                break;
            }
            torder[j] = torder[j - 1];
            j--;
        }
        torder[j] = i;
    }
    return m;
}

/* The live UAVs' plans (those whose intent is fresh and converts), marking the stale ones. */
static void view_live(coavoid_node_view_t *view, const coavoid_node_inbox_t *in,
                      const coavoid_lcm_context_t *ctx, const size_t *order, size_t n, bool *stale,
                      int64_t cycle_start, int64_t now, int64_t before)
{
    const coavoid_node_common_t *c = &in->common;
    for (size_t s = 0; s < n; s++) {
        const coavoid_intent_t *msg = peer_intent(in, order[s], before);
        stale[s] = false;
        if (msg == NULL) {
            continue;
        }
        int64_t age = now - msg->utime;
        stale[s] = age > c->stale_after_us;
        if (stale[s]) {
            continue;
        }
        size_t i = view->live_count;
        if (coavoid_lcm_intent_to_core(msg, ctx, NULL, &view->live_info[i], &view->live_vehicle[i],
                                       &view->live_plan[i], &view->live_arrays[i],
                                       NULL) != COA_OK) {
            continue; /* e.g. stamped further ahead of this clock than allowed */
        }
        view->live_id[i] = (uint16_t)msg->uav_id;
        view->live_current[i] = msg->plan_utime == cycle_start && msg->step == (double)c->dt &&
                                msg->sample_count == (int32_t)c->horizon + 1;
        view->live_count++;
    }
}

void coavoid_node_view_build(coavoid_node_view_t *view, const coavoid_node_inbox_t *in,
                             int64_t cycle_start, int64_t now)
{
    coavoid_node_view_build_before(view, in, cycle_start, now, INT64_MAX);
}

void coavoid_node_view_build_before(coavoid_node_view_t *view, const coavoid_node_inbox_t *in,
                                    int64_t cycle_start, int64_t now, int64_t before)
{
    const coavoid_node_common_t *c = &in->common;
    const coavoid_lcm_context_t ctx = coavoid_node_context(in, now, cycle_start);
    const int64_t drop = drop_after(in);
    size_t order[COAVOID_NODE_MAX_PEERS];
    size_t torder[COAVOID_NODE_MAX_TRACKS];
    bool stale[COAVOID_NODE_MAX_PEERS];

    view->cycle_start = cycle_start;
    view->live_count = 0;
    view->track_count = 0;
    view->real_track_count = 0;
    view->stale_count = 0;
    const size_t n = peers_by_id(in, order);
    view_live(view, in, &ctx, order, n, stale, cycle_start, now, before);
    const size_t m = tracks_by_id(in, now, torder);
    for (size_t s = 0; s < m; s++) {
        const coavoid_track_t *msg = &in->tracks[torder[s]].msg;
        size_t i = view->track_count;
        coavoid_lcm_track_info_t info;
        if (coavoid_lcm_track_to_core(msg, &ctx, NULL, &info, &view->tracks[i], view->real_paths[s],
                                      COAVOID_TRACK_T_MAX_PATH, NULL) != COA_OK) {
            continue;
        }
        view->track_ids[i] = (uint32_t)msg->track_id;
        view->track_count++;
    }
    view->real_track_count = view->track_count;
    /* The silent UAVs, until they are dropped: tracks along the last plan they announced. */
    for (size_t s = 0; s < n; s++) {
        const coavoid_intent_t *msg = peer_intent(in, order[s], before);
        if (!stale[s] || now - msg->utime > drop) {
            continue;
        }
        size_t i = view->track_count;
        if (!stale_track(msg, c, cycle_start, now, &view->tracks[i])) {
            continue;
        }
        (void)stale_plan_track(msg, &ctx, &view->stale_arrays, view->stale_paths[s],
                               &view->tracks[i]);
        view->track_ids[i] = (uint32_t)msg->uav_id;
        view->track_count++;
        view->stale_count++;
    }
}

int coavoid_node_problem_tracks(coavoid_node_problem_tracks_t *out, const coavoid_node_view_t *view,
                                const bool *include, const coavoid_node_common_t *c,
                                uint32_t horizon)
{
    if (horizon + 1u > COAVOID_NODE_MAX_PROBLEM_SAMPLES) {
        return COA_ERR_ARGUMENT;
    }
    size_t n = 0;
    size_t paths = 0;
    for (size_t i = 0; i < view->real_track_count; i++, n++) {
        out->tracks[n] = view->tracks[i];
        if (coa_track_sample(&out->tracks[n], c->dt, horizon, out->storage[n]) != COA_OK) {
            return COA_ERR_ARGUMENT;
        }
        out->samples[n] = out->storage[n];
    }
    for (size_t i = 0; i < view->live_count; i++) {
        if (include == NULL || !include[i]) {
            continue;
        }
        const coa_intent_plan_t *plan = &view->live_plan[i];
        coa_track_point_t *path = out->paths[paths++];
        for (size_t j = 0; j < plan->count; j++) {
            path[j].t = plan->t0 + (coa_real_t)j * plan->step;
            path[j].p = plan->samples[j];
        }
        coa_track_t *tr = &out->tracks[n];
        memset(tr, 0, sizeof *tr);
        tr->id = view->live_id[i];
        tr->volume = plan->volume;
        tr->position = plan->samples[0];
        tr->path = path;
        tr->path_count = plan->count;
        if (view->live_current[i] && horizon < plan->count) {
            /* Its own samples: the positions it flies, bit for bit. */
            out->samples[n] = plan->samples;
        } else {
            if (coa_track_sample(tr, c->dt, horizon, out->storage[n]) != COA_OK) {
                return COA_ERR_ARGUMENT;
            }
            if (view->live_current[i]) {
                /* As far as it reaches bit for bit too; beyond, along its last leg. */
                memcpy(out->storage[n], plan->samples, plan->count * sizeof plan->samples[0]);
            }
            out->samples[n] = out->storage[n];
        }
        n++;
    }
    for (size_t i = view->real_track_count; i < view->track_count; i++, n++) {
        out->tracks[n] = view->tracks[i];
        if (coa_track_sample(&out->tracks[n], c->dt, horizon, out->storage[n]) != COA_OK) {
            return COA_ERR_ARGUMENT;
        }
        out->samples[n] = out->storage[n];
    }
    out->count = n;
    return COA_OK;
}

#define NODE_MIX(h, value) coavoid_node_fnv((h), &(value), sizeof(value))

static uint64_t vec_digest(uint64_t h, const coa_vec3_t *p)
{
    h = NODE_MIX(h, p->x);
    h = NODE_MIX(h, p->y);
    return NODE_MIX(h, p->z);
}

static uint64_t vehicle_digest(uint64_t h, const coa_vehicle_t *v)
{
    h = NODE_MIX(h, v->id);
    h = NODE_MIX(h, v->priority);
    h = NODE_MIX(h, v->cruise_speed);
    h = NODE_MIX(h, v->climb_rate);
    h = NODE_MIX(h, v->steep_factor);
    h = NODE_MIX(h, v->volume.radius);
    h = NODE_MIX(h, v->volume.half_height);
    h = NODE_MIX(h, v->route_count);
    for (size_t r = 0; r < v->route_count; r++) {
        h = vec_digest(h, &v->route[r]);
    }
    h = NODE_MIX(h, v->initial_offset);
    return NODE_MIX(h, v->max_offset);
}

static uint64_t obstacle_digest(uint64_t h, const coa_obstacle_t *o)
{
    h = NODE_MIX(h, o->kind);
    if (o->kind == COA_OBSTACLE_BOX) {
        return vec_digest(vec_digest(h, &o->box.min), &o->box.max);
    }
    h = NODE_MIX(h, o->polytope.count);
    for (size_t k = 0; k < o->polytope.count; k++) {
        h = vec_digest(h, &o->polytope.vertices[k]);
    }
    return h;
}

static uint64_t samples_digest(uint64_t h, const coa_vec3_t *samples, uint32_t horizon)
{
    for (uint32_t k = 0; k <= horizon; k++) {
        h = vec_digest(h, &samples[k]);
    }
    return h;
}

uint64_t coavoid_node_problem_digest(const coa_problem_t *problem)
{
    uint64_t h = COAVOID_NODE_FNV_OFFSET;
    h = NODE_MIX(h, problem->dt);
    h = NODE_MIX(h, problem->horizon);
    h = NODE_MIX(h, problem->vehicle_count);
    for (size_t i = 0; i < problem->vehicle_count; i++) {
        h = vehicle_digest(h, &problem->vehicles[i]);
        h = samples_digest(h, problem->references[i], problem->horizon);
    }
    h = NODE_MIX(h, problem->obstacle_count);
    for (size_t o = 0; o < problem->obstacle_count; o++) {
        h = obstacle_digest(h, &problem->obstacles[o]);
    }
    h = NODE_MIX(h, problem->track_count);
    for (size_t j = 0; j < problem->track_count; j++) {
        h = NODE_MIX(h, problem->tracks[j].volume.radius);
        h = NODE_MIX(h, problem->tracks[j].volume.half_height);
        h = samples_digest(h, problem->track_samples[j], problem->horizon);
    }
    return h;
}

int coavoid_node_problem(coa_problem_t *problem, coavoid_node_problem_tracks_t *tracks,
                         const coavoid_node_view_t *view, const bool *include,
                         const coavoid_node_inbox_t *in, const coa_vehicle_t *vehicles,
                         const coa_vec3_t *const *references, size_t count, uint32_t horizon)
{
    const coavoid_node_common_t *c = &in->common;
    int rc = coavoid_node_problem_tracks(tracks, view, include, c, horizon);
    if (rc != COA_OK) {
        return rc;
    }
    memset(problem, 0, sizeof *problem);
    problem->dt = c->dt;
    problem->horizon = horizon;
    problem->vehicles = vehicles;
    problem->vehicle_count = count;
    problem->references = references;
    problem->obstacles = in->obstacles;
    problem->obstacle_count = in->obstacle_count;
    problem->tracks = tracks->tracks;
    problem->track_count = tracks->count;
    problem->track_samples = tracks->samples;
    return COA_OK;
}

size_t coavoid_node_max_pairs(void)
{
    const size_t n = COAVOID_NODE_MAX_PEERS;
    return n * (n - 1u) / 2u + n * COAVOID_NODE_TRACK_CAPACITY + n * COAVOID_NODE_MAX_OBSTACLES;
}

coa_predict_config_t coavoid_node_predict_config(const coavoid_node_common_t *c)
{
    coa_predict_config_t config;
    memset(&config, 0, sizeof config);
    config.t0 = 0;
    config.dt = c->dt;
    config.horizon = c->horizon;
    config.vehicle_sigma_rate_horizontal = c->vehicle_sigma_rate_horizontal;
    config.vehicle_sigma_rate_vertical = c->vehicle_sigma_rate_vertical;
    config.track_sigma_rate_horizontal = c->track_sigma_rate_horizontal;
    config.track_sigma_rate_vertical = c->track_sigma_rate_vertical;
    config.threshold = c->threshold;
    config.all_pairs = false;
    return config;
}

int coavoid_node_predict(coa_predictor_t *predictor, const coavoid_node_common_t *c,
                         const coa_intent_plan_t *plans, size_t n, const coavoid_node_view_t *view,
                         const coavoid_node_inbox_t *in, coa_conflict_t *conflicts, size_t capacity,
                         coa_predict_result_t *result, uint32_t *labels, size_t *cluster_count)
{
    memset(result, 0, sizeof *result);
    *cluster_count = 0;
    if (n == 0) {
        return COA_OK;
    }
    coa_predict_config_t config = coavoid_node_predict_config(c);
    int rc = coa_predict(predictor, &config, plans, n, in->obstacles, in->obstacle_count,
                         view->tracks, view->track_count, conflicts, capacity, result);
    if (rc != COA_OK) {
        return rc;
    }
    if (result->overflow) {
        return COA_ERR_WORKSPACE;
    }
    return coa_predict_clusters(conflicts, result->conflict_count, n, labels, cluster_count);
}

coa_planner_config_t coavoid_node_planner_config(uint32_t horizon, size_t searched, uint32_t beta)
{
    coa_planner_config_t c;
    c.vehicles = searched;
    c.beta = beta;
    c.horizon = horizon;
    c.steep_factor = COA_MAX_STEEP_FACTOR;
    c.max_offset = -1;
    return c;
}

int coavoid_node_joint_memo_init(coavoid_node_joint_memo_t *memo, uint64_t *keys, size_t capacity)
{
    memset(memo, 0, sizeof *memo);
    if ((capacity & (capacity - 1u)) != 0u || (keys == NULL && capacity > 0u)) {
        return COA_ERR_ARGUMENT;
    }
    if (capacity > 0u) {
        memset(keys, 0, capacity * sizeof keys[0]);
    }
    memo->keys = keys;
    memo->capacity = capacity;
    return COA_OK;
}

/* The key's slot, or the empty one where it would go. 0 is the empty slot's, so key 0
 * is stored as 1 (one more collision in 2^64). */
static size_t memo_slot(const coavoid_node_joint_memo_t *memo, uint64_t *key)
{
    *key = *key != 0u ? *key : 1u;
    const size_t mask = memo->capacity - 1u;
    size_t k = (size_t)(*key ^ (*key >> 32)) & mask;
    while (memo->keys[k] != 0u && memo->keys[k] != *key) {
        k = (k + 1u) & mask;
    }
    return k;
}

bool coavoid_node_joint_memo_has(const coavoid_node_joint_memo_t *memo, uint64_t key)
{
    return memo != NULL && memo->capacity > 0u && memo->keys[memo_slot(memo, &key)] == key;
}

void coavoid_node_joint_memo_add(coavoid_node_joint_memo_t *memo, uint64_t key)
{
    /* Never past half full: a probe stays short, and always ends at an empty slot. */
    if (memo == NULL || memo->capacity == 0u || 2u * (memo->count + 1u) > memo->capacity) {
        return;
    }
    const size_t k = memo_slot(memo, &key);
    if (memo->keys[k] == 0u) {
        memo->keys[k] = key;
        memo->count++;
    }
}

size_t coavoid_node_joint_members(coavoid_node_mode_t mode, size_t fleet)
{
    if (mode != COAVOID_NODE_CENTRALISED || fleet < 2u) {
        return 0u;
    }
    return fleet < COAVOID_NODE_DEFAULT_JOINT_MEMBERS ? fleet : COAVOID_NODE_DEFAULT_JOINT_MEMBERS;
}

int coavoid_node_solver_init(coavoid_node_solver_t *s, uint32_t horizon, uint32_t plan_horizon,
                             size_t searched, uint32_t beta)
{
    memset(s, 0, sizeof *s);
    const size_t pairs = coavoid_node_max_pairs();
    const size_t predictor_size = coa_predictor_workspace_size(
        COAVOID_NODE_MAX_PEERS, COAVOID_NODE_TRACK_CAPACITY, horizon, pairs);
    const coa_planner_config_t config = coavoid_node_planner_config(plan_horizon, searched, beta);
    const size_t planner_size = coa_planner_workspace_size(&config);
    if (predictor_size == 0u || planner_size == 0u) {
        return COA_ERR_ARGUMENT;
    }
    s->predictor_memory = malloc(predictor_size);
    s->planner_memory = malloc(planner_size);
    s->conflict_capacity = pairs;
    s->conflicts = calloc(pairs, sizeof *s->conflicts);
    if (s->predictor_memory != NULL) {
        s->predictor =
            coa_predictor_init(s->predictor_memory, predictor_size, COAVOID_NODE_MAX_PEERS,
                               COAVOID_NODE_TRACK_CAPACITY, horizon, pairs);
    }
    if (s->planner_memory != NULL) {
        s->planner = coa_planner_init(s->planner_memory, planner_size, &config);
    }
    if (s->predictor == NULL || s->planner == NULL || s->conflicts == NULL) {
        coavoid_node_solver_fini(s);
        return COA_ERR_WORKSPACE;
    }
    return COA_OK;
}

void coavoid_node_solver_fini(coavoid_node_solver_t *s)
{
    free(s->predictor_memory);
    free(s->planner_memory);
    free(s->conflicts);
    memset(s, 0, sizeof *s);
}

/* Dropped unchecked since start: over the inbox budget, or by the transport; saturated. */
static int64_t dropped_unchecked(const coavoid_node_inbox_t *in)
{
    const uint64_t transport =
        in->common.transport_dropped != NULL ? *in->common.transport_dropped : 0u;
    const uint64_t total = (uint64_t)in->dropped + transport;
    return total > (uint64_t)INT64_MAX || total < transport ? INT64_MAX : (int64_t)total;
}

/* Datagrams a second over the last whole cycle, saturated. */
static int32_t inbox_rate(const coavoid_node_inbox_t *in)
{
    const double rate = (double)in->last_cycle_datagrams * 1e6 / (double)in->common.dt_us;
    return rate >= (double)INT32_MAX ? INT32_MAX : (int32_t)rate;
}

int coavoid_node_publish_heartbeat(coavoid_node_inbox_t *in, coavoid_status_t *m, int64_t now,
                                   int64_t cycle_start, const coavoid_node_heartbeat_t *h)
{
    memset(m, 0, sizeof *m);
    m->utime = now;
    m->node_id = h->node_id;
    m->node_kind = h->node_kind;
    m->sequence = h->sequence;
    const bool refused = h->rx->rejected > in->rejected_at_heartbeat;
    in->rejected_at_heartbeat = h->rx->rejected;
    budget_roll(in, now);
    const int64_t dropped = dropped_unchecked(in);
    const bool flooded =
        dropped > in->dropped_at_heartbeat || in->last_cycle_datagrams > COAVOID_NODE_INBOX_FLOOD;
    in->dropped_at_heartbeat = dropped;
    m->reasons = h->reasons | (refused ? COAVOID_STATUS_T_REASON_MESSAGES_REFUSED : 0) |
                 (flooded ? COAVOID_STATUS_T_REASON_INBOX_FLOOD : 0) |
                 (in->have_map ? 0 : COAVOID_STATUS_T_REASON_NO_MAP) |
                 (in->secure ? 0 : COAVOID_STATUS_T_REASON_INSECURE);
    m->health = coavoid_lcm_health_of(m->reasons);
    m->mode = h->mode;
    m->last_plan_utime = h->last_plan_utime;
    m->last_plan_duration_us = h->last_plan_duration_us;
    m->nodes_expanded =
        h->last_nodes_expanded > (uint64_t)INT64_MAX ? INT64_MAX : (int64_t)h->last_nodes_expanded;
    m->outcome = h->last_outcome < 0 ? COAVOID_STATUS_T_OUTCOME_NONE : (int8_t)h->last_outcome;
    m->conflicts = h->conflicts > (uint32_t)INT32_MAX ? INT32_MAX : (int32_t)h->conflicts;
    m->plans_run = h->plans_run > (uint32_t)INT32_MAX ? INT32_MAX : (int32_t)h->plans_run;
    m->messages_received = h->rx->received;
    m->messages_rejected = h->rx->rejected;
    m->last_reject_code = h->rx->last_reject_code;
    m->messages_dropped = dropped;
    m->inbox_rate = inbox_rate(in);
    coavoid_lcm_context_t ctx = coavoid_node_context(in, now, cycle_start);
    if (coavoid_lcm_status_check(m, &ctx, NULL) != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    return coavoid_node_publish_status(&in->tx, m);
}

/* ---- publishing ---- */

void coavoid_node_tx_init(coavoid_node_tx_t *tx, lcm_t *lcm, const coavoid_node_common_t *c)
{
    tx->lcm = lcm;
    tx->clock = c->clock;
    tx->sign = !c->insecure && c->signer != NULL;
    memset(&tx->signer, 0, sizeof tx->signer);
    if (tx->sign) {
        tx->signer = *c->signer;
    }
}

void coavoid_node_tx_fini(coavoid_node_tx_t *tx)
{
    coavoid_auth_signer_clear(&tx->signer);
    tx->sign = false;
}

/* Encodes msg into tx->buf with the type's functions and signs it; its size, or a
 * negative error. */
#define COAVOID_NODE_SEAL(tx, type, msg) \
    (seal((tx), type##_encoded_size(msg), type##_encode((tx)->buf, 0, (int)sizeof(tx)->buf, (msg))))

/* Whether an encoded message of `size` bytes may go out: at most one datagram
 * (COAVOID_LCM_MAX_DATAGRAM_BYTES), so that no message is fragmented on the way; every type
 * fits, so a larger one is a bug, refused rather than sent. O(1). */
static bool fits_datagram(int size)
{
    return size > 0 && size <= COAVOID_LCM_MAX_DATAGRAM_BYTES &&
           (size_t)size <= COAVOID_NODE_TX_BYTES;
}

/* The size of the message encoded into tx->buf (encoded: the encoder's return, expected
 * to be `size`), signed unless the node is insecure; or a negative error. Nothing over
 * one datagram is encoded. */
static int seal(coavoid_node_tx_t *tx, int size, int encoded)
{
    if (!fits_datagram(size) || encoded != size) {
        return COA_ERR_WORKSPACE;
    }
    if (tx->sign && coavoid_auth_stamp(&tx->signer, *tx->clock, tx->buf, (size_t)size) != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    return size;
}

static int send_sealed(coavoid_node_tx_t *tx, const char *channel, int size)
{
    if (size < 0) {
        return size;
    }
    return lcm_publish(tx->lcm, channel, tx->buf, (unsigned int)size) == 0 ? COA_OK
                                                                           : COA_ERR_ARGUMENT;
}

#define COAVOID_NODE_DEFINE_PUBLISH(function, type, channel)               \
    int function(coavoid_node_tx_t *tx, const type *msg)                   \
    {                                                                      \
        return send_sealed(tx, channel, COAVOID_NODE_SEAL(tx, type, msg)); \
    }

COAVOID_NODE_DEFINE_PUBLISH(coavoid_node_publish_plan, coavoid_plan_t, COAVOID_CHANNEL_PLAN)
COAVOID_NODE_DEFINE_PUBLISH(coavoid_node_publish_track, coavoid_track_t, COAVOID_CHANNEL_TRACK)
COAVOID_NODE_DEFINE_PUBLISH(coavoid_node_publish_map, coavoid_obstacle_map_t,
                            COAVOID_CHANNEL_OBSTACLES)
COAVOID_NODE_DEFINE_PUBLISH(coavoid_node_publish_conflicts, coavoid_conflict_report_t,
                            COAVOID_CHANNEL_CONFLICTS)
COAVOID_NODE_DEFINE_PUBLISH(coavoid_node_publish_status, coavoid_status_t, COAVOID_CHANNEL_STATUS)
COAVOID_NODE_DEFINE_PUBLISH(coavoid_node_publish_agreement, coavoid_agreement_t,
                            COAVOID_CHANNEL_AGREEMENT)

int coavoid_node_publish_intent(coavoid_node_inbox_t *in, const coavoid_intent_t *msg)
{
    coavoid_node_tx_t *tx = &in->tx;
    const int size = COAVOID_NODE_SEAL(tx, coavoid_intent_t, msg);
    if (size < 0) {
        return size;
    }
    /* Remembered before it is sent (signed, as it will come back): a provider may hand it
     * back within lcm_publish. */
    in->own_hash[in->own_next] = fingerprint(tx->buf, (size_t)size);
    in->own_size[in->own_next] = size;
    in->own_next = (in->own_next + 1u) % COAVOID_NODE_OWN_INTENTS;
    return send_sealed(tx, COAVOID_CHANNEL_INTENT, size);
}

uint64_t coavoid_node_work_of(int64_t us)
{
    if (us <= 0) {
        return 1u;
    }
    return (uint64_t)us > UINT64_MAX / COAVOID_NODE_WORK_PER_US
               ? UINT64_MAX
               : (uint64_t)us * COAVOID_NODE_WORK_PER_US;
}
