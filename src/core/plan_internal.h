/* SPDX-License-Identifier: MIT */
/*
 * plan_internal.h: what the planner's sources share (private, not installed).
 *
 *   plan.c        the public entry points: sizing, problem checks, the centralised front
 *                 end (independence detection) and the decoupled one, costs of rows;
 *   plan_table.c  each vehicle's exact cost-to-go and cost-from-start tables, and the
 *                 plans read off them;
 *   plan_pair.c   the exact cost-to-go of pairs of vehicles over their encounters;
 *   plan_search.c the joint search of a group of vehicles.
 *
 * Exact arithmetic. A vehicle's own deviation is counted in units of 1/(2s) of its
 * L*dh (s its steep factor), where every step's area is an integer (trajectory.h); the
 * problem's unit is 2^E / S m^2 with S = lcm(2 s_i) (coa_area_scale), so a vehicle's own
 * units convert exactly by W_i * (S / 2s_i). Tables hold the vehicle's own units (below
 * 2^35 by the limits of common.h: N * 32767 * 2s <= 6.6e9). The joint search packs a
 * cost into one 128-bit integer, deviation * 2^PLAN_EFF_BITS + effort (coa_cost_t used
 * as a plain 128-bit integer), so that comparing two packed costs compares them
 * lexicographically, and sums and differences of packed costs are exact as long as the
 * effort part of every result stays in range (it is a sum of efforts of at most
 * COA_MAX_CENTRALISED vehicles over N steps, below 2^19).
 */
#ifndef COAVOID_CORE_PLAN_INTERNAL_H
#define COAVOID_CORE_PLAN_INTERNAL_H

#include "coavoid/plan.h"

#include "internal.h"

#define PLAN_ACTIONS COA_ACTION_COUNT
#define PLAN_MAXM COA_MAX_CENTRALISED
_Static_assert(PLAN_MAXM >= 2u && PLAN_MAXM <= 10u, "COA_MAX_CENTRALISED is 2..10");
#define PLAN_NONE UINT32_MAX /* no node, an empty slot, not in the heap */
#define PLAN_EFF_BITS 19u    /* effort bits of a packed cost */
#define PLAN_PAIRS (PLAN_MAXM * (PLAN_MAXM - 1u) / 2u)
#define PLAN_OUT INT16_MIN    /* a group member's offset while it is not in the search */
#define PLAN_SLOTS_FIRST 256u /* the hash table's first size (plan_search.c) */
/* The most members whose surcharges the heuristic matches exactly (the peels of
 * plan_search.c); larger groups match within two sides of at most this many. */
#define PLAN_MATCH_ALL 6u
/* Work (plan.h, "Work"): a polytope test costs one unit per this many vertices, plus one. */
#define PLAN_WORK_VERTICES 8u

/* ------------------------------------------------------------------------------------ */
/* Tables                                                                                */

/* A table cell packs a state's exact cost (to go, or from the start) and, in a cost-to-go
 * table, the actions that leave it:
 *   bits 63..29  deviation, the vehicle's own units (all ones: dead or unreachable)
 *   bits 28..14  effort (at most 3N < 2^15)
 *   bits  4..0   cost-to-go tables: actions (bit a for coa_action_t a) that stay within
 *                the offset bound, conflict with nothing the table was built against and
 *                lead to a live state. A dead state has none; a state at k = N has none
 *                and is live.
 * cell >> CELL_EFF_SHIFT orders two cells' costs lexicographically. */
#define CELL_DEV_SHIFT 29u
#define CELL_EFF_SHIFT 14u
#define CELL_DEV_DEAD ((UINT64_C(1) << 35) - 1u)
#define CELL_MASK_BITS 0x1fu
#define CELL_DEAD (CELL_DEV_DEAD << CELL_DEV_SHIFT)

static inline uint64_t cell_dev(uint64_t c)
{
    return c >> CELL_DEV_SHIFT;
}

static inline uint32_t cell_eff(uint64_t c)
{
    return (uint32_t)((c >> CELL_EFF_SHIFT) & 0x7fffu);
}

static inline uint32_t cell_mask(uint64_t c)
{
    return (uint32_t)(c & CELL_MASK_BITS);
}

static inline bool cell_dead(uint64_t c)
{
    return cell_dev(c) == CELL_DEV_DEAD;
}

/* One vehicle's table: the reachable offsets [plan_row_lo(k), plan_row_hi(k)] of every
 * sample k, stored row after row. Rows are laid out by their widest possible width,
 * min(2ks + 1, 2L + 1), so that a row's start has a closed form. */
typedef struct {
    size_t vehicle; /* index into the problem */
    int32_t origin; /* initial offset */
    int32_t limit;  /* L: the largest |offset| */
    uint32_t steep; /* s */
    uint32_t horizon;
    uint32_t growing; /* q = L / s: rows 0..q are 2ks + 1 wide, the later ones 2L + 1 */
    uint64_t *cells;
} plan_table_t;

/* The moves out of one state of one vehicle, in the order a plan takes them: by the
 * increase of f they cause (deviation, then effort), then by action. */
typedef struct {
    uint32_t count;
    uint8_t action[PLAN_ACTIONS];
    int32_t to[PLAN_ACTIONS];
    uint64_t dev[PLAN_ACTIONS]; /* f's deviation increase, the vehicle's own units */
    int32_t eff[PLAN_ACTIONS];  /* f's effort increase (negative when dev's is positive) */
} plan_moves_t;

/* ------------------------------------------------------------------------------------ */
/* Groups and pairs                                                                      */

/* A joint search over group members m_0..m_{count-1} (problem indices, ascending). A
 * member takes part in the search from sample `first` to sample `last` (the steps
 * first..last are the only ones where it can meet another member or a fixed vehicle);
 * before, it flies its cheapest way to whatever offset it enters at, after, its cheapest
 * way on: both exact from its tables. */
typedef struct {
    size_t count;
    size_t vehicle[PLAN_MAXM];
    uint32_t first[PLAN_MAXM];
    uint32_t last[PLAN_MAXM];
    uint32_t end;                    /* 1 + the largest `last`: the search's goal sample */
    coa_cost_t alone[PLAN_MAXM];     /* each member's cost alone, packed */
    uint32_t entry_count[PLAN_MAXM]; /* offsets in its entry list (pl->entries) */
    /* Pairs (a, b) of members, a < b, in the order (0,1), (0,2), .., (1,2), ..: the steps
     * where they can meet (near_first > near_last: never). */
    uint32_t near_first[PLAN_PAIRS];
    uint32_t near_last[PLAN_PAIRS];
    /* Fixed vehicles (independence detection's re-plans): problem indices, and the steps
     * each member can meet each. */
    size_t fixed[COA_MAX_VEHICLES];
    size_t fixed_count;
    bool bounded;     /* plans that cost more than bound are not wanted */
    coa_cost_t bound; /* packed */
    bool capped;      /* a plan is known that costs `cap` (packed): prune above */
    coa_cost_t cap;
    /* The heuristic's matching pairs members of the same side only (member bit masks;
     * side[1] is 0, one side, up to PLAN_MATCH_ALL members): the family of matchings is
     * fixed for the whole search, which keeps the heuristic consistent. */
    uint32_t side[2];
} plan_group_t;

/* The exact joint cost-to-go of members a and b over rows first..last (sample `last`+1 is
 * the boundary, where it is the sum of their own), over the offsets each can take at a
 * cost within the group's slack (a corridor: every offset whose cheapest plan through it
 * costs at most the cap's slack over its cost alone). Cells outside are dead. */
typedef struct {
    bool present;
    uint32_t first;
    uint32_t last;
    int16_t *row_lo; /* per row (first..last): corridor of a, then of b: lo_a, hi_a, lo_b, hi_b */
    uint32_t *row_base;
    coa_cost_t *cells; /* packed; PLAN_COST_DEAD when dead */
} plan_pair_t;

static const coa_cost_t PLAN_COST_DEAD = {UINT64_MAX, UINT64_MAX};

static inline bool plan_cost_dead(coa_cost_t c)
{
    return c.hi == UINT64_MAX && c.lo == UINT64_MAX;
}

/* ------------------------------------------------------------------------------------ */
/* The planner                                                                           */

typedef struct {
    coa_plan_status_t status;
    uint64_t expanded;
    uint64_t stored;
    coa_cost_t bound2; /* budget exhausted: the least doubled f left open, a lower bound on
                          twice the group's optimum */
} plan_search_out_t;

#define PLAN_MAX_TRIED 64u /* pairs of groups independence detection tried to re-plan */

struct coa_planner {
    uint32_t magic;
    coa_planner_config_t config;
    size_t bytes;
    size_t table_cells;  /* cells one table holds */
    size_t table_count;  /* tables in the workspace */
    size_t row_width;    /* the widest row a table can have */
    uint32_t capacity;   /* nodes: beta (0: no joint search, vehicles == 1) */
    uint32_t slot_count; /* hash slots: 2 * capacity */
    /* Slots the table uses: each search from PLAN_SLOTS_FIRST, doubled (every node
     * entered again) before half of them hold nodes, up to slot_count; a small search
     * touches only what it needs of a large workspace. */
    uint32_t slot_active;
    uint32_t touched_slots; /* the most slots a search used (workspace_touched_bytes) */
    size_t pair_cells;      /* cells of the pair arena */

    uint64_t *cells;  /* table_count tables of table_cells */
    int16_t *entries; /* per member: its entry offsets, cheapest first (row_width) */
    coa_cost_t *pair_arena;

    /* Node pool (one array per field). key: the packed, doubled f of the node's next
     * children; g: its packed cost from the start; k: the sample (bit 15: expanded). */
    coa_cost_t *key;
    coa_cost_t *g;
    uint32_t *parent;
    uint32_t *heap_pos;
    uint32_t *heap;
    uint32_t *slot;
    uint16_t *node_k;
    int16_t *off;

    /* The last search's nodes stay until the next one starts (rows are rebuilt from
     * them); its hash entries are cleared then. */
    uint32_t used;
    uint32_t heap_count;
    size_t m;
    coa_cost_t batch; /* doubled f beyond its key an expansion also generates */

    /* Per call: the problem and its exact cost parameters. */
    const coa_problem_t *problem;
    int32_t *rows;
    uint32_t scale;
    uint64_t weight[COA_MAX_VEHICLES];
    uint32_t unit[COA_MAX_VEHICLES]; /* S / (2 s_i) */
    coa_real_t dh[COA_MAX_VEHICLES];
    int32_t limit[COA_MAX_VEHICLES];

    /* Tables: cost-to-go and cost-from-start of each vehicle (centralised), and one more
     * cost-to-go table for plans against fixed vehicles. */
    plan_table_t to_go[PLAN_MAXM];
    plan_table_t from_start[PLAN_MAXM];
    plan_table_t scratch;

    /* Steps where two vehicles can meet at all (first > last: never), per call. */
    uint32_t near_first[PLAN_MAXM][PLAN_MAXM];
    uint32_t near_last[PLAN_MAXM][PLAN_MAXM];

    /* The current joint search, and the rows its members had before it (a search that
     * fails must leave them as they were). */
    plan_group_t group;
    int32_t *saved_rows;
    plan_pair_t pair[PLAN_PAIRS];
    size_t pair_used; /* arena cells taken */

    /* Independence detection: pairs of groups (member bit masks) it tried to re-plan. */
    uint32_t tried[PLAN_MAX_TRIED][2];
    size_t tried_count;

    /* The work budget (plan.h, "Work"): units spent by this call, the limit (0: none),
     * and whether it ran out; once it has, every loop that charges work stops early and
     * the front end reports COA_PLAN_LIMIT_WORK. */
    uint64_t work_limit;
    uint64_t work_used;
    bool out_of_work;

    /* Centralised: the incumbent, the cheapest plan of every vehicle found so far (rows
     * of all the problem's vehicles), and its packed cost. */
    int32_t *best_rows;
    bool have_best;
    coa_cost_t best_cost;
    int exponent;          /* the deviation unit's power of two, 2^E (coa_deviation_weights) */
    uint32_t match_all;    /* PLAN_MATCH_ALL; a test hook lowers it to split small groups */
    uint64_t bound_breaks; /* leaves below their branch's bound: a defect (test hook) */

    /* What the workspace's calls have written (result.workspace_touched_bytes): the cells
     * of each table, the most nodes and pair cells one search held, and whether a
     * centralised call wrote the members' entries and the saved and incumbent rows. */
    size_t touched_cells[2u * PLAN_MAXM + 1u];
    uint32_t touched_nodes;
    size_t touched_pair_cells;
    bool touched_rows;
};

/* Charges `units` of work before they are done: false, charging nothing, when they do not
 * fit what is left of the budget (and from then on), so work_used never passes the limit. */
static inline bool plan_work(coa_planner_t *pl, uint64_t units)
{
    if (pl->out_of_work) {
        return false;
    }
    if (pl->work_limit != 0u && units > pl->work_limit - pl->work_used) {
        pl->out_of_work = true;
        return false;
    }
    pl->work_used += units;
    return true;
}

/* ------------------------------------------------------------------------------------ */
/* Packed costs                                                                          */

/* plan_cost_add and plan_cost_compare are coa_cost_add and coa_cost_compare (trajectory.h)
 * inlined: the joint search forms and compares costs for every combination it tries, and
 * calling the library's out of line costs a fifth more instructions in a joint search
 * (docs/benchmarks.md). */

static inline coa_cost_t plan_cost_add(coa_cost_t a, coa_cost_t b)
{
    coa_cost_t r;
    r.lo = a.lo + b.lo;
    r.hi = a.hi + b.hi + (r.lo < a.lo ? 1u : 0u);
    return r;
}

/* a - b for a >= b. */
static inline coa_cost_t plan_cost_sub(coa_cost_t a, coa_cost_t b)
{
    coa_cost_t r;
    r.lo = a.lo - b.lo;
    r.hi = a.hi - b.hi - (a.lo < b.lo ? 1u : 0u);
    return r;
}

static inline int plan_cost_compare(coa_cost_t a, coa_cost_t b)
{
    if (a.hi != b.hi) {
        return a.hi < b.hi ? -1 : 1;
    }
    if (a.lo != b.lo) {
        return a.lo < b.lo ? -1 : 1;
    }
    return 0;
}

static inline coa_cost_t plan_cost_twice(coa_cost_t a)
{
    coa_cost_t r;
    r.hi = (a.hi << 1) | (a.lo >> 63);
    r.lo = a.lo << 1;
    return r;
}

/* A deviation in the problem's units (coa_cost_t) with an effort, packed. */
static inline coa_cost_t plan_pack(coa_cost_t dev, uint64_t eff)
{
    coa_cost_t r;
    r.hi = (dev.hi << PLAN_EFF_BITS) | (dev.lo >> (64u - PLAN_EFF_BITS));
    r.lo = dev.lo << PLAN_EFF_BITS;
    return plan_cost_add(r, (coa_cost_t){0u, eff});
}

/* a * b in 128 bits: the compiler's when it has a 128-bit type (the search calls this
 * for every cost it forms), else coa_cost_mul's 32-bit schedule (Cortex-M). */
#ifdef __SIZEOF_INT128__
__extension__ typedef unsigned __int128 plan_u128_t;
static inline coa_cost_t plan_mul(uint64_t a, uint64_t b)
{
    plan_u128_t p = (plan_u128_t)a * b;
    coa_cost_t r;
    r.hi = (uint64_t)(p >> 64);
    r.lo = (uint64_t)p;
    return r;
}
#else
static inline coa_cost_t plan_mul(uint64_t a, uint64_t b)
{
    return coa_cost_mul(a, b);
}
#endif

/* A vehicle's own deviation units as the problem's: W_i * (S / 2s_i) * units. */
static inline coa_cost_t plan_units(const coa_planner_t *pl, size_t v, uint64_t own)
{
    return plan_mul(pl->weight[v], own * pl->unit[v]);
}

/* A table cell's cost as a packed cost of vehicle v. */
static inline coa_cost_t plan_cell_cost(const coa_planner_t *pl, size_t v, uint64_t c)
{
    return plan_pack(plan_units(pl, v, cell_dev(c)), cell_eff(c));
}

/* Group member i's tables. */
static inline const plan_table_t *plan_to_go(const coa_planner_t *pl, size_t i)
{
    return &pl->to_go[pl->group.vehicle[i]];
}

static inline const plan_table_t *plan_from_start(const coa_planner_t *pl, size_t i)
{
    return &pl->from_start[pl->group.vehicle[i]];
}

/* ------------------------------------------------------------------------------------ */
/* Shared functions                                                                      */

/* The swept volume of vehicle v from offset a at sample k0 to offset b at k1. */
coa_sweep_t coa_plan_vehicle_sweep(const coa_problem_t *pr, const coa_real_t *dh, size_t v,
                                   uint32_t k0, int32_t a, uint32_t k1, int32_t b);

/* Whether a sweep over samples k0 -> k1 is clear of every obstacle and track, and its two
 * ends above the floor when the problem has one (k0 == k1: the instant t_k0). */
bool coa_plan_static_clear(const coa_problem_t *pr, const coa_sweep_t *s, uint32_t k0, uint32_t k1);

/* A step's area in the planner's own units, coa_area_scaled(a, b, 2s) exactly, whose
 * divisions were a tenth of a plan's time: a step that does not cross the reference is
 * the trapezoid (|a| + |b|) / 2 times 2s, an integer; only a crossing one (|a|, |b| <= s)
 * takes the library's general path. */
static inline uint64_t plan_area(int32_t a, int32_t b, uint32_t steep)
{
    if ((a < 0 && b > 0) || (a > 0 && b < 0)) {
        return (uint64_t)coa_area_scaled(a, b, 2u * steep);
    }
    return ((uint64_t)(a < 0 ? -(int64_t)a : a) + (uint64_t)(b < 0 ? -(int64_t)b : b)) * steep;
}

/* Cells of a table for horizon N, steep factor s and offset bound L (0 when it would not
 * fit 64 bits, which the limits of common.h rule out). */
uint64_t coa_plan_table_cells(uint32_t horizon, uint32_t steep, int32_t limit);

/* Widest row of such a table: min(2Ns + 1, 2L + 1). */
uint64_t coa_plan_table_row_width(uint32_t horizon, uint32_t steep, int32_t limit);

/* Where row k starts in a table of steep factor s, offset bound L and q = L / s. Inline,
 * with q kept in the table, because every search step and pair cell reads table cells
 * (a division and a call per read were a tenth of the paper's planning time). */
static inline uint64_t plan_row_base(uint32_t k, uint32_t steep, uint32_t q, int32_t limit)
{
    const uint64_t s = steep;
    const uint64_t kk = k;
    if (kk <= (uint64_t)q + 1u) {
        return s * kk * (kk - 1u) + kk;
    }
    return s * ((uint64_t)q + 1u) * q + ((uint64_t)q + 1u) +
           (kk - q - 1u) * (2u * (uint64_t)limit + 1u);
}

static inline int32_t plan_row_lo(const plan_table_t *t, uint32_t k)
{
    int64_t lo = (int64_t)t->origin - (int64_t)k * t->steep;
    return lo < -(int64_t)t->limit ? -t->limit : (int32_t)lo;
}

static inline int32_t plan_row_hi(const plan_table_t *t, uint32_t k)
{
    int64_t hi = (int64_t)t->origin + (int64_t)k * t->steep;
    return hi > (int64_t)t->limit ? t->limit : (int32_t)hi;
}

/* The cell of (k, offset) in a table. Precondition: the offset is in row k. */
static inline uint64_t plan_table_at(const plan_table_t *t, uint32_t k, int32_t offset)
{
    return t->cells[plan_row_base(k, t->steep, t->growing, t->limit) +
                    (uint64_t)(offset - plan_row_lo(t, k))];
}

/* Builds cost-to-go table t for vehicle v against the obstacles, the tracks and the
 * vehicles fixed[0..nfixed-1] flying their rows of pl->rows. */
void coa_plan_table_build(coa_planner_t *pl, plan_table_t *t, size_t v, const size_t *fixed,
                          size_t nfixed);

/* Builds cost-from-start table f of the vehicle of cost-to-go table t, over t's moves. */
void coa_plan_table_build_from_start(coa_planner_t *pl, plan_table_t *f, const plan_table_t *t);

/* The moves out of offset `from` at sample k of cost-to-go table t, sorted (see
 * plan_moves_t). */
void coa_plan_table_moves(const plan_table_t *t, uint32_t k, int32_t from, plan_moves_t *mv);

/* Writes t's vehicle's row of pl->rows from sample k on, from `offset`, along its
 * cheapest plan (each step the first of coa_plan_table_moves). Precondition: live. */
void coa_plan_table_walk(coa_planner_t *pl, const plan_table_t *t, uint32_t k, int32_t offset);

/* Writes t's vehicle's row of pl->rows up to sample k, ending at `offset`, along a
 * cheapest plan from its initial offset (cost-from-start table f). Precondition: f's
 * cell there is reachable. */
void coa_plan_table_walk_back(coa_planner_t *pl, const plan_table_t *t, const plan_table_t *f,
                              uint32_t k, int32_t offset);

/* Builds the pair tables of the current group within the arena (pairs that do not fit
 * are left out). */
void coa_plan_pairs_build(coa_planner_t *pl);

/* The least surcharge members a < b pay over their pair table (their cheapest joint plan
 * through its first row less their costs alone; 0 without a table): how much they
 * interact, which chooses the group's sides. O(cells of that row). */
coa_cost_t coa_plan_pair_weight(const coa_planner_t *pl, size_t a, size_t b);

/* Chooses the group's sides (plan_group_t.side) after its pair tables are built: one side
 * up to PLAN_MATCH_ALL members, else the split of the members into two sides of at most
 * PLAN_MATCH_ALL whose matchings of the pairs' weights add up most (work charged per
 * split tried; out of work, the best split so far). */
void coa_plan_sides_choose(coa_planner_t *pl);

/* The surcharge of members a < b at sample k (packed: their joint cost-to-go less the sum
 * of their own), 0 where the pair has no table or the sample is outside it, or
 * PLAN_COST_DEAD. */
coa_cost_t coa_plan_pair_surcharge(const coa_planner_t *pl, size_t a, size_t b, uint32_t k,
                                   int32_t oa, int32_t ob, coa_cost_t to_go_a, coa_cost_t to_go_b);

/* Index of pair (a, b), a < b < m. */
static inline size_t plan_pair_index(size_t a, size_t b, size_t m)
{
    /* b (b - 1) / 2 + a: pairs by their larger member, so the index does not depend on m
     * (the joint search asks for it at every step of its enumeration). */
    static const uint8_t before[10] = {0u, 0u, 1u, 3u, 6u, 10u, 15u, 21u, 28u, 36u};
    (void)m;
    return (size_t)before[b] + a;
}

/* Records that table t now holds its problem's cells (workspace_touched_bytes). */
void coa_plan_touch_table(coa_planner_t *pl, const plan_table_t *t);

/* The members of a bit mask (of vehicles or of group members). */
static inline uint32_t plan_popcount(uint32_t mask)
{
    uint32_t n = 0u;
    for (; mask != 0u; mask &= mask - 1u) {
        ++n;
    }
    return n;
}

/* The hash table's size at the start of each search (plan_search.c, slots_reserve). */
static inline uint32_t plan_slots_first(const coa_planner_t *pl)
{
    return pl->slot_count < PLAN_SLOTS_FIRST ? pl->slot_count : PLAN_SLOTS_FIRST;
}

/* Vehicle v's cost alone (its own table, from its initial offset), packed. */
static inline coa_cost_t plan_cost_alone(const coa_planner_t *pl, size_t v)
{
    return plan_cell_cost(
        pl, v, plan_table_at(&pl->to_go[v], 0u, pl->problem->vehicles[v].initial_offset));
}

/* The exact deviation of vehicle v's row (N + 1 offsets) in the problem's units, as the
 * search counts it, and its effort in *effort when not NULL. */
coa_cost_t coa_plan_row_units(const coa_planner_t *pl, size_t v, const int32_t *row,
                              uint64_t *effort);

/* Totals of the rows of vehicles which[0..count-1] into r's costs. */
void coa_plan_fill_costs(const coa_planner_t *pl, const size_t *which, size_t count,
                         coa_plan_result_t *r);

/* Whether some vehicle meets an obstacle, a track or another vehicle at t = 0 (positions
 * at k = 0 with the initial offsets): then no plan and no order avoids it. */
bool coa_plan_any_initial_conflict(const coa_planner_t *pl);

/* The packed cost of the rows of the vehicles in `members` (a bit mask) in `rows` (every
 * vehicle's, N + 1 offsets each: pl->rows or the incumbent's). O(members N). */
coa_cost_t coa_plan_rows_cost(const coa_planner_t *pl, const int32_t *rows, uint32_t members);

/* Copies the rows of `members` from `from` to `to` (every vehicle's, N + 1 each). */
void coa_plan_rows_copy(const coa_planner_t *pl, int32_t *to, const int32_t *from,
                        uint32_t members);

/* Independence detection over the loaded problem (plan_group.c): the centralised plan's
 * status; the rows of every vehicle when solved. */
coa_plan_status_t coa_plan_independence(coa_planner_t *pl, coa_plan_result_t *r);

/* The incumbent (centralised, after every vehicle's own table): the decoupled order search
 * over the loaded problem from the priority order, tried as the decoupled front end tries
 * orders, and on past the first order that works as a branch and bound: an order is
 * abandoned at the first vehicle where the costs so far and the rest's costs alone reach
 * the best plan's. The cheapest plan is kept in pl->best_rows and pl->best_cost (true:
 * one was found). Once one is, the work limit drops to improve_limit (when lower). Stops
 * after max_orders attempts, when every order is ruled out or tried, or when the work
 * budget runs out. Adds its searches and table walks to r's counters; leaves pl->rows
 * undefined. */
bool coa_plan_orders_best(coa_planner_t *pl, uint32_t max_orders, uint64_t improve_limit,
                          coa_plan_result_t *r);

/* One joint search over pl->group. When solved, writes the members' rows of pl->rows.
 * Precondition: coa_plan_search_release since the last search. */
void coa_plan_search(coa_planner_t *pl, plan_search_out_t *out);

/* Empties the hash table of the last search's nodes (wholesale when they filled a good
 * part of it, else one by one so that a small search does not pay for a large table).
 * Call it before pl->group changes: the states' hashes depend on the group. */
void coa_plan_search_release(coa_planner_t *pl);

/* ------------------------------------------------------------------------------------ */
/* Test hooks (tests/test_heuristic.c): not used by the planner itself.                  */

/* Sets up pl->group as a joint search of `members` (a bit mask of vehicles) with nothing
 * fixed, no bound and no cap (so the pair tables' corridors are every live offset):
 * rebuilds every vehicle's cost-to-go and cost-from-start tables, the steps where
 * vehicles can meet, the spans, the entry lists and the pair tables. Precondition: the
 * problem is loaded (a coa_plan_* call on it returned COA_OK) and the planner has room
 * for a joint search of all its vehicles. */
void coa_plan_test_group_setup(coa_planner_t *pl, uint32_t members);

/* The joint search's doubled heuristic (plan_search.c) of the state at sample k with
 * member offsets off[0..count-1] (read only for the members in the search at k): false
 * when a pair is dead there. */
bool coa_plan_test_heuristic(const coa_planner_t *pl, uint32_t k, const int16_t *off,
                             coa_cost_t *h2);

/* Splits every group of more than `members` (2..PLAN_MATCH_ALL; false otherwise) into two
 * sides of at most that many, as groups above PLAN_MATCH_ALL are. Precondition: the
 * problems planned have no group of more than 2 * members. */
bool coa_plan_test_match_all(coa_planner_t *pl, uint32_t members);

/* The leaves the joint searches found below the bound their branch was let through with,
 * since the planner's init: a defect of the branch bounds when not 0. */
uint64_t coa_plan_test_bound_breaks(const coa_planner_t *pl);

/* The doubled matching the heuristic adds (plan_search.c) of surcharges s[] (pairs of m
 * members in plan_pair_index order) among the members of mask. */
coa_cost_t coa_plan_test_matching(const coa_cost_t *s, size_t m, uint32_t mask);

#endif /* COAVOID_CORE_PLAN_INTERNAL_H */
