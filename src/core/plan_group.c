/* SPDX-License-Identifier: MIT */
#define _POSIX_C_SOURCE 200809L
/*
 * plan_group.c: the centralised front end's independence detection (plan.h, "Centralised")
 * and the set-up of each joint search (plan.h, "The joint search").
 *
 * Independence detection (Standley 2010). Every vehicle is first planned alone, off its
 * table. While the rows of two groups conflict, one group is re-planned around the other's
 * rows at exactly its own cost, then the other around the first, once per pair of groups;
 * if neither can, the two merge and are searched jointly. Each group's rows stay optimal
 * for the group alone and no two groups conflict at the end, so the sum of the groups'
 * costs is a lower bound that the plan meets.
 *
 * A joint search knows, for each pair of members (and each member and fixed vehicle), the
 * steps where they can meet at all: those where their horizontal discs come within reach
 * of each other, whatever their altitudes (coa_conflict_horizontal on the references).
 * A member is in the search only from the first to the last of its steps with anyone;
 * elsewhere it cannot conflict with them, so it flies its own cheapest way. Before the
 * search, the members are planned one after the other (each against those before it, as
 * the decoupled front end does): a plan of the group, whose cost caps the search (nothing
 * dearer is stored) and whose slack bounds the pair tables' corridors; when it costs no
 * more than the members alone, it is optimal and no search runs.
 */
#include "plan_internal.h"

#include <math.h>

/* ------------------------------------------------------------------------------------ */
/* Costs                                                                                 */

static coa_cost_t rows_cost(const coa_planner_t *pl, uint32_t members)
{
    return coa_plan_rows_cost(pl, pl->rows, members);
}

/* ------------------------------------------------------------------------------------ */
/* Where vehicles can meet                                                               */

/* The steps where vehicles u and v can meet at all, into near[u][v]: first > last when
 * never. The references alone decide it (offsets only move a vehicle vertically). */
static void near_steps(coa_planner_t *pl, size_t u, size_t v, uint32_t *first, uint32_t *last)
{
    const coa_problem_t *pr = pl->problem;
    uint32_t k;
    *first = UINT32_MAX;
    *last = 0u;
    for (k = 0; k < pr->horizon; ++k) {
        coa_sweep_t a = coa_plan_vehicle_sweep(pr, pl->dh, u, k, 0, k + 1u, 0);
        coa_sweep_t b = coa_plan_vehicle_sweep(pr, pl->dh, v, k, 0, k + 1u, 0);
        if (coa_conflict_horizontal(&a, &b)) {
            *first = k < *first ? k : *first;
            *last = k;
        }
    }
}

static void near_all(coa_planner_t *pl)
{
    const size_t n = pl->problem->vehicle_count;
    size_t u;
    size_t v;
    for (u = 0; u < n; ++u) {
        for (v = u + 1u; v < n; ++v) {
            near_steps(pl, u, v, &pl->near_first[u][v], &pl->near_last[u][v]);
            pl->near_first[v][u] = pl->near_first[u][v];
            pl->near_last[v][u] = pl->near_last[u][v];
        }
    }
}

/* ------------------------------------------------------------------------------------ */
/* A joint search's set-up                                                               */

/* Member i's first and last step with another member or a fixed vehicle. */
static void member_span(coa_planner_t *pl, size_t i, uint32_t members, uint32_t fixed)
{
    plan_group_t *g = &pl->group;
    const size_t v = g->vehicle[i];
    uint32_t first = UINT32_MAX;
    uint32_t last = 0u;
    size_t u;
    for (u = 0; u < pl->problem->vehicle_count; ++u) {
        if (u == v || ((members | fixed) & (UINT32_C(1) << u)) == 0u ||
            pl->near_first[v][u] > pl->near_last[v][u]) {
            continue;
        }
        first = pl->near_first[v][u] < first ? pl->near_first[v][u] : first;
        last = pl->near_last[v][u] > last ? pl->near_last[v][u] : last;
    }
    /* A member that meets no one (it cannot be in a merged group, but stay defined) takes
     * part in the first step only. */
    g->first[i] = first == UINT32_MAX ? 0u : first;
    g->last[i] = first == UINT32_MAX ? 0u : last;
}

static void group_spans(coa_planner_t *pl, uint32_t members, uint32_t fixed)
{
    plan_group_t *g = &pl->group;
    size_t i;
    size_t j;
    g->end = 0u;
    for (i = 0; i < g->count; ++i) {
        member_span(pl, i, members, fixed);
        g->end = g->last[i] + 1u > g->end ? g->last[i] + 1u : g->end;
    }
    for (i = 0; i < g->count; ++i) {
        for (j = i + 1u; j < g->count; ++j) {
            size_t pi = plan_pair_index(i, j, g->count);
            g->near_first[pi] = pl->near_first[g->vehicle[i]][g->vehicle[j]];
            g->near_last[pi] = pl->near_last[g->vehicle[i]][g->vehicle[j]];
        }
    }
}

/* The slack of member i's offset o at its entry sample (see plan_pair.c's slack_of). */
static coa_cost_t entry_slack(const coa_planner_t *pl, size_t i, int32_t o)
{
    const plan_group_t *g = &pl->group;
    uint32_t k = g->first[i];
    uint64_t from = plan_table_at(plan_from_start(pl, i), k, o);
    uint64_t to = plan_table_at(plan_to_go(pl, i), k, o);
    coa_cost_t sum;
    if (cell_dead(from) || cell_dead(to)) {
        return PLAN_COST_DEAD;
    }
    sum = plan_cost_add(plan_cell_cost(pl, g->vehicle[i], from),
                        plan_cell_cost(pl, g->vehicle[i], to));
    return plan_cost_sub(sum, g->alone[i]);
}

static bool entry_before(const coa_planner_t *pl, size_t i, int16_t a, int16_t b)
{
    int c = plan_cost_compare(entry_slack(pl, i, a), entry_slack(pl, i, b));
    return c < 0 || (c == 0 && a < b);
}

/* Moves e[root] down the max-heap e[0..n-1] (ordered by entry_before) to its place. */
static void entries_sift(const coa_planner_t *pl, size_t i, int16_t *e, size_t root, size_t n)
{
    while (2u * root + 1u < n) {
        size_t child = 2u * root + 1u;
        int16_t t;
        if (child + 1u < n && entry_before(pl, i, e[child], e[child + 1u])) {
            ++child;
        }
        if (!entry_before(pl, i, e[root], e[child])) {
            break;
        }
        t = e[root];
        e[root] = e[child];
        e[child] = t;
        root = child;
    }
}

/* Heapsort of member i's entry list by (slack, offset): in place, no recursion. */
static void entries_sort(const coa_planner_t *pl, size_t i, int16_t *e, size_t n)
{
    size_t end;
    size_t start;
    for (start = n / 2u; start-- > 0u;) {
        entries_sift(pl, i, e, start, n);
    }
    for (end = n; end-- > 1u;) {
        int16_t t = e[0];
        e[0] = e[end];
        e[end] = t;
        entries_sift(pl, i, e, 0u, end);
    }
}

/* Member i's entry offsets: those it can be at when it enters with a plan through them
 * within the group's slack, cheapest first. */
static void group_entries(coa_planner_t *pl, size_t i, const coa_cost_t *slack)
{
    plan_group_t *g = &pl->group;
    const plan_table_t *t = plan_to_go(pl, i);
    int16_t *e = &pl->entries[i * pl->row_width];
    uint32_t n = 0u;
    int32_t o;
    g->entry_count[i] = 0u;
    if (g->first[i] == 0u) {
        return; /* in the search from the start, at its initial offset */
    }
    for (o = plan_row_lo(t, g->first[i]); o <= plan_row_hi(t, g->first[i]); ++o) {
        coa_cost_t s = entry_slack(pl, i, o);
        if (!plan_cost_dead(s) && (slack == NULL || plan_cost_compare(s, *slack) <= 0)) {
            e[n++] = (int16_t)o;
        }
    }
    entries_sort(pl, i, e, n);
    g->entry_count[i] = n;
}

/* The members one after the other, each against the fixed vehicles and those before it:
 * false when one has no plan. Writes their rows; *cost is the total. */
static bool members_in_turn(coa_planner_t *pl, coa_cost_t *cost, coa_plan_result_t *r)
{
    const plan_group_t *g = &pl->group;
    size_t against[COA_MAX_VEHICLES];
    size_t n = g->fixed_count;
    size_t i;

    *cost = (coa_cost_t){0u, 0u};
    for (i = 0; i < n; ++i) {
        against[i] = g->fixed[i];
    }
    for (i = 0; i < g->count; ++i) {
        const size_t v = g->vehicle[i];
        const int32_t start = pl->problem->vehicles[v].initial_offset;
        uint64_t root;
        coa_plan_table_build(pl, &pl->scratch, v, against, n);
        ++r->searches;
        root = plan_table_at(&pl->scratch, 0u, start);
        if (cell_dead(root)) {
            return false;
        }
        coa_plan_table_walk(pl, &pl->scratch, 0u, start);
        r->nodes_expanded += pl->problem->horizon;
        *cost = plan_cost_add(*cost, plan_cell_cost(pl, v, root));
        against[n++] = v;
    }
    return true;
}

static coa_cost_t costs_sum(const coa_cost_t *c, size_t n)
{
    coa_cost_t sum = {0u, 0u};
    size_t i;
    for (i = 0; i < n; ++i) {
        sum = plan_cost_add(sum, c[i]);
    }
    return sum;
}

static coa_cost_t sum_alone(const plan_group_t *g)
{
    return costs_sum(g->alone, g->count);
}

/* Keeps (or puts back) the rows of the group's members. */
static void rows_save(coa_planner_t *pl, bool back)
{
    const plan_group_t *g = &pl->group;
    const size_t row = (size_t)pl->problem->horizon + 1u;
    size_t i;
    size_t k;
    pl->touched_rows = true;
    for (i = 0; i < g->count; ++i) {
        int32_t *live = &pl->rows[g->vehicle[i] * row];
        int32_t *kept = &pl->saved_rows[i * row];
        for (k = 0; k < row; ++k) {
            if (back) {
                live[k] = kept[k];
            } else {
                kept[k] = live[k];
            }
        }
    }
}

/* Starts a group: the last search's nodes released, the members (bit mask of vehicles)
 * with their costs alone, and the fixed vehicles. */
static void group_collect(coa_planner_t *pl, uint32_t members, uint32_t fixed)
{
    plan_group_t *g = &pl->group;
    size_t v;

    coa_plan_search_release(pl);
    g->count = 0u;
    g->fixed_count = 0u;
    for (v = 0; v < pl->problem->vehicle_count; ++v) {
        if ((members & (UINT32_C(1) << v)) != 0u) {
            g->vehicle[g->count] = v;
            g->alone[g->count] = plan_cost_alone(pl, v);
            ++g->count;
        } else if ((fixed & (UINT32_C(1) << v)) != 0u) {
            g->fixed[g->fixed_count++] = v;
        }
    }
    g->side[0] = (UINT32_C(1) << g->count) - 1u;
    g->side[1] = 0u;
}

/* Everything a joint search of `members` around the rows of `fixed` (at most `bound`,
 * when not NULL) needs. Returns true when the members' plan in turn is already optimal
 * (or, with a bound, meets it), with their rows written: no search is needed. Otherwise
 * the members' rows are as they were. */
static bool group_setup(coa_planner_t *pl, uint32_t members, uint32_t fixed,
                        const coa_cost_t *bound, coa_plan_result_t *r)
{
    plan_group_t *g = &pl->group;
    coa_cost_t cap;
    coa_cost_t slack;
    size_t i;

    group_collect(pl, members, fixed);
    g->bounded = bound != NULL;
    if (bound != NULL) {
        g->bound = *bound;
    }
    group_spans(pl, members, fixed);
    rows_save(pl, false);
    g->capped = members_in_turn(pl, &cap, r) && !pl->out_of_work;
    if (fixed == 0u && pl->have_best) {
        /* The incumbent's rows of the members are a plan of the group alone too. */
        coa_cost_t best = coa_plan_rows_cost(pl, pl->best_rows, members);
        if (!g->capped || plan_cost_compare(best, cap) < 0) {
            coa_plan_rows_copy(pl, pl->rows, pl->best_rows, members);
            cap = best;
            g->capped = true;
        }
    }
    if (pl->out_of_work) {
        rows_save(pl, true);
        return false;
    }
    if (g->capped) {
        int c = plan_cost_compare(cap, sum_alone(g));
        if (c <= 0 || (bound != NULL && plan_cost_compare(cap, *bound) <= 0)) {
            return true;
        }
        g->cap = cap;
        slack = plan_cost_sub(cap, sum_alone(g));
    }
    rows_save(pl, true);
    for (i = 0; i < g->count; ++i) {
        group_entries(pl, i, g->capped ? &slack : NULL);
    }
    coa_plan_pairs_build(pl);
    return false;
}

/* A joint search of `members` around `fixed`, at most `bound` when not NULL. Budget
 * exhausted (beta or work): *bound2 is a lower bound on twice the group's optimum (0 when
 * the search did not start). */
static coa_plan_status_t search_group(coa_planner_t *pl, uint32_t members, uint32_t fixed,
                                      const coa_cost_t *bound, coa_plan_result_t *r,
                                      coa_cost_t *bound2)
{
    plan_search_out_t out;
    *bound2 = (coa_cost_t){0u, 0u};
    if (group_setup(pl, members, fixed, bound, r)) {
        return COA_PLAN_SOLVED;
    }
    if (pl->out_of_work) {
        return COA_PLAN_BUDGET_EXHAUSTED;
    }
    coa_plan_search(pl, &out);
    r->nodes_expanded += out.expanded;
    r->nodes_generated += out.stored;
    ++r->searches;
    if (out.status == COA_PLAN_BUDGET_EXHAUSTED) {
        *bound2 = out.bound2;
        if (!pl->out_of_work) {
            r->limit = COA_PLAN_LIMIT_BETA;
        }
    }
    return out.status;
}

/* ------------------------------------------------------------------------------------ */
/* Independence detection                                                                */

/* Disjoint bit masks of vehicles, each with the packed cost of its rows, which are
 * optimal for the group alone. */
typedef struct {
    uint32_t members[COA_MAX_CENTRALISED];
    coa_cost_t cost[COA_MAX_CENTRALISED];
    size_t count;
} groups_t;

static size_t group_of(const groups_t *g, size_t vehicle)
{
    size_t i;
    for (i = 0; i + 1u < g->count && (g->members[i] & (UINT32_C(1) << vehicle)) == 0u; ++i) {
    }
    return i;
}

/* The first conflict between the rows of two vehicles of different groups (earliest
 * step, then the lowest pair): false when there is none. */
static bool groups_conflict(const coa_planner_t *pl, const groups_t *g, size_t *a, size_t *b)
{
    const coa_problem_t *pr = pl->problem;
    const size_t row = (size_t)pr->horizon + 1u;
    const size_t n = pr->vehicle_count;
    coa_sweep_t s[COA_MAX_CENTRALISED];
    size_t gi[COA_MAX_CENTRALISED];
    uint32_t k;
    size_t i;
    size_t j;

    for (i = 0; i < n; ++i) {
        gi[i] = group_of(g, i);
    }
    for (k = 0; k < pr->horizon; ++k) {
        for (i = 0; i < n; ++i) {
            const int32_t *r = &pl->rows[i * row];
            s[i] = coa_plan_vehicle_sweep(pr, pl->dh, i, k, r[k], k + 1u, r[k + 1u]);
            for (j = 0; j < i; ++j) {
                if (gi[i] != gi[j] && k >= pl->near_first[i][j] && k <= pl->near_last[i][j] &&
                    coa_conflict_volumes(&s[j], &s[i])) {
                    *a = gi[j];
                    *b = gi[i];
                    return true;
                }
            }
        }
    }
    return false;
}

/* Whether the pair of groups was tried before; records it if not (and if there is room:
 * a pair that cannot be recorded is not re-planned, only merged). */
static bool tried_before(coa_planner_t *pl, uint32_t x, uint32_t y)
{
    uint32_t lo = x < y ? x : y;
    uint32_t hi = x < y ? y : x;
    size_t i;
    for (i = 0; i < pl->tried_count; ++i) {
        if (pl->tried[i][0] == lo && pl->tried[i][1] == hi) {
            return true;
        }
    }
    if (pl->tried_count == PLAN_MAX_TRIED) {
        return true;
    }
    pl->tried[pl->tried_count][0] = lo;
    pl->tried[pl->tried_count][1] = hi;
    ++pl->tried_count;
    return false;
}

/* Group x re-planned around group y's rows at exactly x's cost (it cannot cost less: x's
 * rows are optimal for x alone). On success x's rows change and nothing else does. A
 * single vehicle's plan is read off its table built against y. */
static bool replan_around(coa_planner_t *pl, const groups_t *g, size_t x, size_t y,
                          coa_plan_result_t *r)
{
    size_t against[COA_MAX_CENTRALISED];
    size_t n = 0u;
    size_t v;
    size_t u;
    uint64_t root;
    int32_t start;

    if (plan_popcount(g->members[x]) > 1u) {
        coa_cost_t ignored;
        return search_group(pl, g->members[x], g->members[y], &g->cost[x], r, &ignored) ==
               COA_PLAN_SOLVED;
    }
    for (u = 0; u < pl->problem->vehicle_count; ++u) {
        if ((g->members[y] & (UINT32_C(1) << u)) != 0u) {
            against[n++] = u;
        }
    }
    for (v = 0; (g->members[x] & (UINT32_C(1) << v)) == 0u; ++v) {
    }
    start = pl->problem->vehicles[v].initial_offset;
    coa_plan_table_build(pl, &pl->scratch, v, against, n);
    ++r->searches;
    if (pl->out_of_work) {
        return false;
    }
    root = plan_table_at(&pl->scratch, 0u, start);
    if (cell_dead(root) || plan_cost_compare(plan_cell_cost(pl, v, root), g->cost[x]) != 0) {
        return false;
    }
    coa_plan_table_walk(pl, &pl->scratch, 0u, start);
    r->nodes_expanded += pl->problem->horizon;
    return true;
}

/* Group y joins group x (x < y), which is planned again as a whole. Budget exhausted:
 * g->cost[x] becomes a lower bound on the merged group's optimum. */
static coa_plan_status_t merge(coa_planner_t *pl, groups_t *g, size_t x, size_t y,
                               coa_plan_result_t *r)
{
    const coa_cost_t before = plan_cost_add(g->cost[x], g->cost[y]);
    coa_plan_status_t st;
    coa_cost_t bound2;
    size_t i;
    g->members[x] |= g->members[y];
    for (i = y; i + 1u < g->count; ++i) {
        g->members[i] = g->members[i + 1u];
        g->cost[i] = g->cost[i + 1u];
    }
    --g->count;
    if (plan_popcount(g->members[x]) > r->largest_group) {
        r->largest_group = plan_popcount(g->members[x]);
    }
    st = search_group(pl, g->members[x], 0u, NULL, r, &bound2);
    if (st == COA_PLAN_SOLVED) {
        g->cost[x] = rows_cost(pl, g->members[x]);
    } else if (st == COA_PLAN_BUDGET_EXHAUSTED) {
        /* Costs are integers: half of a doubled bound, rounded up, is still a bound. */
        coa_cost_t half = plan_cost_add(bound2, (coa_cost_t){0u, 1u});
        half.lo = (half.lo >> 1) | (half.hi << 63);
        half.hi >>= 1;
        g->cost[x] = plan_cost_compare(half, before) > 0 ? half : before;
    }
    return st;
}

/* Each vehicle alone, off its table: infeasible when one has no plan even alone. */
static coa_plan_status_t alone(coa_planner_t *pl, groups_t *g, coa_plan_result_t *r)
{
    const coa_problem_t *pr = pl->problem;
    size_t v;
    g->count = pr->vehicle_count;
    for (v = 0; v < pr->vehicle_count; ++v) {
        const int32_t start = pr->vehicles[v].initial_offset;
        uint64_t root;
        coa_plan_table_build(pl, &pl->to_go[v], v, NULL, 0u);
        ++r->searches;
        if (pl->out_of_work) {
            return COA_PLAN_BUDGET_EXHAUSTED;
        }
        root = plan_table_at(&pl->to_go[v], 0u, start);
        if (cell_dead(root)) {
            return COA_PLAN_INFEASIBLE;
        }
        if (pr->vehicle_count > 1u) {
            coa_plan_table_build_from_start(pl, &pl->from_start[v], &pl->to_go[v]);
            if (pl->out_of_work) {
                return COA_PLAN_BUDGET_EXHAUSTED;
            }
        }
        coa_plan_table_walk(pl, &pl->to_go[v], 0u, start);
        r->nodes_expanded += pr->horizon;
        g->members[v] = UINT32_C(1) << v;
        g->cost[v] = plan_cell_cost(pl, v, root);
    }
    r->largest_group = 1u;
    return COA_PLAN_SOLVED;
}

/* The incumbent's order search may spend at most half of what is left of a limited
 * budget, so that the joint searches keep the other half, and tries at most this many
 * orders (7!, every order of 7 vehicles) when the budget is not limited. */
#define INCUMBENT_ORDERS 5040u

static uint32_t all_vehicles(const coa_planner_t *pl)
{
    return (uint32_t)((UINT64_C(1) << pl->problem->vehicle_count) - 1u);
}

/* The incumbent: the cheapest plan of the priority orders tried (coa_plan_orders_best),
 * kept in pl->best_rows with its cost. Finding one may take up to half of the work left;
 * improving it, up to a quarter, counted from the start: the joint searches keep the rest.
 * Leaves pl->rows undefined. */
static void incumbent(coa_planner_t *pl, coa_plan_result_t *r)
{
    const uint64_t limit = pl->work_limit;
    uint64_t improve = 0u;
    if (limit != 0u) {
        pl->work_limit = pl->work_used + (limit - pl->work_used) / 2u;
        improve = pl->work_used + (limit - pl->work_used) / 4u;
    }
    (void)coa_plan_orders_best(pl, INCUMBENT_ORDERS, improve, r);
    pl->work_limit = limit;
    pl->out_of_work = false;
}

/* The result's lower bound, from a packed cost. */
static void set_bound(const coa_planner_t *pl, coa_plan_result_t *r, coa_cost_t packed)
{
    coa_cost_t dev;
    dev.lo = (packed.lo >> PLAN_EFF_BITS) | (packed.hi << (64u - PLAN_EFF_BITS));
    dev.hi = packed.hi >> PLAN_EFF_BITS;
    r->bound_units = dev;
    r->bound_effort = (uint32_t)(packed.lo & ((UINT64_C(1) << PLAN_EFF_BITS) - 1u));
    r->bound_deviation =
        ldexp(ldexp((double)dev.hi, 64) + (double)dev.lo, pl->exponent) / (double)pl->scale;
}

static coa_cost_t groups_sum(const groups_t *g)
{
    return costs_sum(g->cost, g->count);
}

/* A limit ended independence detection: every group's cost is its optimum alone or a lower
 * bound on it, so their sum bounds the whole. The incumbent is the answer, optimal when
 * the bound meets it; without one nothing was found. */
static coa_plan_status_t finish_early(coa_planner_t *pl, const groups_t *g, coa_plan_result_t *r)
{
    coa_cost_t bound = groups_sum(g);
    if (!pl->have_best) {
        set_bound(pl, r, bound);
        return COA_PLAN_BUDGET_EXHAUSTED;
    }
    coa_plan_rows_copy(pl, pl->rows, pl->best_rows, all_vehicles(pl));
    if (plan_cost_compare(bound, pl->best_cost) >= 0) {
        bound = pl->best_cost;
        r->optimal = true;
    }
    set_bound(pl, r, bound);
    return COA_PLAN_SOLVED;
}

/* The whole plan is optimal: the groups' optima alone, whose sum it costs. */
static coa_plan_status_t finish_optimal(coa_planner_t *pl, const groups_t *g, coa_plan_result_t *r)
{
    set_bound(pl, r, groups_sum(g));
    r->optimal = true;
    return COA_PLAN_SOLVED;
}

/* Each vehicle's own plan again (the incumbent's search overwrote the rows). */
static void walk_alone(coa_planner_t *pl)
{
    size_t v;
    for (v = 0; v < pl->problem->vehicle_count; ++v) {
        coa_plan_table_walk(pl, &pl->to_go[v], 0u, pl->problem->vehicles[v].initial_offset);
    }
}

/* One round of independence detection on the first conflict between groups a and b: a
 * re-plan of one around the other, else a merge. */
static coa_plan_status_t resolve(coa_planner_t *pl, groups_t *g, size_t a, size_t b,
                                 coa_plan_result_t *r)
{
    size_t x = a < b ? a : b;
    size_t y = a < b ? b : a;
    if (!tried_before(pl, g->members[x], g->members[y]) &&
        (replan_around(pl, g, x, y, r) || replan_around(pl, g, y, x, r))) {
        return COA_PLAN_SOLVED;
    }
    if (pl->out_of_work) {
        return COA_PLAN_BUDGET_EXHAUSTED;
    }
    return merge(pl, g, x, y, r);
}

coa_plan_status_t coa_plan_independence(coa_planner_t *pl, coa_plan_result_t *r)
{
    const size_t n = pl->problem->vehicle_count;
    coa_plan_status_t st;
    groups_t g;
    size_t a;
    size_t b;

    pl->tried_count = 0u;
    st = alone(pl, &g, r);
    if (st != COA_PLAN_SOLVED) {
        return st;
    }
    near_all(pl);
    for (;;) {
        /* Charged before the check runs: O(N n^2) volume tests. */
        if (!plan_work(pl, (uint64_t)pl->problem->horizon * n * n)) {
            return finish_early(pl, &g, r);
        }
        if (!groups_conflict(pl, &g, &a, &b)) {
            return finish_optimal(pl, &g, r);
        }
        /* The first conflict, while every group is still a vehicle alone: the incumbent,
         * which caps every joint search of a group without fixed vehicles from here on. */
        if (g.count == n && pl->tried_count == 0u) {
            incumbent(pl, r);
            if (pl->have_best && plan_cost_compare(pl->best_cost, groups_sum(&g)) <= 0) {
                coa_plan_rows_copy(pl, pl->rows, pl->best_rows, all_vehicles(pl));
                return finish_optimal(pl, &g, r);
            }
            walk_alone(pl);
        }
        st = resolve(pl, &g, a, b, r);
        if (st == COA_PLAN_INFEASIBLE) {
            return st;
        }
        if (st == COA_PLAN_BUDGET_EXHAUSTED) {
            return finish_early(pl, &g, r);
        }
    }
}

/* ------------------------------------------------------------------------------------ */
/* Test hooks (plan_internal.h)                                                          */

void coa_plan_test_group_setup(coa_planner_t *pl, uint32_t members)
{
    plan_group_t *g = &pl->group;
    size_t v;
    size_t i;

    for (v = 0; v < pl->problem->vehicle_count; ++v) {
        coa_plan_table_build(pl, &pl->to_go[v], v, NULL, 0u);
        coa_plan_table_build_from_start(pl, &pl->from_start[v], &pl->to_go[v]);
    }
    near_all(pl);
    group_collect(pl, members, 0u);
    g->bounded = false;
    g->capped = false;
    group_spans(pl, members, 0u);
    for (i = 0; i < g->count; ++i) {
        group_entries(pl, i, NULL);
    }
    coa_plan_pairs_build(pl);
}
