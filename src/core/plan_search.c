/* SPDX-License-Identifier: MIT */
/*
 * plan_search.c: the joint A* search of a group of vehicles (plan.h, "The joint search").
 *
 * State. A node is a sample k and the offsets of the members in the search at k (member i
 * is in it from sample first_i to last_i; before, it waits to enter; after, it has left
 * and the node keeps the offset it left at, for the plan, but two nodes that differ only
 * there are the same state). Its g is exact: the members that left carry their exact cost
 * to go, the members that entered their exact cost from the start.
 *
 * Heuristic (all costs packed and doubled, so that halves stay integers): twice each
 * member's own cost to go (in the search) or cost alone (waiting), plus the largest
 * half-integral fractional matching of the pair surcharges among the members in the
 * search: a pair counted twice, or the three pairs of a triangle once each. Each such
 * matching gives a sum of exact costs to go of disjoint pairs and triangles' halves, a
 * consistent heuristic; the largest of them is consistent too.
 *
 * Partial expansion (EPEA*, Goldenberg et al. 2014). Expanding a node generates only the
 * children whose f is the node's key: the moves of the members in the search and the
 * offsets of the members entering at k + 1 are enumerated depth first, each member's in
 * the order of the increase of the additive part of f they cause (their own tables), and
 * a branch whose increase already passes the key is cut; the node goes back to the open
 * list under the least increase it cut, or retires. A child's f is at least the larger of
 * its parent's f and its additive part, which is how the enumeration bounds it.
 */
#include "plan_internal.h"

/* An expansion generates the children up to its key plus a window, not just up to the key:
 * with costs as fine-grained as (deviation, effort) nearly every child has an f of its
 * own, and partial expansion alone would take a node back once per child (measured: 10 to
 * 25 times per stored node). The window is half the gap between the root and the cap
 * (the incumbent's or the members' plan in turn) when there is one, and at least half the
 * key; children beyond the key are stored early, which costs memory but never optimality.
 * Against a quarter of each: 10-14% fewer work units on the 4-UAV bench and montecarlo
 * encounters (the dearest 67 to 57 million), one more 5-UAV proof in 200, the same stored
 * nodes at most (docs/benchmarks.md). */
#define BATCH_SHIFT 1u
#define KEY_SHIFT 1u
#define K_EXPANDED 0x8000u /* node_k bit: expanded at least once (closed) */
#define K_SAMPLE 0x7fffu
#define PLAN_WORK_LEAF 4u  /* work units of a complete combination, beyond its members' */
#define PLAN_WORK_MATCH 2u /* work units of a direct matching of four members */

static size_t node_sample(const coa_planner_t *pl, uint32_t n)
{
    return (size_t)(pl->node_k[n] & K_SAMPLE);
}

static const int16_t *node_off(const coa_planner_t *pl, uint32_t n)
{
    return &pl->off[(size_t)n * pl->m];
}

static bool in_search(const plan_group_t *g, size_t i, uint32_t k)
{
    return k >= g->first[i] && k <= g->last[i];
}

/* ------------------------------------------------------------------------------------ */
/* States: hash table                                                                    */

/* Only the offsets of members in the search at k make the state. */
static uint32_t state_hash(const coa_planner_t *pl, uint32_t k, const int16_t *off)
{
    uint64_t h = 0x9e3779b97f4a7c15u ^ (uint64_t)k;
    size_t i;
    for (i = 0; i < pl->m; ++i) {
        uint16_t o = in_search(&pl->group, i, k) ? (uint16_t)off[i] : 0x5a5au;
        h = (h ^ (uint64_t)o) * 0xff51afd7ed558ccdu;
        h ^= h >> 32;
    }
    h ^= h >> 29;
    h *= 0xc4ceb9fe1a85ec53u;
    h ^= h >> 32;
    return (uint32_t)h;
}

static bool same_state(const coa_planner_t *pl, uint32_t n, uint32_t k, const int16_t *off)
{
    const int16_t *o = node_off(pl, n);
    size_t i;
    if (node_sample(pl, n) != k) {
        return false;
    }
    for (i = 0; i < pl->m; ++i) {
        if (in_search(&pl->group, i, k) && o[i] != off[i]) {
            return false;
        }
    }
    return true;
}

/* The slot a hash starts probing at: the hash scaled to the table, which need not be a
 * power of two (in full, it is exactly twice the pool). */
static uint32_t home_slot(const coa_planner_t *pl, uint32_t hash)
{
    return (uint32_t)(((uint64_t)hash * pl->slot_active) >> 32);
}

static uint32_t next_slot(const coa_planner_t *pl, uint32_t slot)
{
    return slot + 1u == pl->slot_active ? 0u : slot + 1u;
}

/* The node of this state, or PLAN_NONE and the empty slot where it would go. At most half
 * the slots are used, so the probe ends. */
static uint32_t state_find(const coa_planner_t *pl, uint32_t k, const int16_t *off,
                           uint32_t *slot_out)
{
    uint32_t slot = home_slot(pl, state_hash(pl, k, off));
    for (;;) {
        uint32_t n = pl->slot[slot];
        if (n == PLAN_NONE) {
            break;
        }
        if (same_state(pl, n, k, off)) {
            return n;
        }
        slot = next_slot(pl, slot);
    }
    *slot_out = slot;
    return PLAN_NONE;
}

/* Room in the table for one more node: before half its slots would hold nodes it doubles
 * (up to its full size) and takes every node again, charged a unit per node and per 32
 * slots cleared. False: out of work. */
static bool slots_reserve(coa_planner_t *pl)
{
    uint32_t size;
    uint32_t n;
    if ((uint64_t)pl->used * 2u + 2u <= pl->slot_active || pl->slot_active == pl->slot_count) {
        return true;
    }
    size = pl->slot_active > pl->slot_count / 2u ? pl->slot_count : 2u * pl->slot_active;
    if (!plan_work(pl, size / 32u + pl->used)) {
        return false;
    }
    pl->slot_active = size;
    if (size > pl->touched_slots) {
        pl->touched_slots = size;
    }
    for (n = 0; n < size; ++n) {
        pl->slot[n] = PLAN_NONE;
    }
    for (n = 0; n < pl->used; ++n) {
        uint32_t slot =
            home_slot(pl, state_hash(pl, (uint32_t)node_sample(pl, n), node_off(pl, n)));
        while (pl->slot[slot] != PLAN_NONE) {
            slot = next_slot(pl, slot);
        }
        pl->slot[slot] = n;
    }
    return true;
}

void coa_plan_search_release(coa_planner_t *pl)
{
    uint32_t n;
    if ((uint64_t)pl->used * 4u >= (uint64_t)pl->slot_active) {
        for (n = 0; n < pl->slot_active; ++n) {
            pl->slot[n] = PLAN_NONE;
        }
    } else {
        for (n = 0; n < pl->used; ++n) {
            uint32_t k = (uint32_t)node_sample(pl, n);
            uint32_t slot = home_slot(pl, state_hash(pl, k, node_off(pl, n)));
            /* Entries cleared before this one may have left holes in its probe run, so
             * walk past empty slots: every node is in the table. */
            while (pl->slot[slot] != n) {
                slot = next_slot(pl, slot);
            }
            pl->slot[slot] = PLAN_NONE;
        }
    }
    /* Every search starts from the first size, so that its growth, and the work charged
     * for it, do not depend on the searches before it. */
    pl->slot_active = plan_slots_first(pl);
    pl->used = 0u;
    pl->heap_count = 0u;
}

/* ------------------------------------------------------------------------------------ */
/* Open list                                                                             */

/* Key, then the later sample first (the paper's larger k first), then the order nodes
 * were stored. */
static bool node_before(const coa_planner_t *pl, uint32_t a, uint32_t b)
{
    int c = plan_cost_compare(pl->key[a], pl->key[b]);
    if (c != 0) {
        return c < 0;
    }
    if (node_sample(pl, a) != node_sample(pl, b)) {
        return node_sample(pl, a) > node_sample(pl, b);
    }
    return a < b;
}

static void heap_place(coa_planner_t *pl, uint32_t pos, uint32_t n)
{
    pl->heap[pos] = n;
    pl->heap_pos[n] = pos;
}

static void sift_up(coa_planner_t *pl, uint32_t pos)
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

static void sift_down(coa_planner_t *pl, uint32_t pos)
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

static void heap_push(coa_planner_t *pl, uint32_t n)
{
    heap_place(pl, pl->heap_count, n);
    ++pl->heap_count;
    sift_up(pl, pl->heap_count - 1u);
}

static void heap_pop(coa_planner_t *pl)
{
    uint32_t top = pl->heap[0];
    --pl->heap_count;
    if (pl->heap_count > 0u) {
        heap_place(pl, 0u, pl->heap[pl->heap_count]);
        sift_down(pl, 0u);
    }
    pl->heap_pos[top] = PLAN_NONE;
}

/* ------------------------------------------------------------------------------------ */
/* Heuristic                                                                             */

/* Member i's own cost to go at (k, o), packed. */
static coa_cost_t own_to_go(const coa_planner_t *pl, size_t i, uint32_t k, int32_t o)
{
    return plan_cell_cost(pl, pl->group.vehicle[i], plan_table_at(plan_to_go(pl, i), k, o));
}

static coa_cost_t cost_larger(coa_cost_t a, coa_cost_t b)
{
    return plan_cost_compare(a, b) > 0 ? a : b;
}

/* Up to four members the matching is the largest of a few sums, said directly, since the
 * leaves of every expansion ask for it (the pass over subsets cost a quarter of a 4-UAV
 * search's instructions). Surcharges are >= 0, so a larger set never loses: two members
 * give their pair, three the larger of their largest pair and their triangle, four the
 * largest of their three perfect matchings and four triangles. at[] lists the members. */
static coa_cost_t matching_direct(const coa_cost_t *s, size_t m, const size_t *at, size_t count)
{
    static const uint8_t triangles[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
    static const uint8_t perfect[3][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}};
    size_t i;
    coa_cost_t best = {0u, 0u};

    if (count == 2u) {
        best = plan_cost_twice(s[plan_pair_index(at[0], at[1], m)]);
    } else if (count == 3u) {
        coa_cost_t ab = s[plan_pair_index(at[0], at[1], m)];
        coa_cost_t ac = s[plan_pair_index(at[0], at[2], m)];
        coa_cost_t bc = s[plan_pair_index(at[1], at[2], m)];
        best = cost_larger(plan_cost_twice(cost_larger(ab, cost_larger(ac, bc))),
                           plan_cost_add(ab, plan_cost_add(ac, bc)));
    } else if (count == 4u) {
        for (i = 0; i < 3u; ++i) {
            const uint8_t *p = perfect[i];
            best = cost_larger(
                best, plan_cost_twice(plan_cost_add(s[plan_pair_index(at[p[0]], at[p[1]], m)],
                                                    s[plan_pair_index(at[p[2]], at[p[3]], m)])));
        }
        for (i = 0; i < 4u; ++i) {
            const uint8_t *t = triangles[i];
            best = cost_larger(
                best, plan_cost_add(s[plan_pair_index(at[t[0]], at[t[1]], m)],
                                    plan_cost_add(s[plan_pair_index(at[t[0]], at[t[2]], m)],
                                                  s[plan_pair_index(at[t[1]], at[t[2]], m)])));
        }
    }
    return best;
}

/* The members of at[] but positions a, b and c (a < b < c; SIZE_MAX: none). */
static size_t members_without(const size_t *at, size_t count, size_t a, size_t b, size_t c,
                              size_t *out)
{
    size_t i;
    size_t n = 0u;
    for (i = 0; i < count; ++i) {
        if (i != a && i != b && i != c) {
            out[n++] = at[i];
        }
    }
    return n;
}

/* The largest half-integral fractional matching of the surcharges s[] among the members
 * at[] (count of them, 5 or 6; doubled: an edge twice, a triangle's edges once each),
 * given `alone`, the matching of at[1..]: the first member is left alone, matched to one
 * other, or in a triangle, and the rest (at most four) is matching_direct's. */
static coa_cost_t matching_peel(const coa_cost_t *s, size_t m, const size_t *at, size_t count,
                                coa_cost_t alone)
{
    size_t rest[PLAN_MAXM];
    size_t j;
    size_t l;
    coa_cost_t best = alone;

    for (j = 1u; j < count; ++j) {
        size_t n = members_without(at, count, 0u, j, SIZE_MAX, rest);
        coa_cost_t pair = plan_cost_twice(s[plan_pair_index(at[0], at[j], m)]);
        best = cost_larger(best, plan_cost_add(pair, matching_direct(s, m, rest, n)));
        for (l = j + 1u; l < count; ++l) {
            coa_cost_t tri = plan_cost_add(plan_cost_add(s[plan_pair_index(at[0], at[j], m)],
                                                         s[plan_pair_index(at[0], at[l], m)]),
                                           s[plan_pair_index(at[j], at[l], m)]);
            n = members_without(at, count, 0u, j, l, rest);
            best = cost_larger(best, plan_cost_add(tri, matching_direct(s, m, rest, n)));
        }
    }
    return best;
}

/* The matching of the members at[]: directly up to four, peeled member by member above
 * (6 members: 26 direct calls, against 64 subsets of a pass over them). No recursion: the
 * firmware's stack bound is a sum of frames. */
static coa_cost_t matching_list(const coa_cost_t *s, size_t m, const size_t *at, size_t count)
{
    _Static_assert(PLAN_MATCH_ALL == 6u, "matching_list peels at most two members");
    if (count <= 4u) {
        return matching_direct(s, m, at, count);
    }
    if (count == 5u) {
        return matching_peel(s, m, at, 5u, matching_direct(s, m, &at[1], 4u));
    }
    return matching_peel(s, m, at, 6u,
                         matching_peel(s, m, &at[1], 5u, matching_direct(s, m, &at[2], 4u)));
}

/* The work units of matching(mask) beyond a leaf's own: PLAN_WORK_MATCH per direct call
 * past the first (members: 5 -> 11 calls, 6 -> 26; each call adds one per member, less
 * the pairs and triangles of the first and the calls under them), on each side. */
static uint64_t matching_work(const plan_group_t *g, uint32_t mask)
{
    static const uint8_t calls[PLAN_MATCH_ALL + 1u] = {1, 1, 1, 1, 1, 11, 26};
    uint64_t units = (uint64_t)(calls[plan_popcount(mask & g->side[0])] - 1u) * PLAN_WORK_MATCH;
    if (g->side[1] != 0u) {
        units += (uint64_t)calls[plan_popcount(mask & g->side[1])] * PLAN_WORK_MATCH;
    }
    return units;
}

/* matching_list of the members of `mask`. */
static coa_cost_t matching_of(const coa_cost_t *s, size_t m, uint32_t mask)
{
    size_t at[PLAN_MAXM];
    size_t count = 0u;
    size_t i;
    for (i = 0; i < m; ++i) {
        if ((mask & (1u << i)) != 0u) {
            at[count++] = i;
        }
    }
    return matching_list(s, m, at, count);
}

/* The heuristic's matching of the members of `mask`: within each side of the group. */
static coa_cost_t matching(const plan_group_t *g, const coa_cost_t *s, uint32_t mask)
{
    coa_cost_t r = matching_of(s, g->count, mask & g->side[0]);
    if (g->side[1] != 0u) {
        r = plan_cost_add(r, matching_of(s, g->count, mask & g->side[1]));
    }
    return r;
}

/* Whether members i and j are on the same side: their surcharge is in the matching. */
static bool same_side(const plan_group_t *g, size_t i, size_t j)
{
    return (((g->side[0] >> i) ^ (g->side[0] >> j)) & 1u) == 0u;
}

/* The split of the members into two sides of at most PLAN_MATCH_ALL each (side 0 holds
 * member 0) whose matchings of the pair weights w[] add up most. */
static uint32_t sides_best(coa_planner_t *pl, const coa_cost_t *w)
{
    const size_t m = pl->group.count;
    const uint32_t all = (1u << m) - 1u;
    uint32_t best_side = all >> (m - pl->match_all);
    coa_cost_t best = {0u, 0u};
    bool any = false;
    uint32_t a;

    for (a = 1u; a < all; a += 2u) {
        uint32_t na = plan_popcount(a);
        coa_cost_t v;
        if (na > pl->match_all || m - na > pl->match_all) {
            continue;
        }
        if (!plan_work(pl, 2u * PLAN_WORK_MATCH + m)) {
            break;
        }
        v = plan_cost_add(matching_of(w, m, a), matching_of(w, m, all & ~a));
        if (!any || plan_cost_compare(v, best) > 0) {
            best = v;
            best_side = a;
            any = true;
        }
    }
    return best_side;
}

void coa_plan_sides_choose(coa_planner_t *pl)
{
    plan_group_t *g = &pl->group;
    coa_cost_t w[PLAN_PAIRS];
    size_t i;
    size_t j;

    g->side[0] = (1u << g->count) - 1u;
    g->side[1] = 0u;
    if (g->count <= pl->match_all) {
        return;
    }
    for (j = 1u; j < g->count; ++j) {
        for (i = 0; i < j; ++i) {
            w[plan_pair_index(i, j, g->count)] = coa_plan_pair_weight(pl, i, j);
        }
    }
    g->side[0] = sides_best(pl, w);
    g->side[1] = ((1u << g->count) - 1u) & ~g->side[0];
}

typedef struct {
    coa_cost_t h2; /* the doubled heuristic */
    coa_cost_t m2; /* its matching part */
} heur_t;

/* The doubled heuristic of a state at sample k; false when a pair is dead there. */
static bool heuristic(const coa_planner_t *pl, uint32_t k, const int16_t *off, heur_t *out)
{
    const plan_group_t *g = &pl->group;
    const size_t m = g->count;
    coa_cost_t own[PLAN_MAXM];
    coa_cost_t s[PLAN_PAIRS];
    coa_cost_t sum = {0u, 0u};
    uint32_t mask = 0u;
    size_t i;
    size_t j;

    for (i = 0; i < m; ++i) {
        if (in_search(g, i, k)) {
            own[i] = own_to_go(pl, i, k, off[i]);
            sum = plan_cost_add(sum, own[i]);
            mask |= 1u << i;
        } else if (k < g->first[i]) {
            sum = plan_cost_add(sum, g->alone[i]);
        }
    }
    for (i = 0; i < m; ++i) {
        for (j = i + 1u; j < m; ++j) {
            coa_cost_t c = {0u, 0u};
            if ((mask & (1u << i)) != 0u && (mask & (1u << j)) != 0u) {
                c = coa_plan_pair_surcharge(pl, i, j, k, off[i], off[j], own[i], own[j]);
                if (plan_cost_dead(c)) {
                    return false;
                }
            }
            s[plan_pair_index(i, j, m)] = c;
        }
    }
    out->m2 = matching(g, s, mask);
    out->h2 = plan_cost_add(plan_cost_twice(sum), out->m2);
    return true;
}

/* ------------------------------------------------------------------------------------ */
/* Nodes                                                                                 */

typedef struct {
    uint32_t parent;
    uint32_t k;
    const int16_t *off;
    coa_cost_t g;
    coa_cost_t f2;
} node_init_t;

static bool over(const coa_planner_t *pl, coa_cost_t f2)
{
    const plan_group_t *g = &pl->group;
    return (g->capped && plan_cost_compare(f2, plan_cost_twice(g->cap)) > 0) ||
           (g->bounded && plan_cost_compare(f2, plan_cost_twice(g->bound)) > 0);
}

/* Stores a state that state_find found as node n (or PLAN_NONE, with its empty slot): a
 * new node, or a better path to one not expanded yet. Returns false when the pool is
 * full (budget exhausted). */
static bool node_put(coa_planner_t *pl, const node_init_t *in, uint32_t n, uint32_t slot,
                     plan_search_out_t *out)
{
    size_t i;

    if (n != PLAN_NONE) {
        if ((pl->node_k[n] & K_EXPANDED) != 0u || plan_cost_compare(in->f2, pl->key[n]) >= 0) {
            return true; /* closed (final, the heuristic is consistent) or no better */
        }
    } else {
        if (pl->used >= pl->capacity) {
            return false;
        }
        n = pl->used++;
        if (pl->used > pl->touched_nodes) {
            pl->touched_nodes = pl->used;
        }
        pl->slot[slot] = n;
        pl->node_k[n] = (uint16_t)in->k;
        heap_place(pl, pl->heap_count++, n);
        ++out->stored;
    }
    pl->parent[n] = in->parent;
    pl->key[n] = in->f2;
    pl->g[n] = in->g;
    for (i = 0; i < pl->m; ++i) {
        pl->off[(size_t)n * pl->m + i] = in->off[i];
    }
    sift_up(pl, pl->heap_pos[n]);
    return true;
}

static bool node_add(coa_planner_t *pl, const node_init_t *in, plan_search_out_t *out)
{
    uint32_t slot = 0u;
    uint32_t n;
    if (!slots_reserve(pl)) {
        return false;
    }
    n = state_find(pl, in->k, in->off, &slot);
    return node_put(pl, in, n, slot, out);
}

/* ------------------------------------------------------------------------------------ */
/* Expansion                                                                             */

/* Who decides what at step k -> k + 1: the members in the search move (each one of its
 * moves), the members entering at k + 1 pick their entry offset. Options come cheapest
 * first, with their increase of the additive f (packed, doubled). */
typedef struct {
    size_t count;
    size_t member[PLAN_MAXM];
    bool enters[PLAN_MAXM];
    uint32_t options[PLAN_MAXM];
    plan_moves_t moves[PLAN_MAXM];                /* movers */
    coa_cost_t move_inc[PLAN_MAXM][PLAN_ACTIONS]; /* movers: increase() of each move */
    coa_cost_t rest_min[PLAN_MAXM + 1u];          /* least increase of choosers c.. */
    coa_sweep_t sweep[PLAN_MAXM][PLAN_ACTIONS];
    /* 0 ?, 1 ok, 2 no: a mover's option against the fixed vehicles (its sweep is built
     * once this is known), and against an earlier mover's (choosers d < c, by their
     * plan_pair_index) */
    uint8_t clear[PLAN_MAXM][PLAN_ACTIONS];
    uint8_t pair_ok[PLAN_PAIRS][PLAN_ACTIONS][PLAN_ACTIONS];
} choosers_t;

/* The doubled, packed increase of the additive f that option t of chooser c causes: for
 * a mover, its move's increase (W * unit * dev, and the effort's, which may be negative
 * when the deviation's is positive); for a member entering at k + 1, the slack of its
 * entry offset (its cheapest cost through it less its cost alone). */
static coa_cost_t increase_of(const coa_planner_t *pl, const choosers_t *ch, size_t c, uint32_t k,
                              uint32_t t)
{
    const size_t i = ch->member[c];
    const size_t v = pl->group.vehicle[i];
    coa_cost_t sum;
    if (ch->enters[c]) {
        int32_t o = pl->entries[i * pl->row_width + t];
        uint64_t from = plan_table_at(plan_from_start(pl, i), k + 1u, o);
        uint64_t to = plan_table_at(plan_to_go(pl, i), k + 1u, o);
        sum = plan_cost_add(plan_cell_cost(pl, v, from), plan_cell_cost(pl, v, to));
        return plan_cost_twice(plan_cost_sub(sum, pl->group.alone[i]));
    } else {
        const plan_moves_t *mv = &ch->moves[c];
        coa_cost_t eff = {0u, (uint64_t)(mv->eff[t] < 0 ? -(int64_t)mv->eff[t] : mv->eff[t])};
        sum = plan_pack(plan_units(pl, v, mv->dev[t]), 0u);
        /* The table's minimum makes (dev, eff) lexicographically >= 0, so the sum is too. */
        sum = mv->eff[t] < 0 ? plan_cost_sub(sum, eff) : plan_cost_add(sum, eff);
        return plan_cost_twice(sum);
    }
}

/* increase_of, from the movers' cache (the enumeration asks again for each branch above). */
static coa_cost_t increase(const coa_planner_t *pl, const choosers_t *ch, size_t c, uint32_t k,
                           uint32_t t)
{
    return ch->enters[c] ? increase_of(pl, ch, c, k, t) : ch->move_inc[c][t];
}

static void choosers_make(const coa_planner_t *pl, uint32_t n, choosers_t *ch)
{
    const plan_group_t *g = &pl->group;
    const uint32_t k = (uint32_t)node_sample(pl, n);
    const int16_t *off = node_off(pl, n);
    coa_cost_t zero = {0u, 0u};
    size_t i;
    size_t c;

    ch->count = 0u;
    for (i = 0; i < g->count; ++i) {
        c = ch->count;
        if (in_search(g, i, k)) {
            ch->member[c] = i;
            ch->enters[c] = false;
            uint32_t t;
            coa_plan_table_moves(plan_to_go(pl, i), k, off[i], &ch->moves[c]);
            ch->options[c] = ch->moves[c].count;
            for (t = 0; t < ch->options[c]; ++t) {
                ch->move_inc[c][t] = increase_of(pl, ch, c, k, t);
            }
            ++ch->count;
        } else if (g->first[i] == k + 1u) {
            ch->member[c] = i;
            ch->enters[c] = true;
            ch->options[c] = g->entry_count[i];
            ++ch->count;
        }
    }
    ch->rest_min[ch->count] = zero;
    for (c = ch->count; c-- > 0u;) {
        coa_cost_t least = ch->options[c] > 0u ? increase(pl, ch, c, k, 0u) : zero;
        ch->rest_min[c] = plan_cost_add(least, ch->rest_min[c + 1u]);
    }
    for (c = 0; c < ch->count; ++c) {
        uint32_t a;
        for (a = 0; a < PLAN_ACTIONS; ++a) {
            ch->clear[c][a] = 0u;
        }
    }
    for (c = 0; c < ch->count * (ch->count - 1u) / 2u; ++c) {
        uint32_t a;
        for (a = 0; a < PLAN_ACTIONS; ++a) {
            uint32_t b;
            for (b = 0; b < PLAN_ACTIONS; ++b) {
                ch->pair_ok[c][a][b] = 0u;
            }
        }
    }
}

/* Whether a mover's sweep is clear of the fixed vehicles at step k. */
static bool fixed_clear(const coa_planner_t *pl, const coa_sweep_t *s, uint32_t k)
{
    const plan_group_t *g = &pl->group;
    const size_t row = (size_t)pl->problem->horizon + 1u;
    size_t j;
    for (j = 0; j < g->fixed_count; ++j) {
        size_t u = g->fixed[j];
        const int32_t *r = &pl->rows[u * row];
        coa_sweep_t f = coa_plan_vehicle_sweep(pl->problem, pl->dh, u, k, r[k], k + 1u, r[k + 1u]);
        if (coa_conflict_volumes(s, &f)) {
            return false;
        }
    }
    return true;
}

/* Whether option a of mover c is clear of the options chosen by the movers before it. */
static bool mover_clear(const coa_planner_t *pl, choosers_t *ch, uint32_t k, size_t c,
                        const uint32_t *choice, const int16_t *off)
{
    const plan_group_t *g = &pl->group;
    const size_t i = ch->member[c];
    const uint32_t a = choice[c];
    size_t d;

    if (ch->clear[c][a] == 0u) {
        ch->sweep[c][a] = coa_plan_vehicle_sweep(pl->problem, pl->dh, g->vehicle[i], k, off[i],
                                                 k + 1u, ch->moves[c].to[a]);
        ch->clear[c][a] = fixed_clear(pl, &ch->sweep[c][a], k) ? 1u : 2u;
    }
    if (ch->clear[c][a] != 1u) {
        return false;
    }
    for (d = 0; d < c; ++d) {
        size_t j = ch->member[d];
        size_t pi;
        uint8_t *ok;
        if (ch->enters[d]) {
            continue;
        }
        pi = plan_pair_index(j, i, g->count);
        if (k < g->near_first[pi] || k > g->near_last[pi]) {
            continue;
        }
        ok = &ch->pair_ok[plan_pair_index(d, c, ch->count)][choice[d]][a];
        if (*ok == 0u) {
            *ok = coa_conflict_volumes(&ch->sweep[d][choice[d]], &ch->sweep[c][a]) ? 2u : 1u;
        }
        if (*ok != 1u) {
            return false;
        }
    }
    return true;
}

/* Where one expansion stands. The children are enumerated depth first over the choosers;
 * at depth c the first c have chosen, and what the child's f can be is bounded below by
 * the additive part so far, the least increase of the choosers left and the largest
 * surcharge among the pairs chosen so far (one pair is a matching). */
typedef struct {
    uint32_t n;
    uint32_t k;
    coa_cost_t key; /* children of doubled f up to this are generated */
    bool have_next;
    coa_cost_t next; /* the least doubled f, or bound, left above the key */
    choosers_t ch;
    uint32_t choice[PLAN_MAXM];
    coa_cost_t partial[PLAN_MAXM + 1u]; /* additive doubled f after choosers 0..c-1 */
    coa_cost_t pairmax[PLAN_MAXM + 1u]; /* largest doubled surcharge among them */
    int16_t off[PLAN_MAXM];             /* the child's offsets, as chosen so far */
    coa_cost_t own[PLAN_MAXM];          /* its members' own costs to go at k + 1 */
    coa_cost_t s[PLAN_PAIRS];           /* its surcharges, pairs chosen so far */
    uint32_t in_child;                  /* members in the search at k + 1 */
} expansion_t;

static void cut(expansion_t *e, coa_cost_t bound)
{
    if (!e->have_next || plan_cost_compare(bound, e->next) < 0) {
        e->next = bound;
        e->have_next = true;
    }
}

/* Whether a branch whose children's f is at least `bound` can be left: all of them cost
 * more than the cap or the bound (none would be stored, and a next key above it retires
 * the node), or it generates none (bound above the key) and cannot lower the next key
 * (which an exact f found so far already beats). Branches above the key are still
 * searched while they might hold the least f above it, so that the node goes back under
 * its exact next key, never under a bound that would make it come back with nothing to
 * generate. */
static bool beyond(const coa_planner_t *pl, const expansion_t *e, coa_cost_t bound)
{
    return over(pl, bound) || (plan_cost_compare(bound, e->key) > 0 && e->have_next &&
                               plan_cost_compare(bound, e->next) >= 0);
}

/* The matching of the surcharges among choosers 0..c (at most four) in the search at k1,
 * within each side: a lower bound on the child's, which contains it. */
static coa_cost_t chosen_matching(const coa_planner_t *pl, const expansion_t *e, size_t c,
                                  uint32_t k1)
{
    const plan_group_t *g = &pl->group;
    coa_cost_t r = {0u, 0u};
    size_t side;
    for (side = 0; side < 2u && g->side[side] != 0u; ++side) {
        size_t at[4];
        size_t count = 0u;
        size_t d;
        for (d = 0; d <= c; ++d) {
            size_t i = e->ch.member[d];
            if (in_search(g, i, k1) && ((g->side[side] >> i) & 1u) != 0u) {
                at[count++] = i;
            }
        }
        r = plan_cost_add(r, matching_direct(e->s, g->count, at, count));
    }
    return r;
}

/* Chooser c takes option choice[c]: its offset at k + 1, and, if it is in the search
 * there, its own cost to go and its surcharges with the members chosen before it. False
 * when a pair is dead there (no plan of the pair from that state). */
static bool choose(const coa_planner_t *pl, expansion_t *e, size_t c)
{
    const plan_group_t *g = &pl->group;
    const size_t i = e->ch.member[c];
    const uint32_t k1 = e->k + 1u;
    const uint32_t t = e->choice[c];
    coa_cost_t best = e->pairmax[c];
    size_t d;

    e->off[i] =
        e->ch.enters[c] ? pl->entries[i * pl->row_width + t] : (int16_t)e->ch.moves[c].to[t];
    if (in_search(g, i, k1)) {
        e->own[i] = own_to_go(pl, i, k1, e->off[i]);
        for (d = 0; d < c; ++d) {
            size_t j = e->ch.member[d];
            size_t pi = plan_pair_index(j, i, g->count);
            coa_cost_t twice;
            if (!in_search(g, j, k1)) {
                continue;
            }
            e->s[pi] =
                coa_plan_pair_surcharge(pl, j, i, k1, e->off[j], e->off[i], e->own[j], e->own[i]);
            if (plan_cost_dead(e->s[pi])) {
                return false;
            }
            twice = plan_cost_twice(e->s[pi]);
            if (same_side(g, i, j) && plan_cost_compare(twice, best) > 0) {
                best = twice;
            }
        }
    }
    /* The largest doubled surcharge among the pairs chosen so far (one pair is a matching
     * of the child's), and from three choosers on their matching in closed form: lower
     * bounds on what the leaf adds exactly, which cut branches (4-8% fewer work units in
     * 4-UAV searches than the largest pair alone). */
    if (c >= 2u && c < 4u) {
        best = cost_larger(best, chosen_matching(pl, e, c, k1));
    }
    e->pairmax[c + 1u] = best;
    return true;
}

/* The child of the current combination, of doubled f f2: its exact g, stored. */
static bool child_add(coa_planner_t *pl, const expansion_t *e, coa_cost_t f2, uint32_t n,
                      uint32_t slot, plan_search_out_t *out)
{
    const plan_group_t *g = &pl->group;
    const uint32_t k1 = e->k + 1u;
    const int16_t *from = node_off(pl, e->n);
    node_init_t in;
    size_t c;

    in.g = pl->g[e->n];
    for (c = 0; c < e->ch.count; ++c) {
        const size_t i = e->ch.member[c];
        const size_t v = g->vehicle[i];
        const uint32_t t = e->choice[c];
        if (e->ch.enters[c]) {
            uint64_t cell = plan_table_at(plan_from_start(pl, i), k1, e->off[i]);
            in.g = plan_cost_add(in.g, plan_cell_cost(pl, v, cell));
            continue;
        }
        in.g = plan_cost_add(
            in.g,
            plan_pack(plan_units(pl, v, plan_area(from[i], e->off[i], plan_to_go(pl, i)->steep)),
                      coa_action_effort((coa_action_t)e->ch.moves[c].action[t])));
        if (g->last[i] == e->k) { /* leaves the search: its cost to go is exact */
            in.g = plan_cost_add(in.g, own_to_go(pl, i, k1, e->off[i]));
        }
    }
    in.parent = e->n;
    in.k = k1;
    in.off = e->off;
    in.f2 = f2;
    return node_put(pl, &in, n, slot, out);
}

/* A complete combination: its exact doubled f adds the matching of its surcharges. A
 * child already expanded is final (the heuristic is consistent): it is neither stored
 * nor counted for the next key, so its matching is not even computed (97% of the
 * children of a 4-UAV search are such duplicates). */
static bool leaf(coa_planner_t *pl, expansion_t *e, plan_search_out_t *out)
{
    uint32_t slot = 0u;
    uint32_t n;
    coa_cost_t f2;
    if (!slots_reserve(pl)) {
        return false;
    }
    n = state_find(pl, e->k + 1u, e->off, &slot);
    if (n != PLAN_NONE && (pl->node_k[n] & K_EXPANDED) != 0u) {
        return true;
    }
    if (!plan_work(pl, matching_work(&pl->group, e->in_child))) {
        return false;
    }
    f2 = plan_cost_add(e->partial[e->ch.count], matching(&pl->group, e->s, e->in_child));
    /* The branch bounds are lower bounds on the leaf's f, or branches that hold cheaper
     * children than their bound were cut: counted for the tests, which require none. */
    if (plan_cost_compare(f2, plan_cost_add(e->partial[e->ch.count], e->pairmax[e->ch.count])) <
        0) {
        ++pl->bound_breaks;
    }
    if (plan_cost_compare(f2, e->key) > 0) {
        cut(e, f2);
        return true;
    }
    if (over(pl, f2)) {
        return true;
    }
    return child_add(pl, e, f2, n, slot, out);
}

/* The combinations whose doubled f is at most the key, depth first in option order;
 * branches that cannot get there are cut. False: the pool is full, or the work budget
 * ran out (one unit per combination visited, plan.h "Work"). */
static bool enumerate(coa_planner_t *pl, expansion_t *e, plan_search_out_t *out)
{
    const size_t count = e->ch.count;
    const int16_t *off = node_off(pl, e->n);
    size_t c = 0u;

    e->choice[0] = 0u;
    for (;;) {
        coa_cost_t inc;
        coa_cost_t bound;
        /* Weighed by what the step costs: a member's move or entry tests and prices its
         * pairs with the c members chosen before it; a leaf finds, prices and stores the
         * child (plan.h, "Work"). */
        if (!plan_work(pl, c == count ? PLAN_WORK_LEAF + c : 1u + c)) {
            return false;
        }
        if (c == count) {
            if (!leaf(pl, e, out)) {
                return false;
            }
            if (c == 0u) {
                return true;
            }
            ++e->choice[--c];
            continue;
        }
        if (e->choice[c] >= e->ch.options[c]) {
            if (c == 0u) {
                return true;
            }
            ++e->choice[--c];
            continue;
        }
        inc = increase(pl, &e->ch, c, e->k, e->choice[c]);
        bound = plan_cost_add(plan_cost_add(e->partial[c], inc), e->ch.rest_min[c + 1u]);
        if (beyond(pl, e, plan_cost_add(bound, e->pairmax[c]))) {
            e->choice[c] = e->ch.options[c]; /* cheapest first: the rest go past it too */
            continue;
        }
        if ((!e->ch.enters[c] && !mover_clear(pl, &e->ch, e->k, c, e->choice, off)) ||
            !choose(pl, e, c)) {
            ++e->choice[c];
            continue;
        }
        bound = plan_cost_add(bound, e->pairmax[c + 1u]);
        if (beyond(pl, e, bound)) {
            ++e->choice[c];
            continue;
        }
        e->partial[c + 1u] = plan_cost_add(e->partial[c], inc);
        e->choice[++c] = 0u;
    }
}

/* Generates node n's children of doubled f up to its key, and puts it back under the
 * least f (or bound) left above it, if any. */
static bool expand(coa_planner_t *pl, uint32_t n, plan_search_out_t *out)
{
    const plan_group_t *g = &pl->group;
    expansion_t e;
    heur_t h;
    size_t i;

    e.n = n;
    e.k = (uint32_t)node_sample(pl, n);
    e.key = pl->key[n];
    /* Children of f up to the next node's key would be expanded before it anyway:
     * generating them now keeps the order and saves taking this node again for each. */
    if (pl->heap_count > 0u && plan_cost_compare(pl->key[pl->heap[0]], e.key) > 0) {
        e.key = pl->key[pl->heap[0]];
    }
    {
        coa_cost_t w = pl->batch;
        coa_cost_t r;
        r.lo = (pl->key[n].lo >> KEY_SHIFT) | (pl->key[n].hi << (64u - KEY_SHIFT));
        r.hi = pl->key[n].hi >> KEY_SHIFT;
        if (!pl->group.capped || plan_cost_compare(r, w) > 0) {
            w = r;
        }
        if (plan_cost_compare(plan_cost_add(pl->key[n], w), e.key) > 0) {
            e.key = plan_cost_add(pl->key[n], w);
        }
    }
    e.have_next = false;
    pl->node_k[n] |= K_EXPANDED;
    (void)heuristic(pl, e.k, node_off(pl, n), &h); /* live: the node was stored */
    e.partial[0] = plan_cost_sub(plan_cost_add(plan_cost_twice(pl->g[n]), h.h2), h.m2);
    e.pairmax[0] = (coa_cost_t){0u, 0u};
    e.in_child = 0u;
    for (i = 0; i < g->count; ++i) {
        e.off[i] = node_off(pl, n)[i];
        e.in_child |= in_search(g, i, e.k + 1u) ? 1u << i : 0u;
    }
    for (i = 0; i < g->count * (g->count - 1u) / 2u; ++i) {
        e.s[i] = (coa_cost_t){0u, 0u};
    }
    choosers_make(pl, n, &e.ch);
    if (!enumerate(pl, &e, out)) {
        return false;
    }
    if (e.have_next && !over(pl, e.next)) {
        pl->key[n] = e.next;
        heap_push(pl, n);
    }
    return true;
}

/* ------------------------------------------------------------------------------------ */
/* The search                                                                            */

/* Whether the members in the search at t = 0 are clear of each other and of the fixed
 * vehicles (obstacles and tracks: their tables' first steps cover t = 0). */
static bool root_clear(const coa_planner_t *pl)
{
    const plan_group_t *g = &pl->group;
    const coa_problem_t *pr = pl->problem;
    coa_sweep_t at0[PLAN_MAXM];
    size_t i;
    size_t j;

    for (i = 0; i < g->count; ++i) {
        int32_t o = pr->vehicles[g->vehicle[i]].initial_offset;
        if (g->first[i] != 0u) {
            continue;
        }
        at0[i] = coa_plan_vehicle_sweep(pr, pl->dh, g->vehicle[i], 0u, o, 0u, o);
        for (j = 0; j < i; ++j) {
            if (g->first[j] == 0u && coa_conflict_volumes(&at0[i], &at0[j])) {
                return false;
            }
        }
        for (j = 0; j < g->fixed_count; ++j) {
            size_t u = g->fixed[j];
            int32_t ou = pl->rows[u * ((size_t)pr->horizon + 1u)];
            coa_sweep_t f = coa_plan_vehicle_sweep(pr, pl->dh, u, 0u, ou, 0u, ou);
            if (coa_conflict_volumes(&at0[i], &f)) {
                return false;
            }
        }
    }
    return true;
}

/* The root: at sample 0 with the members that are in the search from the start, or just
 * before the first member enters. False when no plan can start. */
static bool root_add(coa_planner_t *pl, plan_search_out_t *out)
{
    const plan_group_t *g = &pl->group;
    int16_t off[PLAN_MAXM];
    uint32_t k = UINT32_MAX;
    node_init_t in;
    heur_t h;
    size_t i;

    for (i = 0; i < g->count; ++i) {
        off[i] = (int16_t)pl->problem->vehicles[g->vehicle[i]].initial_offset;
        k = g->first[i] < k ? g->first[i] : k;
    }
    k = k > 0u ? k - 1u : 0u;
    if ((k == 0u && !root_clear(pl)) || !heuristic(pl, k, off, &h)) {
        return false;
    }
    in.parent = PLAN_NONE;
    in.k = k;
    in.off = off;
    in.g = (coa_cost_t){0u, 0u};
    in.f2 = h.h2;
    pl->batch = (coa_cost_t){0u, 0u};
    if (!over(pl, in.f2)) {
        coa_cost_t span =
            pl->group.capped ? plan_cost_sub(plan_cost_twice(pl->group.cap), in.f2) : in.f2;
        unsigned sh = BATCH_SHIFT;
        pl->batch.lo = (span.lo >> sh) | (span.hi << (64u - sh));
        pl->batch.hi = span.hi >> sh;
    }
    return !over(pl, in.f2) && node_add(pl, &in, out);
}

/* The members' rows from the goal: the samples in the search from the nodes, before them
 * the cheapest way to the entry offset, after them the cheapest way on from the offset
 * each left at. */
static void write_rows(coa_planner_t *pl, uint32_t goal)
{
    const plan_group_t *g = &pl->group;
    const size_t row = (size_t)pl->problem->horizon + 1u;
    uint32_t n;
    size_t i;

    for (n = goal; n != PLAN_NONE; n = pl->parent[n]) {
        uint32_t k = (uint32_t)node_sample(pl, n);
        for (i = 0; i < g->count; ++i) {
            if (in_search(g, i, k)) {
                pl->rows[g->vehicle[i] * row + k] = node_off(pl, n)[i];
            }
        }
    }
    for (i = 0; i < g->count; ++i) {
        int32_t entry = pl->rows[g->vehicle[i] * row + g->first[i]];
        coa_plan_table_walk_back(pl, plan_to_go(pl, i), plan_from_start(pl, i), g->first[i], entry);
        coa_plan_table_walk(pl, plan_to_go(pl, i), g->last[i] + 1u, node_off(pl, goal)[i]);
    }
}

void coa_plan_search(coa_planner_t *pl, plan_search_out_t *out)
{
    out->status = COA_PLAN_INFEASIBLE;
    out->expanded = 0u;
    out->stored = 0u;
    out->bound2 = (coa_cost_t){0u, 0u};
    pl->m = pl->group.count;
    if (!root_add(pl, out)) {
        if (pl->used >= pl->capacity && pl->capacity > 0u) {
            out->status = COA_PLAN_BUDGET_EXHAUSTED;
        }
        return;
    }
    while (pl->heap_count > 0u) {
        uint32_t n = pl->heap[0];
        if (over(pl, pl->key[n])) {
            return; /* every plan left costs more than the cap or the bound */
        }
        if (node_sample(pl, n) == pl->group.end) {
            write_rows(pl, n);
            out->status = COA_PLAN_SOLVED;
            return;
        }
        /* The least f open: what the search has proven no plan costs less than. */
        out->bound2 = pl->key[n];
        heap_pop(pl);
        ++out->expanded;
        if (!expand(pl, n, out)) {
            out->status = COA_PLAN_BUDGET_EXHAUSTED;
            return;
        }
    }
}

/* ------------------------------------------------------------------------------------ */
/* Test hooks (plan_internal.h)                                                          */

bool coa_plan_test_heuristic(const coa_planner_t *pl, uint32_t k, const int16_t *off,
                             coa_cost_t *h2)
{
    heur_t h;
    if (!heuristic(pl, k, off, &h)) {
        return false;
    }
    *h2 = h.h2;
    return true;
}

uint64_t coa_plan_test_bound_breaks(const coa_planner_t *pl)
{
    return pl->bound_breaks;
}

bool coa_plan_test_match_all(coa_planner_t *pl, uint32_t members)
{
    if (members < 2u || members > PLAN_MATCH_ALL) {
        return false;
    }
    pl->match_all = members;
    return true;
}

coa_cost_t coa_plan_test_matching(const coa_cost_t *s, size_t m, uint32_t mask)
{
    return matching_of(s, m, mask);
}
