/* SPDX-License-Identifier: MIT */
/*
 * plan_v1.c: a composite A* over every UAV's joint state (test-only reference).
 *
 * The composite A* search with every 5^n combination of actions as children, the
 * return-to-reference triangle heuristic and a node pool of 1 + beta * 5^n nodes, kept
 * unchanged (but for its names) as an independent oracle: test_plan checks that the
 * planner of src/core finds the same optimal costs on thousands of random encounters.
 * Nothing outside tests/ uses it.
 */
#include "plan_v1.h"

#include <math.h>

#include "internal.h"

#define PLAN_MAGIC 0x434f4150u /* marks a buffer built by ref_planner_init */
#define NONE UINT32_MAX        /* no node, empty table slot, not in the heap */
#define ACTIONS COA_ACTION_COUNT
#define MAXM COA_MAX_CENTRALISED
/* Node indices, heap positions and table slots are uint32 with NONE reserved; a pool of
 * at most 2^30 nodes keeps the table (>= 2C slots, a power of two) below 2^32 too. */
#define MAX_NODES (UINT32_C(1) << 30)

struct ref_planner {
    uint32_t magic;
    uint32_t beta;
    size_t max_vehicles;
    size_t bytes;
    uint32_t capacity;
    uint32_t table_mask;

    coa_cost_t *g_dev;
    coa_cost_t *f_dev;
    uint32_t *parent;
    uint32_t *g_eff;
    uint32_t *heap_pos;
    uint32_t *heap;
    uint32_t *table;
    uint16_t *node_k;
    int16_t *off;

    /* The last search's nodes stay until the next one starts (results are rebuilt from
     * them); their table entries are cleared then, with the stride they were stored at. */
    uint32_t used;
    uint32_t heap_count;
    size_t m;

    /* Per call: the problem and its exact cost parameters. */
    const coa_problem_t *problem;
    uint32_t scale;
    uint64_t weight[COA_MAX_VEHICLES];
    coa_real_t dh[COA_MAX_VEHICLES];
    int32_t limit[COA_MAX_VEHICLES];

    /* Per search: who moves, who is fixed (rows of `rows`), where results go. */
    size_t searched[MAXM];
    const size_t *fixed;
    size_t fixed_count;
    int32_t *rows;
    uint32_t fixed_k0;
    uint32_t fixed_k1;
    bool fixed_ready;

    /* Per expansion: each (vehicle, action) once, each pair of them once. */
    coa_sweep_t fixed_sweep[COA_MAX_VEHICLES];
    coa_sweep_t sweep[MAXM][ACTIONS];
    int32_t next[MAXM][ACTIONS];
    coa_cost_t dev[MAXM][ACTIONS];
    coa_cost_t heur[MAXM][ACTIONS];
    bool env_ok[MAXM][ACTIONS];
    bool pair_ok[MAXM][MAXM][ACTIONS][ACTIONS];
};

typedef struct {
    uint32_t capacity;
    uint32_t table_size;
    size_t at_g_dev;
    size_t at_f_dev;
    size_t at_parent;
    size_t at_g_eff;
    size_t at_heap_pos;
    size_t at_heap;
    size_t at_table;
    size_t at_k;
    size_t at_off;
    size_t total;
} plan_layout_t;

typedef struct {
    coa_plan_status_t status;
    uint64_t expanded;
    uint64_t generated;
} search_out_t;

/* ------------------------------------------------------------------------------------ */
/* Exact costs on the hot path                                                           */

/* The same arithmetic as coa_cost_add and coa_cost_compare (trajectory.c), repeated for
 * the search loop so that the compiler can inline it: the open list compares costs
 * O(log pool) times per child, and the out-of-line calls made the paper scenario's
 * centralised search about a quarter slower. Colder code calls the public pair.
 * test_trajectory pins the public pair and test_plan checks the planner's costs against
 * an independent exact oracle, so the copies cannot drift unnoticed. */
static inline coa_cost_t cost_add(coa_cost_t a, coa_cost_t b)
{
    coa_cost_t r;
    r.lo = a.lo + b.lo;
    r.hi = a.hi + b.hi + (r.lo < a.lo ? 1u : 0u);
    return r;
}

static inline int cost_compare(coa_cost_t a, coa_cost_t b)
{
    if (a.hi != b.hi) {
        return a.hi < b.hi ? -1 : 1;
    }
    if (a.lo != b.lo) {
        return a.lo < b.lo ? -1 : 1;
    }
    return 0;
}

/* ------------------------------------------------------------------------------------ */
/* Sizes                                                                                 */

/* Children of one expansion of n searched UAVs at most: 5^n (n <= MAXM, so below 2^14). */
static uint32_t children_per_node(size_t n)
{
    uint32_t pow5 = 1u;
    for (size_t i = 0; i < n; ++i) {
        pow5 *= ACTIONS;
    }
    return pow5;
}

static bool layout_compute(size_t max_vehicles, uint32_t beta, plan_layout_t *lo)
{
    uint64_t nodes;
    uint64_t table = 1u;
    size_t cursor;
    size_t c;

    if (max_vehicles == 0u || max_vehicles > MAXM || beta == 0u) {
        return false;
    }
    /* beta < 2^32 and 5^6 < 2^14: the product cannot overflow 64 bits. */
    nodes = 1u + (uint64_t)beta * children_per_node(max_vehicles);
    if (nodes > MAX_NODES) {
        return false;
    }
    while (table < 2u * nodes) {
        table <<= 1;
    }
    lo->capacity = (uint32_t)nodes;
    lo->table_size = (uint32_t)table;
    c = (size_t)nodes;
    if (!size_round(sizeof(ref_planner_t), &cursor)) {
        return false;
    }
    if (!reserve(&cursor, c, sizeof(coa_cost_t), &lo->at_g_dev) ||
        !reserve(&cursor, c, sizeof(coa_cost_t), &lo->at_f_dev) ||
        !reserve(&cursor, c, sizeof(uint32_t), &lo->at_parent) ||
        !reserve(&cursor, c, sizeof(uint32_t), &lo->at_g_eff) ||
        !reserve(&cursor, c, sizeof(uint32_t), &lo->at_heap_pos) ||
        !reserve(&cursor, c, sizeof(uint32_t), &lo->at_heap) ||
        !reserve(&cursor, (size_t)table, sizeof(uint32_t), &lo->at_table) ||
        !reserve(&cursor, c, sizeof(uint16_t), &lo->at_k) || !size_mul(c, max_vehicles, &c) ||
        !reserve(&cursor, c, sizeof(int16_t), &lo->at_off)) {
        return false;
    }
    lo->total = cursor;
    return true;
}

size_t ref_planner_workspace_size(size_t max_vehicles, uint32_t beta)
{
    plan_layout_t lo;
    return layout_compute(max_vehicles, beta, &lo) ? lo.total : 0u;
}

ref_planner_t *ref_planner_init(void *buffer, size_t size, size_t max_vehicles, uint32_t beta)
{
    plan_layout_t lo;
    ref_planner_t *pl;
    unsigned char *base = (unsigned char *)buffer;
    uint32_t i;

    if (buffer == NULL || (uintptr_t)buffer % WS_ALIGN != 0u) {
        return NULL;
    }
    if (!layout_compute(max_vehicles, beta, &lo) || size < lo.total) {
        return NULL;
    }
    pl = (ref_planner_t *)buffer;
    *pl = (ref_planner_t){0};
    pl->beta = beta;
    pl->max_vehicles = max_vehicles;
    pl->bytes = lo.total;
    pl->capacity = lo.capacity;
    pl->table_mask = lo.table_size - 1u;
    pl->g_dev = (coa_cost_t *)(void *)(base + lo.at_g_dev);
    pl->f_dev = (coa_cost_t *)(void *)(base + lo.at_f_dev);
    pl->parent = (uint32_t *)(void *)(base + lo.at_parent);
    pl->g_eff = (uint32_t *)(void *)(base + lo.at_g_eff);
    pl->heap_pos = (uint32_t *)(void *)(base + lo.at_heap_pos);
    pl->heap = (uint32_t *)(void *)(base + lo.at_heap);
    pl->table = (uint32_t *)(void *)(base + lo.at_table);
    pl->node_k = (uint16_t *)(void *)(base + lo.at_k);
    pl->off = (int16_t *)(void *)(base + lo.at_off);
    for (i = 0; i <= pl->table_mask; ++i) {
        pl->table[i] = NONE;
    }
    pl->m = 1u;
    pl->magic = PLAN_MAGIC;
    return pl;
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
    if (p->obstacle_count > 0u && p->obstacles == NULL) {
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

/* The largest |offset| a vehicle may take: its own bound, and the int16 node storage. */
static int32_t offset_limit(const coa_vehicle_t *v)
{
    return (v->max_offset >= 0 && v->max_offset < COA_MAX_OFFSET) ? v->max_offset : COA_MAX_OFFSET;
}

/* Whether the worst case f = g + h of any node stays below 2^127, which leaves every sum
 * the search forms (g + one step, g + h) far from the 2^128 wrap. One step costs at most
 * W * S * max(|a|, |b|) <= W * S * B and the heuristic at most W * S * R * B, so
 * f <= 2 N * sum_i W_i S B_i. With the limits of common.h that is below 2^64 * 2^13 *
 * 2^15 * 2^15 * 2^5 = 2^112, so only coa_deviation_weights' own COA_ERR_RANGE (weights
 * that do not fit 64 bits) can refuse a problem today; the check stays so that raising a
 * limit cannot silently break exactness. Fills the weights and the scale on success. */
static int check_range(const coa_problem_t *p, uint64_t *weights, uint32_t *scale)
{
    coa_cost_t total = {0u, 0u};
    uint32_t s;
    int exponent;
    int rc;
    size_t i;

    s = coa_area_scale(p->vehicles, p->vehicle_count);
    if (s == 0u) {
        return COA_ERR_ARGUMENT;
    }
    rc = coa_deviation_weights(p->vehicles, p->vehicle_count, p->dt, weights, &exponent);
    if (rc != COA_OK) {
        return rc;
    }
    for (i = 0; i < p->vehicle_count; ++i) {
        const coa_vehicle_t *v = &p->vehicles[i];
        uint64_t init = (uint64_t)(v->initial_offset < 0 ? -(int64_t)v->initial_offset
                                                         : (int64_t)v->initial_offset);
        uint64_t bound = init + (uint64_t)p->horizon * v->steep_factor;
        uint64_t factor;
        if (bound > (uint64_t)offset_limit(v)) {
            bound = (uint64_t)offset_limit(v);
        }
        /* S <= 5040, B <= 32767, 2N <= 20000: the factor is below 2^42. */
        factor = (uint64_t)s * bound * 2u * (uint64_t)p->horizon;
        /* Each term is below 2^106 and there are at most 32: the sum cannot wrap before
         * the test. */
        total = coa_cost_add(total, coa_cost_mul(weights[i], factor));
        if (total.hi >= (UINT64_C(1) << 63)) {
            return COA_ERR_RANGE;
        }
    }
    *scale = s;
    return COA_OK;
}

/* ------------------------------------------------------------------------------------ */
/* Costs of a finished row                                                               */

static int32_t abs_i32(int32_t a)
{
    return a < 0 ? -a : a;
}

/* The exact deviation of one step in the search's units. Areas and heuristics are never
 * negative, so the casts below are exact. */
static coa_cost_t step_units(const ref_planner_t *pl, size_t v, int32_t a, int32_t b)
{
    return coa_cost_mul(pl->weight[v], (uint64_t)coa_area_scaled(a, b, pl->scale));
}

/* The heuristic for vehicle v at offset a with `left` steps to go, in the same units. */
static coa_cost_t heuristic_units(const ref_planner_t *pl, size_t v, int32_t a, uint32_t left)
{
    const coa_vehicle_t *veh = &pl->problem->vehicles[v];
    return coa_cost_mul(pl->weight[v],
                        (uint64_t)coa_heuristic_scaled(a, left, veh->steep_factor, pl->scale));
}

/* The exact integer deviation of a row, as the search counts it. */
static coa_cost_t row_units(const ref_planner_t *pl, size_t v, const int32_t *row)
{
    coa_cost_t units = {0u, 0u};
    uint32_t k;
    for (k = 0; k < pl->problem->horizon; ++k) {
        units = coa_cost_add(units, step_units(pl, v, row[k], row[k + 1u]));
    }
    return units;
}

/* ------------------------------------------------------------------------------------ */
/* Geometry of the problem                                                               */

static coa_sweep_t vehicle_sweep(const coa_problem_t *pr, const coa_real_t *dh, size_t v,
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

/* Obstacles and tracks over samples k0 -> k1 (k0 == k1: the instant t_k0). */
static bool static_clear(const coa_problem_t *pr, const coa_sweep_t *s, uint32_t k0, uint32_t k1)
{
    size_t j;
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

static void prepare_fixed(ref_planner_t *pl, uint32_t k0, uint32_t k1)
{
    size_t i;
    if (pl->fixed_ready && pl->fixed_k0 == k0 && pl->fixed_k1 == k1) {
        return;
    }
    for (i = 0; i < pl->fixed_count; ++i) {
        size_t u = pl->fixed[i];
        const int32_t *row = &pl->rows[u * ((size_t)pl->problem->horizon + 1u)];
        pl->fixed_sweep[i] = vehicle_sweep(pl->problem, pl->dh, u, k0, row[k0], k1, row[k1]);
    }
    pl->fixed_k0 = k0;
    pl->fixed_k1 = k1;
    pl->fixed_ready = true;
}

/* Obstacles, tracks and the fixed vehicles: everything but the other searched vehicles. */
static bool env_clear(ref_planner_t *pl, const coa_sweep_t *s, uint32_t k0, uint32_t k1)
{
    size_t i;
    if (!static_clear(pl->problem, s, k0, k1)) {
        return false;
    }
    prepare_fixed(pl, k0, k1);
    for (i = 0; i < pl->fixed_count; ++i) {
        if (coa_conflict_volumes(s, &pl->fixed_sweep[i])) {
            return false;
        }
    }
    return true;
}

/* ------------------------------------------------------------------------------------ */
/* Node table and open list                                                              */

static uint32_t key_hash(uint16_t k, const int16_t *off, size_t m)
{
    uint64_t h = 0x9e3779b97f4a7c15u ^ (uint64_t)k;
    size_t i;
    for (i = 0; i < m; ++i) {
        h = (h ^ (uint64_t)(uint16_t)off[i]) * 0xff51afd7ed558ccdu;
        h ^= h >> 32;
    }
    h ^= h >> 29;
    h *= 0xc4ceb9fe1a85ec53u;
    h ^= h >> 32;
    return (uint32_t)h;
}

static const int16_t *node_off(const ref_planner_t *pl, uint32_t n)
{
    return &pl->off[(size_t)n * pl->m];
}

/* The node with this key, or NONE and the empty slot where it would go. The table is at
 * most half full, so the probe always ends within table_mask + 1 steps. */
static uint32_t table_find(const ref_planner_t *pl, uint16_t k, const int16_t *key,
                           uint32_t *slot_out)
{
    uint32_t slot = key_hash(k, key, pl->m) & pl->table_mask;
    uint32_t probe;
    size_t i;

    for (probe = 0; probe <= pl->table_mask; ++probe) {
        uint32_t n = pl->table[slot];
        if (n == NONE) {
            break;
        }
        if (pl->node_k[n] == k) {
            const int16_t *o = node_off(pl, n);
            for (i = 0; i < pl->m && o[i] == key[i]; ++i) {
            }
            if (i == pl->m) {
                return n;
            }
        }
        slot = (slot + 1u) & pl->table_mask;
    }
    *slot_out = slot;
    return NONE;
}

/* Empties the table of the previous search's nodes: wholesale when they filled a good
 * part of it, else entry by entry so a small search does not pay for a large table. */
static void table_reset(ref_planner_t *pl)
{
    uint32_t n;
    if ((uint64_t)pl->used * 4u >= (uint64_t)pl->table_mask + 1u) {
        for (n = 0; n <= pl->table_mask; ++n) {
            pl->table[n] = NONE;
        }
    } else {
        for (n = 0; n < pl->used; ++n) {
            uint32_t slot = key_hash(pl->node_k[n], node_off(pl, n), pl->m) & pl->table_mask;
            uint32_t probe;
            /* Entries cleared before this one may have left holes in its probe run, so
             * walk past empty slots: the entry is known to be present. */
            for (probe = 0; probe <= pl->table_mask; ++probe) {
                if (pl->table[slot] == n) {
                    pl->table[slot] = NONE;
                    break;
                }
                slot = (slot + 1u) & pl->table_mask;
            }
        }
    }
    pl->used = 0u;
    pl->heap_count = 0u;
}

/* Open-list order: f_dev, then f_eff (= g_eff), then larger k, then generation order. */
static bool node_before(const ref_planner_t *pl, uint32_t a, uint32_t b)
{
    int c = cost_compare(pl->f_dev[a], pl->f_dev[b]);
    if (c != 0) {
        return c < 0;
    }
    if (pl->g_eff[a] != pl->g_eff[b]) {
        return pl->g_eff[a] < pl->g_eff[b];
    }
    if (pl->node_k[a] != pl->node_k[b]) {
        return pl->node_k[a] > pl->node_k[b];
    }
    return a < b;
}

static void heap_place(ref_planner_t *pl, uint32_t pos, uint32_t n)
{
    pl->heap[pos] = n;
    pl->heap_pos[n] = pos;
}

static void sift_up(ref_planner_t *pl, uint32_t pos)
{
    uint32_t n = pl->heap[pos];
    while (pos > 0u) {
        uint32_t up = (pos - 1u) / 2u;
        if (!node_before(pl, n, pl->heap[up])) {
            break;
        }
        heap_place(pl, pos, pl->heap[up]);
        pos = up;
    }
    heap_place(pl, pos, n);
}

static void sift_down(ref_planner_t *pl, uint32_t pos)
{
    uint32_t n = pl->heap[pos];
    for (;;) {
        uint32_t child = 2u * pos + 1u;
        if (child >= pl->heap_count) {
            break;
        }
        if (child + 1u < pl->heap_count && node_before(pl, pl->heap[child + 1u], pl->heap[child])) {
            ++child;
        }
        if (!node_before(pl, pl->heap[child], n)) {
            break;
        }
        heap_place(pl, pos, pl->heap[child]);
        pos = child;
    }
    heap_place(pl, pos, n);
}

static void heap_push(ref_planner_t *pl, uint32_t n)
{
    pl->heap[pl->heap_count] = n;
    pl->heap_pos[n] = pl->heap_count;
    ++pl->heap_count;
    sift_up(pl, pl->heap_count - 1u);
}

static uint32_t heap_pop(ref_planner_t *pl)
{
    uint32_t top = pl->heap[0];
    --pl->heap_count;
    if (pl->heap_count > 0u) {
        heap_place(pl, 0u, pl->heap[pl->heap_count]);
        sift_down(pl, 0u);
    }
    pl->heap_pos[top] = NONE; /* closed from now on */
    return top;
}

/* ------------------------------------------------------------------------------------ */
/* The search                                                                            */

/* A new child, or a better path to an open one. Returns false only if the pool is full,
 * which the sizing makes impossible; the caller then reports the budget as exhausted. */
static bool add_child(ref_planner_t *pl, uint32_t parent, uint16_t k, const int16_t *key,
                      coa_cost_t g, coa_cost_t f, uint32_t eff)
{
    uint32_t slot = 0u;
    uint32_t n = table_find(pl, k, key, &slot);
    size_t i;

    if (n != NONE) {
        if (pl->heap_pos[n] == NONE) {
            return true; /* closed: final, the heuristic is consistent */
        }
        int c = cost_compare(g, pl->g_dev[n]);
        if (c < 0 || (c == 0 && eff < pl->g_eff[n])) {
            pl->parent[n] = parent;
            pl->g_dev[n] = g;
            pl->f_dev[n] = f;
            pl->g_eff[n] = eff;
            sift_up(pl, pl->heap_pos[n]);
        }
        return true;
    }
    if (pl->used >= pl->capacity) {
        return false;
    }
    n = pl->used++;
    pl->node_k[n] = k;
    pl->parent[n] = parent;
    pl->g_dev[n] = g;
    pl->f_dev[n] = f;
    pl->g_eff[n] = eff;
    for (i = 0; i < pl->m; ++i) {
        pl->off[(size_t)n * pl->m + i] = key[i];
    }
    pl->table[slot] = n;
    heap_push(pl, n);
    return true;
}

static bool expand(ref_planner_t *pl, uint32_t n, search_out_t *out)
{
    const coa_problem_t *pr = pl->problem;
    const size_t m = pl->m;
    const uint32_t k = pl->node_k[n];
    const uint32_t k1 = k + 1u;
    const uint32_t left = pr->horizon - k1;
    int16_t key[MAXM];
    int act[MAXM];
    size_t i;
    size_t j;
    int a;
    int b;
    long d;

    /* Copy the parent's offsets: adding children never moves them, but this keeps the
     * inner loops free of repeated index arithmetic. */
    for (i = 0; i < m; ++i) {
        key[i] = node_off(pl, n)[i];
    }
    for (i = 0; i < m; ++i) {
        size_t v = pl->searched[i];
        const coa_vehicle_t *veh = &pr->vehicles[v];
        int32_t from = key[i];
        for (a = 0; a < (int)ACTIONS; ++a) {
            int32_t to = from + coa_action_delta((coa_action_t)a, veh->steep_factor);
            bool ok = abs_i32(to) <= pl->limit[v];
            if (ok) {
                pl->sweep[i][a] = vehicle_sweep(pr, pl->dh, v, k, from, k1, to);
                ok = env_clear(pl, &pl->sweep[i][a], k, k1);
            }
            pl->env_ok[i][a] = ok;
            if (ok) {
                pl->next[i][a] = to;
                pl->dev[i][a] = step_units(pl, v, from, to);
                pl->heur[i][a] = heuristic_units(pl, v, to, left);
            }
        }
    }
    for (i = 0; i < m; ++i) {
        for (j = i + 1u; j < m; ++j) {
            for (a = 0; a < (int)ACTIONS; ++a) {
                for (b = 0; b < (int)ACTIONS; ++b) {
                    pl->pair_ok[i][j][a][b] =
                        pl->env_ok[i][a] && pl->env_ok[j][b] &&
                        !coa_conflict_volumes(&pl->sweep[i][a], &pl->sweep[j][b]);
                }
            }
        }
    }

    /* Depth-first over the composite actions, vehicle 0 outermost, each vehicle's actions
     * in coa_action_t order; a prefix that fails a table entry is cut at once. At most
     * 5 + 25 + ... + 5^m steps. */
    d = 0;
    act[0] = -1;
    while (d >= 0) {
        size_t di = (size_t)d;
        bool ok;
        ++act[di];
        if (act[di] >= (int)ACTIONS) {
            --d;
            continue;
        }
        ok = pl->env_ok[di][act[di]];
        for (j = 0; ok && j < di; ++j) {
            ok = pl->pair_ok[j][di][act[j]][act[di]];
        }
        if (!ok) {
            continue;
        }
        if (di + 1u < m) {
            ++d;
            act[di + 1u] = -1;
            continue;
        }
        {
            int16_t child[MAXM];
            coa_cost_t g = pl->g_dev[n];
            coa_cost_t h = {0u, 0u};
            uint32_t eff = pl->g_eff[n];
            for (i = 0; i < m; ++i) {
                child[i] = (int16_t)pl->next[i][act[i]];
                g = cost_add(g, pl->dev[i][act[i]]);
                h = cost_add(h, pl->heur[i][act[i]]);
                eff += coa_action_effort((coa_action_t)act[i]);
            }
            ++out->generated;
            if (!add_child(pl, n, (uint16_t)k1, child, g, cost_add(g, h), eff)) {
                return false;
            }
        }
    }
    return true;
}

/* Whether the searched vehicles are clear of everything at t = 0. */
static bool root_clear(ref_planner_t *pl)
{
    const coa_problem_t *pr = pl->problem;
    coa_sweep_t at0[MAXM];
    size_t i;
    size_t j;

    for (i = 0; i < pl->m; ++i) {
        size_t v = pl->searched[i];
        int32_t o = pr->vehicles[v].initial_offset;
        at0[i] = vehicle_sweep(pr, pl->dh, v, 0u, o, 0u, o);
        if (!env_clear(pl, &at0[i], 0u, 0u)) {
            return false;
        }
        for (j = 0; j < i; ++j) {
            if (coa_conflict_volumes(&at0[i], &at0[j])) {
                return false;
            }
        }
    }
    return true;
}

/* One A* search over pl->searched[0..m-1] against the fixed rows. When solved, writes
 * the searched vehicles' rows of pl->rows. */
static void search(ref_planner_t *pl, size_t m, search_out_t *out)
{
    const coa_problem_t *pr = pl->problem;
    const uint32_t horizon = pr->horizon;
    int16_t key[MAXM];
    uint32_t closed = 0u;
    coa_cost_t h = {0u, 0u};
    coa_cost_t zero = {0u, 0u};
    size_t i;

    out->status = COA_PLAN_INFEASIBLE;
    out->expanded = 0u;
    out->generated = 0u;
    table_reset(pl);
    pl->m = m;
    pl->fixed_ready = false;

    if (!root_clear(pl)) {
        return;
    }
    for (i = 0; i < m; ++i) {
        const coa_vehicle_t *v = &pr->vehicles[pl->searched[i]];
        key[i] = (int16_t)v->initial_offset;
        h = coa_cost_add(h, heuristic_units(pl, pl->searched[i], v->initial_offset, horizon));
    }
    if (!add_child(pl, NONE, 0u, key, zero, h, 0u)) {
        out->status = COA_PLAN_BUDGET_EXHAUSTED;
        return;
    }

    /* The goal test comes before the budget test: a goal on top of the open list is
     * optimal however many states were closed to get there, and closing it costs nothing. */
    while (pl->heap_count > 0u) {
        uint32_t n = pl->heap[0];
        if (pl->node_k[n] == horizon) {
            uint32_t step;
            for (step = 0; step <= horizon && n != NONE; ++step) {
                const int16_t *o = node_off(pl, n);
                for (i = 0; i < m; ++i) {
                    pl->rows[pl->searched[i] * ((size_t)horizon + 1u) + pl->node_k[n]] = o[i];
                }
                n = pl->parent[n];
            }
            out->status = COA_PLAN_SOLVED;
            return;
        }
        if (closed >= pl->beta) {
            out->status = COA_PLAN_BUDGET_EXHAUSTED;
            return;
        }
        (void)heap_pop(pl);
        if (!expand(pl, n, out)) {
            out->status = COA_PLAN_BUDGET_EXHAUSTED;
            return;
        }
        ++closed;
        ++out->expanded;
    }
    out->status = COA_PLAN_INFEASIBLE;
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
    for (i = 0; i < COA_MAX_VEHICLES; ++i) {
        r->order[i] = i;
    }
    r->planned_count = 0u;
    r->failed_vehicle = COA_NO_VEHICLE;
    r->orders_tried = 0u;
    r->all_orders_covered = false;
}

/* Validates the call and loads the problem's cost parameters into the planner. */
static int load(ref_planner_t *pl, const coa_problem_t *problem, const int32_t *offsets,
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
    rc = check_range(problem, pl->weight, &pl->scale);
    if (rc != COA_OK) {
        return rc;
    }
    pl->problem = problem;
    for (i = 0; i < problem->vehicle_count; ++i) {
        pl->dh[i] = coa_climb_step(&problem->vehicles[i], problem->dt);
        pl->limit[i] = offset_limit(&problem->vehicles[i]);
    }
    return COA_OK;
}

/* Totals of the rows of vehicles[which[0..count-1]]. */
static void fill_costs(const ref_planner_t *pl, const size_t *which, size_t count,
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
        /* Rows come from the search, so every step is an action and this cannot fail. */
        (void)coa_plan_vehicle_cost(&pr->vehicles[which[i]], pr->dt, pr->horizon, row, &dev, &eff);
        r->deviation += dev;
        r->effort += eff;
        r->deviation_units = coa_cost_add(r->deviation_units, row_units(pl, which[i], row));
    }
}

int ref_plan_centralised(ref_planner_t *planner, const coa_problem_t *problem, int32_t *offsets,
                         coa_plan_result_t *result)
{
    search_out_t out;
    size_t i;
    int rc;

    if (result != NULL) {
        result_clear(result);
    }
    rc = load(planner, problem, offsets, result);
    if (rc != COA_OK) {
        return rc;
    }
    if (problem->vehicle_count > planner->max_vehicles) {
        return COA_ERR_WORKSPACE;
    }
    for (i = 0; i < problem->vehicle_count; ++i) {
        planner->searched[i] = i;
    }
    planner->fixed = NULL;
    planner->fixed_count = 0u;
    planner->rows = offsets;
    search(planner, problem->vehicle_count, &out);

    result->status = out.status;
    result->nodes_expanded = out.expanded;
    result->nodes_generated = out.generated;
    result->workspace_bytes = planner->bytes;
    result->orders_tried = 1u;
    if (out.status == COA_PLAN_SOLVED) {
        result->planned_count = problem->vehicle_count;
        fill_costs(planner, planner->searched, problem->vehicle_count, result);
    }
    return COA_OK;
}

/* Plans order[level] against the plans of order[0..level-1]. */
static coa_plan_status_t plan_one(ref_planner_t *pl, const size_t *order, size_t level,
                                  coa_plan_result_t *r)
{
    search_out_t out;
    pl->searched[0] = order[level];
    pl->fixed = order;
    pl->fixed_count = level;
    search(pl, 1u, &out);
    r->nodes_expanded += out.expanded;
    r->nodes_generated += out.generated;
    return out.status;
}

/* Whether some vehicle meets an obstacle, a track or another vehicle at t = 0 (positions
 * at k = 0 with the initial offsets). Every order then fails: the root of whichever
 * vehicle of the pair is planned second (or of the vehicle itself) is in conflict.
 * Uses the planner's fixed-vehicle scratch, which the next search rebuilds anyway. */
static bool any_initial_conflict(ref_planner_t *pl)
{
    const coa_problem_t *pr = pl->problem;
    coa_sweep_t *at0 = pl->fixed_sweep;
    size_t i;
    size_t j;

    pl->fixed_ready = false;
    for (i = 0; i < pr->vehicle_count; ++i) {
        int32_t o = pr->vehicles[i].initial_offset;
        at0[i] = vehicle_sweep(pr, pl->dh, i, 0u, o, 0u, o);
        if (!static_clear(pr, &at0[i], 0u, 0u)) {
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

int ref_plan_decoupled(ref_planner_t *planner, const coa_problem_t *problem, const size_t *order,
                       uint32_t max_orders, int32_t *offsets, coa_plan_result_t *result)
{
    size_t first[COA_MAX_VEHICLES];
    size_t cur[COA_MAX_VEHICLES];
    /* tried[L]: vehicles already tried at position L under the current cur[0..L-1]. */
    uint32_t tried[COA_MAX_VEHICLES];
    size_t n;
    size_t start = 0u;
    size_t keep; /* levels below this still hold the first attempt's plans */
    size_t first_fail = 0u;
    bool any_budget = false;
    bool proven = false;  /* infeasible in every order, whatever beta did */
    bool covered = false; /* every order tried or ruled out */
    size_t i;
    int rc;

    if (result != NULL) {
        result_clear(result);
    }
    if (max_orders == 0u) {
        return COA_ERR_ARGUMENT;
    }
    rc = load(planner, problem, offsets, result);
    if (rc != COA_OK) {
        return rc;
    }
    n = problem->vehicle_count;
    if (order != NULL) {
        uint32_t seen = 0u;
        for (i = 0; i < n; ++i) {
            if (order[i] >= n || (seen & (UINT32_C(1) << order[i])) != 0u) {
                return COA_ERR_ARGUMENT;
            }
            seen |= UINT32_C(1) << order[i];
            first[i] = order[i];
        }
    } else {
        (void)coa_priority_order(problem->vehicles, n, first);
    }
    for (i = 0; i < n; ++i) {
        cur[i] = first[i];
        tried[i] = 0u;
    }
    keep = n;
    planner->rows = offsets;
    result->workspace_bytes = planner->bytes;

    while (result->orders_tried < max_orders) {
        size_t level;
        size_t fail = n;
        coa_plan_status_t st = COA_PLAN_SOLVED;
        size_t v;
        size_t to;
        bool found;

        if (result->orders_tried > 0u && start < keep) {
            keep = start;
        }
        ++result->orders_tried;
        for (level = start; level < n; ++level) {
            tried[level] |= UINT32_C(1) << cur[level];
            st = plan_one(planner, cur, level, result);
            if (st != COA_PLAN_SOLVED) {
                fail = level;
                break;
            }
        }
        if (fail == n) {
            result->status = COA_PLAN_SOLVED;
            for (i = 0; i < n; ++i) {
                result->order[i] = cur[i];
            }
            result->planned_count = n;
            fill_costs(planner, cur, n, result);
            return COA_OK;
        }
        if (st == COA_PLAN_BUDGET_EXHAUSTED) {
            any_budget = true;
        }
        /* Alone against obstacles and tracks, nothing it could meet later is easier. */
        if (fail == 0u && st == COA_PLAN_INFEASIBLE) {
            proven = true;
        }
        if (result->orders_tried == 1u) {
            first_fail = fail;
            /* Checked only once an order has failed, so a solved call never pays for it;
             * without it, two vehicles in conflict at t = 0 among n would cost up to n!
             * attempts before the order space ran out. */
            if (!proven && any_initial_conflict(planner)) {
                proven = true;
            }
        }
        if (proven) {
            break;
        }
        v = cur[fail];
        /* Depth-first: every order below cur[0..fail] is ruled out, so go back to the
         * deepest position that still has an untried candidate under its prefix (deeper
         * positions have been exhausted). There the failing vehicle goes first if it has
         * not been tried there, else the first untried one in the current order. Jumping
         * higher would abandon part of a subtree that the per-position bitmasks could never
         * return to, and the search would no longer be exhaustive. */
        found = false;
        for (to = fail + 1u; !found && to-- > 0u;) {
            if ((tried[to] & (UINT32_C(1) << v)) == 0u) {
                promote(cur, fail, to);
                found = true;
            }
            for (i = to; i < n && !found; ++i) {
                if ((tried[to] & (UINT32_C(1) << cur[i])) == 0u) {
                    promote(cur, i, to);
                    found = true;
                }
            }
        }
        if (!found) {
            covered = true; /* every order tried or ruled out */
            break;
        }
        for (i = to + 1u; i < n; ++i) {
            tried[i] = 0u;
        }
        start = to;
    }

    /* No order worked: report the first attempt, re-planning the part of its prefix that
     * later attempts overwrote (the searches are deterministic, so they succeed again).
     * A proof for every order outranks an attempt that ran out of beta: more beta could
     * not have helped it. */
    result->all_orders_covered = proven || covered;
    result->status = (any_budget && !proven) ? COA_PLAN_BUDGET_EXHAUSTED : COA_PLAN_INFEASIBLE;
    result->planned_count = first_fail;
    for (i = 0; i < n; ++i) {
        result->order[i] = first[i];
    }
    for (i = keep; i < first_fail; ++i) {
        if (plan_one(planner, first, i, result) != COA_PLAN_SOLVED) {
            result->planned_count = i; /* unreachable; keeps the report truthful anyway */
            break;
        }
    }
    result->failed_vehicle = first[result->planned_count];
    fill_costs(planner, first, result->planned_count, result);
    return COA_OK;
}

/* ------------------------------------------------------------------------------------ */
/* Checking a finished plan                                                              */
