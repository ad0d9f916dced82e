/* SPDX-License-Identifier: MIT */
/*
 * predict.h: collision prediction over the horizon, with probability of conflict, at
 * fleet scale, in caller-provided memory.
 *
 * The big picture. The paper's prediction module runs continuously: it propagates every
 * published UAV plan and every tracked non-cooperative aircraft over the next N steps and,
 * when a conflict is predicted or its probability exceeds a threshold, triggers planning.
 * coa_predict does one such cycle:
 *
 *   1. Alignment. Plans arrive from the network each with its own start time, step and
 *      length; none is aligned with the predictor's clock. Each is resampled onto the
 *      predictor's grid t_k = t0 + k*dt, k = 0..N, by linear interpolation between its
 *      samples and, outside them, by the constant velocity of its nearest leg (one sample:
 *      stationary) - the semantics docs/scenario-format.md gives track paths. Tracks are
 *      sampled with coa_track_at at the same t_k: a track's time is the predictor's
 *      clock. Between grid samples everything moves in a straight line.
 *   2. Broad phase. For every step, the swept bounding boxes of all UAVs and tracks
 *      (inflated by COA_PREDICT_SIGMA_MARGIN standard deviations when there is
 *      uncertainty) are counting-sorted into a uniform square grid laid over that step's
 *      boxes: cells two median box extents wide, or wider so that there are at most four
 *      cells per mover. A box reaching at most into the next column and row belongs to
 *      the cell of its min corner and meets only the boxes of that cell and the 8 around
 *      it; a wider box (a track with a large sigma) is checked against the cells it
 *      reaches and, by a sweep along x, against the other wide ones. So the work per box
 *      is the traffic within a few cells of it: for sparse traffic, a small constant.
 *      Pairs whose boxes overlap in x, y and z in some step become candidates, kept once
 *      each in a hash set in the workspace. Obstacles are tested against each UAV's swept
 *      box of the whole horizon first (a polytope by the box of its vertices); those pairs
 *      are candidates too. Track-track pairs are never candidates.
 *   3. Narrow phase. Each candidate pair is evaluated over the whole horizon with the
 *      planner's own conflict tests (geometry.h: one conflict test, not two): the first
 *      conflicting step and time, the least horizontal and vertical separation (exact
 *      minima over each linear step, not just at the samples), and the probability of
 *      conflict. Candidates are evaluated in the output order, so the broad phase changes
 *      nothing but the work: its answer equals all_pairs' bit for bit (for thresholds
 *      above 2.6e-12, see COA_PREDICT_SIGMA_MARGIN).
 *
 * Probability model. Each moving thing's position error is Gaussian, zero-mean,
 * independent between things and between the horizontal plane and the vertical, isotropic
 * in the plane, with one-sigma sigma_h(tau) = sigma_h0 + rate_h * tau and likewise
 * vertically, tau = t - t0 the look-ahead time. For a pair, the relative error has
 * sigma^2 = sigma_a^2 + sigma_b^2 on each axis. At one instant, with nominal horizontal
 * distance d and vertical distance dz, the protected volumes overlap with probability
 *     P = P_h * P_v,
 *     P_h = P(|d + e| < R), e ~ N(0, sigma_h^2 I_2), R = r_a + r_b
 *         = 1 - Q_1(d / sigma_h, R / sigma_h)       (Marcum Q; the CDF at (R/sigma_h)^2
 *           of a non-central chi-square with two degrees of freedom and non-centrality
 *           (d/sigma_h)^2),
 *     P_v = Phi((H - dz) / sigma_v) - Phi((-H - dz) / sigma_v), H = h_a + h_b.
 * The probability of conflict of a pair over the horizon is the largest instantaneous P
 * over the horizon (a lower bound of the probability that a conflict happens at some
 * instant, and the quantity a Monte Carlo of one instant checks). It is evaluated in each
 * step [t_k, t_k+1] at a fixed set of instants: both ends, the instant of least horizontal
 * and the instant of least vertical separation, and the quarters u = 1/4, 1/2, 3/4 of
 * the step. So the nominal closest approaches are never missed; a peak of P elsewhere
 * (where growing sigma and a receding pair balance) is found to within what P changes
 * over an eighth of a step. Instants and steps whose P is provably below the threshold
 * (or below the maximum already found) by the Gaussian tail bounds are skipped: this
 * changes no reported number. first_step is the first step with an instant at or above
 * the threshold. With zero sigma on an axis that factor is the deterministic indicator
 * (strict, as the conflict test is); a pair with zero sigma and zero growth on both axes
 * on both sides has no uncertainty: it is a conflict, with P = 1, exactly when the exact
 * conflict test finds one (the planner's answer), and its first_step is the test's.
 * Obstacles are static and exact: a UAV-obstacle pair has probability 1 when the nominal
 * trajectory conflicts, else it is not a conflict (terrain margins belong in the map).
 *
 * P_h is computed as P(N_y > N_mu) for independent Poisson variables with means
 * (R/sigma_h)^2/2 and (d/sigma_h)^2/2 (the non-central chi-square's Poisson mixture, each
 * central CDF being a Poisson tail), summing whichever of P_h and 1 - P_h is smaller over
 * windows that drop tails below e^-40; when R/sigma_h >= 20 the disc's edge is nearly
 * flat over the Gaussian and 32-point Gauss-Hermite across the line of centres is used
 * instead (bounded work whatever the ratio). P_v takes each normal CDF from the tail it
 * lies in. Measured against mpmath: within 1e-14 absolute.
 *
 * Memory: one workspace (o1heap-style: size function, init that refuses a short buffer);
 * the conflicts go to a caller array of fixed capacity. Nothing is allocated.
 */
#ifndef COAVOID_PREDICT_H
#define COAVOID_PREDICT_H

#include "coavoid/common.h"
#include "coavoid/geometry.h"
#include "coavoid/trajectory.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Broad-phase boxes are inflated by this many standard deviations: a pair farther apart
 * than that has a conflict probability below 2 Q(7) = 2.6e-12 (whichever axis separates
 * the boxes). So with a threshold above that the broad phase drops no pair all_pairs
 * would report; below it, it may. */
#define COA_PREDICT_SIGMA_MARGIN 7

/* A UAV's published plan: positions at t0 + j*step, j = 0..count-1 (absolute, on the
 * predictor's clock). The samples are the caller's. */
typedef struct {
    uint16_t id;
    coa_volume_t volume;
    coa_real_t t0;
    coa_real_t step; /* s, > 0 */
    const coa_vec3_t *samples;
    size_t count;                /* >= 1 */
    coa_real_t sigma_horizontal; /* m at look-ahead 0, >= 0 */
    coa_real_t sigma_vertical;
} coa_intent_plan_t;

typedef struct {
    coa_real_t t0;                            /* predictor's clock at k = 0 (s) */
    coa_real_t dt;                            /* s, > 0 */
    uint32_t horizon;                         /* N, 1..max_horizon of the workspace */
    coa_real_t vehicle_sigma_rate_horizontal; /* m/s of look-ahead, >= 0 */
    coa_real_t vehicle_sigma_rate_vertical;
    coa_real_t track_sigma_rate_horizontal;
    coa_real_t track_sigma_rate_vertical;
    double threshold; /* a pair with uncertainty is a conflict when P >= threshold, in (0, 1] */
    bool all_pairs;   /* skip the broad phase: every pair is a candidate (the
                                      reference the broad phase is tested against) */
} coa_predict_config_t;

typedef enum {
    COA_CONFLICT_VEHICLE = 0, /* b is another plan's index, a < b */
    COA_CONFLICT_TRACK = 1,   /* b is a track's index */
    COA_CONFLICT_OBSTACLE = 2 /* b is an obstacle's index */
} coa_conflict_kind_t;

typedef struct {
    coa_conflict_kind_t kind;
    uint32_t a; /* plan index */
    uint32_t b;
    uint32_t first_step;   /* first k whose [t_k, t_k+1] holds the conflict (P >= threshold) */
    coa_real_t first_time; /* t_k of first_step on the predictor's clock */
    coa_real_t
        min_horizontal; /* least horizontal centre distance over the horizon (m); obstacles: to a box, 0 for a polytope */
    coa_real_t
        min_vertical; /* least vertical centre distance over the horizon (m); obstacles as above */
    double probability; /* of conflict over the horizon, see the file comment */
} coa_conflict_t;

typedef struct {
    size_t conflict_count;    /* entries written to the caller's array (<= capacity) */
    size_t conflicts_found;   /* every conflict found; more than conflict_count: overflow */
    bool overflow;            /* conflicts_found > capacity: the array holds the first ones found */
    uint64_t pair_tests;      /* pairs evaluated in the narrow phase (vs n(n-1)/2 all-pairs) */
    uint64_t candidate_pairs; /* distinct pairs the broad phase produced */
} coa_predict_result_t;

typedef struct coa_predictor coa_predictor_t;

/* Bytes of workspace for up to max_vehicles plans, max_tracks tracks, horizons up to
 * max_horizon and up to max_pairs distinct candidate pairs per cycle (UAV-UAV, UAV-track
 * and UAV-obstacle together). Returns 0 when a limit is 0 (max_tracks may be 0),
 * max_horizon > COA_MAX_HORIZON, max_vehicles + max_tracks > 2^30, max_pairs > 2^30 or
 * the size overflows. Exact: one byte less is refused. Cost O(1).
 * Per mover (plan or track), 24 (N + 1) + 124 bytes in double (12 (N + 1) + 72 in
 * float; of these, 16 are the broad phase's grid of at most 4 cells per mover), plus 48
 * (24) per plan; per pair 12 bytes plus 16 to 32 bytes of hash table (a power of two of
 * at least 2 max_pairs slots of 8 bytes); a header of about 180 bytes (docs/benchmarks.md
 * gives sizes for 100 to 10,000 UAVs). */
size_t coa_predictor_workspace_size(size_t max_vehicles, size_t max_tracks, uint32_t max_horizon,
                                    size_t max_pairs);

/* Builds a predictor in `buffer` (aligned to COA_WORKSPACE_ALIGNMENT). Returns the handle or
 * NULL (NULL or misaligned buffer, limits refused, size too small). Cost O(size of the
 * pair set). */
coa_predictor_t *coa_predictor_init(void *buffer, size_t size, size_t max_vehicles,
                                    size_t max_tracks, uint32_t max_horizon, size_t max_pairs);

/* One prediction cycle (see the file comment). Writes up to `capacity` conflicts, in the
 * order: vehicle pairs, then tracks, then obstacles, each by (a, b) ascending.
 * `conflicts` may be NULL when capacity is 0. Plans: count >= 1, samples non-NULL and
 * finite, t0 finite, step finite and > 0, volume > 0, sigmas finite and >= 0. Config:
 * every number finite, dt > 0, 1 <= horizon <= max_horizon, rates >= 0, threshold in
 * (0, 1]. Tracks as coa_track_check, obstacles as coa_problem_check checks them.
 * Returns COA_OK, COA_ERR_ARGUMENT (NULL, a count beyond the workspace's limits, a
 * non-finite number, a bad plan, track, obstacle or config, a resampled position or a
 * sigma at the horizon that overflows), or COA_ERR_WORKSPACE when `predictor` is not one
 * that coa_predictor_init built, or the broad phase finds more distinct candidate pairs
 * than max_pairs (nothing is dropped silently: the caller must size max_pairs for its
 * traffic or split it). On an error *result is cleared (when not NULL). The predictor
 * keeps nothing a later call depends on, but one predictor serves one thread at a time.
 * result: pair_tests counts every pair the narrow phase evaluated (all three kinds;
 * with all_pairs, n(n-1)/2 + n (tracks + obstacles)); candidate_pairs the distinct
 * pairs the broad phase produced (0 with all_pairs).
 * Cost: alignment O((n + m) N + plan samples + track paths * N); broad phase
 * O(N (n + m + pairs of boxes in neighbouring grid cells + wide boxes x (the cells they
 * reach + log wide boxes) + wide pairs overlapping in x)): near-linear for sparse traffic
 * (docs/benchmarks.md, "Collision prediction"); quadratic only when every box is in a few
 * cells (a crowd) or wide. Plus
 * O(n * obstacles + obstacle vertices); sorting the candidates O(P log P); narrow phase
 * O(candidates * N), a polytope step costing what coa_conflict_polytope does, an
 * uncertain step at most 7 coa_conflict_probability calls. No heap, O(1) stack. */
int coa_predict(coa_predictor_t *predictor, const coa_predict_config_t *config,
                const coa_intent_plan_t *plans, size_t plan_count, const coa_obstacle_t *obstacles,
                size_t obstacle_count, const coa_track_t *tracks, size_t track_count,
                coa_conflict_t *conflicts, size_t capacity, coa_predict_result_t *result);

/* Groups to plan together: cluster[i] receives the cluster label of plan i, or
 * COA_NO_CLUSTER when plan i has no conflict. Labels are 0..*cluster_count-1, numbered in
 * the order of each cluster's smallest plan index; a cluster is a connected component of
 * the vehicle-vehicle conflicts, and a UAV whose conflicts are only with tracks or
 * obstacles is a cluster of its own. Returns COA_OK or COA_ERR_ARGUMENT (NULL with a
 * non-zero count, an index a >= plan_count, a vehicle b >= plan_count, an unknown kind,
 * plan_count >= COA_NO_CLUSTER); on an error cluster[] is untouched. Union-find in
 * cluster[] itself with path halving, always linking under the smaller index (which is
 * what numbers the labels in one ascending pass): cost O(count log plan_count +
 * plan_count) in the worst case, memory: cluster[] only. */
#define COA_NO_CLUSTER UINT32_MAX
int coa_predict_clusters(const coa_conflict_t *conflicts, size_t count, size_t plan_count,
                         uint32_t *cluster, size_t *cluster_count);

/* The instantaneous overlap probability of the file comment for nominal horizontal
 * distance d >= 0, vertical distance dz, combined radii and half-heights (> 0), and
 * combined sigmas (>= 0). Returns a value in [0, 1], accurate to about 1e-9 absolute
 * (measured: 1e-14), computed in double whatever coa_real_t is. A zero sigma makes its
 * factor the indicator (strict: d < R, |dz| < H). Arguments out of range (negative,
 * NaN, infinite) return 1: the safe side for a trigger. Cost at most
 * COA_PROBABILITY_MAX_TERMS series terms (in practice at most about 800) or 32 erfc
 * calls, no memory. */
#define COA_PROBABILITY_MAX_TERMS 2000u
double coa_conflict_probability(coa_real_t d, coa_real_t dz, coa_real_t radius_sum,
                                coa_real_t half_height_sum, coa_real_t sigma_h, coa_real_t sigma_v);

#ifdef __cplusplus
}
#endif

#endif /* COAVOID_PREDICT_H */
