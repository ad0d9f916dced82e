/* SPDX-License-Identifier: MIT */
/*
 * plan.h: the A* planner, its fixed workspace, and the centralised and decoupled front ends.
 *
 * The big picture. A problem (coa_problem_t) is a set of co-operative UAVs with their
 * sampled reference trajectories, static obstacles and sampled non-cooperative tracks over
 * samples k = 0..N. A plan gives every UAV an altitude offset at every sample; it is
 * conflict-free when no step of it conflicts (geometry.h) with another UAV's step, an
 * obstacle or a track's step. Its cost is lexicographic: the deviation area first, then
 * the effort (trajectory.h). The decoupled front end returns a plan optimal for each UAV
 * given the ones before it, or proves there is none; the centralised one is anytime: it
 * returns the best plan it found within its limits, with a proven lower bound on the
 * optimum, and says when the two meet (optimal). Both run on one engine:
 *
 *   - Centralised: optimal for the whole group. Every UAV is first planned alone; while
 *     the plans of two groups of UAVs conflict, one group is re-planned around the
 *     other's plan at its own optimal cost (and then the other around the first), and
 *     only if neither can do that do the two merge into one group planned jointly:
 *     independence detection (Standley 2010). Each group's plan is optimal for the group
 *     alone and no two groups conflict at the end, so the sum of the groups' costs, a
 *     lower bound for the whole, is met: the plan is optimal. UAVs whose optimal plans
 *     never interact are never searched together.
 *   - Decoupled: UAVs plan one at a time in priority order; each treats the plans of the
 *     UAVs before it as moving obstacles and ignores those after it. Optionally, when one
 *     fails, other orders are tried, the failing UAV earlier first.
 *
 * Tables. Before planning, each UAV gets a table of its exact cost to go alone: a
 * backward pass over every (k, offset) it can reach from its initial offset, keeping for
 * each the least (deviation, effort) over its actions that stay within max_offset,
 * conflict with no obstacle and no track (decoupled: and no UAV planned before it) and
 * lead to a state from which k = N can be reached; states with no such action are dead.
 * A single UAV's optimal plan is then read off its table (walk from the start, taking
 * at each step the cheapest live action, ties in coa_action_t order and towards the
 * larger k as the paper orders them): no search, N steps. That is the whole decoupled
 * front end, one table per UAV against the plans before it, and how the centralised one
 * plans each UAV alone. A centralised planner also keeps each UAV's cost from the start
 * (the forward pass) for the joint searches.
 *
 * The joint search of a group. A member takes part only between the first and the last
 * step where it can come horizontally near another member or a fixed UAV (its span);
 * before, it flies its cheapest way to the offset it enters at, after, its cheapest way
 * on from where it leaves: both exact from its tables. A search state is (k, offsets of
 * the members in their span at k). Before searching, the members are planned in turn
 * (each around those before it): a plan of the group whose cost caps the search (nothing
 * dearer is stored), and which is already optimal when it costs no more than the members
 * alone. The heuristic (doubled so that halves stay integers) is twice the sum of the
 * members' own costs to go (or costs alone, for members not yet entered) plus the
 * largest half-integral fractional matching of the pairs' surcharges, a surcharge being
 * a pair's exact joint cost to go (a table over the pair's common span, within the cap's
 * corridor) less the two own costs. Each matching is a sum of exact pair costs to go and
 * own costs over disjoint sets, so it is admissible and consistent; so is their maximum
 * over any family of matchings fixed for the search. A group of more than six members
 * takes the matchings within two sides of at most six (the split, chosen before the
 * search, whose sides' matchings of the pairs' least surcharges add up most): the exact
 * matching of ten members would cost every child thousands of sums.
 * Expansion is partial (EPEA*, Goldenberg et al. 2014): the members' moves and the
 * entering members' offsets are enumerated depth first, each member's options in the
 * order of the increase of f they cause, cutting branches that cannot reach the
 * expansion's threshold; the node goes back to the open list under the least f it left,
 * so no expansion stores 5^n children. The threshold is the node's key plus a window (a
 * quarter of the gap between the root and the cap, at least a quarter of the key): with
 * costs as fine-grained as (deviation, effort) almost every child has an f of its own,
 * and a node would otherwise come back once per child. The open list orders f's
 * deviation, then its effort, then the later sample first, then the order nodes were
 * stored, so results are deterministic. States are found again by a hash table; a
 * better path to one not yet expanded updates it, expanded ones are final (the
 * heuristic is consistent). A goal at the top of the open list ends the search (solved);
 * an empty open list, or one whose least f is above the cap or the wanted bound, proves
 * there is no plan (infeasible); a pool with no room for a new state ends it with
 * nothing proven (budget exhausted).
 *
 * What beta counts. beta bounds the states each joint search stores (its node pool):
 * every state generated and kept, expanded or still open, the root included. Single UAVs
 * and decoupled plans store none (they walk tables), so the decoupled front end is never
 * budget exhausted and a one-UAV planner's workspace does not depend on beta. The
 * centralised front end runs at most one joint search per re-plan and per merge; beta
 * bounds each of them. An initial conflict (t = 0), or a UAV whose table is dead at its
 * initial offset, is infeasible with nothing expanded. nodes_expanded counts expansions,
 * a node taken back off the open list for more children counting again.
 *
 * Anytime (centralised). When the vehicles' own plans conflict, the planner first finds
 * an incumbent: the decoupled order search (coa_plan_decoupled with reordering, from the
 * priority order, at most 7! orders), which finds the first order that works within half
 * of what is left of the work budget and then, within a quarter of it counted from the
 * start, goes on through the other orders as a branch and bound (an order is abandoned
 * at the first vehicle where the costs so far and the others' costs alone reach the best
 * plan's) and keeps the cheapest plan. Every joint search of a group without fixed vehicles
 * is then capped by the incumbent's rows of its members (a plan of the group alone) when
 * they cost less than the members' plan in turn: nothing dearer is stored. When beta or
 * the work budget stops independence detection, each group's optimum alone (or, for the
 * group whose search stopped, the least f left open, and at least its parts' optima) is a
 * lower bound on what the group costs in any plan, so their sum bounds the whole; the
 * answer is then the incumbent, optimal when the bound reaches its cost, or no plan
 * (COA_PLAN_BUDGET_EXHAUSTED, only when no priority order tried worked) with the bound.
 * So a centralised answer never costs more than the cheapest priority order it tried
 * (every order, when the order search ran to its end; at least the first that works), and
 * COA_PLAN_SOLVED with result.optimal false carries a plan and [bound, cost] around the
 * optimum. Among plans of the optimal cost, the one returned is the first found: the
 * incumbent (the first order found at its cost) when it is proven optimal, else the joint searches' (ties as the open list
 * orders them); deterministic, and the same in both precisions.
 *
 * Work. A planning call can be given a budget of work units (coa_planner_set_work), which
 * it never passes: work is charged before it is done, and the call stops at the first
 * charge that does not fit (result.limit COA_PLAN_LIMIT_WORK). A unit is about one cheap
 * step of the planner: a table costs 5 units per cell of each row plus 5 per offset
 * tested against each obstacle, track or fixed vehicle whose box the row touches (a
 * polytope 1 + vertices / 8 units per test, its MPR test evaluating the support function
 * several times); a cost-from-start table 5 per cell; a pair table 1 per cell; a joint
 * search 1 + c per member choice made with c members chosen before it and 4 + m per
 * complete combination of m choosers, and for a new child 20 more per side of five members
 * and 50 per side of six (the pair matching of its heuristic; a second side 2 more at
 * least), and choosing the sides of a group above six 4 + m per split tried; growing
 * the hash table 1 per node it holds and per 32 slots; each check of the groups' plans
 * N n^2. The same
 * call with the same budget does the same work everywhere (the count never depends on a
 * clock), so a budget is a deterministic bound on time: docs/benchmarks.md gives the time
 * per unit measured on the host.
 *
 * Costs. The search minimises, lexicographically, the integer deviation
 * sum_i W_i * coa_area_scaled(a, b, S) (S = coa_area_scale and W_i 2^E =
 * coa_deviation_weights over all the problem's UAVs, whichever are searched), one unit
 * being 2^E / S m^2, and then the effort. Deviations are exact 128-bit integers
 * (coa_cost_t): the worst f = g + h, 2 N sum_i W_i S B_i with B_i the largest |offset|
 * vehicle i can reach, is below 2^64 * 2^13 * 2^15 * 2^15 * 2^5 = 2^112 by the limits of
 * common.h (W_i < 2^64, S <= 5040, B_i <= 32767, 2N <= 20000, n <= 32), so no sum the
 * search forms can wrap. The tables hold each UAV's own deviation in units of 1/(2 s_i)
 * of its L_i dh_i, below 2^35.
 *
 * Memory. The planner lives in a buffer the caller provides, as in o1heap: describe the
 * largest problems it must take in a coa_planner_config_t, ask coa_planner_workspace_size
 * for the byte count, hand coa_planner_init a buffer of that size aligned to
 * COA_WORKSPACE_ALIGNMENT, and use the returned handle. Nothing is allocated, nothing
 * needs freeing; the buffer can be reused for any number of plans within the config. It
 * holds:
 *   - the tables: one for vehicles == 1, else 2 * vehicles + 1 (cost to go and from the
 *     start of each, one for re-plans around fixed UAVs), each of
 *     T = sum over k = 0..N of min(2 k s + 1, 2 L + 1) cells of 8 bytes (N, s and L the
 *     config's horizon, steep factor and offset bound): every offset reachable in k
 *     steps, within the bound; 1,225 cells (9.8 kB) for N = 24 and s = 2;
 *   - for vehicles > 1: per member an entry list of one table row, its saved plan row and
 *     its incumbent row,
 *     and the node pool of beta nodes of 70 + 2 * vehicles bytes: key and g 16 each
 *     (128-bit packed costs), parent, heap entry and position 4 each, 2 hash slots of 4,
 *     sample 2, offsets 2 per UAV, and 16 bytes of pair-table arena (a pair table that
 *     does not fit is left out: a weaker heuristic, never a wrong one);
 *   - a fixed header (the per-call context, a few kB).
 * A call writes only what it uses of this (result.workspace_touched_bytes): the tables of
 * its problem's size, and for a joint search the nodes it stores and a hash table that
 * starts at 256 slots and doubles before it is half full (each growth re-enters the
 * search's nodes and is charged as work), so a small problem in a large workspace leaves
 * most of its pages untouched.
 * Running out of room can only happen through beta and is always reported as
 * COA_PLAN_BUDGET_EXHAUSTED (or, centralised, as a plan not proven optimal), never as
 * infeasible. docs/embedded.md has the bytes for
 * each vehicle count on the host and on a Cortex-M4F. The planner keeps state between
 * calls in its buffer: one planner serves one thread at a time.
 *
 * Floor. A problem may set a floor (has_floor, floor_z): a minimum altitude for the
 * bottom of every UAV's protected volume. A sample whose offset puts the volume's bottom
 * below it is invalid exactly as a sample whose step meets an obstacle: its table cell is
 * dead, so no table walk, no cost from the start, no pair table and no joint search (all
 * of which take their moves from the tables) ever goes there, and a UAV below the floor
 * at its initial offset is an initial conflict (infeasible, nothing expanded). The
 * floor is tested at the samples only: between two samples a UAV moves in a straight
 * line, so a step whose two ends are above the floor stays above it. Terrain itself comes
 * in as obstacles (boxes and polytopes); the floor is the minimum altitude everywhere
 * else.
 *
 * Time. A table costs one pass over its cells with a conflict test for each action whose
 * step comes near (box test) an obstacle, a track or a fixed UAV; a pair table one pass
 * over its corridor with the pair's conflict tests. A joint expansion enumerates at most
 * 5^m move combinations of the m members in their span (times their entry offsets),
 * usually far fewer thanks to the cuts, with O(m^2) conflict tests per combination tried
 * and O(log beta) heap work per child; a search stores at most beta nodes, and a node is
 * expanded at most once per distinct f among its children. Independence detection
 * checks the groups' plans for conflicts after every search (O(N n^2) volume tests) and
 * runs fewer than n^2 re-plans and merges. docs/benchmarks.md has the figures.
 */
#ifndef COAVOID_PLAN_H
#define COAVOID_PLAN_H

#include "coavoid/common.h"
#include "coavoid/geometry.h"
#include "coavoid/trajectory.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A planning problem. Everything is the caller's and is only read. */
typedef struct {
    coa_real_t dt;    /* s, > 0 */
    uint32_t horizon; /* N, 1..COA_MAX_HORIZON */
    const coa_vehicle_t *vehicles;
    size_t vehicle_count; /* 1..COA_MAX_VEHICLES */
    /* references[i] holds horizon+1 samples of vehicle i's reference (coa_reference_sample) */
    const coa_vec3_t *const *references;
    const coa_obstacle_t *obstacles;
    size_t obstacle_count;
    const coa_track_t *tracks; /* only each track's volume is used here */
    size_t track_count;
    /* track_samples[j] holds horizon+1 samples of track j (coa_track_sample) */
    const coa_vec3_t *const *track_samples;
    /* The floor (file comment, "Floor"): with has_floor, no UAV's protected volume may
     * reach below floor_z (m, finite) at any sample; false: no floor, floor_z unread. */
    bool has_floor;
    coa_real_t floor_z;
} coa_problem_t;

typedef enum {
    COA_PLAN_SOLVED = 0, /* a conflict-free plan; centralised, optimal when result.optimal */
    COA_PLAN_INFEASIBLE =
        1, /* the search space is exhausted: no plan exists (decoupled: for this order) */
    COA_PLAN_BUDGET_EXHAUSTED = 2 /* beta or the work budget ran out before any plan was
                                     found: no plan, and none proven impossible */
} coa_plan_status_t;

/* Which limit ended a planning call early (file comment, "Anytime"). */
typedef enum {
    COA_PLAN_LIMIT_NONE = 0, /* nothing: the call finished its search */
    COA_PLAN_LIMIT_BETA = 1, /* a joint search filled its beta nodes */
    COA_PLAN_LIMIT_WORK = 2  /* the call spent its work budget */
} coa_plan_limit_t;

#define COA_NO_VEHICLE ((size_t)-1)

typedef struct {
    coa_plan_status_t status;
    /* Costs: totals over every vehicle when solved; decoupled and not solved, over the
     * planned_count vehicles of `order`; otherwise 0. */
    double deviation;           /* m^2, by the exact formula */
    coa_cost_t deviation_units; /* the exact integer the planner minimised, in units of
                                   2^E / S m^2 (file comment, "Costs") */
    uint32_t effort;
    uint64_t nodes_expanded;  /* over every search this call ran */
    uint64_t nodes_generated; /* states the joint searches stored (at most beta a
                                  search; 0 when none ran): duplicates of stored states,
                                  dead ones and those above the cap are not stored */
    size_t workspace_bytes;   /* size of the workspace the planner ran in */
    /* The bytes of it the planner has written since coa_planner_init, every call
     * counted (a high-water mark: its header, the tables' cells its problems reached,
     * the incumbent's rows, and the nodes, pair cells and hash slots its largest search
     * used; each array rounded up to 8 bytes): what a caller's memory actually holds of
     * it, the rest untouched. */
    size_t workspace_touched_bytes;
    /* Planning order as vehicle indices: decoupled, the order of the reported attempt;
     * centralised, 0..n-1. */
    size_t order[COA_MAX_VEHICLES];
    /* Vehicles whose offsets rows are a valid plan: n when solved; decoupled and not
     * solved, the first planned_count vehicles of `order`. */
    size_t planned_count;
    size_t failed_vehicle;   /* decoupled, not solved: index of the first UAV with no plan */
    uint32_t orders_tried;   /* decoupled: priority orders attempted (1 without reordering) */
    bool all_orders_covered; /* decoupled, not solved: every order was tried or ruled out
                                  (a failing prefix; a UAV infeasible when planned first; a
                                  conflict at t = 0, which no order avoids). With status
                                  infeasible, no order has a plan; with budget exhausted,
                                  some order failed only through beta. false when solved,
                                  centralised, or when max_orders ended the search first */
    uint32_t searches;       /* plans this call made: each table built and walked
                                  against fixed UAVs (decoupled: one per UAV planned)
                                  and each joint search of a group */
    size_t largest_group;    /* centralised: the most UAVs searched together (0 when
                                  nothing was searched) */
    /* Centralised (file comment, "Anytime"): a lower bound on the optimum, exact and
     * lexicographic: no plan costs less than (bound_units, bound_effort); bound_deviation
     * is bound_units in m^2. 0 when nothing is known (decoupled, infeasible, or the
     * budget ran out before every vehicle's table was built). */
    double bound_deviation;
    coa_cost_t bound_units;
    uint32_t bound_effort;
    bool optimal;           /* solved and proven optimal: the cost meets the bound */
    coa_plan_limit_t limit; /* the limit that ended the call early, if any */
    uint64_t work;          /* work units the call spent (file comment, "Work") */
} coa_plan_result_t;

typedef struct coa_planner coa_planner_t;

/* The largest problems a planner must take. A problem fits when it has at most
 * `vehicles` UAVs (centralised; decoupled plans any number with vehicles >= 1), its
 * horizon is at most `horizon`, and each UAV's table (file comment, "Memory"), computed
 * with its own steep factor and offset bound, holds no more cells than one computed with
 * `steep_factor` and `max_offset`: so any UAV with a steep factor <= steep_factor and
 * |max_offset| <= max_offset (unbounded only when max_offset < 0). */
typedef struct {
    size_t vehicles;       /* UAVs searched together: 1..COA_MAX_CENTRALISED */
    uint32_t beta;         /* nodes a joint search stores, >= 1 */
    uint32_t horizon;      /* longest N, 1..COA_MAX_HORIZON */
    uint32_t steep_factor; /* largest steep factor, 2..COA_MAX_STEEP_FACTOR */
    int32_t max_offset;    /* largest offset bound; negative: unbounded (COA_MAX_OFFSET) */
} coa_planner_config_t;

/* The config that fits `problem` exactly: its horizon, its largest steep factor and
 * offset bound (negative when a UAV is unbounded), with the given vehicles and beta.
 * Returns COA_OK, or COA_ERR_ARGUMENT when a pointer is NULL, the problem has no UAVs or
 * more than COA_MAX_VEHICLES, or the resulting config is not one the size function
 * accepts (vehicles or beta out of range, horizon 0 or too long, steep factor > 10).
 * Reads the problem's counts and vehicles only. Cost O(vehicles), no memory. */
int coa_planner_config_of(const coa_problem_t *problem, size_t vehicles, uint32_t beta,
                          coa_planner_config_t *config);

/* Bytes of workspace for a config (file comment, "Memory"). Returns 0 when config is
 * NULL, a field is out of its range, beta reaches 2^30 nodes, or the
 * size would not fit in size_t. Cost O(1), no memory. The size is exact: one byte less is
 * refused by coa_planner_init. */
size_t coa_planner_workspace_size(const coa_planner_config_t *config);

/* The inverse, for a buffer whose size is fixed first (a static array in firmware): the
 * largest beta with coa_planner_workspace_size(config with that beta) <= bytes, so that
 * coa_planner_init succeeds on any suitably aligned buffer of `bytes` bytes with it.
 * config->beta is ignored. Returns 0 when config is NULL or out of range, or `bytes` is
 * smaller than the workspace for beta = 1; at most 2^30 - 1. Exact: with b =
 * coa_planner_max_beta(c, coa_planner_workspace_size(c)), b == c->beta when c->vehicles
 * > 1; a one-vehicle planner stores no nodes, its size does not depend on beta, and any
 * `bytes` that hold it give 2^30 - 1. Cost O(log beta) (a bisection over the size
 * function), no memory. Note that beta also sizes the arena of the joint searches' pair
 * tables (file comment, "Memory"): a pair table that does not fit is left out, so a
 * search at a small beta can store more nodes than the same search with room. */
uint32_t coa_planner_max_beta(const coa_planner_config_t *config, size_t bytes);

/* Builds a planner inside `buffer`. Returns the handle (which points into the buffer, so
 * the buffer must not move while it is used), or NULL when buffer is NULL or not aligned
 * to COA_WORKSPACE_ALIGNMENT, the config is refused by coa_planner_workspace_size, or
 * size is smaller than it says. Writes the header and the hash table's first 256 slots,
 * nothing else: O(1). Each later search first clears the slots the one before it used
 * (one by one, or all when that is cheaper). */
coa_planner_t *coa_planner_init(void *buffer, size_t size, const coa_planner_config_t *config);

/* Sets the work budget of each of the planner's later calls, in work units (file
 * comment, "Work"); 0, what coa_planner_init sets, is no limit. A coordinator gives each
 * call what is left of its cycle. Returns COA_OK, COA_ERR_ARGUMENT for NULL, or
 * COA_ERR_WORKSPACE for a buffer coa_planner_init did not build. Cost O(1), no memory. */
int coa_planner_set_work(coa_planner_t *planner, uint64_t work);

/* Checks a problem in full (counts, finite numbers, every vehicle and track, unique ids,
 * obstacles, non-NULL and finite samples) before a search trusts it. Returns COA_OK,
 * COA_ERR_ARGUMENT, or COA_ERR_RANGE when the costs cannot be exact: the deviation
 * weights do not fit 64 bits (coa_deviation_weights), or the worst-case f = g + h,
 * 2 N sum_i W_i S B_i with B_i = min(|initial_offset| + N s_i, max_offset when bounded,
 * COA_MAX_OFFSET), reaches 2^127 (which the limits of common.h rule out today: see the
 * file comment; the check guards against raising them). Cost O(vehicles * (route + N +
 * vehicles) + tracks * (path + N) + polytope vertices), no memory. */
int coa_problem_check(const coa_problem_t *problem);

/* Centralised plan of every vehicle of the problem, anytime (file comment, "Anytime"):
 * independence detection over searches of groups, capped by an incumbent found by the
 * decoupled order search.
 * offsets: vehicle_count * (horizon+1) int32, row i is vehicle i; filled when solved,
 * unspecified otherwise (the searches of groups write their rows as they go). Returns
 * COA_OK with the outcome in *result, or COA_ERR_ARGUMENT (NULL, problem check failed),
 * COA_ERR_RANGE, or COA_ERR_WORKSPACE (planner built for fewer vehicles, a horizon, steep
 * factor or offset bound beyond its config, or not a planner). On an error *result is
 * cleared (when not NULL). An initial conflict (t = 0) is COA_PLAN_INFEASIBLE with no
 * node expanded; so is a vehicle that cannot reach k = N alone. A group without a plan
 * makes the call infeasible. When beta or the work budget stops it (result.limit), the
 * answer is the incumbent (COA_PLAN_SOLVED, optimal when the bound meets its cost) or,
 * without one, COA_PLAN_BUDGET_EXHAUSTED; bound_* hold the lower bound in every outcome
 * but infeasible. The result's order is 0..n-1, orders_tried 1, failed_vehicle
 * COA_NO_VEHICLE; the costs are 0 unless solved. Cost: the problem check, 2n tables, the
 * incumbent's order search (at most 7! orders of n tables), then fewer than n^2 joint
 * searches (each with its pair tables) of at most beta stored nodes each (see the file
 * comment), all within the work budget when one is set; no memory beyond the workspace
 * and O(1) stack. */
int coa_plan_centralised(coa_planner_t *planner, const coa_problem_t *problem, int32_t *offsets,
                         coa_plan_result_t *result);

/* Decoupled plan: vehicles plan one at a time in `order` (vehicle indices, a permutation
 * of 0..n-1; NULL: ascending priority, ties by ascending id), each against obstacles,
 * tracks and the plans of the vehicles before it. With max_orders == 1 the first failure
 * ends the call (status infeasible, failed_vehicle set: a table walk cannot run out of
 * beta, so decoupled is never budget exhausted). With
 * max_orders > 1, other orders are tried depth-first over their prefixes, reusing the
 * plans of the prefix they share: after a failure at position F the search goes back to
 * the deepest position P <= F that still has a vehicle not yet tried there under the
 * same prefix (a bitmask per position), and puts there the vehicle that failed if it has
 * not been tried at P, else the first untried one in the current order; the vehicles
 * after P keep their relative order. So the failing vehicle moves earlier as the orders
 * below each prefix run out, and no part of the tree is left behind: the search stops
 * when an order succeeds, when every order has been tried or ruled out, or after
 * max_orders attempts. Orders are ruled out by a failing prefix (every order that starts
 * with it), and all at once by a proof that none can work: a vehicle infeasible in first
 * position, against obstacles and tracks alone; or, checked once the first attempt has
 * failed, a conflict at t = 0 (two vehicles at their k = 0 positions and initial offsets,
 * or one of them and an obstacle or a track), which is in the way of every order. If
 * none succeeds the result reports the first order's attempt (order, planned_count,
 * failed_vehicle and the rows of the planned vehicles, re-planned if a later attempt
 * overwrote them) and all_orders_covered. The status is infeasible when a proof covers
 * every order (even if some attempt, the reported one included, ran out of beta) or when
 * no attempt ran out of beta; otherwise budget exhausted. orders_tried counts the
 * attempts; nodes are summed over every search, re-plans included. The costs cover the
 * planned_count vehicles of the reported order. Rows of other vehicles are unspecified.
 * With a work budget (file comment, "Work") that runs out, the search stops there: status
 * budget exhausted unless a proof covers every order, result.limit COA_PLAN_LIMIT_WORK,
 * and the report keeps only the planned rows no later attempt overwrote.
 * Errors as coa_plan_centralised (the planner needs room for one vehicle), and
 * COA_ERR_ARGUMENT when max_orders is 0 or `order` is not a permutation.
 * Cost: in the worst case min(max_orders, n!) attempts of at most n single-UAV tables and
 * walks each (fewer when attempts share a prefix), then
 * at most n re-plans of the first order; plus, after a failed first attempt,
 * n (obstacles + tracks) + n(n-1)/2 volume checks at t = 0. The rules above only cut
 * this short in the cases they name: two UAVs that can never pass each other (but are
 * clear at t = 0) among n-2 that never interact still take about half of the n! orders
 * (docs/benchmarks.md has counts), so bound max_orders when n is more than a few. No
 * memory beyond the workspace, O(n) stack. */
int coa_plan_decoupled(coa_planner_t *planner, const coa_problem_t *problem, const size_t *order,
                       uint32_t max_orders, int32_t *offsets, coa_plan_result_t *result);

/* The priority order of a problem's vehicles (ascending priority, ties by ascending id)
 * as indices into order[0..n-1]. Returns COA_OK or COA_ERR_ARGUMENT (NULL, n == 0 or
 * n > COA_MAX_VEHICLES). Cost O(n^2), no memory. */
int coa_priority_order(const coa_vehicle_t *vehicles, size_t n, size_t *order);

/* Deviation (m^2, exact formula, in double) and effort of one vehicle's
 * offsets[0..horizon]. Returns COA_OK, or COA_ERR_ARGUMENT when a step is not one of the
 * five actions, an offset exceeds COA_MAX_OFFSET, a pointer is NULL, dt is not finite and
 * positive, horizon is out of range, or the vehicle's speeds or steep factor are invalid
 * (outputs untouched). Cost O(N), no memory. */
int coa_plan_vehicle_cost(const coa_vehicle_t *vehicle, coa_real_t dt, uint32_t horizon,
                          const int32_t *offsets, double *deviation, uint32_t *effort);

/* Whether a UAV whose protected volume is `volume`, its centre at altitude z (its
 * reference's z plus offset * dh, as the planner computes it), keeps the whole volume at
 * or above floor_z: z - half_height >= floor_z (touching the floor is clear; NaN is not).
 * The one rule of the floor for the planner and for a node checking a received plan.
 * Cannot fail (volume non-NULL); O(1), no memory. */
bool coa_above_floor(coa_real_t floor_z, const coa_volume_t *volume, coa_real_t z);

/* Whether a full plan (rows for the vehicles listed in `which[0..count-1]`, others
 * ignored) is conflict-free against obstacles, tracks and each other by geometry.h, and
 * above the floor when the problem has one (a sample below it is a conflict of the step
 * that reaches it, or of step 0 for sample 0).
 * Returns 0 (conflict-free), 1 (a conflict: the earliest step, and at that step the first
 * listed vehicle in conflict; *vehicle and *step say where when not NULL), or
 * COA_ERR_ARGUMENT (the problem's argument checks of coa_problem_check, the range check
 * excepted; NULL offsets; `which` NULL, out of range or repeating a vehicle). Cost
 * O(N * count * (count + obstacles + tracks)) plus the problem's argument checks, no
 * memory. */
int coa_plan_find_conflict(const coa_problem_t *problem, const int32_t *offsets,
                           const size_t *which, size_t count, size_t *vehicle, uint32_t *step);

#ifdef __cplusplus
}
#endif

#endif /* COAVOID_PLAN_H */
