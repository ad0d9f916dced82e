/* SPDX-License-Identifier: MIT */
/*
 * plan.c: the planner's public entry points (see plan.h for the contract): workspace
 * sizing, problem checks, the decoupled front end, the entry of the centralised one
 * (independence detection is plan_group.c), and the costs and conflicts of finished rows.
 *
 * Workspace layout (every array starts on an 8-byte boundary), with T cells per table,
 * W the widest row of a table and C = beta nodes:
 *
 *   coa_planner_t header (limits, per-call context, independence detection's state)
 *   uint64_t cells[tables * T]       (1 table for one vehicle; else each vehicle's cost to
 *                                     go and cost from the start, and one more)
 *   int16_t  entries[vehicles * W]   (joint searches only, as everything below)
 *   int32_t  saved_rows[vehicles * (N + 1)]
 *   int32_t  best_rows[vehicles * (N + 1)] (the incumbent)
 *   coa_cost_t pair_arena[C]         (pair tables: 16-byte cells)
 *   coa_cost_t key[C], g[C]          (packed 128-bit costs)
 *   uint32_t parent[C], heap_pos[C], heap[C]
 *   uint32_t slot[2C]                (open addressing over the states)
 *   uint16_t k[C]
 *   int16_t  off[C * vehicles]
 */
#include "coavoid/plan.h"

#include <math.h>

#include "plan_internal.h"

#define PLAN_MAGIC 0x434f4151u /* marks a buffer built by coa_planner_init */
/* Node indices, heap positions and slots are uint32 with PLAN_NONE reserved; a pool of
 * at most 2^30 nodes keeps the 2C slots below 2^32 too. */
#define MAX_NODES (UINT32_C(1) << 30)
#define PAIR_CELLS_PER_NODE 1u

typedef struct {
    size_t tables;
    size_t table_cells;
    size_t row_width;
    uint32_t capacity;
    uint32_t slot_count;
    size_t pair_cells;
    size_t at_cells;
    size_t at_entries;
    size_t at_saved;
    size_t at_best;
    size_t at_pairs;
    size_t at_key;
    size_t at_g;
    size_t at_parent;
    size_t at_heap_pos;
    size_t at_heap;
    size_t at_slot;
    size_t at_k;
    size_t at_off;
    size_t total;
} plan_layout_t;

/* ------------------------------------------------------------------------------------ */
/* Sizes                                                                                 */

/* The largest |offset| a max_offset allows: itself, or COA_MAX_OFFSET (the int16 node
 * storage) when unbounded (negative) or above it. Tables and vehicles both use it. */
static int32_t bound_of(int32_t max_offset)
{
    return (max_offset >= 0 && max_offset < COA_MAX_OFFSET) ? max_offset : COA_MAX_OFFSET;
}

static bool config_ok(const coa_planner_config_t *c)
{
    return c != NULL && c->vehicles >= 1u && c->vehicles <= PLAN_MAXM && c->beta >= 1u &&
           c->beta < MAX_NODES && c->horizon >= 1u && c->horizon <= COA_MAX_HORIZON &&
           c->steep_factor >= 2u && c->steep_factor <= COA_MAX_STEEP_FACTOR;
}

/* The node pool and what goes with it, for a planner that searches jointly. */
static bool layout_nodes(const coa_planner_config_t *c, size_t *cursor, plan_layout_t *lo)
{
    size_t n = c->beta;
    size_t off;
    lo->capacity = c->beta;
    lo->slot_count = 2u * c->beta;
    lo->pair_cells = (size_t)PAIR_CELLS_PER_NODE * n;
    size_t rows;
    return size_mul(c->vehicles, lo->row_width, &off) &&
           reserve(cursor, off, sizeof(int16_t), &lo->at_entries) &&
           size_mul(c->vehicles, (size_t)c->horizon + 1u, &rows) &&
           reserve(cursor, rows, sizeof(int32_t), &lo->at_saved) &&
           reserve(cursor, rows, sizeof(int32_t), &lo->at_best) &&
           reserve(cursor, lo->pair_cells, sizeof(coa_cost_t), &lo->at_pairs) &&
           reserve(cursor, n, sizeof(coa_cost_t), &lo->at_key) &&
           reserve(cursor, n, sizeof(coa_cost_t), &lo->at_g) &&
           reserve(cursor, n, sizeof(uint32_t), &lo->at_parent) &&
           reserve(cursor, n, sizeof(uint32_t), &lo->at_heap_pos) &&
           reserve(cursor, n, sizeof(uint32_t), &lo->at_heap) &&
           reserve(cursor, lo->slot_count, sizeof(uint32_t), &lo->at_slot) &&
           reserve(cursor, n, sizeof(uint16_t), &lo->at_k) && size_mul(n, c->vehicles, &off) &&
           reserve(cursor, off, sizeof(int16_t), &lo->at_off);
}

static bool layout_compute(const coa_planner_config_t *c, plan_layout_t *lo)
{
    uint64_t cells;
    uint64_t width;
    size_t cursor;
    size_t all;

    if (!config_ok(c)) {
        return false;
    }
    *lo = (plan_layout_t){0};
    cells = coa_plan_table_cells(c->horizon, c->steep_factor, bound_of(c->max_offset));
    width = coa_plan_table_row_width(c->horizon, c->steep_factor, bound_of(c->max_offset));
    if (cells == 0u || cells > SIZE_MAX || width > SIZE_MAX) {
        return false;
    }
    lo->table_cells = (size_t)cells;
    lo->row_width = (size_t)width;
    lo->tables = c->vehicles == 1u ? 1u : 2u * c->vehicles + 1u;
    if (!size_round(sizeof(coa_planner_t), &cursor) ||
        !size_mul(lo->table_cells, lo->tables, &all) ||
        !reserve(&cursor, all, sizeof(uint64_t), &lo->at_cells)) {
        return false;
    }
    if (c->vehicles > 1u && !layout_nodes(c, &cursor, lo)) {
        return false;
    }
    lo->total = cursor;
    return true;
}

size_t coa_planner_workspace_size(const coa_planner_config_t *config)
{
    plan_layout_t lo;
    return layout_compute(config, &lo) ? lo.total : 0u;
}

uint32_t coa_planner_max_beta(const coa_planner_config_t *config, size_t bytes)
{
    coa_planner_config_t c;
    plan_layout_t lo;
    uint32_t lo_beta = 0u; /* fits (0 stands for "nothing fits") */
    uint32_t hi_beta = MAX_NODES - 1u;

    if (config == NULL) {
        return 0u;
    }
    c = *config;
    c.beta = hi_beta;
    if (layout_compute(&c, &lo) && lo.total <= bytes) {
        return hi_beta;
    }
    /* The size grows strictly with beta (vehicles > 1; with one vehicle it does not
     * depend on beta and the test above answered): size(lo_beta) <= bytes < size(hi_beta). */
    while (hi_beta - lo_beta > 1u) {
        c.beta = lo_beta + (hi_beta - lo_beta) / 2u;
        if (layout_compute(&c, &lo) && lo.total <= bytes) {
            lo_beta = c.beta;
        } else {
            hi_beta = c.beta;
        }
    }
    return lo_beta;
}

static void point_into(coa_planner_t *pl, unsigned char *base, const plan_layout_t *lo)
{
    pl->cells = (uint64_t *)(void *)(base + lo->at_cells);
    if (pl->config.vehicles == 1u) {
        return;
    }
    pl->entries = (int16_t *)(void *)(base + lo->at_entries);
    pl->saved_rows = (int32_t *)(void *)(base + lo->at_saved);
    pl->best_rows = (int32_t *)(void *)(base + lo->at_best);
    pl->pair_arena = (coa_cost_t *)(void *)(base + lo->at_pairs);
    pl->key = (coa_cost_t *)(void *)(base + lo->at_key);
    pl->g = (coa_cost_t *)(void *)(base + lo->at_g);
    pl->parent = (uint32_t *)(void *)(base + lo->at_parent);
    pl->heap_pos = (uint32_t *)(void *)(base + lo->at_heap_pos);
    pl->heap = (uint32_t *)(void *)(base + lo->at_heap);
    pl->slot = (uint32_t *)(void *)(base + lo->at_slot);
    pl->node_k = (uint16_t *)(void *)(base + lo->at_k);
    pl->off = (int16_t *)(void *)(base + lo->at_off);
}

coa_planner_t *coa_planner_init(void *buffer, size_t size, const coa_planner_config_t *config)
{
    plan_layout_t lo;
    coa_planner_t *pl;
    uint32_t i;
    size_t t;

    if (buffer == NULL || (uintptr_t)buffer % WS_ALIGN != 0u) {
        return NULL;
    }
    if (!layout_compute(config, &lo) || size < lo.total) {
        return NULL;
    }
    pl = (coa_planner_t *)buffer;
    *pl = (coa_planner_t){0};
    pl->config = *config;
    pl->bytes = lo.total;
    pl->table_cells = lo.table_cells;
    pl->table_count = lo.tables;
    pl->row_width = lo.row_width;
    pl->capacity = lo.capacity;
    pl->slot_count = lo.slot_count;
    pl->slot_active = plan_slots_first(pl);
    pl->touched_slots = pl->slot_active;
    pl->pair_cells = lo.pair_cells;
    point_into(pl, (unsigned char *)buffer, &lo);
    for (i = 0; i < pl->slot_active; ++i) {
        pl->slot[i] = PLAN_NONE;
    }
    /* Tables 0..v-1 are the vehicles' costs to go, v..2v-1 their costs from the start,
     * the last one is for plans against fixed vehicles. */
    for (t = 0; t < PLAN_MAXM; ++t) {
        pl->to_go[t].cells = &pl->cells[(t % pl->table_count) * pl->table_cells];
        pl->from_start[t].cells =
            &pl->cells[((config->vehicles + t) % pl->table_count) * pl->table_cells];
    }
    pl->scratch.cells = &pl->cells[(pl->table_count - 1u) * pl->table_cells];
    pl->m = 1u;
    pl->match_all = PLAN_MATCH_ALL;
    pl->magic = PLAN_MAGIC;
    return pl;
}

int coa_planner_set_work(coa_planner_t *planner, uint64_t work)
{
    if (planner == NULL) {
        return COA_ERR_ARGUMENT;
    }
    if (planner->magic != PLAN_MAGIC) {
        return COA_ERR_WORKSPACE;
    }
    planner->work_limit = work;
    return COA_OK;
}

int coa_planner_config_of(const coa_problem_t *problem, size_t vehicles, uint32_t beta,
                          coa_planner_config_t *config)
{
    size_t i;

    if (problem == NULL || config == NULL || problem->vehicles == NULL ||
        problem->vehicle_count == 0u || problem->vehicle_count > COA_MAX_VEHICLES) {
        return COA_ERR_ARGUMENT;
    }
    config->vehicles = vehicles;
    config->beta = beta;
    config->horizon = problem->horizon;
    config->steep_factor = 2u;
    config->max_offset = 0;
    for (i = 0; i < problem->vehicle_count; ++i) {
        const coa_vehicle_t *v = &problem->vehicles[i];
        if (v->steep_factor > config->steep_factor) {
            config->steep_factor = v->steep_factor;
        }
        if (config->max_offset >= 0 && (v->max_offset < 0 || v->max_offset > config->max_offset)) {
            config->max_offset = v->max_offset;
        }
    }
    return config_ok(config) ? COA_OK : COA_ERR_ARGUMENT;
}

/* ------------------------------------------------------------------------------------ */
/* Problem validation                                                                    */

static bool samples_ok(const coa_vec3_t *s, uint32_t horizon)
{
    uint32_t k;
    if (s == NULL) {
        return false;
    }
    for (k = 0; k <= horizon; ++k) {
        if (!vec_ok(&s[k])) {
            return false;
        }
    }
    return true;
}

/* Everything but the integer range: what a conflict check needs to be safe to run. */
static int check_arguments(const coa_problem_t *p)
{
    size_t i;
    size_t j;

    if (p == NULL || !real_ok(p->dt) || !(p->dt > (coa_real_t)0) || p->horizon == 0u ||
        p->horizon > COA_MAX_HORIZON || p->vehicles == NULL || p->references == NULL ||
        p->vehicle_count == 0u || p->vehicle_count > COA_MAX_VEHICLES) {
        return COA_ERR_ARGUMENT;
    }
    for (i = 0; i < p->vehicle_count; ++i) {
        if (coa_vehicle_check(&p->vehicles[i]) != COA_OK ||
            !samples_ok(p->references[i], p->horizon)) {
            return COA_ERR_ARGUMENT;
        }
        for (j = 0; j < i; ++j) {
            if (p->vehicles[j].id == p->vehicles[i].id) {
                return COA_ERR_ARGUMENT;
            }
        }
    }
    if ((p->obstacle_count > 0u && p->obstacles == NULL) ||
        (p->has_floor && !real_ok(p->floor_z))) {
        return COA_ERR_ARGUMENT;
    }
    for (i = 0; i < p->obstacle_count; ++i) {
        if (coa_obstacle_check(&p->obstacles[i]) != COA_OK) {
            return COA_ERR_ARGUMENT;
        }
    }
    if (p->track_count > 0u && (p->tracks == NULL || p->track_samples == NULL)) {
        return COA_ERR_ARGUMENT;
    }
    for (i = 0; i < p->track_count; ++i) {
        if (coa_track_check(&p->tracks[i]) != COA_OK ||
            !samples_ok(p->track_samples[i], p->horizon)) {
            return COA_ERR_ARGUMENT;
        }
    }
    return COA_OK;
}

static int32_t offset_limit(const coa_vehicle_t *v)
{
    return bound_of(v->max_offset);
}

/* The worst case f = g + h of any node, 2 N * sum_i W_i S B_i: one step costs at most
 * W * S * max(|a|, |b|) <= W * S * B and the heuristic at most W * S * N * B, with B_i =
 * min(|initial offset| + N s_i, the vehicle's offset bound). With the limits of common.h
 * it is below 2^64 * 2^13 * 2^15 * 2^15 * 2^5 = 2^112: each term is below 2^106 and there
 * are at most 32, so the sum cannot wrap. */
static coa_cost_t worst_f(const coa_problem_t *p, const uint64_t *weights, uint32_t s)
{
    coa_cost_t total = {0u, 0u};
    size_t i;
    for (i = 0; i < p->vehicle_count; ++i) {
        const coa_vehicle_t *v = &p->vehicles[i];
        uint64_t init = (uint64_t)(v->initial_offset < 0 ? -(int64_t)v->initial_offset
                                                         : (int64_t)v->initial_offset);
        uint64_t bound = init + (uint64_t)p->horizon * v->steep_factor;
        if (bound > (uint64_t)offset_limit(v)) {
            bound = (uint64_t)offset_limit(v);
        }
        /* S <= 5040, B <= 32767, 2N <= 20000: the factor is below 2^42. */
        total =
            coa_cost_add(total, coa_cost_mul(weights[i], (uint64_t)s * bound * 2u * p->horizon));
    }
    return total;
}

/* Whether worst_f stays below 2^127, which leaves every sum the search forms (g + one
 * step, g + h) far from the 2^128 wrap. Only coa_deviation_weights' own COA_ERR_RANGE
 * (weights that do not fit 64 bits) can refuse a problem today; the check stays so that
 * raising a limit cannot silently break exactness. Fills the weights and the scale on
 * success. */
static int check_range(const coa_problem_t *p, uint64_t *weights, uint32_t *scale, int *exponent)
{
    uint32_t s;
    int rc;

    s = coa_area_scale(p->vehicles, p->vehicle_count);
    if (s == 0u) {
        return COA_ERR_ARGUMENT;
    }
    rc = coa_deviation_weights(p->vehicles, p->vehicle_count, p->dt, weights, exponent);
    if (rc != COA_OK) {
        return rc;
    }
    if (worst_f(p, weights, s).hi >= (UINT64_C(1) << 63)) {
        return COA_ERR_RANGE;
    }
    *scale = s;
    return COA_OK;
}

int coa_problem_check(const coa_problem_t *problem)
{
    uint64_t weights[COA_MAX_VEHICLES];
    uint32_t scale;
    int exponent;
    int rc = check_arguments(problem);
    if (rc != COA_OK) {
        return rc;
    }
    return check_range(problem, weights, &scale, &exponent);
}

int coa_priority_order(const coa_vehicle_t *vehicles, size_t n, size_t *order)
{
    size_t i;
    size_t j;

    if (vehicles == NULL || order == NULL || n == 0u || n > COA_MAX_VEHICLES) {
        return COA_ERR_ARGUMENT;
    }
    for (i = 0; i < n; ++i) {
        order[i] = i;
    }
    /* Insertion sort: stable, and n <= 32. */
    for (i = 1; i < n; ++i) {
        size_t cur = order[i];
        const coa_vehicle_t *c = &vehicles[cur];
        for (j = i; j > 0u; --j) {
            const coa_vehicle_t *q = &vehicles[order[j - 1u]];
            if (q->priority < c->priority || (q->priority == c->priority && q->id <= c->id)) {
                break;
            }
            order[j] = order[j - 1u];
        }
        order[j] = cur;
    }
    return COA_OK;
}

/* ------------------------------------------------------------------------------------ */
/* Costs of a finished row                                                               */

int coa_plan_vehicle_cost(const coa_vehicle_t *vehicle, coa_real_t dt, uint32_t horizon,
                          const int32_t *offsets, double *deviation, uint32_t *effort)
{
    double step = (double)dt;
    double area = 0.0;
    uint32_t eff = 0u;
    uint32_t k;

    if (vehicle == NULL || offsets == NULL || deviation == NULL || effort == NULL ||
        !(isfinite(step) && step > 0.0) || horizon == 0u || horizon > COA_MAX_HORIZON ||
        !(isfinite(vehicle->cruise_speed) && vehicle->cruise_speed > (coa_real_t)0) ||
        !(isfinite(vehicle->climb_rate) && vehicle->climb_rate > (coa_real_t)0) ||
        vehicle->steep_factor < 2u || vehicle->steep_factor > COA_MAX_STEEP_FACTOR) {
        return COA_ERR_ARGUMENT;
    }
    for (k = 0; k <= horizon; ++k) {
        if (offsets[k] < -COA_MAX_OFFSET || offsets[k] > COA_MAX_OFFSET) {
            return COA_ERR_ARGUMENT;
        }
    }
    for (k = 0; k < horizon; ++k) {
        int act = coa_action_between(offsets[k], offsets[k + 1u], vehicle->steep_factor);
        if (act < 0) {
            return COA_ERR_ARGUMENT;
        }
        eff += coa_action_effort((coa_action_t)act);
        area += coa_area(offsets[k], offsets[k + 1u]);
    }
    *deviation = (double)vehicle->cruise_speed * step * ((double)vehicle->climb_rate * step) * area;
    *effort = eff;
    return COA_OK;
}

/* ------------------------------------------------------------------------------------ */
/* Geometry and costs of rows                                                            */

coa_sweep_t coa_plan_vehicle_sweep(const coa_problem_t *pr, const coa_real_t *dh, size_t v,
                                   uint32_t k0, int32_t a, uint32_t k1, int32_t b)
{
    coa_sweep_t s;
    s.volume = pr->vehicles[v].volume;
    s.p0 = pr->references[v][k0];
    s.p0.z += (coa_real_t)a * dh[v];
    s.p1 = pr->references[v][k1];
    s.p1.z += (coa_real_t)b * dh[v];
    return s;
}

bool coa_above_floor(coa_real_t floor_z, const coa_volume_t *volume, coa_real_t z)
{
    return z - volume->half_height >= floor_z;
}

bool coa_plan_static_clear(const coa_problem_t *pr, const coa_sweep_t *s, uint32_t k0, uint32_t k1)
{
    size_t j;
    if (pr->has_floor && (!coa_above_floor(pr->floor_z, &s->volume, s->p0.z) ||
                          !coa_above_floor(pr->floor_z, &s->volume, s->p1.z))) {
        return false;
    }
    for (j = 0; j < pr->obstacle_count; ++j) {
        /* The problem check ruled out the polytope test's errors; were one to happen
         * anyway, counting it as a conflict is the safe side. */
        if (coa_conflict_obstacle(s, &pr->obstacles[j]) != 0) {
            return false;
        }
    }
    for (j = 0; j < pr->track_count; ++j) {
        coa_sweep_t t;
        t.volume = pr->tracks[j].volume;
        t.p0 = pr->track_samples[j][k0];
        t.p1 = pr->track_samples[j][k1];
        if (coa_conflict_volumes(s, &t)) {
            return false;
        }
    }
    return true;
}

coa_cost_t coa_plan_row_units(const coa_planner_t *pl, size_t v, const int32_t *row,
                              uint64_t *effort)
{
    const uint32_t steep = pl->problem->vehicles[v].steep_factor;
    uint64_t own = 0u;
    uint64_t eff = 0u;
    uint32_t k;
    for (k = 0; k < pl->problem->horizon; ++k) {
        int act = coa_action_between(row[k], row[k + 1u], steep);
        own += plan_area(row[k], row[k + 1u], steep);
        eff += coa_action_effort((coa_action_t)(act < 0 ? 0 : act));
    }
    if (effort != NULL) {
        *effort = eff;
    }
    return plan_units(pl, v, own);
}

coa_cost_t coa_plan_rows_cost(const coa_planner_t *pl, const int32_t *rows, uint32_t members)
{
    const size_t row = (size_t)pl->problem->horizon + 1u;
    coa_cost_t sum = {0u, 0u};
    size_t v;
    for (v = 0; v < pl->problem->vehicle_count; ++v) {
        if ((members & (UINT32_C(1) << v)) != 0u) {
            uint64_t eff;
            coa_cost_t dev = coa_plan_row_units(pl, v, &rows[v * row], &eff);
            sum = plan_cost_add(sum, plan_pack(dev, eff));
        }
    }
    return sum;
}

void coa_plan_rows_copy(const coa_planner_t *pl, int32_t *to, const int32_t *from, uint32_t members)
{
    const size_t row = (size_t)pl->problem->horizon + 1u;
    size_t v;
    size_t k;
    for (v = 0; v < pl->problem->vehicle_count; ++v) {
        if ((members & (UINT32_C(1) << v)) != 0u) {
            for (k = 0; k < row; ++k) {
                to[v * row + k] = from[v * row + k];
            }
        }
    }
}

/* ------------------------------------------------------------------------------------ */
/* Front ends                                                                            */

static void result_clear(coa_plan_result_t *r)
{
    size_t i;
    r->status = COA_PLAN_INFEASIBLE;
    r->deviation = 0.0;
    r->deviation_units.hi = 0u;
    r->deviation_units.lo = 0u;
    r->effort = 0u;
    r->nodes_expanded = 0u;
    r->nodes_generated = 0u;
    r->workspace_bytes = 0u;
    r->workspace_touched_bytes = 0u;
    for (i = 0; i < COA_MAX_VEHICLES; ++i) {
        r->order[i] = i;
    }
    r->planned_count = 0u;
    r->failed_vehicle = COA_NO_VEHICLE;
    r->orders_tried = 0u;
    r->all_orders_covered = false;
    r->searches = 0u;
    r->largest_group = 0u;
    r->bound_deviation = 0.0;
    r->bound_units.hi = 0u;
    r->bound_units.lo = 0u;
    r->bound_effort = 0u;
    r->optimal = false;
    r->limit = COA_PLAN_LIMIT_NONE;
    r->work = 0u;
}

/* Validates the call and loads the problem's cost parameters into the planner. */
static int load(coa_planner_t *pl, const coa_problem_t *problem, const int32_t *offsets,
                const coa_plan_result_t *result)
{
    size_t i;
    int rc;

    if (pl == NULL || problem == NULL || offsets == NULL || result == NULL) {
        return COA_ERR_ARGUMENT;
    }
    if (pl->magic != PLAN_MAGIC) {
        return COA_ERR_WORKSPACE;
    }
    rc = check_arguments(problem);
    if (rc != COA_OK) {
        return rc;
    }
    rc = check_range(problem, pl->weight, &pl->scale, &pl->exponent);
    if (rc != COA_OK) {
        return rc;
    }
    if (problem->horizon > pl->config.horizon) {
        return COA_ERR_WORKSPACE;
    }
    for (i = 0; i < problem->vehicle_count; ++i) {
        const coa_vehicle_t *v = &problem->vehicles[i];
        if (coa_plan_table_cells(problem->horizon, v->steep_factor, offset_limit(v)) >
                pl->table_cells ||
            coa_plan_table_row_width(problem->horizon, v->steep_factor, offset_limit(v)) >
                pl->row_width) {
            return COA_ERR_WORKSPACE;
        }
    }
    coa_plan_search_release(pl);
    pl->work_used = 0u;
    pl->out_of_work = false;
    pl->have_best = false;
    pl->problem = problem;
    pl->rows = (int32_t *)(uintptr_t)offsets;
    for (i = 0; i < problem->vehicle_count; ++i) {
        pl->dh[i] = coa_climb_step(&problem->vehicles[i], problem->dt);
        pl->limit[i] = offset_limit(&problem->vehicles[i]);
        pl->unit[i] = pl->scale / (2u * problem->vehicles[i].steep_factor);
    }
    return COA_OK;
}

void coa_plan_fill_costs(const coa_planner_t *pl, const size_t *which, size_t count,
                         coa_plan_result_t *r)
{
    const coa_problem_t *pr = pl->problem;
    size_t i;
    r->deviation = 0.0;
    r->deviation_units.hi = 0u;
    r->deviation_units.lo = 0u;
    r->effort = 0u;
    for (i = 0; i < count; ++i) {
        const int32_t *row = &pl->rows[which[i] * ((size_t)pr->horizon + 1u)];
        double dev = 0.0;
        uint32_t eff = 0u;
        /* Rows come from the planner, so every step is an action and this cannot fail. */
        (void)coa_plan_vehicle_cost(&pr->vehicles[which[i]], pr->dt, pr->horizon, row, &dev, &eff);
        r->deviation += dev;
        r->effort += eff;
        r->deviation_units =
            coa_cost_add(r->deviation_units, coa_plan_row_units(pl, which[i], row, NULL));
    }
}

bool coa_plan_any_initial_conflict(const coa_planner_t *pl)
{
    const coa_problem_t *pr = pl->problem;
    coa_sweep_t at0[COA_MAX_VEHICLES];
    size_t i;
    size_t j;

    for (i = 0; i < pr->vehicle_count; ++i) {
        int32_t o = pr->vehicles[i].initial_offset;
        at0[i] = coa_plan_vehicle_sweep(pr, pl->dh, i, 0u, o, 0u, o);
        if (!coa_plan_static_clear(pr, &at0[i], 0u, 0u)) {
            return true;
        }
        for (j = 0; j < i; ++j) {
            if (coa_conflict_volumes(&at0[i], &at0[j])) {
                return true;
            }
        }
    }
    return false;
}

/* The packed worst case of a joint search must leave the doubled keys below 2^128: the
 * worst deviation check_range allows (2^127) is far above what the packing leaves room
 * for (2^(127 - PLAN_EFF_BITS - 1)), so a centralised problem of more than one vehicle is
 * checked again here. The limits of common.h keep every real problem far below. */
static bool packed_range_ok(const coa_planner_t *pl)
{
    return worst_f(pl->problem, pl->weight, pl->scale).hi <
           (UINT64_C(1) << (64u - PLAN_EFF_BITS - 2u));
}

void coa_plan_touch_table(coa_planner_t *pl, const plan_table_t *t)
{
    const size_t i = (size_t)(t->cells - pl->cells) / pl->table_cells;
    const uint64_t cells = coa_plan_table_cells(t->horizon, t->steep, t->limit);
    if (cells > pl->touched_cells[i]) {
        pl->touched_cells[i] = cells < pl->table_cells ? (size_t)cells : pl->table_cells;
    }
}

static size_t round8(size_t bytes)
{
    return (bytes + 7u) / 8u * 8u;
}

/* result.workspace_touched_bytes: the header and what each array holds of it. */
static size_t touched_bytes(const coa_planner_t *pl)
{
    const coa_planner_config_t *c = &pl->config;
    const size_t nodes = pl->touched_nodes;
    size_t b = round8(sizeof *pl);
    size_t t;
    for (t = 0; t < pl->table_count; ++t) {
        b += pl->touched_cells[t] * sizeof(uint64_t);
    }
    if (pl->touched_rows) {
        b += round8(c->vehicles * pl->row_width * sizeof(int16_t)) +
             2u * round8(c->vehicles * ((size_t)c->horizon + 1u) * sizeof(int32_t));
    }
    b += pl->touched_pair_cells * sizeof(coa_cost_t);
    if (nodes > 0u) {
        b += 2u * nodes * sizeof(coa_cost_t) + 3u * round8(nodes * sizeof(uint32_t)) +
             round8(nodes * sizeof(uint16_t)) + round8(nodes * c->vehicles * sizeof(int16_t));
    }
    b += round8((size_t)pl->touched_slots * sizeof(uint32_t));
    return b;
}

/* The work the call spent, and whether the budget ended it; what it has touched. */
static void plan_result_work(const coa_planner_t *pl, coa_plan_result_t *r)
{
    r->workspace_touched_bytes = touched_bytes(pl);
    r->work = pl->work_used;
    if (pl->out_of_work) {
        r->limit = COA_PLAN_LIMIT_WORK;
    }
}

int coa_plan_centralised(coa_planner_t *planner, const coa_problem_t *problem, int32_t *offsets,
                         coa_plan_result_t *result)
{
    size_t i;
    int rc;

    if (result != NULL) {
        result_clear(result);
    }
    rc = load(planner, problem, offsets, result);
    if (rc != COA_OK) {
        return rc;
    }
    if (problem->vehicle_count > planner->config.vehicles) {
        return COA_ERR_WORKSPACE;
    }
    if (problem->vehicle_count > 1u && !packed_range_ok(planner)) {
        return COA_ERR_RANGE;
    }
    result->workspace_bytes = planner->bytes;
    result->orders_tried = 1u;
    if (coa_plan_any_initial_conflict(planner)) {
        plan_result_work(planner, result);
        return COA_OK; /* infeasible, nothing expanded */
    }
    result->status = coa_plan_independence(planner, result);
    if (result->status == COA_PLAN_SOLVED) {
        for (i = 0; i < problem->vehicle_count; ++i) {
            result->order[i] = i;
        }
        result->planned_count = problem->vehicle_count;
        coa_plan_fill_costs(planner, result->order, problem->vehicle_count, result);
        if (result->optimal) {
            /* The same cost: the formula's m^2, not the units' conversion. */
            result->bound_deviation = result->deviation;
        }
    }
    plan_result_work(planner, result);
    return COA_OK;
}

/* Plans order[level] against the plans of order[0..level-1]: its table knows them, so
 * its plan is read off the table (infeasible when its start is dead there). */
static coa_plan_status_t plan_one(coa_planner_t *pl, const size_t *order, size_t level,
                                  coa_plan_result_t *r)
{
    const size_t v = order[level];
    const int32_t start = pl->problem->vehicles[v].initial_offset;
    coa_plan_table_build(pl, &pl->scratch, v, order, level);
    ++r->searches;
    if (pl->out_of_work) {
        return COA_PLAN_BUDGET_EXHAUSTED;
    }
    if (cell_dead(plan_table_at(&pl->scratch, 0u, start))) {
        return COA_PLAN_INFEASIBLE;
    }
    coa_plan_table_walk(pl, &pl->scratch, 0u, start);
    r->nodes_expanded += pl->problem->horizon;
    return COA_PLAN_SOLVED;
}

/* order without the vehicle at `from`, that vehicle re-inserted at `to` <= from. */
static void promote(size_t *order, size_t from, size_t to)
{
    size_t v = order[from];
    size_t i;
    for (i = from; i > to; --i) {
        order[i] = order[i - 1u];
    }
    order[to] = v;
}

/* The search over priority orders of coa_plan_decoupled (plan.h). */
typedef struct {
    size_t n;
    size_t first[COA_MAX_VEHICLES]; /* the order asked for */
    size_t cur[COA_MAX_VEHICLES];   /* the order being tried */
    /* tried[L]: vehicles already tried at position L under the current cur[0..L-1]. */
    uint32_t tried[COA_MAX_VEHICLES];
    size_t start;      /* the first position the next attempt plans */
    size_t keep;       /* levels below this still hold the first attempt's plans */
    size_t first_fail; /* where the first attempt failed */
    bool any_budget;   /* an attempt ran out of beta */
    bool proven;       /* infeasible in every order, whatever beta did */
    bool covered;      /* every order tried or ruled out */
} orders_t;

/* The first order (the one given, checked to be a permutation, or priority order). */
static int orders_init(const coa_problem_t *problem, const size_t *order, orders_t *o)
{
    size_t i;
    *o = (orders_t){0};
    o->n = problem->vehicle_count;
    if (order != NULL) {
        uint32_t seen = 0u;
        for (i = 0; i < o->n; ++i) {
            if (order[i] >= o->n || (seen & (UINT32_C(1) << order[i])) != 0u) {
                return COA_ERR_ARGUMENT;
            }
            seen |= UINT32_C(1) << order[i];
            o->first[i] = order[i];
        }
    } else {
        (void)coa_priority_order(problem->vehicles, o->n, o->first);
    }
    for (i = 0; i < o->n; ++i) {
        o->cur[i] = o->first[i];
    }
    o->keep = o->n;
    return COA_OK;
}

/* One attempt: the vehicles of cur from `start` on, each against those before it. Returns
 * the position that failed (n: solved), its status in *st. */
static size_t orders_attempt(coa_planner_t *planner, orders_t *o, coa_plan_result_t *result,
                             coa_plan_status_t *st)
{
    size_t level;
    if (result->orders_tried > 0u && o->start < o->keep) {
        o->keep = o->start;
    }
    ++result->orders_tried;
    *st = COA_PLAN_SOLVED;
    for (level = o->start; level < o->n; ++level) {
        o->tried[level] |= UINT32_C(1) << o->cur[level];
        *st = plan_one(planner, o->cur, level, result);
        if (*st != COA_PLAN_SOLVED) {
            return level;
        }
    }
    return o->n;
}

/* The next order after a failure at `fail`, depth first: every order below cur[0..fail] is
 * ruled out, so go back to the deepest position that still has an untried candidate under
 * its prefix (deeper positions have been exhausted). There the failing vehicle goes first
 * if it has not been tried there, else the first untried one in the current order. Jumping
 * higher would abandon part of a subtree that the per-position bitmasks could never
 * return to, and the search would no longer be exhaustive. False: every order is tried or
 * ruled out. */
static bool orders_next(orders_t *o, size_t fail)
{
    const size_t v = o->cur[fail];
    bool found = false;
    size_t to;
    size_t i;
    for (to = fail + 1u; !found && to-- > 0u;) {
        if ((o->tried[to] & (UINT32_C(1) << v)) == 0u) {
            promote(o->cur, fail, to);
            found = true;
        }
        for (i = to; i < o->n && !found; ++i) {
            if ((o->tried[to] & (UINT32_C(1) << o->cur[i])) == 0u) {
                promote(o->cur, i, to);
                found = true;
            }
        }
    }
    if (!found) {
        return false;
    }
    for (i = to + 1u; i < o->n; ++i) {
        o->tried[i] = 0u;
    }
    o->start = to;
    return true;
}

/* No order worked: report the first attempt, re-planning the part of its prefix that later
 * attempts overwrote (the searches are deterministic, so they succeed again). A proof for
 * every order outranks an attempt that ran out of beta: more beta could not have helped
 * it. */
static void orders_report(coa_planner_t *planner, const orders_t *o, coa_plan_result_t *result)
{
    size_t i;
    result->all_orders_covered = o->proven || o->covered;
    result->status =
        (o->any_budget && !o->proven) ? COA_PLAN_BUDGET_EXHAUSTED : COA_PLAN_INFEASIBLE;
    result->planned_count = o->first_fail;
    for (i = 0; i < o->n; ++i) {
        result->order[i] = o->first[i];
    }
    for (i = o->keep; i < o->first_fail; ++i) {
        if (plan_one(planner, o->first, i, result) != COA_PLAN_SOLVED) {
            result->planned_count = i; /* unreachable; keeps the report truthful anyway */
            break;
        }
    }
    result->failed_vehicle = o->first[result->planned_count];
    coa_plan_fill_costs(planner, o->first, result->planned_count, result);
}

int coa_plan_decoupled(coa_planner_t *planner, const coa_problem_t *problem, const size_t *order,
                       uint32_t max_orders, int32_t *offsets, coa_plan_result_t *result)
{
    orders_t o;
    size_t i;
    int rc;

    if (result != NULL) {
        result_clear(result);
    }
    if (max_orders == 0u) {
        return COA_ERR_ARGUMENT;
    }
    rc = load(planner, problem, offsets, result);
    if (rc == COA_OK) {
        rc = orders_init(problem, order, &o);
    }
    if (rc != COA_OK) {
        return rc;
    }
    result->workspace_bytes = planner->bytes;
    while (result->orders_tried < max_orders) {
        coa_plan_status_t st;
        size_t fail = orders_attempt(planner, &o, result, &st);
        if (fail == o.n) {
            result->status = COA_PLAN_SOLVED;
            for (i = 0; i < o.n; ++i) {
                result->order[i] = o.cur[i];
            }
            result->planned_count = o.n;
            coa_plan_fill_costs(planner, o.cur, o.n, result);
            plan_result_work(planner, result);
            return COA_OK;
        }
        o.any_budget = o.any_budget || st == COA_PLAN_BUDGET_EXHAUSTED;
        /* Alone against obstacles and tracks, nothing it could meet later is easier. */
        o.proven = o.proven || (fail == 0u && st == COA_PLAN_INFEASIBLE);
        if (result->orders_tried == 1u) {
            o.first_fail = fail;
            /* Checked only once an order has failed, so a solved call never pays for it;
             * without it, two vehicles in conflict at t = 0 among n would cost up to n!
             * attempts before the order space ran out. */
            o.proven = o.proven || coa_plan_any_initial_conflict(planner);
        }
        if (o.proven || planner->out_of_work) {
            break;
        }
        if (!orders_next(&o, fail)) {
            o.covered = true;
            break;
        }
    }
    orders_report(planner, &o, result);
    plan_result_work(planner, result);
    return COA_OK;
}

/* Where the order search of coa_plan_orders_best stands: the packed cost of the first
 * `level` vehicles of the current order, and the least the others can add (their costs
 * alone, which no plan among others beats). */
typedef struct {
    coa_cost_t prefix[COA_MAX_VEHICLES + 1u];
    coa_cost_t alone_from[COA_MAX_VEHICLES + 1u];
} orders_costs_t;

static void alone_from(const coa_planner_t *pl, const orders_t *o, orders_costs_t *c)
{
    size_t i = o->n;
    c->alone_from[i] = (coa_cost_t){0u, 0u};
    while (i-- > 0u) {
        c->alone_from[i] = plan_cost_add(c->alone_from[i + 1u], plan_cost_alone(pl, o->cur[i]));
    }
}

/* One attempt of the current order from o->start, abandoned (as a failure at that level)
 * once its vehicles so far and the rest alone cost at least the best plan's. Returns the
 * level that failed or was abandoned (n: a cheaper plan, in pl->rows). */
static size_t orders_attempt_below(coa_planner_t *pl, orders_t *o, orders_costs_t *c,
                                   coa_plan_result_t *r, coa_plan_status_t *st)
{
    size_t level;
    ++r->orders_tried;
    alone_from(pl, o, c);
    *st = COA_PLAN_SOLVED;
    for (level = o->start; level < o->n; ++level) {
        o->tried[level] |= UINT32_C(1) << o->cur[level];
        *st = plan_one(pl, o->cur, level, r);
        if (*st != COA_PLAN_SOLVED) {
            return level;
        }
        c->prefix[level + 1u] = plan_cost_add(
            c->prefix[level], coa_plan_rows_cost(pl, pl->rows, UINT32_C(1) << o->cur[level]));
        if (pl->have_best &&
            plan_cost_compare(plan_cost_add(c->prefix[level + 1u], c->alone_from[level + 1u]),
                              pl->best_cost) >= 0) {
            return level;
        }
    }
    return o->n;
}

bool coa_plan_orders_best(coa_planner_t *pl, uint32_t max_orders, uint64_t improve_limit,
                          coa_plan_result_t *r)
{
    const uint32_t all = (uint32_t)((UINT64_C(1) << pl->problem->vehicle_count) - 1u);
    orders_t o;
    orders_costs_t c;
    coa_plan_result_t counted;
    size_t fail = 0u;
    coa_plan_status_t st = COA_PLAN_SOLVED;

    result_clear(&counted);
    c.prefix[0] = (coa_cost_t){0u, 0u};
    pl->have_best = false;
    pl->touched_rows = true;
    (void)orders_init(pl->problem, NULL, &o); /* priority order: cannot fail */
    while (counted.orders_tried < max_orders && !pl->out_of_work &&
           !(fail == 0u && st == COA_PLAN_INFEASIBLE)) {
        fail = orders_attempt_below(pl, &o, &c, &counted, &st);
        if (fail == o.n) {
            coa_plan_rows_copy(pl, pl->best_rows, pl->rows, all);
            pl->best_cost = c.prefix[o.n];
            if (!pl->have_best && improve_limit < pl->work_limit) {
                pl->work_limit = improve_limit;
                pl->out_of_work = improve_limit <= pl->work_used; /* no improvement left */
            }
            pl->have_best = true;
            fail = o.n - 1u; /* on to the next order */
        }
        if (!orders_next(&o, fail)) {
            break;
        }
    }
    r->searches += counted.searches;
    r->nodes_expanded += counted.nodes_expanded;
    return pl->have_best;
}

/* ------------------------------------------------------------------------------------ */
/* Checking a finished plan                                                              */

int coa_plan_find_conflict(const coa_problem_t *problem, const int32_t *offsets,
                           const size_t *which, size_t count, size_t *vehicle, uint32_t *step)
{
    coa_real_t dh[COA_MAX_VEHICLES];
    size_t row;
    uint32_t k;
    size_t i;
    size_t j;
    int rc = check_arguments(problem);

    if (rc != COA_OK) {
        return rc;
    }
    if (offsets == NULL || (count > 0u && which == NULL) || count > problem->vehicle_count) {
        return COA_ERR_ARGUMENT;
    }
    for (i = 0; i < count; ++i) {
        if (which[i] >= problem->vehicle_count) {
            return COA_ERR_ARGUMENT;
        }
        for (j = 0; j < i; ++j) {
            if (which[j] == which[i]) {
                return COA_ERR_ARGUMENT;
            }
        }
    }
    for (i = 0; i < problem->vehicle_count; ++i) {
        dh[i] = coa_climb_step(&problem->vehicles[i], problem->dt);
    }
    row = (size_t)problem->horizon + 1u;
    for (k = 0; k < problem->horizon; ++k) {
        for (i = 0; i < count; ++i) {
            size_t v = which[i];
            const int32_t *ov = &offsets[v * row];
            coa_sweep_t s = coa_plan_vehicle_sweep(problem, dh, v, k, ov[k], k + 1u, ov[k + 1u]);
            bool hit = !coa_plan_static_clear(problem, &s, k, k + 1u);
            for (j = 0; !hit && j < count; ++j) {
                if (j != i) {
                    const int32_t *ou = &offsets[which[j] * row];
                    coa_sweep_t t =
                        coa_plan_vehicle_sweep(problem, dh, which[j], k, ou[k], k + 1u, ou[k + 1u]);
                    hit = coa_conflict_volumes(&s, &t);
                }
            }
            if (hit) {
                if (vehicle != NULL) {
                    *vehicle = v;
                }
                if (step != NULL) {
                    *step = k;
                }
                return 1;
            }
        }
    }
    return 0;
}
