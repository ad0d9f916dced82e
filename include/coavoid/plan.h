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
 * (the heuristic is consistent). The search stops when the goal is taken from the open
 * list (solved), when the open list empties (infeasible: the space is exhausted), or when
 * beta states have been closed (budget exhausted: nothing proven).
 *
 *   - Centralised: one search over the composite state of all UAVs, with the composite
 *     action space (every combination of five actions per UAV, 5^n children a node).
 *     Optimal for the whole group.
 *   - Decoupled: UAVs plan one at a time in priority order; each treats the plans of the
 *     UAVs before it as moving obstacles and ignores those after it. Optionally, when one
 *     fails, other orders are tried, the failing UAV earlier first.
 *
 * Memory. The planner lives in a buffer the caller provides, as in o1heap: ask
 * coa_planner_workspace_size(n, beta) for the byte count, hand coa_planner_init a buffer
 * of that size aligned to COA_WORKSPACE_ALIGNMENT, and use the returned handle. Nothing
 * is allocated, nothing needs freeing; the buffer can be reused for any number of plans
 * with at most n searched UAVs and beta closed states. Node storage is sized for the worst
 * case (1 + beta * 5^n nodes), so running out of room can only happen through beta and is
 * always reported as COA_PLAN_BUDGET_EXHAUSTED, never as infeasible.
 *
 * Time. One expansion costs O(5^n * n^2) pairwise checks among the searched UAVs plus
 * O(5 n (obstacles + tracks + fixed UAVs)) environment checks (polytopes cost MPR support
 * calls); a search does at most beta expansions, plus O(log pool) heap work per node.
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
    double deviation;          /* m^2, total over all vehicles; when solved */
    int64_t deviation_units;   /* the exact integer the planner minimised (trajectory.h) */
    uint32_t effort;           /* total; when solved */
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
} coa_plan_result_t;

typedef struct coa_planner coa_planner_t;

/* Bytes of workspace for searches over at most `max_vehicles` UAVs at once (n for
 * centralised, 1 is enough for decoupled) with closed-set bound beta. Returns 0 when
 * max_vehicles is 0 or > COA_MAX_CENTRALISED, beta is 0, or the size would not fit in
 * size_t or 32-bit node indices. Cost O(1). The size is exact: one byte less is refused. */
size_t coa_planner_workspace_size(size_t max_vehicles, uint32_t beta);

/* Builds a planner inside `buffer`. Returns the handle (which points into the buffer), or
 * NULL when buffer is NULL or not aligned to COA_WORKSPACE_ALIGNMENT, the arguments are
 * refused by coa_planner_workspace_size, or size is smaller than it says.
 * Cost O(hash table) to clear it. */
coa_planner_t *coa_planner_init(void *buffer, size_t size, size_t max_vehicles, uint32_t beta);

/* Checks a problem in full (counts, finite numbers, every vehicle and track, obstacles,
 * non-NULL samples) before a search trusts it. Returns COA_OK, COA_ERR_ARGUMENT, or
 * COA_ERR_RANGE when offsets or integer costs could overflow over this horizon.
 * Cost O(vehicles * route + tracks * path + polytope vertices). */
int coa_problem_check(const coa_problem_t *problem);

/* Centralised plan of every vehicle of the problem in one composite search.
 * offsets: vehicle_count * (horizon+1) int32, row i is vehicle i; filled when solved.
 * Returns COA_OK with the outcome in *result, or COA_ERR_ARGUMENT (NULL, problem check
 * failed), COA_ERR_RANGE, or COA_ERR_WORKSPACE (planner built for fewer vehicles).
 * An initial conflict (t = 0) is COA_PLAN_INFEASIBLE with no node expanded.
 * Cost: at most beta expansions (see the file comment). */
int coa_plan_centralised(coa_planner_t *planner, const coa_problem_t *problem,
                         int32_t *offsets, coa_plan_result_t *result);

/* Decoupled plan: vehicles plan one at a time in `order` (vehicle indices, a permutation
 * of 0..n-1; NULL: ascending priority, ties by ascending id), each against obstacles,
 * tracks and the plans of the vehicles before it. With max_orders == 1 the first failure
 * ends the call (status infeasible or budget exhausted, failed_vehicle set). With
 * max_orders > 1, other orders are tried depth-first, reusing the plans of the prefix
 * they share, the vehicle that failed promoted to the earliest position not yet tried
 * for it, until one succeeds, every order has been tried or ruled out (a failing prefix
 * rules out every order that starts with it), or max_orders orders were attempted. If
 * none succeeds the result reports the attempt of the first order. An order that failed
 * through beta makes the final status budget exhausted rather than infeasible.
 * Errors as coa_plan_centralised (the planner needs room for one vehicle).
 * Cost: at most beta expansions per single-UAV search, at most n searches per order. */
int coa_plan_decoupled(coa_planner_t *planner, const coa_problem_t *problem,
                       const size_t *order, uint32_t max_orders, int32_t *offsets,
                       coa_plan_result_t *result);

/* The priority order of a problem's vehicles (ascending priority, ties by ascending id)
 * as indices into order[0..n-1]. Returns COA_OK or COA_ERR_ARGUMENT. Cost O(n^2). */
int coa_priority_order(const coa_vehicle_t *vehicles, size_t n, size_t *order);

/* Deviation (m^2, exact formula) and effort of one vehicle's offsets[0..horizon]. Returns
 * COA_OK, or COA_ERR_ARGUMENT when a step is not one of the five actions. Cost O(N). */
int coa_plan_vehicle_cost(const coa_vehicle_t *vehicle, coa_real_t dt, uint32_t horizon,
                          const int32_t *offsets, double *deviation, uint32_t *effort);

/* Whether a full plan (rows for the vehicles listed in `which[0..count-1]`, others
 * ignored) is conflict-free against obstacles, tracks and each other by geometry.h.
 * Returns 0 (conflict-free), 1 (a conflict; *vehicle and *step say where when not NULL),
 * or a negative error. Cost O(N * count * (count + obstacles + tracks)). */
int coa_plan_find_conflict(const coa_problem_t *problem, const int32_t *offsets,
                           const size_t *which, size_t count, size_t *vehicle, uint32_t *step);

#ifdef __cplusplus
}
#endif

#endif /* COAVOID_PLAN_H */
