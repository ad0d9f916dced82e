/* SPDX-License-Identifier: MIT */
/*
 * The view of one cycle (protocol_internal.h): the stored intents and tracks on the
 * cycle's clock, stale UAVs as tracks; the planning problems built from it, their
 * digests, and prediction over it.
 */
#include "protocol_internal.h"

#include <limits.h>
#include <math.h>
#include <string.h>

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

/* Peer i's latest intent of a cycle that began before `before`, opened in *out: its
 * latest, or the one before it; NULL when it has none. O(samples). */
static const coavoid_intent_t *peer_intent(const coavoid_node_inbox_t *in, size_t i, int64_t before,
                                           coavoid_intent_t *out)
{
    const coavoid_node_peer_t *p = &in->peers[i];
    if (p->msg.plan_utime < before) {
        return coavoid_node_intent_open(&p->msg, out);
    }
    return p->has_prev && p->prev.plan_utime < before ? coavoid_node_intent_open(&p->prev, out)
                                                      : NULL;
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
        const coavoid_intent_t *msg = peer_intent(in, order[s], before, &view->opened);
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
    const int64_t drop = coavoid_node_inbox_drop_after(in);
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
        const coavoid_intent_t *msg = peer_intent(in, order[s], before, &view->opened);
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
    return n * (n - 1u) / 2u + n * COAVOID_NODE_MAX_TRACKS + n * COAVOID_NODE_MAX_OBSTACLES;
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
