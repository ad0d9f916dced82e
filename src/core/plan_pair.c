/* SPDX-License-Identifier: MIT */
/*
 * plan_pair.c: the exact joint cost-to-go of pairs of group members over their encounter
 * (plan.h, "Heuristic").
 *
 * Members a and b can only meet at the steps near_first..near_last of the group's pair
 * table; after the last of them their joint cost-to-go is the sum of their own. Before
 * it, a backward pass over the pair's states (k, offset of a, offset of b), from the last
 * step they can meet back to the first sample both are in the search, takes the least
 * cost over both members' moves (each valid for its own table) that do not conflict with
 * each other. The difference between that and the sum of their own costs to go is the
 * pair's surcharge: what avoiding each other costs them at least.
 *
 * Only offsets within the group's corridor are kept when a plan of the group is known
 * (its cost, the cap): the plans worth finding cost at most the cap, and every offset a
 * member takes on such a plan has a cheapest plan through it (cost from the start plus
 * cost to go) within the cap's slack over its cost alone; a pair's two slacks within it
 * together. Pair states outside the corridor are dead for the search, which drops them.
 */
#include "plan_internal.h"

/* The slack of member i's offset o at sample k: its cheapest cost through (k, o) less its
 * cost alone, packed; PLAN_COST_DEAD when no plan goes through it. */
static coa_cost_t slack_of(const coa_planner_t *pl, size_t i, uint32_t k, int32_t o)
{
    const plan_group_t *g = &pl->group;
    size_t v = g->vehicle[i];
    uint64_t from = plan_table_at(plan_from_start(pl, i), k, o);
    uint64_t to = plan_table_at(plan_to_go(pl, i), k, o);
    if (cell_dead(from) || cell_dead(to)) {
        return PLAN_COST_DEAD;
    }
    return plan_cost_sub(plan_cost_add(plan_cell_cost(pl, v, from), plan_cell_cost(pl, v, to)),
                         g->alone[i]);
}

/* The group's slack: the cap less the sum of the members' costs alone. */
static coa_cost_t group_slack(const plan_group_t *g)
{
    coa_cost_t sum = {0u, 0u};
    size_t i;
    for (i = 0; i < g->count; ++i) {
        sum = plan_cost_add(sum, g->alone[i]);
    }
    return plan_cost_sub(g->cap, sum);
}

/* Member i's corridor at sample k: the smallest range holding every offset whose slack
 * is within `slack` (all live offsets when uncapped). Empty: lo > hi. */
static void corridor(const coa_planner_t *pl, size_t i, uint32_t k, const coa_cost_t *slack,
                     int16_t *lo, int16_t *hi)
{
    const plan_table_t *t = plan_to_go(pl, i);
    int32_t o;
    *lo = INT16_MAX;
    *hi = INT16_MIN;
    for (o = plan_row_lo(t, k); o <= plan_row_hi(t, k); ++o) {
        coa_cost_t s = slack_of(pl, i, k, o);
        if (plan_cost_dead(s) || (slack != NULL && plan_cost_compare(s, *slack) > 0)) {
            continue;
        }
        *lo = (int16_t)(o < *lo ? o : *lo);
        *hi = (int16_t)(o > *hi ? o : *hi);
    }
}

static size_t width(int16_t lo, int16_t hi)
{
    return lo > hi ? 0u : (size_t)(hi - lo) + 1u;
}

/* Carves `bytes` from the arena (whole cells); NULL when it is full. */
static void *arena_take(coa_planner_t *pl, size_t bytes)
{
    size_t cells = (bytes + sizeof(coa_cost_t) - 1u) / sizeof(coa_cost_t);
    void *p;
    if (cells > pl->pair_cells - pl->pair_used) {
        return NULL;
    }
    p = &pl->pair_arena[pl->pair_used];
    pl->pair_used += cells;
    return p;
}

/* Lays out pair p's rows first..last; false when the arena cannot hold it. */
static bool pair_layout(coa_planner_t *pl, plan_pair_t *p, size_t a, size_t b,
                        const coa_cost_t *slack)
{
    const size_t rows = (size_t)(p->last - p->first) + 1u;
    size_t cells = 0u;
    size_t r;
    size_t mark = pl->pair_used;

    p->row_lo = arena_take(pl, rows * 4u * sizeof(int16_t));
    p->row_base = arena_take(pl, rows * sizeof(uint32_t));
    if (p->row_lo == NULL || p->row_base == NULL) {
        pl->pair_used = mark;
        return false;
    }
    for (r = 0; r < rows; ++r) {
        int16_t *c = &p->row_lo[4u * r];
        uint32_t k = p->first + (uint32_t)r;
        corridor(pl, a, k, slack, &c[0], &c[1]);
        corridor(pl, b, k, slack, &c[2], &c[3]);
        if (cells > UINT32_MAX) {
            pl->pair_used = mark;
            return false;
        }
        p->row_base[r] = (uint32_t)cells;
        cells += width(c[0], c[1]) * width(c[2], c[3]);
    }
    if (cells > pl->pair_cells || (p->cells = arena_take(pl, cells * sizeof(coa_cost_t))) == NULL) {
        pl->pair_used = mark;
        return false;
    }
    return true;
}

/* One row of a pair as its cells are read: NULL cells when the row is not the pair's. */
typedef struct {
    coa_cost_t *cells;
    int16_t a_lo, a_hi, b_lo, b_hi; /* the row's corridor */
    size_t b_width;
} pair_view_t;

static pair_view_t pair_view(const plan_pair_t *p, uint32_t k)
{
    pair_view_t v = {NULL, 0, -1, 0, -1, 0u};
    if (k >= p->first && k <= p->last) {
        const size_t r = (size_t)(k - p->first);
        const int16_t *c = &p->row_lo[4u * r];
        v.cells = &p->cells[p->row_base[r]];
        v.a_lo = c[0];
        v.a_hi = c[1];
        v.b_lo = c[2];
        v.b_hi = c[3];
        v.b_width = width(c[2], c[3]);
    }
    return v;
}

/* The view's cell of (oa, ob): NULL outside the row or its corridor. */
static coa_cost_t *pair_view_cell(const pair_view_t *v, int32_t oa, int32_t ob)
{
    if (v->cells == NULL || oa < v->a_lo || oa > v->a_hi || ob < v->b_lo || ob > v->b_hi) {
        return NULL;
    }
    return &v->cells[(size_t)(oa - v->a_lo) * v->b_width + (size_t)(ob - v->b_lo)];
}

/* The pair's cell at (k, oa, ob): NULL outside its rows or corridor. */
static coa_cost_t *pair_cell(const plan_pair_t *p, uint32_t k, int32_t oa, int32_t ob)
{
    const pair_view_t v = pair_view(p, k);
    return pair_view_cell(&v, oa, ob);
}

/* One member's moves out of (k, o) as packed step costs and targets, cheapest first by
 * `alone`: the step plus the member's own cost to go after it, a lower bound of what the
 * move costs the pair (a pair's cost to go is at least the sum of its members' own). */
typedef struct {
    uint32_t count;
    int32_t to[PLAN_ACTIONS];
    coa_cost_t step[PLAN_ACTIONS];
    coa_cost_t alone[PLAN_ACTIONS];
    coa_sweep_t sweep[PLAN_ACTIONS];
} pair_moves_t;

/* Inserts move n (the last) in `alone` order; ties keep action order. */
static void pair_moves_sort(pair_moves_t *mv, uint32_t n)
{
    while (n > 0u && plan_cost_compare(mv->alone[n], mv->alone[n - 1u]) < 0) {
        int32_t to = mv->to[n];
        coa_cost_t step = mv->step[n];
        coa_cost_t alone = mv->alone[n];
        coa_sweep_t sweep = mv->sweep[n];
        mv->to[n] = mv->to[n - 1u];
        mv->step[n] = mv->step[n - 1u];
        mv->alone[n] = mv->alone[n - 1u];
        mv->sweep[n] = mv->sweep[n - 1u];
        mv->to[n - 1u] = to;
        mv->step[n - 1u] = step;
        mv->alone[n - 1u] = alone;
        mv->sweep[n - 1u] = sweep;
        --n;
    }
}

static void pair_moves(const coa_planner_t *pl, size_t i, uint32_t k, int32_t o, bool sweeps,
                       pair_moves_t *mv)
{
    const plan_table_t *t = plan_to_go(pl, i);
    const size_t v = pl->group.vehicle[i];
    uint32_t mask = cell_mask(plan_table_at(t, k, o));
    uint32_t a;
    mv->count = 0u;
    for (a = 0; a < PLAN_ACTIONS; ++a) {
        const uint32_t n = mv->count;
        int32_t to;
        if ((mask & (1u << a)) == 0u) {
            continue;
        }
        to = o + coa_action_delta((coa_action_t)a, t->steep);
        mv->to[n] = to;
        mv->step[n] = plan_pack(plan_units(pl, v, plan_area(o, to, t->steep)),
                                coa_action_effort((coa_action_t)a));
        mv->alone[n] =
            plan_cost_add(mv->step[n], plan_cell_cost(pl, v, plan_table_at(t, k + 1u, to)));
        if (sweeps) {
            mv->sweep[n] = coa_plan_vehicle_sweep(pl->problem, pl->dh, v, k, o, k + 1u, to);
        }
        pair_moves_sort(mv, n);
        ++mv->count;
    }
}

/* Row k + 1 of a pair, as pair_value reads it for every combination of moves: no cells
 * past the pair's last row, where the pair's cost to go is the sum of its members' own (so
 * a combination costs exactly its two moves' `alone`). */
static pair_view_t pair_next_row(const plan_pair_t *p, uint32_t k)
{
    pair_view_t none = {NULL, 0, -1, 0, -1, 0u};
    return k < p->last ? pair_view(p, k + 1u) : none;
}

/* What moves x of a and y of b cost the pair from (k, ., .) on, conflicts aside. */
static coa_cost_t pair_next(const pair_view_t *n, const pair_moves_t *ma, uint32_t x,
                            const pair_moves_t *mb, uint32_t y)
{
    const coa_cost_t *c;
    if (n->cells == NULL) {
        return plan_cost_add(ma->alone[x], mb->alone[y]);
    }
    c = pair_view_cell(n, ma->to[x], mb->to[y]);
    if (c == NULL || plan_cost_dead(*c)) {
        return PLAN_COST_DEAD;
    }
    return plan_cost_add(*c, plan_cost_add(ma->step[x], mb->step[y]));
}

/* The pair's cell at (k, oa, ob) from the cells of row k + 1, given both members' moves
 * out of it. */
static coa_cost_t pair_value(const pair_view_t *next, const pair_moves_t *ma,
                             const pair_moves_t *mb, const coa_span_t *near)
{
    coa_cost_t best = PLAN_COST_DEAD;
    uint32_t x;
    uint32_t y;

    /* Moves come cheapest alone first and a combination costs at least the sum of its
     * two `alone`, so the loops stop once that sum cannot beat the best found: at once
     * where the members cannot meet (the first combination costs just that). */
    for (x = 0; x < ma->count; ++x) {
        if (mb->count == 0u ||
            plan_cost_compare(plan_cost_add(ma->alone[x], mb->alone[0]), best) >= 0) {
            break;
        }
        for (y = 0; y < mb->count; ++y) {
            coa_cost_t c;
            if (plan_cost_compare(plan_cost_add(ma->alone[x], mb->alone[y]), best) >= 0) {
                break;
            }
            c = pair_next(next, ma, x, mb, y);
            if (plan_cost_dead(c) || plan_cost_compare(c, best) >= 0) {
                continue;
            }
            if (near != NULL && coa_conflict_volumes_given(&ma->sweep[x], &mb->sweep[y], *near)) {
                continue;
            }
            best = c;
        }
    }
    return best;
}

/* Offsets of b whose moves (and sweeps) are built once per row rather than once per cell:
 * the sweeps were a fifth of the paper's planning time. A block, not the whole row, keeps
 * the stack bounded (a few KiB on the firmware's 8 KiB); a's moves are built once per
 * block. */
#define PAIR_BLOCK 8

/* A member's slack at (k, o) and, when live, its moves out of it. */
static coa_cost_t pair_side(const coa_planner_t *pl, size_t i, uint32_t k, int32_t o, bool near,
                            pair_moves_t *mv)
{
    coa_cost_t s = slack_of(pl, i, k, o);
    mv->count = 0u;
    if (!plan_cost_dead(s)) {
        pair_moves(pl, i, k, o, near, mv);
    }
    return s;
}

/* Whether a pair state whose members have these slacks can be on a plan within the cap. */
static bool pair_live(coa_cost_t sa, coa_cost_t sb, const coa_cost_t *slack)
{
    return !plan_cost_dead(sa) && !plan_cost_dead(sb) &&
           (slack == NULL || plan_cost_compare(plan_cost_add(sa, sb), *slack) <= 0);
}

/* Whether a and b can meet at step k: one of the steps they can meet at (near_first..
 * near_last), with horizontal paths that come close within it. Every pair of their sweeps
 * at k has the same horizontal paths (offsets move them vertically only), so the
 * horizontal half of the conflict test is computed here once for the row. */
static bool pair_near(const coa_planner_t *pl, size_t a, size_t b, uint32_t k,
                      coa_span_t *horizontal)
{
    const size_t pi = plan_pair_index(a, b, pl->group.count);
    coa_sweep_t sa;
    coa_sweep_t sb;
    if (k < pl->group.near_first[pi] || k > pl->group.near_last[pi]) {
        return false;
    }
    sa = coa_plan_vehicle_sweep(pl->problem, pl->dh, pl->group.vehicle[a], k, 0, k + 1u, 0);
    sb = coa_plan_vehicle_sweep(pl->problem, pl->dh, pl->group.vehicle[b], k, 0, k + 1u, 0);
    *horizontal = coa_conflict_horizontal_span(&sa, &sb);
    return coa_conflict_span_in_step(*horizontal);
}

/* Fills row k of pair p. */
static void pair_row(coa_planner_t *pl, plan_pair_t *p, size_t a, size_t b, uint32_t k,
                     const coa_cost_t *slack)
{
    const int16_t *c = &p->row_lo[4u * (size_t)(k - p->first)];
    const pair_view_t next = pair_next_row(p, k);
    coa_span_t horizontal;
    const bool near = pair_near(pl, a, b, k, &horizontal);
    pair_moves_t mb[PAIR_BLOCK];
    coa_cost_t sb[PAIR_BLOCK];
    int32_t ob0;

    for (ob0 = c[2]; ob0 <= c[3]; ob0 += PAIR_BLOCK) {
        const int32_t n = c[3] - ob0 + 1 < PAIR_BLOCK ? c[3] - ob0 + 1 : PAIR_BLOCK;
        int32_t oa;
        int32_t j;
        for (j = 0; j < n; ++j) {
            sb[j] = pair_side(pl, b, k, ob0 + j, near, &mb[j]);
        }
        for (oa = c[0]; oa <= c[1]; ++oa) {
            pair_moves_t ma;
            coa_cost_t sa = pair_side(pl, a, k, oa, near, &ma);
            coa_cost_t *cell = pair_cell(p, k, oa, ob0);
            for (j = 0; j < n; ++j) {
                cell[j] = pair_live(sa, sb[j], slack)
                              ? pair_value(&next, &ma, &mb[j], near ? &horizontal : NULL)
                              : PLAN_COST_DEAD;
            }
        }
    }
}

/* Pair (a, b): rows from the first sample both are in the search to the last step they
 * can meet. */
static void pair_build(coa_planner_t *pl, size_t a, size_t b, const coa_cost_t *slack)
{
    const plan_group_t *g = &pl->group;
    const size_t pi = plan_pair_index(a, b, g->count);
    plan_pair_t *p = &pl->pair[pi];
    uint32_t k;

    p->present = false;
    if (g->near_first[pi] > g->near_last[pi]) {
        return;
    }
    p->first = g->first[a] > g->first[b] ? g->first[a] : g->first[b];
    p->last = g->near_last[pi];
    if (!pair_layout(pl, p, a, b, slack)) {
        return;
    }
    for (k = p->last + 1u; k-- > p->first;) {
        const int16_t *c = &p->row_lo[4u * (size_t)(k - p->first)];
        if (!plan_work(pl, width(c[0], c[1]) * width(c[2], c[3]))) {
            return; /* out of work: the search that follows stops at once */
        }
        pair_row(pl, p, a, b, k, slack);
    }
    p->present = true;
}

void coa_plan_pairs_build(coa_planner_t *pl)
{
    const plan_group_t *g = &pl->group;
    coa_cost_t slack;
    size_t a;
    size_t b;

    pl->pair_used = 0u;
    if (g->capped) {
        slack = group_slack(g);
    }
    for (a = 0; a < g->count; ++a) {
        for (b = a + 1u; b < g->count; ++b) {
            pair_build(pl, a, b, g->capped ? &slack : NULL);
        }
    }
    if (pl->pair_used > pl->touched_pair_cells) {
        pl->touched_pair_cells = pl->pair_used;
    }
    coa_plan_sides_choose(pl);
}

coa_cost_t coa_plan_pair_weight(const coa_planner_t *pl, size_t a, size_t b)
{
    const plan_group_t *g = &pl->group;
    const plan_pair_t *p = &pl->pair[plan_pair_index(a, b, g->count)];
    const coa_cost_t alone = plan_cost_add(g->alone[a], g->alone[b]);
    coa_cost_t best = {0u, 0u};
    bool any = false;
    pair_view_t v;
    int32_t oa;
    int32_t ob;

    if (!p->present) {
        return best;
    }
    v = pair_view(p, p->first);
    for (oa = v.a_lo; oa <= v.a_hi; ++oa) {
        uint64_t fa = plan_table_at(plan_from_start(pl, a), p->first, oa);
        for (ob = v.b_lo; ob <= v.b_hi && !cell_dead(fa); ++ob) {
            uint64_t fb = plan_table_at(plan_from_start(pl, b), p->first, ob);
            const coa_cost_t *c = pair_view_cell(&v, oa, ob);
            coa_cost_t w;
            if (cell_dead(fb) || c == NULL || plan_cost_dead(*c)) {
                continue;
            }
            w = plan_cost_add(plan_cost_add(plan_cell_cost(pl, g->vehicle[a], fa),
                                            plan_cell_cost(pl, g->vehicle[b], fb)),
                              *c);
            if (!any || plan_cost_compare(w, best) < 0) {
                best = w;
                any = true;
            }
        }
    }
    return any && plan_cost_compare(best, alone) > 0 ? plan_cost_sub(best, alone)
                                                     : (coa_cost_t){0u, 0u};
}

coa_cost_t coa_plan_pair_surcharge(const coa_planner_t *pl, size_t a, size_t b, uint32_t k,
                                   int32_t oa, int32_t ob, coa_cost_t to_go_a, coa_cost_t to_go_b)
{
    const plan_pair_t *p = &pl->pair[plan_pair_index(a, b, pl->group.count)];
    const coa_cost_t *c;
    coa_cost_t zero = {0u, 0u};
    if (!p->present || k < p->first || k > p->last) {
        return zero;
    }
    c = pair_cell(p, k, oa, ob);
    if (c == NULL || plan_cost_dead(*c)) {
        return PLAN_COST_DEAD;
    }
    return plan_cost_sub(*c, plan_cost_add(to_go_a, to_go_b));
}
