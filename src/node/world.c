/* SPDX-License-Identifier: MIT */
/*
 * The world node (node.h): a scenario's terrain database and tracker. Every cycle it
 * republishes every tile of the obstacle map (so that a node that joins late gets it) and each track's
 * estimate at the cycle's start.
 */
#include "protocol_internal.h"
#include "node_lcm.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct coavoid_world {
    coavoid_world_config_t config;
    coavoid_node_lcm_t transport; /* its LCM subscriptions and the lcm it publishes on */
    coavoid_node_tx_t tx;
    bool started;
    int64_t cycle;
    int64_t track_sequence;
    int64_t max_age_us;
    size_t map_tiles; /* the map's tiles, each published every cycle */
    coavoid_obstacle_map_t map_msg;
    coavoid_track_t track_msg;
};

/* The velocity a track has at t: its constant velocity, or that of the path leg that
 * coa_track_at uses there. */
static coa_vec3_t track_velocity(const coa_track_t *tr, coa_real_t t)
{
    coa_vec3_t v = {0, 0, 0};
    if (tr->path_count == 0u) {
        return tr->velocity;
    }
    if (tr->path_count == 1u) {
        return v;
    }
    size_t last = tr->path_count - 1u;
    size_t i = 0;
    if (!(t < tr->path[last].t)) {
        i = last - 1u;
    } else {
        while (i + 1u < last && t >= tr->path[i + 1u].t) {
            i++;
        }
    }
    const coa_track_point_t *a = &tr->path[i];
    const coa_track_point_t *b = &tr->path[i + 1u];
    coa_real_t span = b->t - a->t;
    v.x = (b->p.x - a->p.x) / span;
    v.y = (b->p.y - a->p.y) / span;
    v.z = (b->p.z - a->p.z) / span;
    return v;
}

/* A path track's estimate at scenario time t: its position there, then the path points
 * after it within one horizon W, closed by the position at the first point left out (or
 * at t + W), all relative to t. So the receiver's path is exact over the horizon up to
 * the message's capacity, and its times stay within the validation window. */
static size_t estimate_path(const coa_track_t *tr, coa_real_t t, coa_real_t window,
                            coa_track_point_t *out)
{
    const size_t cap = (size_t)COAVOID_TRACK_T_MAX_PATH;
    size_t n = 0;
    out[n].t = 0;
    out[n].p = coa_track_at(tr, t);
    n++;
    coa_real_t end = t + window;
    for (size_t j = 0; j < tr->path_count; j++) {
        coa_real_t tj = tr->path[j].t;
        if (!(tj > t)) {
            continue;
        }
        if (!(tj < t + window)) {
            break;
        }
        if (n + 1u >= cap) {
            end = tj;
            break;
        }
        out[n].t = tj - t;
        out[n].p = tr->path[j].p;
        n++;
    }
    out[n].t = end - t;
    out[n].p = coa_track_at(tr, end);
    n++;
    return n;
}

static coavoid_lcm_context_t world_context(const coavoid_world_t *w, int64_t now, int64_t epoch)
{
    coavoid_lcm_context_t ctx;
    ctx.now_utime = now;
    ctx.max_age_us = w->max_age_us;
    ctx.max_future_us = w->config.common.dt_us;
    ctx.epoch_utime = epoch;
    return ctx;
}

coavoid_world_t *coavoid_world_create(const coavoid_world_config_t *config, lcm_t *lcm, int *error)
{
    int dummy = 0;
    if (error == NULL) {
        error = &dummy;
    }
    *error = COA_ERR_ARGUMENT;
    if (config == NULL || lcm == NULL || coavoid_node_common_check(&config->common) != COA_OK ||
        (config->obstacles == NULL && config->obstacle_count > 0u) ||
        (config->tracks == NULL && config->track_count > 0u) ||
        config->track_count > COAVOID_NODE_MAX_TRACKS) {
        return NULL;
    }
    for (size_t i = 0; i < config->track_count; i++) {
        if (coa_track_check(&config->tracks[i]) != COA_OK || config->tracks[i].id < 1u ||
            config->tracks[i].id > (uint32_t)INT32_MAX) {
            return NULL;
        }
        for (size_t j = 0; j < i; j++) {
            if (config->tracks[j].id == config->tracks[i].id) {
                return NULL;
            }
        }
    }
    coavoid_world_t *w = calloc(1, sizeof *w);
    if (w == NULL) {
        *error = COA_ERR_WORKSPACE;
        return NULL;
    }
    w->config = *config;
    if (w->config.id == 0u) {
        w->config.id = (uint16_t)COAVOID_NODE_WORLD_ID;
    }
    coavoid_node_lcm_init(&w->transport, lcm, NULL);
    const coavoid_node_link_t link = coavoid_node_lcm_link(&w->transport);
    coavoid_node_tx_init(&w->tx, &link, &w->config.common);
    w->config.common.signer = NULL; /* copied: the caller's may go */
    w->config.common.trust = NULL;
    w->cycle = -1;
    w->max_age_us = config->common.stale_after_us +
                    ((int64_t)config->common.horizon + 2) * config->common.dt_us;
    /* The map must fit its tiles and each pass its check: find out now, not every cycle. */
    coavoid_lcm_context_t ctx = world_context(w, 0, config->common.epoch_utime);
    int rc = coavoid_lcm_obstacle_map_tiles(config->obstacles, config->obstacle_count,
                                            &w->map_tiles, NULL);
    for (size_t i = 0; rc == COA_OK && i < w->map_tiles; i++) {
        rc = coavoid_lcm_obstacle_map_from_core(config->obstacles, config->obstacle_count,
                                                config->common.epoch_utime, w->config.id, 1, i,
                                                &ctx, &w->map_msg, NULL);
    }
    if (rc != COA_OK) {
        coavoid_world_destroy(w);
        return NULL;
    }
    *error = COA_OK;
    return w;
}

void coavoid_world_destroy(coavoid_world_t *node)
{
    if (node != NULL) {
        coavoid_node_tx_fini(&node->tx);
    }
    free(node);
}

/* Every tile of the map and every track's estimate at cycle k, once. COA_OK or the first
 * error. */
static int world_send(coavoid_world_t *node, int64_t now, int64_t k,
                      const coavoid_lcm_context_t *ctx_in)
{
    const coavoid_node_common_t *c = &node->config.common;
    coavoid_lcm_context_t ctx = *ctx_in;
    int first_error = COA_OK;
    for (size_t i = 0; i < node->map_tiles; i++) {
        int rc = coavoid_lcm_obstacle_map_from_core(
            node->config.obstacles, node->config.obstacle_count, now, node->config.id, 1, i, &ctx,
            &node->map_msg, NULL);
        if (rc == COA_OK) {
            rc = coavoid_node_publish_map(&node->tx, &node->map_msg);
        }
        first_error = (first_error == COA_OK) ? rc : first_error;
    }

    const coa_real_t t = (coa_real_t)k * c->dt;
    const coa_real_t window = (coa_real_t)c->horizon * c->dt;
    for (size_t i = 0; i < node->config.track_count; i++) {
        const coa_track_t *tr = &node->config.tracks[i];
        coa_track_point_t path[COAVOID_TRACK_T_MAX_PATH];
        coa_track_t estimate = *tr;
        estimate.position = coa_track_at(tr, t);
        estimate.velocity = track_velocity(tr, t);
        estimate.path = NULL;
        estimate.path_count = 0;
        if (tr->path_count > 0u) {
            estimate.path_count = estimate_path(tr, t, window, path);
            estimate.path = path;
        }
        coavoid_lcm_track_info_t info;
        info.utime = now;
        info.source_id = node->config.id;
        info.sequence = node->track_sequence++;
        int rc = coavoid_lcm_track_from_core(&estimate, &info, &ctx, &node->track_msg, NULL);
        if (rc == COA_OK) {
            rc = coavoid_node_publish_track(&node->tx, &node->track_msg);
        }
        if (first_error == COA_OK) {
            first_error = rc;
        }
    }
    return first_error;
}

int coavoid_world_cycle(coavoid_world_t *node, int64_t now)
{
    if (node == NULL) {
        return COA_ERR_ARGUMENT;
    }
    const coavoid_node_common_t *c = &node->config.common;
    int64_t k = coavoid_node_cycle_of(c, now);
    if (k < 0) {
        return COA_ERR_ARGUMENT;
    }
    if (node->started && k <= node->cycle) {
        return COA_OK;
    }
    /* In its first cycle no node has an earlier estimate to extrapolate when every copy is
     * lost (later, the last one stands in for a cycle), and a decoupled fleet searches its
     * order from what it knows then: twice the copies, as a vehicle's first intent has. */
    const uint32_t copies = node->started ? node->config.copies : 2u * node->config.copies;
    node->started = true;
    node->cycle = k;
    const int64_t cycle_start = coavoid_node_cycle_utime(c, k);
    coavoid_lcm_context_t ctx = world_context(node, now, cycle_start);
    int first_error = COA_OK;
    /* Each message goes out 1 + copies times, each freshly stamped: a track lost to the
     * coordinator in the first cycles is one it cannot plan around. */
    for (uint32_t send = 0; send <= copies; send++) {
        int rc = world_send(node, now, k, &ctx);
        first_error = first_error == COA_OK ? rc : first_error;
    }
    return first_error;
}