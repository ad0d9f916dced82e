/*
 * plan.h: the A* planner, its fixed workspace, and the centralised and decoupled front ends.
 *
 * The big picture. A problem (coa_problem_t) is a set of co-operative UAVs with their
 * sampled reference trajectories, static obstacles and sampled non-cooperative tracks over
 * samples k = 0..N. A plan gives every UAV an altitude offset at every sample; it is
 * conflict-free when no step of it conflicts (geometry.h) with another UAV's step, an
 * obstacle or a track's step. Its cost is lexicographic: the deviation area first, then
 * the effort (trajectory.h).
 *
 * One A* engine solves both front ends. A search state is (k, offsets of the searched
 * UAVs); the goal is any state with k = N. The open list is a binary heap ordered by
 * f-deviation, then f-effort, then larger k first (as the paper orders it), then by the
 * order nodes were generated, so results are deterministic. Duplicate states are found
 * by a hash table: a better path to an open state updates it; closed states are final
 * (the heuristic is consistent). The search looks at the top of the open list before
 * each expansion: a goal there is optimal and ends the search (solved), even when beta
 * states have already been closed; otherwise the search stops when beta states have been
 * closed (budget exhausted: nothing proven) or when the open list empties (infeasible:
 * the space is exhausted). So a problem whose plan needs exactly beta expansions is
 * solved: a free single UAV over N steps needs beta = N.
 *
 *   - Centralised: one search over the composite state of all UAVs, with the composite
 *     action space (every combination of five actions per UAV, 5^n children a node).
 *     Optimal for the whole group.
 *   - Decoupled: UAVs plan one at a time in priority order; each treats the plans of the
 *     UAVs before it as moving obstacles and ignores those after it. Optionally, when one
 *     fails, other orders are tried, the failing UAV earlier first.
 *
 * Children. Each UAV's actions come in coa_action_t order (level, climb, dive, steep climb,
 * steep dive); a composite child combines them with UAV 0 varying slowest. An action is
 * not generated when it would take |offset| past the UAV's max_offset or past
 * COA_MAX_OFFSET. A child is valid when each UAV's step (its protected volume swept from
 * its position at k to k+1) conflicts with no obstacle, no track's step, no fixed UAV's
 * step (decoupled: the UAVs planned before it) and no other searched UAV's step in the
 * same composite action. Each expansion tests every (UAV, action) against the environment
 * once and every pair of UAVs' actions once, then combines the results over the 5^m
 * children. The root is checked at t = 0 (positions at k = 0) the same way; a conflict
 * there is infeasible with nothing expanded.
 *
 * Costs. The search minimises, lexicographically, the integer deviation
 * sum_i W_i * coa_area_scaled(a, b, S) (S = coa_area_scale and W_i 2^E =
 * coa_deviation_weights over all the problem's UAVs, whichever are searched), one unit
 * being 2^E / S m^2, and then the effort; the heuristic is
 * sum_i W_i * coa_heuristic_scaled(offset_i, N - k, s_i, S) for the deviation and 0 for
 * the effort. Deviations are exact 128-bit integers (coa_cost_t): the worst f = g + h,
 * 2 N sum_i W_i S B_i with B_i the largest |offset| vehicle i can reach, is below
 * 2^64 * 2^13 * 2^15 * 2^15 * 2^5 = 2^112 by the limits of common.h (W_i < 2^64,
 * S <= 5040, B_i <= 32767, 2N <= 20000, n <= 32), so no sum the search forms can wrap.
 *
 * Memory. The planner lives in a buffer the caller provides, as in o1heap: ask
 * coa_planner_workspace_size(n, beta) for the byte count, hand coa_planner_init a buffer
 * of that size aligned to COA_WORKSPACE_ALIGNMENT, and use the returned handle. Nothing
 * is allocated, nothing needs freeing; the buffer can be reused for any number of plans
 * with at most n searched UAVs and beta closed states. Node storage is sized for the worst
 * case (1 + beta * 5^n nodes), so running out of room can only happen through beta and is
 * always reported as COA_PLAN_BUDGET_EXHAUSTED, never as infeasible.
 *
 * A node takes 50 + 2n bytes (k 2, parent 4, g and f deviation 16 + 16, g effort 4, heap
 * position 4, heap entry 4, offsets 2 per UAV) plus 8 to 16 bytes of hash table (a power
 * of two of at least two slots per node, 4 bytes a slot): 60 to 68 bytes for n = 1, 70 to
 * 78 for n = 6 (16 more than with 64-bit costs, the price of exact ties between any
 * vehicles). Add a fixed header of about 6.9 kB (the per-expansion validity tables and
 * sweeps live there, not on the stack; 2,112 bytes less with COA_SINGLE_PRECISION, whose
 * 62 sweeps and 32 climb steps there are float). For example n = 1, beta = 10000: 3.1 MB; n = 3,
 * beta = 1000: 8.1 MB; n = 4, beta = 1000: 45 MB. The planner keeps state between calls
 * in its buffer: one planner serves one thread at a time.
 *
 * Time. One expansion costs 25 n(n-1)/2 pairwise volume checks among the searched UAVs,
 * 5 n (obstacles + tracks + fixed UAVs) environment checks (polytopes cost MPR support
 * calls past a bounding-box test), and O(5^n * n) to combine them into children, each
 * with an expected O(n) hash look-up and O(log pool) heap work; a search does at most
 * beta expansions. Measured (x86-64, -O2): two UAVs head-on over 12 steps take 121
 * expansions (0.24 ms); four UAVs converging on one point over 20 steps take 72k
 * expansions and 36M children (2.4 s), against 271 expansions (0.2 ms) decoupled. Exact
 * 128-bit costs make large searches about 8% slower: the paper scenario's centralised plan
 * (three UAVs, 24 steps, 48.5k expansions, 4.2M children) went from 0.215 s to 0.233 s
 * (medians of seven runs, coavoid plan, RelWithDebInfo).
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
    coa_real_t dt;         /* s, > 0 */
    uint32_t horizon;      /* N, 1..COA_MAX_HORIZON */
    const coa_vehicle_t *vehicles;
    size_t vehicle_count;  /* 1..COA_MAX_VEHICLES */
    /* references[i] holds horizon+1 samples of vehicle i's reference (coa_reference_sample) */
    const coa_vec3_t *const *references;
    const coa_obstacle_t *obstacles;
    size_t obstacle_count;
    const coa_track_t *tracks; /* only each track's volume is used here */
    size_t track_count;
    /* track_samples[j] holds horizon+1 samples of track j (coa_track_sample) */
    const coa_vec3_t *const *track_samples;
} coa_problem_t;

typedef enum {
    COA_PLAN_SOLVED = 0,           /* a plan was found and it is optimal */
    COA_PLAN_INFEASIBLE = 1,       /* the search space is exhausted: no plan exists (decoupled: for this order) */
    COA_PLAN_BUDGET_EXHAUSTED = 2  /* beta states were closed before an answer: nothing proven */
} coa_plan_status_t;

#define COA_NO_VEHICLE ((size_t)-1)

typedef struct {
    coa_plan_status_t status;
    /* Costs: totals over every vehicle when solved; decoupled and not solved, over the
     * planned_count vehicles of `order`; otherwise 0. */
    double deviation;          /* m^2, by the exact formula */
    coa_cost_t deviation_units; /* the exact integer the planner minimised, in units of
                                   2^E / S m^2 (file comment, "Costs") */
    uint32_t effort;
    uint64_t nodes_expanded;   /* over every search this call ran */
    uint64_t nodes_generated;  /* children that passed the conflict checks */
    size_t workspace_bytes;    /* size of the workspace the planner ran in */
    /* Planning order as vehicle indices: decoupled, the order of the reported attempt;
     * centralised, 0..n-1. */
    size_t order[COA_MAX_VEHICLES];
    /* Vehicles whose offsets rows are a valid plan: n when solved; decoupled and not
     * solved, the first planned_count vehicles of `order`. */
    size_t planned_count;
    size_t failed_vehicle;     /* decoupled, not solved: index of the first UAV with no plan */
    uint32_t orders_tried;     /* decoupled: priority orders attempted (1 without reordering) */
    bool all_orders_covered;   /* decoupled, not solved: every order was tried or ruled out
                                  (a failing prefix; a UAV infeasible when planned first; a
                                  conflict at t = 0, which no order avoids). With status
                                  infeasible, no order has a plan; with budget exhausted,
                                  some order failed only through beta. false when solved,
                                  centralised, or when max_orders ended the search first */
} coa_plan_result_t;

typedef struct coa_planner coa_planner_t;

/* Bytes of workspace for searches over at most `max_vehicles` UAVs at once (n for
 * centralised, 1 is enough for decoupled) with closed-set bound beta (see the file comment
 * for the bytes per node). Returns 0 when max_vehicles is 0 or > COA_MAX_CENTRALISED,
 * beta is 0, the node pool 1 + beta * 5^max_vehicles exceeds 2^30, or the size would not
 * fit in size_t. Cost O(n), no memory. The size is exact: one byte less is refused. */
size_t coa_planner_workspace_size(size_t max_vehicles, uint32_t beta);

/* The inverse, for a buffer whose size is fixed first (a static array in firmware): the
 * largest beta with coa_planner_workspace_size(max_vehicles, beta) <= bytes, so that
 * coa_planner_init(buffer, bytes, max_vehicles, coa_planner_max_beta(max_vehicles, bytes))
 * succeeds on any suitably aligned buffer of `bytes` bytes. Returns 0 when max_vehicles is
 * 0 or > COA_MAX_CENTRALISED or `bytes` is smaller than the workspace for beta = 1; at
 * most the largest beta whose node pool 1 + beta * 5^max_vehicles fits 2^30. Exact: with
 * b = coa_planner_max_beta(n, coa_planner_workspace_size(n, beta)), b == beta. Cost
 * O(n log beta) (a bisection over the size function), no memory. */
uint32_t coa_planner_max_beta(size_t max_vehicles, size_t bytes);

/* Builds a planner inside `buffer`. Returns the handle (which points into the buffer, so
 * the buffer must not move while it is used), or NULL when buffer is NULL or not aligned
 * to COA_WORKSPACE_ALIGNMENT, the arguments are refused by coa_planner_workspace_size, or
 * size is smaller than it says. Writes only the first coa_planner_workspace_size bytes.
 * Cost O(hash table) to clear it; each later search first clears the entries the one
 * before it used (entry by entry, or the whole table when that is cheaper). */
coa_planner_t *coa_planner_init(void *buffer, size_t size, size_t max_vehicles, uint32_t beta);

/* Checks a problem in full (counts, finite numbers, every vehicle and track, unique ids,
 * obstacles, non-NULL and finite samples) before a search trusts it. Returns COA_OK,
 * COA_ERR_ARGUMENT, or COA_ERR_RANGE when the costs cannot be exact: the deviation
 * weights do not fit 64 bits (coa_deviation_weights), or the worst-case f = g + h,
 * 2 N sum_i W_i S B_i with B_i = min(|initial_offset| + N s_i, max_offset when bounded,
 * COA_MAX_OFFSET), reaches 2^127 (which the limits of common.h rule out today: see the
 * file comment; the check guards against raising them). Cost O(vehicles * (route + N +
 * vehicles) + tracks * (path + N) + polytope vertices), no memory. */
int coa_problem_check(const coa_problem_t *problem);

/* Centralised plan of every vehicle of the problem in one composite search.
 * offsets: vehicle_count * (horizon+1) int32, row i is vehicle i; filled when solved,
 * untouched otherwise. Returns COA_OK with the outcome in *result, or COA_ERR_ARGUMENT
 * (NULL, problem check failed), COA_ERR_RANGE, or COA_ERR_WORKSPACE (planner built for
 * fewer vehicles, or not a planner). On an error *result is cleared (when not NULL).
 * An initial conflict (t = 0) is COA_PLAN_INFEASIBLE with no node expanded. The result's
 * order is 0..n-1, orders_tried 1, failed_vehicle COA_NO_VEHICLE; the costs are 0 unless
 * solved. Cost: the problem check, then at most beta expansions (see the file comment);
 * no memory beyond the workspace and O(1) stack. */
int coa_plan_centralised(coa_planner_t *planner, const coa_problem_t *problem,
                         int32_t *offsets, coa_plan_result_t *result);

/* Decoupled plan: vehicles plan one at a time in `order` (vehicle indices, a permutation
 * of 0..n-1; NULL: ascending priority, ties by ascending id), each against obstacles,
 * tracks and the plans of the vehicles before it. With max_orders == 1 the first failure
 * ends the call (status infeasible or budget exhausted, failed_vehicle set). With
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
 * Errors as coa_plan_centralised (the planner needs room for one vehicle), and
 * COA_ERR_ARGUMENT when max_orders is 0 or `order` is not a permutation.
 * Cost: in the worst case min(max_orders, n!) attempts of at most n single-UAV searches
 * each (fewer when attempts share a prefix), each search at most beta expansions, then
 * at most n re-plans of the first order; plus, after a failed first attempt,
 * n (obstacles + tracks) + n(n-1)/2 volume checks at t = 0. The rules above only cut
 * this short in the cases they name: two UAVs that can never pass each other (but are
 * clear at t = 0) among n-2 that never interact still take about half of the n! orders
 * (measured: 3262 attempts for n = 7, 191802 for n = 9), so bound max_orders when n is
 * more than a few. No memory beyond the workspace, O(n) stack. */
int coa_plan_decoupled(coa_planner_t *planner, const coa_problem_t *problem,
                       const size_t *order, uint32_t max_orders, int32_t *offsets,
                       coa_plan_result_t *result);

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

/* Whether a full plan (rows for the vehicles listed in `which[0..count-1]`, others
 * ignored) is conflict-free against obstacles, tracks and each other by geometry.h.
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
