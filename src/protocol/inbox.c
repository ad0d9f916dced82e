/* SPDX-License-Identifier: MIT */
/*
 * The inbox (protocol_internal.h): what arrives, checked (tail, fleet tag, budget,
 * signature, sender), decoded, validated, counted and stored.
 */
#include "protocol_internal.h"

#include <limits.h>
#include <math.h>
#include <string.h>

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

void coavoid_node_inbox_roll(coavoid_node_inbox_t *in, int64_t now)
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
static bool signature_ok(coavoid_node_inbox_t *in, const uint8_t *data, int size, size_t stream,
                         coavoid_auth_role_t role, size_t *key)
{
    *key = 0;
    coavoid_node_inbox_roll(in, *in->common.clock);
    if (in->cycle_datagrams < UINT32_MAX) {
        in->cycle_datagrams++;
    }
    if (!in->secure) {
        return true;
    }
    const coavoid_auth_expect_t expect = {stream, role, *in->common.clock, in->max_age_us,
                                          in->common.dt_us};
    int rc = coavoid_auth_precheck(&in->trust, data, (size_t)size, &expect, key);
    if (rc == COA_OK && !budget_check(in, *key, stream)) {
        return false;
    }
    if (rc == COA_OK) {
        rc = coavoid_auth_verify(&in->trust, data, (size_t)size, key);
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

void coavoid_node_intent_keep(coavoid_node_intent_t *kept, const coavoid_intent_t *msg)
{
    kept->utime = msg->utime;
    kept->plan_utime = msg->plan_utime;
    kept->uav_id = msg->uav_id;
    memcpy(kept->head, msg, sizeof kept->head);
    for (size_t j = 0; j < COAVOID_NODE_MAX_SAMPLES; j++) {
        for (size_t d = 0; d < 3u; d++) {
            kept->reference[j][d] = (coa_real_t)msg->reference[j][d];
        }
    }
    memcpy(kept->offsets, msg->offsets, sizeof kept->offsets);
    memcpy(kept->tail, (const uint8_t *)msg + COAVOID_NODE_INTENT_TAIL_AT, sizeof kept->tail);
}

const coavoid_intent_t *coavoid_node_intent_open(const coavoid_node_intent_t *kept,
                                                 coavoid_intent_t *out)
{
    memset(out, 0, sizeof *out);
    memcpy(out, kept->head, sizeof kept->head);
    for (size_t j = 0; j < COAVOID_NODE_MAX_SAMPLES; j++) {
        for (size_t d = 0; d < 3u; d++) {
            out->reference[j][d] = (double)kept->reference[j][d];
        }
    }
    memcpy(out->offsets, kept->offsets, sizeof kept->offsets);
    memcpy((uint8_t *)out + COAVOID_NODE_INTENT_TAIL_AT, kept->tail, sizeof kept->tail);
    return out;
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
    coavoid_node_intent_keep(&peer->msg, msg);
}

/* UAV uav_id's slot among the peers, or a free one while fewer than peer_capacity are
 * used, else COAVOID_NODE_MAX_PEERS. O(MAX_PEERS). */
static size_t peer_slot(const coavoid_node_inbox_t *in, int32_t uav_id)
{
    size_t slot = COAVOID_NODE_MAX_PEERS;
    size_t used = 0;
    for (size_t i = 0; i < COAVOID_NODE_MAX_PEERS; i++) {
        if (in->peers[i].used) {
            used++;
            slot = in->peers[i].msg.uav_id == uav_id ? i : slot;
        }
    }
    for (size_t i = 0;
         slot == COAVOID_NODE_MAX_PEERS && used < in->peer_capacity && i < COAVOID_NODE_MAX_PEERS;
         i++) {
        slot = in->peers[i].used ? slot : i;
    }
    return slot;
}

static void on_intent(coavoid_node_inbox_t *in, const uint8_t *data, int size)
{
    coavoid_intent_t *msg = &in->rx_msg.intent;
    size_t key = 0;
    /* Its own, looped back, byte for byte: nothing to check (a copy of it changes nothing). */
    if (in->self_uav != 0u && sent_by_self(in, data, (size_t)size)) {
        return;
    }
    if (!signature_ok(in, data, size, COAVOID_AUTH_STREAM_INTENT, COAVOID_AUTH_VEHICLE, &key)) {
        return;
    }
    if (coavoid_intent_t_decode(data, 0, size, msg) < 0) {
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
    const size_t slot = peer_slot(in, msg->uav_id);
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
    if (rc == COA_OK && vehicle.steep_factor > COAVOID_NODE_MAX_STEEP_FACTOR) {
        rc = COAVOID_LCM_ERR_CAPACITY; /* its planner could not plan that UAV */
        reason = "intent: a steep factor above what this node plans with";
    }
    coavoid_lcm_rx_count(in->rx, rc, reason);
    if (rc != COA_OK) {
        return;
    }
    senders_heard(&in->intent_seq, (uint32_t)msg->uav_id, now);
    peer_keep(&in->peers[slot], msg);
}

static void on_track(coavoid_node_inbox_t *in, const uint8_t *data, int size)
{
    coavoid_track_t *msg = &in->rx_msg.track;
    size_t key = 0;
    if (!signature_ok(in, data, size, COAVOID_AUTH_STREAM_TRACK, COAVOID_AUTH_WORLD, &key)) {
        return;
    }
    if (coavoid_track_t_decode(data, 0, size, msg) < 0) {
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
    if ((size_t)msg->tile_count > COAVOID_NODE_MAX_MAP_TILES) {
        *reason = "obstacle_map: more tiles than this node holds";
        return COAVOID_LCM_ERR_CAPACITY;
    }
    const coavoid_obstacle_map_t *first = &in->map_tiles[0];
    bool same = false;
    for (size_t i = 0; i < COAVOID_NODE_MAX_MAP_TILES && !same; i++) {
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

static void on_map(coavoid_node_inbox_t *in, const uint8_t *data, int size)
{
    coavoid_obstacle_map_t *msg = &in->rx_msg.map;
    size_t key = 0;
    if (!signature_ok(in, data, size, COAVOID_AUTH_STREAM_MAP, COAVOID_AUTH_WORLD, &key)) {
        return;
    }
    if (coavoid_obstacle_map_t_decode(data, 0, size, msg) < 0) {
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

static void on_status(coavoid_node_inbox_t *in, const uint8_t *data, int size)
{
    coavoid_status_t *msg = &in->rx_msg.status;
    size_t key = 0;
    if (!signature_ok(in, data, size, COAVOID_AUTH_STREAM_STATUS, COAVOID_AUTH_ANY_ROLE, &key)) {
        return;
    }
    if (coavoid_status_t_decode(data, 0, size, msg) < 0) {
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

static void on_plan(coavoid_node_inbox_t *in, const uint8_t *data, int size)
{
    coavoid_plan_t *msg = &in->rx_msg.plan;
    size_t key = 0;
    if (!signature_ok(in, data, size, COAVOID_AUTH_STREAM_PLAN, COAVOID_AUTH_COORDINATOR, &key)) {
        return;
    }
    if (coavoid_plan_t_decode(data, 0, size, msg) < 0) {
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

static void on_agreement(coavoid_node_inbox_t *in, const uint8_t *data, int size)
{
    coavoid_agreement_t *msg = &in->rx_msg.agreement;
    size_t key = 0;
    if (!signature_ok(in, data, size, COAVOID_AUTH_STREAM_AGREEMENT, COAVOID_AUTH_ANY_ROLE, &key)) {
        return;
    }
    if (coavoid_agreement_t_decode(data, 0, size, msg) < 0) {
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

/* The channels an inbox can listen to, in the order a transport subscribes to them. */
static const struct {
    const char *name;
    void (*handler)(coavoid_node_inbox_t *in, const uint8_t *data, int size);
} channels[COAVOID_NODE_CHANNELS] = {
    {COAVOID_CHANNEL_INTENT, on_intent}, {COAVOID_CHANNEL_TRACK, on_track},
    {COAVOID_CHANNEL_OBSTACLES, on_map}, {COAVOID_CHANNEL_STATUS, on_status},
    {COAVOID_CHANNEL_PLAN, on_plan},     {COAVOID_CHANNEL_AGREEMENT, on_agreement},
};

const char *coavoid_node_inbox_channel(const coavoid_node_inbox_t *in, size_t i)
{
    return i < COAVOID_NODE_CHANNELS && (in->wants & (1u << i)) != 0u ? channels[i].name : NULL;
}

int coavoid_node_inbox_receive(coavoid_node_inbox_t *in, const char *channel, const void *data,
                               size_t size)
{
    if (in == NULL || channel == NULL || data == NULL || size > (size_t)INT_MAX) {
        return COA_ERR_ARGUMENT;
    }
    for (size_t i = 0; i < COAVOID_NODE_CHANNELS; i++) {
        if ((in->wants & (1u << i)) != 0u && strcmp(channel, channels[i].name) == 0) {
            channels[i].handler(in, data, (int)size);
            return COA_OK;
        }
    }
    return COA_ERR_ARGUMENT;
}

/* Nothing received yet: no senders, peers, tracks or map, nothing counted. */
static void inbox_empty(coavoid_node_inbox_t *in)
{
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
}

int coavoid_node_inbox_init(coavoid_node_inbox_t *in, const coavoid_node_common_t *common,
                            uint16_t self_uav, uint16_t self_node, uint16_t coordinator_id,
                            size_t peer_capacity, const coavoid_node_link_t *link,
                            coavoid_lcm_rx_stats_t *rx, bool want_status,
                            coavoid_node_plan_handler_t plan_handler, void *owner)
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
    coavoid_node_tx_init(&in->tx, link, common);
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
    inbox_empty(in);
    in->on_plan = plan_handler;
    in->on_agreement = NULL;
    in->on_plan_row = NULL;
    in->owner = owner;
    in->wants = COAVOID_NODE_WANTS(INTENT) | COAVOID_NODE_WANTS(TRACK) | COAVOID_NODE_WANTS(MAP);
    in->wants |= want_status ? COAVOID_NODE_WANTS(STATUS) : 0u;
    in->wants |= plan_handler != NULL ? COAVOID_NODE_WANTS(PLAN) : 0u;
    return COA_OK;
}

void coavoid_node_inbox_agreements(coavoid_node_inbox_t *in,
                                   coavoid_node_agreement_handler_t handler)
{
    in->on_agreement = handler;
    in->wants |= COAVOID_NODE_WANTS(AGREEMENT);
}

void coavoid_node_inbox_fini(coavoid_node_inbox_t *in)
{
    in->wants = 0u;
    coavoid_node_tx_fini(&in->tx);
}

int64_t coavoid_node_inbox_drop_after(const coavoid_node_inbox_t *in)
{
    return in->common.stale_after_us +
           (int64_t)COAVOID_NODE_DROP_HORIZONS * (int64_t)in->common.horizon * in->common.dt_us;
}

void coavoid_node_inbox_expire(coavoid_node_inbox_t *in, int64_t now)
{
    const int64_t stale = in->common.stale_after_us;
    const int64_t drop = coavoid_node_inbox_drop_after(in);
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
