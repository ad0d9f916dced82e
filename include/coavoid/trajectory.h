/* SPDX-License-Identifier: MIT */
/*
 * trajectory.h: vehicles, reference trajectories, tracks, the altitude-offset lattice and
 * the exact integer step costs.
 *
 * The big picture. A co-operative UAV flies a reference path (its route) at constant
 * horizontal speed. Over a planning window of N steps of dt seconds it may only change its
 * altitude: at every step it picks one of five actions that move its altitude offset from
 * the reference by a whole number of climb steps dh = climb_rate * dt:
 *
 *   action       offset change   effort
 *   level              0            0
 *   climb / dive     +1 / -1        1
 *   steep_climb/dive +s / -s        3      (s = steep_factor >= 2)
 *
 * The planned position at sample k is ref(t_k) + offset_k * dh * z_hat. Between samples
 * every moving thing moves in a straight line (see geometry.h).
 *
 * Costs are lexicographic: deviation first, then effort. The deviation of one step from
 * offset a to offset b is L * dh * A(a, b) m^2 with L = cruise_speed * dt and A the area
 * between the reference and the planned profile in (step x climb step) units:
 *   A(a, b) = (|a| + |b|) / 2            when a*b >= 0
 *   A(a, b) = (a^2 + b^2) / (2 |a - b|)  when the profile crosses the reference.
 * A is a rational with denominator 2 or 2|a - b| = 2s, so A * S is an integer for the
 * problem's area scale S = lcm of 2*s_i over its vehicles. To compare sums over vehicles
 * with different L*dh exactly, each vehicle's w_i = L_i*dh_i (evaluated in double as
 * fl(fl(v*dt) * fl(c*dt)), which is what the contract's formula means on a computer) is
 * written exactly as W_i * 2^E: W_i an unsigned 64-bit integer, E common to the problem
 * (coa_deviation_weights). A double is a 53-bit integer times a power of two, so this
 * always fits when the largest and smallest weight are within 2^10 of each other, and
 * much further apart when the weights have short binary expansions (integers such as 30
 * and 10, or halves); otherwise the problem is refused with COA_ERR_RANGE rather than
 * compared inexactly. The planner minimises
 * sum W_i * (A_i * S) exactly in 128-bit unsigned integers (coa_cost_t): ties between any
 * vehicles (climb or dive, which UAV moves) compare exactly, so the effort tie-break the
 * contract asks for is honoured, and a plan is the same on every machine. The deviation
 * reported in m^2 is the contract's formula sum L_i dh_i A_i in double.
 *
 * The heuristic (cost to go) is the paper's return-to-reference triangle truncated at the
 * horizon: with R steps left the profile can at best shrink by s per step, so
 *   H(a, R) = a^2 / (2s)             when |a| <= s R
 *   H(a, R) = R |a| - s R^2 / 2      otherwise (a trapezoid: the horizon ends first).
 * It never overestimates and it is consistent (H(a,R) <= A(a,b) + H(b,R-1) for every
 * action), which A* with a closed set needs to be optimal.
 */
#ifndef COAVOID_TRAJECTORY_H
#define COAVOID_TRAJECTORY_H

#include "coavoid/common.h"
#include "coavoid/geometry.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A co-operative UAV. All numbers finite; the pointers are the caller's. */
typedef struct {
    uint16_t id;             /* 1..65535, unique in a problem */
    uint32_t priority;       /* >= 1; 1 is highest; ties by ascending id */
    coa_real_t cruise_speed; /* m/s, > 0 */
    coa_real_t climb_rate;   /* m/s, > 0 */
    uint32_t steep_factor;   /* 2..COA_MAX_STEEP_FACTOR */
    coa_volume_t volume;     /* protected volume */
    const coa_vec3_t *route; /* >= 2 points; consecutive points differ horizontally */
    size_t route_count;
    int32_t initial_offset; /* offset at k = 0, climb steps */
    int32_t max_offset;     /* bound on |offset| at every k; negative: unbounded */
} coa_vehicle_t;

/* One point of a track's predicted path. */
typedef struct {
    coa_real_t t;
    coa_vec3_t p;
} coa_track_point_t;

/* A non-cooperative aircraft as predicted by a tracker: constant velocity from `position`
 * at t = 0, or, when path_count >= 1, the piecewise-linear `path` (ascending t; constant
 * velocity of the nearest leg outside it; a single point is stationary). */
typedef struct {
    uint32_t id;
    coa_volume_t volume;
    coa_vec3_t position;
    coa_vec3_t velocity;
    const coa_track_point_t *path;
    size_t path_count;
    coa_real_t sigma_horizontal; /* m, one standard deviation; prediction only */
    coa_real_t sigma_vertical;
} coa_track_t;

/* The five actions, in the order the planner generates them. */
typedef enum {
    COA_ACTION_LEVEL = 0,
    COA_ACTION_CLIMB = 1,
    COA_ACTION_DIVE = 2,
    COA_ACTION_STEEP_CLIMB = 3,
    COA_ACTION_STEEP_DIVE = 4
} coa_action_t;
#define COA_ACTION_COUNT 5u

/* Checks a vehicle against every rule above (finite numbers, positive speeds, route of >=
 * 2 points with horizontal legs, steep factor range, |initial_offset| <= max_offset when
 * bounded and <= COA_MAX_OFFSET). Returns COA_OK or COA_ERR_ARGUMENT. Cost O(route). */
int coa_vehicle_check(const coa_vehicle_t *v);

/* Reference position at time t >= 0 (extrapolated along the last leg past the route's
 * end). Precondition: coa_vehicle_check(v) == COA_OK. Cost O(route_count). */
coa_vec3_t coa_reference_at(const coa_vehicle_t *v, coa_real_t t);

/* Samples the reference at t_k = k*dt, k = 0..horizon, into out[0..horizon] (the
 * initial offset is NOT applied: out is the reference itself). Returns COA_OK, or
 * COA_ERR_ARGUMENT (NULL, invalid vehicle, dt not finite or <= 0, horizon == 0 or >
 * COA_MAX_HORIZON, or a sample that overflows to a non-finite position). Cost
 * O(horizon + route_count) in one walk along the route. */
int coa_reference_sample(const coa_vehicle_t *v, coa_real_t dt, uint32_t horizon, coa_vec3_t *out);

/* Track position at time t. Precondition: coa_track_check(tr) == COA_OK. Cost O(path). */
coa_vec3_t coa_track_at(const coa_track_t *tr, coa_real_t t);

/* Checks a track (finite numbers, positive volume, ascending path times, non-negative
 * sigmas). Returns COA_OK or COA_ERR_ARGUMENT. Cost O(path_count). */
int coa_track_check(const coa_track_t *tr);

/* Samples a track at t_k = k*dt, k = 0..horizon. Errors as coa_reference_sample.
 * Cost O(horizon + path_count). */
int coa_track_sample(const coa_track_t *tr, coa_real_t dt, uint32_t horizon, coa_vec3_t *out);

/* Climb step dh = climb_rate * dt (m). Cannot fail. Cost O(1). */
coa_real_t coa_climb_step(const coa_vehicle_t *v, coa_real_t dt);

/* Offset change of an action for steep factor s. Cannot fail (an unknown action is level).
 * Cost O(1). */
int32_t coa_action_delta(coa_action_t action, uint32_t steep_factor);

/* Effort of an action: 0, 1 or 3. Cannot fail. Cost O(1). */
uint32_t coa_action_effort(coa_action_t action);

/* Contract name of an action ("level", "climb", "dive", "steep_climb", "steep_dive").
 * Never NULL. Cost O(1). */
const char *coa_action_name(coa_action_t action);

/* The action that moves offset a to offset b for steep factor s, or -1 when no action
 * does. Cost O(1). */
int coa_action_between(int32_t a, int32_t b, uint32_t steep_factor);

/* The exact area A(a, b) as a double, for reporting. Cost O(1). */
double coa_area(int32_t a, int32_t b);

/* A(a, b) * scale exactly. Precondition: scale is a multiple of 2 and, when the profile
 * crosses the reference, of 2|a - b| (true for the problem scale of coa_area_scale and
 * any step the actions allow). Cost O(1). */
int64_t coa_area_scaled(int32_t a, int32_t b, uint32_t scale);

/* The truncated-triangle heuristic H(a, steps_left) * scale exactly, for steep factor s.
 * Precondition: scale is a multiple of 2s. Cost O(1). */
int64_t coa_heuristic_scaled(int32_t a, uint32_t steps_left, uint32_t steep_factor, uint32_t scale);

/* The problem's area scale S = lcm over the vehicles of 2*steep_factor. Returns 0 when n
 * is 0 or a steep factor is out of range. Cost O(n). */
uint32_t coa_area_scale(const coa_vehicle_t *vehicles, size_t n);

/* The exact deviation weights of the file comment: w_i = weights[i] * 2^(*exponent) for
 * i = 0..n-1, with the common factors of two moved into the exponent (some weights[i] is
 * odd), e.g. w = 30 and 10 give 15 and 5 with exponent 1. Returns COA_OK,
 * COA_ERR_ARGUMENT (NULL, n == 0, dt, L or dh not finite or <= 0), or COA_ERR_RANGE
 * (the weights span too many binary orders of magnitude for 64-bit integers); on an
 * error the outputs are unspecified. Computed in double whatever coa_real_t is, read
 * from the IEEE 754 bits rather than through libm, so host and firmware agree. Cost O(n). */
int coa_deviation_weights(const coa_vehicle_t *vehicles, size_t n, coa_real_t dt, uint64_t *weights,
                          int *exponent);

/* An exact non-negative cost in the planner's deviation unit: hi * 2^64 + lo. The
 * helpers below use only 64-bit arithmetic (no __int128), so they build for 32-bit
 * microcontrollers too. */
typedef struct {
    uint64_t hi;
    uint64_t lo;
} coa_cost_t;

/* a + b. Precondition: no overflow past 2^128 (the planner's range check ensures it).
 * Cost O(1). */
coa_cost_t coa_cost_add(coa_cost_t a, coa_cost_t b);

/* The exact 128-bit product of two 64-bit integers (portable: no __int128). Cost O(1). */
coa_cost_t coa_cost_mul(uint64_t a, uint64_t b);

/* -1, 0 or 1 as a <, ==, > b. Cost O(1). */
int coa_cost_compare(coa_cost_t a, coa_cost_t b);

#ifdef __cplusplus
}
#endif

#endif /* COAVOID_TRAJECTORY_H */
