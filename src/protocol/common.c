/* SPDX-License-Identifier: MIT */
/*
 * What the nodes share (protocol.h, protocol_internal.h): the configuration and its
 * clock arithmetic, the decoupled order, the memo of failed joint searches and the
 * solver's memory. The inbox is inbox.c, the view of a cycle and its planning problems
 * view.c, publishing publish.c.
 */
#include "protocol_internal.h"

#include <limits.h>
#include <math.h>
#include <string.h>

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
        !rate_ok(c->stale_sigma_rate) || c->stale_after_us < 1 ||
        c->stale_after_us > COAVOID_NODE_MAX_DURATION_US || c->beta < 1u) {
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

uint64_t coavoid_node_fnv(uint64_t h, const void *data, size_t size)
{
    const uint8_t *p = data;
    for (size_t i = 0; i < size; i++) {
        h = (h ^ p[i]) * UINT64_C(1099511628211);
    }
    return h;
}

coa_planner_config_t coavoid_node_planner_config(uint32_t horizon, size_t searched, uint32_t beta)
{
    coa_planner_config_t c;
    c.vehicles = searched;
    c.beta = beta;
    c.horizon = horizon;
    c.steep_factor = COAVOID_NODE_MAX_STEEP_FACTOR;
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

size_t coavoid_node_align_up(size_t x)
{
    const size_t a = COA_WORKSPACE_ALIGNMENT;
    return x > SIZE_MAX - (a - 1u) ? 0u : (x + a - 1u) / a * a;
}

/* The three parts' sizes (predictor, planner, conflicts), each rounded up to the
 * alignment; false when the core refuses the sizes. */
static bool solver_parts(const coavoid_node_solver_shape_t *shape, size_t part[3])
{
    const coa_planner_config_t config =
        coavoid_node_planner_config(shape->plan_horizon, shape->searched, shape->beta);
    part[0] = coavoid_node_align_up(
        coa_predictor_workspace_size(COAVOID_NODE_MAX_PEERS, COAVOID_NODE_TRACK_CAPACITY,
                                     shape->horizon, coavoid_node_max_pairs()));
    part[1] = coavoid_node_align_up(coa_planner_workspace_size(&config));
    part[2] = coavoid_node_align_up(coavoid_node_max_pairs() * sizeof(coa_conflict_t));
    return part[0] != 0u && part[1] != 0u && part[2] != 0u && part[0] <= SIZE_MAX - part[2] &&
           part[1] <= SIZE_MAX - part[2];
}

/* The shared workspace: the larger of the predictor's and the planner's. */
static size_t solver_shared(const size_t part[3])
{
    return part[0] > part[1] ? part[0] : part[1];
}

size_t coavoid_node_solver_size(const coavoid_node_solver_shape_t *shape)
{
    size_t part[3];
    return solver_parts(shape, part) ? solver_shared(part) + part[2] : 0u;
}

int coavoid_node_solver_place(coavoid_node_solver_t *s, void *memory, size_t size,
                              const coavoid_node_solver_shape_t *shape)
{
    memset(s, 0, sizeof *s);
    size_t part[3];
    if (!solver_parts(shape, part)) {
        return COA_ERR_ARGUMENT;
    }
    const size_t shared = solver_shared(part);
    if (memory == NULL || size < shared + part[2]) {
        return COA_ERR_WORKSPACE;
    }
    uint8_t *p = memory;
    s->workspace = p;
    s->workspace_size = shared;
    s->horizon = shape->horizon;
    s->planner_config =
        coavoid_node_planner_config(shape->plan_horizon, shape->searched, shape->beta);
    s->conflicts = (coa_conflict_t *)(void *)(p + shared);
    s->conflict_capacity = coavoid_node_max_pairs();
    /* Both are built once here, so that a misaligned block is refused now, not in flight. */
    if (coavoid_node_solver_planner(s) == NULL || coavoid_node_solver_predictor(s) == NULL) {
        memset(s, 0, sizeof *s);
        return COA_ERR_WORKSPACE; /* misaligned memory */
    }
    return COA_OK;
}

coa_predictor_t *coavoid_node_solver_predictor(coavoid_node_solver_t *s)
{
    if (s->predictor == NULL && s->workspace != NULL) {
        s->planner = NULL;
        s->predictor =
            coa_predictor_init(s->workspace, s->workspace_size, COAVOID_NODE_MAX_PEERS,
                               COAVOID_NODE_TRACK_CAPACITY, s->horizon, coavoid_node_max_pairs());
    }
    return s->predictor;
}

coa_planner_t *coavoid_node_solver_planner(coavoid_node_solver_t *s)
{
    if (s->planner == NULL && s->workspace != NULL) {
        s->predictor = NULL;
        s->planner = coa_planner_init(s->workspace, s->workspace_size, &s->planner_config);
    }
    return s->planner;
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
