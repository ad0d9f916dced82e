/* SPDX-License-Identifier: MIT */
/*
 * plan_table.c: the exact cost-to-go and cost-from-start of each vehicle alone (plan.h,
 * "Heuristic"), and the plans read off them.
 *
 * A backward pass over the states (k, offset) the vehicle can reach from its initial
 * offset: at k = N every state costs nothing more; at k < N a state's cost to go is the
 * least, lexicographically (deviation, then effort), over its actions that stay within the
 * offset bound, conflict with no obstacle, track or vehicle the table is built against
 * and reach a live state, of the step's cost plus the cost to go from there. A state with
 * no such action is dead, and so is one below the problem's floor (plan.h, "Floor"). The
 * pass visits each reachable state once and each of its five actions once.
 *
 * Conflict tests dominate, so they are filtered twice before the exact test runs: per row
 * and obstacle (or track, or fixed vehicle), by the box that holds every step of the row,
 * and per step, by the step's own box; both widened by SLACK_ULPS so that rounding in the
 * boxes can never skip a step that the exact test would find in conflict. The exact tests
 * themselves say no conflict for boxes that do not touch (geometry.h), so the filters
 * change no decision, only what it costs.
 */
#include "plan_internal.h"

uint64_t coa_plan_table_cells(uint32_t horizon, uint32_t steep, int32_t limit)
{
    return plan_row_base(horizon + 1u, steep, (uint32_t)limit / steep, limit);
}

uint64_t coa_plan_table_row_width(uint32_t horizon, uint32_t steep, int32_t limit)
{
    uint64_t reach = 2u * (uint64_t)horizon * steep + 1u;
    uint64_t bound = 2u * (uint64_t)limit + 1u;
    return reach < bound ? reach : bound;
}

static inline uint64_t *row_of(const plan_table_t *t, uint32_t k)
{
    return &t->cells[plan_row_base(k, t->steep, t->growing, t->limit)];
}

static inline uint64_t *cell_of(const plan_table_t *t, uint32_t k, int32_t offset)
{
    return &row_of(t, k)[offset - plan_row_lo(t, k)];
}

/* ------------------------------------------------------------------------------------ */
/* Conflicts of one row                                                                  */

static coa_real_t box_scale(const coa_box_t *b)
{
    return real_max_abs3(&b->max, real_max_abs3(&b->min, (coa_real_t)0));
}

static coa_box_t box_union(coa_box_t a, const coa_box_t *b)
{
    a.min.x = b->min.x < a.min.x ? b->min.x : a.min.x;
    a.min.y = b->min.y < a.min.y ? b->min.y : a.min.y;
    a.min.z = b->min.z < a.min.z ? b->min.z : a.min.z;
    a.max.x = b->max.x > a.max.x ? b->max.x : a.max.x;
    a.max.y = b->max.y > a.max.y ? b->max.y : a.max.y;
    a.max.z = b->max.z > a.max.z ? b->max.z : a.max.z;
    return a;
}

/* What a row's steps are tested against: one obstacle, or one moving volume. */
typedef struct {
    const coa_obstacle_t *obstacle; /* NULL: `moving` */
    coa_sweep_t moving;
    coa_box_t bounds;
} row_item_t;

typedef struct {
    coa_planner_t *pl;
    const plan_table_t *t;
    uint32_t k;
    int32_t lo;
    int32_t hi;
    uint64_t *row;    /* row k: only the action bits are set while conflicts are cleared */
    coa_box_t bounds; /* every step of the row lies in it */
} row_ctx_t;

/* Work units of one exact test against the item (plan.h, "Work"): a polytope's MPR test
 * evaluates its support function, O(vertices), several times. */
static uint64_t item_weight(const row_item_t *it)
{
    if (it->obstacle != NULL && it->obstacle->kind == COA_OBSTACLE_POLYTOPE) {
        return 1u + it->obstacle->polytope.count / PLAN_WORK_VERTICES;
    }
    return 1u;
}

static bool item_conflict(const row_item_t *it, const coa_sweep_t *s)
{
    if (it->obstacle != NULL) {
        /* The problem check ruled out the polytope test's errors; were one to happen
         * anyway, counting it as a conflict is the safe side. */
        return coa_conflict_obstacle(s, it->obstacle) != 0;
    }
    return coa_conflict_volumes(s, &it->moving);
}

/* The offsets of row k whose steps can reach the (widened) item box vertically. A step
 * from offset o climbs or dives at most s offsets, so its volume stays within o dh plus
 * the lower reference altitude less s dh and the half height, and o dh plus the higher
 * one plus s dh and the half height; offsets whose band misses the box are skipped
 * before their five sweeps are built (on the paper they were most of the table's
 * conflict work). Two offsets of margin on each side cover the rounding of this
 * arithmetic, far below dh; the steps kept still go through the box and exact tests. */
static void row_item_range(const row_ctx_t *r, const coa_box_t *item, int32_t *lo, int32_t *hi)
{
    const coa_problem_t *pr = r->pl->problem;
    const size_t v = r->t->vehicle;
    const coa_real_t dh = r->pl->dh[v];
    const coa_real_t z0 = pr->references[v][r->k].z;
    const coa_real_t z1 = pr->references[v][r->k + 1u].z;
    const coa_real_t reach = (coa_real_t)r->t->steep * dh + pr->vehicles[v].volume.half_height;
    coa_real_t below = (item->min.z - reach - (z0 > z1 ? z0 : z1)) / dh - (coa_real_t)2;
    coa_real_t above = (item->max.z + reach - (z0 < z1 ? z0 : z1)) / dh + (coa_real_t)2;

    *lo = r->lo;
    *hi = r->hi;
    /* Comparisons first, so that only values within the row are converted (and NaN,
     * which no comparison passes, restricts nothing). */
    if (below > (coa_real_t)r->hi || above < (coa_real_t)r->lo) {
        *hi = *lo - 1;
        return;
    }
    if (below > (coa_real_t)r->lo) {
        *lo = (int32_t)below; /* truncation moves it down, or up by less than the margin */
    }
    if (above < (coa_real_t)r->hi) {
        *hi = (int32_t)above;
    }
}

/* Clears, in row k, the actions whose step conflicts with the item. False: the work
 * budget ran out first (the row is then unfinished). */
static bool row_clear_item(const row_ctx_t *r, const row_item_t *it)
{
    coa_planner_t *pl = r->pl;
    const plan_table_t *t = r->t;
    coa_real_t slack =
        (box_scale(&r->bounds) + box_scale(&it->bounds)) * (coa_real_t)(SLACK_ULPS * REAL_EPSILON);
    coa_box_t item = box_widened(it->bounds, slack);
    int32_t o;

    int32_t lo;
    int32_t hi;

    if (!coa_boxes_touch(&r->bounds, &item)) {
        return true;
    }
    row_item_range(r, &item, &lo, &hi);
    if (hi >= lo && !plan_work(pl, (uint64_t)(hi - lo + 1) * PLAN_ACTIONS * item_weight(it))) {
        return false;
    }
    for (o = lo; o <= hi; ++o) {
        uint64_t *c = &r->row[o - r->lo];
        uint32_t a;
        for (a = 0; a < PLAN_ACTIONS; ++a) {
            coa_sweep_t s;
            coa_box_t sb;
            if ((*c & (UINT64_C(1) << a)) == 0u) {
                continue;
            }
            s = coa_plan_vehicle_sweep(pl->problem, pl->dh, t->vehicle, r->k, o, r->k + 1u,
                                       o + coa_action_delta((coa_action_t)a, t->steep));
            sb = coa_sweep_bounds(&s);
            if (coa_boxes_touch(&sb, &item) && item_conflict(it, &s)) {
                *c &= ~(UINT64_C(1) << a);
            }
        }
    }
    return true;
}

/* Clears, in row k, every action whose step conflicts with an obstacle, a track or a
 * fixed vehicle. False: the work budget ran out first. */
static bool row_clear_conflicts(const row_ctx_t *r, const size_t *fixed, size_t nfixed)
{
    const coa_problem_t *pr = r->pl->problem;
    row_item_t it;
    size_t j;
    bool ok = true;

    for (j = 0; ok && j < pr->obstacle_count; ++j) {
        it.obstacle = &pr->obstacles[j];
        it.bounds = coa_obstacle_bounds(it.obstacle);
        ok = row_clear_item(r, &it);
    }
    it.obstacle = NULL;
    for (j = 0; ok && j < pr->track_count; ++j) {
        it.moving.volume = pr->tracks[j].volume;
        it.moving.p0 = pr->track_samples[j][r->k];
        it.moving.p1 = pr->track_samples[j][r->k + 1u];
        it.bounds = coa_sweep_bounds(&it.moving);
        ok = row_clear_item(r, &it);
    }
    for (j = 0; ok && j < nfixed; ++j) {
        const int32_t *row = &r->pl->rows[fixed[j] * ((size_t)pr->horizon + 1u)];
        it.moving = coa_plan_vehicle_sweep(pr, r->pl->dh, fixed[j], r->k, row[r->k], r->k + 1u,
                                           row[r->k + 1u]);
        it.bounds = coa_sweep_bounds(&it.moving);
        ok = row_clear_item(r, &it);
    }
    return ok;
}

/* ------------------------------------------------------------------------------------ */
/* The backward pass                                                                     */

static uint64_t cell_pack(uint64_t dev, uint32_t eff, uint32_t mask)
{
    return (dev << CELL_DEV_SHIFT) | ((uint64_t)eff << CELL_EFF_SHIFT) | mask;
}

/* Row k's actions that stay within the bound and reach a live state of row k + 1. */
static void row_moves(const plan_table_t *t, uint32_t k, int32_t lo, int32_t hi, uint64_t *row)
{
    int32_t o;
    for (o = lo; o <= hi; ++o) {
        uint32_t mask = 0u;
        uint32_t a;
        for (a = 0; a < PLAN_ACTIONS; ++a) {
            int32_t b = o + coa_action_delta((coa_action_t)a, t->steep);
            /* b is within row k + 1 whenever |b| <= L: rows widen by s a step. */
            if (b >= -t->limit && b <= t->limit && !cell_dead(*cell_of(t, k + 1u, b))) {
                mask |= 1u << a;
            }
        }
        row[o - lo] = mask;
    }
}

/* Row k's costs to go from its remaining actions. */
static void row_costs(const plan_table_t *t, uint32_t k, int32_t lo, int32_t hi, uint64_t *row)
{
    int32_t o;
    for (o = lo; o <= hi; ++o) {
        uint32_t mask = cell_mask(row[o - lo]);
        uint64_t best = UINT64_MAX;
        uint32_t a;
        for (a = 0; a < PLAN_ACTIONS; ++a) {
            if ((mask & (1u << a)) != 0u) {
                int32_t b = o + coa_action_delta((coa_action_t)a, t->steep);
                uint64_t next = *cell_of(t, k + 1u, b);
                /* Own units: an area times 2s is an integer (trajectory.h). */
                uint64_t dev = cell_dev(next) + plan_area(o, b, t->steep);
                uint64_t eff = cell_eff(next) + coa_action_effort((coa_action_t)a);
                uint64_t cost = (dev << (CELL_DEV_SHIFT - CELL_EFF_SHIFT)) | eff;
                best = cost < best ? cost : best;
            }
        }
        row[o - lo] =
            mask == 0u ? cell_pack(CELL_DEV_DEAD, 0u, 0u) : (best << CELL_EFF_SHIFT) | mask;
    }
}

/* The box that holds every step of row k: its lowest and highest steps span it. */
static coa_box_t row_bounds(const coa_planner_t *pl, const plan_table_t *t, uint32_t k)
{
    coa_sweep_t low = coa_plan_vehicle_sweep(pl->problem, pl->dh, t->vehicle, k, plan_row_lo(t, k),
                                             k + 1u, plan_row_lo(t, k + 1u));
    coa_sweep_t high = coa_plan_vehicle_sweep(pl->problem, pl->dh, t->vehicle, k, plan_row_hi(t, k),
                                              k + 1u, plan_row_hi(t, k + 1u));
    coa_box_t b = coa_sweep_bounds(&low);
    coa_box_t h = coa_sweep_bounds(&high);
    return box_union(b, &h);
}

/* Kills the states of row k whose volume reaches below the problem's floor (plan.h,
 * "Floor"): a prefix of the row, since the altitude grows with the offset. The states the
 * row before leads to are then dead, as beyond an obstacle. O(row) at most. */
static void row_floor(const coa_planner_t *pl, const plan_table_t *t, uint32_t k)
{
    const coa_problem_t *pr = pl->problem;
    int32_t o;
    if (!pr->has_floor) {
        return;
    }
    for (o = plan_row_lo(t, k); o <= plan_row_hi(t, k); ++o) {
        coa_sweep_t s = coa_plan_vehicle_sweep(pr, pl->dh, t->vehicle, k, o, k, o);
        if (coa_above_floor(pr->floor_z, &s.volume, s.p0.z)) {
            return;
        }
        *cell_of(t, k, o) = CELL_DEAD;
    }
}

void coa_plan_table_build(coa_planner_t *pl, plan_table_t *tb, size_t v, const size_t *fixed,
                          size_t nfixed)
{
    const coa_vehicle_t *veh = &pl->problem->vehicles[v];
    const uint32_t horizon = pl->problem->horizon;
    uint32_t k;
    int32_t o;

    tb->vehicle = v;
    tb->origin = veh->initial_offset;
    tb->limit = pl->limit[v];
    tb->steep = veh->steep_factor;
    tb->growing = (uint32_t)tb->limit / tb->steep;
    tb->horizon = horizon;
    coa_plan_touch_table(pl, tb);
    for (o = plan_row_lo(tb, horizon); o <= plan_row_hi(tb, horizon); ++o) {
        *cell_of(tb, horizon, o) = cell_pack(0u, 0u, 0u);
    }
    row_floor(pl, tb, horizon);
    for (k = horizon; k-- > 0u;) {
        row_ctx_t r;
        r.pl = pl;
        r.t = tb;
        r.k = k;
        r.lo = plan_row_lo(tb, k);
        r.hi = plan_row_hi(tb, k);
        r.row = row_of(tb, k);
        r.bounds = row_bounds(pl, tb, k);
        if (!plan_work(pl, (uint64_t)(r.hi - r.lo + 1) * PLAN_ACTIONS)) {
            return;
        }
        row_moves(tb, k, r.lo, r.hi, r.row);
        if (!row_clear_conflicts(&r, fixed, nfixed)) {
            return;
        }
        row_costs(tb, k, r.lo, r.hi, r.row);
        row_floor(pl, tb, k);
    }
}

/* ------------------------------------------------------------------------------------ */
/* Moves in search order                                                                 */

void coa_plan_table_moves(const plan_table_t *t, uint32_t k, int32_t from, plan_moves_t *mv)
{
    const uint64_t here = *cell_of(t, k, from);
    const uint32_t mask = cell_mask(here);
    uint32_t a;

    mv->count = 0u;
    for (a = 0; a < PLAN_ACTIONS; ++a) {
        int32_t b;
        uint64_t next;
        uint32_t i;
        uint64_t dev;
        int32_t eff;
        if ((mask & (1u << a)) == 0u) {
            continue;
        }
        b = from + coa_action_delta((coa_action_t)a, t->steep);
        next = *cell_of(t, k + 1u, b);
        /* The table's minimum makes both increases lexicographically >= 0. */
        dev = cell_dev(next) + plan_area(from, b, t->steep) - cell_dev(here);
        eff = (int32_t)(cell_eff(next) + coa_action_effort((coa_action_t)a)) -
              (int32_t)cell_eff(here);
        /* Insertion: stable for equal increases, so ties keep coa_action_t order. */
        for (i = mv->count;
             i > 0u && (mv->dev[i - 1u] > dev || (mv->dev[i - 1u] == dev && mv->eff[i - 1u] > eff));
             --i) {
            mv->action[i] = mv->action[i - 1u];
            mv->to[i] = mv->to[i - 1u];
            mv->dev[i] = mv->dev[i - 1u];
            mv->eff[i] = mv->eff[i - 1u];
        }
        mv->action[i] = (uint8_t)a;
        mv->to[i] = b;
        mv->dev[i] = dev;
        mv->eff[i] = eff;
        ++mv->count;
    }
}

/* ------------------------------------------------------------------------------------ */
/* Cost from the start, and plans                                                        */

void coa_plan_table_build_from_start(coa_planner_t *pl, plan_table_t *f, const plan_table_t *t)
{
    uint32_t k;
    int32_t o;

    f->vehicle = t->vehicle;
    f->origin = t->origin;
    f->limit = t->limit;
    f->steep = t->steep;
    f->growing = t->growing;
    f->horizon = t->horizon;
    coa_plan_touch_table(pl, f);
    for (k = 0; k <= t->horizon; ++k) {
        for (o = plan_row_lo(t, k); o <= plan_row_hi(t, k); ++o) {
            *cell_of(f, k, o) = CELL_DEAD;
        }
    }
    *cell_of(f, 0u, t->origin) = cell_pack(0u, 0u, 0u);
    for (k = 0; k < t->horizon; ++k) {
        if (!plan_work(pl, (uint64_t)(plan_row_hi(t, k) - plan_row_lo(t, k) + 1) * PLAN_ACTIONS)) {
            return;
        }
        for (o = plan_row_lo(t, k); o <= plan_row_hi(t, k); ++o) {
            uint64_t here = *cell_of(f, k, o);
            uint32_t mask = cell_mask(*cell_of(t, k, o));
            uint32_t a;
            if (cell_dead(here)) {
                continue;
            }
            for (a = 0; a < PLAN_ACTIONS; ++a) {
                int32_t b;
                uint64_t cand;
                uint64_t *there;
                if ((mask & (1u << a)) == 0u) {
                    continue;
                }
                b = o + coa_action_delta((coa_action_t)a, t->steep);
                cand = cell_pack(cell_dev(here) + plan_area(o, b, t->steep),
                                 cell_eff(here) + coa_action_effort((coa_action_t)a), 0u);
                there = cell_of(f, k + 1u, b);
                if (cand < *there) {
                    *there = cand;
                }
            }
        }
    }
}

void coa_plan_table_walk(coa_planner_t *pl, const plan_table_t *t, uint32_t k, int32_t offset)
{
    int32_t *row = &pl->rows[t->vehicle * ((size_t)t->horizon + 1u)];
    row[k] = offset;
    for (; k < t->horizon; ++k) {
        plan_moves_t mv;
        coa_plan_table_moves(t, k, offset, &mv);
        offset = mv.to[0];
        row[k + 1u] = offset;
    }
}

void coa_plan_table_walk_back(coa_planner_t *pl, const plan_table_t *t, const plan_table_t *f,
                              uint32_t k, int32_t offset)
{
    int32_t *row = &pl->rows[t->vehicle * ((size_t)t->horizon + 1u)];

    row[k] = offset;
    /* Each step back, the first predecessor (in coa_action_t order of the step that
     * leaves it) on a cheapest path: the one whose cost plus the step's is this cost. */
    for (; k > 0u; --k) {
        uint64_t here = *cell_of(f, k, offset);
        uint32_t a;
        for (a = 0; a < PLAN_ACTIONS; ++a) {
            int32_t from = offset - coa_action_delta((coa_action_t)a, t->steep);
            uint64_t prev;
            if (from < plan_row_lo(t, k - 1u) || from > plan_row_hi(t, k - 1u) ||
                (cell_mask(*cell_of(t, k - 1u, from)) & (1u << a)) == 0u) {
                continue;
            }
            prev = *cell_of(f, k - 1u, from);
            if (!cell_dead(prev) &&
                cell_pack(cell_dev(prev) + plan_area(from, offset, t->steep),
                          cell_eff(prev) + coa_action_effort((coa_action_t)a), 0u) == here) {
                offset = from;
                break;
            }
        }
        row[k - 1u] = offset;
    }
}
