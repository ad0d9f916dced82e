/* SPDX-License-Identifier: MIT */
/*
 * flight.h: what a closed loop flew, judged and drawn. Filled by `coavoid sim` from its
 * nodes, and by `coavoid summary` from an lcm-logger log of a real-time run (the intents
 * each UAV published: its reference and offset at each cycle's start).
 *
 *   - coavoid_flight_evaluate: loss of separation by the contract's semantics (the flown
 *     samples, straight between consecutive samples, against each other, the tracks and
 *     the obstacles: the same tests the planner uses, via coa_plan_find_conflict over a
 *     problem whose references are the flown references), and the deviation and effort
 *     of what was flown (coa_plan_vehicle_cost over the flown offsets).
 *   - coavoid_flight_svg: the figure: a top view (routes, terrain footprints, tracks, where
 *     the references would have conflicted, where separation was lost) and, per UAV, its
 *     altitude against time: reference dashed, flown solid, the terrain under its path
 *     and the tracks near it drawn, conflicts marked, as in the paper's figures.
 *
 * Memory: the record's arrays are the caller's; evaluate and svg allocate only their own
 * scratch (apps layer), and free it before returning.
 */
#ifndef COAVOID_FLIGHT_H
#define COAVOID_FLIGHT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "coavoid/coavoid.h"

typedef struct {
    coa_vehicle_t vehicle; /* as in the scenario (route, speeds, volume, priority) */
    coa_vec3_t *reference; /* steps + 1: reference at t_k = k * dt */
    int32_t *offsets;      /* steps + 1: offset flown at t_k */
    bool *known;           /* steps + 1, or NULL (all known): false where no intent
                                   in a log covered that sample (neither the cycle's own
                                   nor an earlier plan reaching it): reference and offset
                                   there are stand-ins, not what was flown */
} coavoid_flight_vehicle_t;

typedef struct {
    const char *scenario; /* name */
    const char *mode;     /* "centralised" or "decoupled" */
    coa_real_t dt;
    uint32_t steps; /* K: samples 0..K */
    coavoid_flight_vehicle_t *vehicles;
    size_t vehicle_count;
    const coa_obstacle_t *obstacles;
    size_t obstacle_count;
    const coa_track_t *tracks; /* positions at t = 0, as the scenario gives them */
    size_t track_count;
    uint32_t replans; /* planning calls during the run */
} coavoid_flight_t;

typedef struct {
    bool loss_of_separation;
    size_t first_vehicle; /* when lost: index of a UAV involved, and the step */
    uint32_t first_step;
    double deviation; /* m^2, total over what was flown */
    uint32_t effort;
    double *vehicle_deviation; /* caller's array of vehicle_count, or NULL */
    uint32_t *vehicle_effort;  /* caller's array of vehicle_count, or NULL */
} coavoid_flight_eval_t;

/* Returns COA_OK, COA_ERR_ARGUMENT (a flown step is not an action, more than
 * COA_MAX_VEHICLES UAVs, steps out of range, NULL, or what coa_plan_find_conflict refuses:
 * an invalid vehicle, obstacle or track, repeated ids, a non-finite sample) or
 * COA_ERR_WORKSPACE (out of memory). When lost, first_vehicle and first_step are
 * coa_plan_find_conflict's (the earliest step, the first UAV in conflict there); else
 * first_vehicle is COA_NO_VEHICLE and first_step 0. Cost O(K n (n + obstacles + tracks))
 * plus sampling the tracks; allocates O(K (n + tracks)) scratch. */
int coavoid_flight_evaluate(const coavoid_flight_t *flight, coavoid_flight_eval_t *eval);

/* Where UAV i is at sample k when it flies `offset` there: reference[k] +
 * (coa_real_t)offset * coa_climb_step(vehicle, dt) * z_hat, the planner's formula, so
 * that every consumer of a record computes the same positions bit for bit.
 * Preconditions: i < vehicle_count, k <= steps. Cost O(1). */
coa_vec3_t coavoid_flight_position(const coavoid_flight_t *flight, size_t i, uint32_t k,
                                   int32_t offset);

/* Which trajectories coavoid_flight_conflicts judges. */
typedef enum {
    COAVOID_FLIGHT_FLOWN = 0,    /* offsets[k] at every sample: what was flown */
    COAVOID_FLIGHT_REFERENCE = 1 /* offsets[0] at every sample: the run without manoeuvres */
} coavoid_flight_trajectory_t;

/* One conflicting pair over one step. */
typedef struct {
    coa_conflict_kind_t kind; /* what `other` indexes */
    size_t vehicle;           /* UAV index */
    size_t other;             /* a UAV index (> vehicle), a track or an obstacle index */
    uint32_t step;            /* the interval [t_k, t_k+1] */
} coavoid_flight_conflict_t;

/* Every (pair, step) in conflict by the same geometry tests as coavoid_flight_evaluate (so
 * with COAVOID_FLIGHT_FLOWN the list is empty exactly when no separation was lost), ordered by
 * step, then UAV, then UAV-UAV, track, obstacle pairs. Writes the first `capacity` to out
 * (out may be NULL when capacity is 0) and the total to *found. Returns COA_OK,
 * COA_ERR_ARGUMENT (as coavoid_flight_evaluate, except that steps need not be actions) or
 * COA_ERR_WORKSPACE (out of memory). Cost O(K n (n + obstacles + tracks)); allocates the
 * tracks' samples. */
int coavoid_flight_conflicts(const coavoid_flight_t *flight, coavoid_flight_trajectory_t which,
                             coavoid_flight_conflict_t *out, size_t capacity, size_t *found);

/* Writes the SVG document to out: self-contained (no scripts, no external references).
 * eval may be NULL (no result line). Returns COA_OK, COA_ERR_ARGUMENT (as
 * coavoid_flight_conflicts, or a NULL flight or out), or COA_ERR_WORKSPACE (out of memory or
 * a write failed). Cost O(K n (n + obstacles + tracks)); allocates O(K (n + tracks)). */
int coavoid_flight_svg(const coavoid_flight_t *flight, const coavoid_flight_eval_t *eval,
                       FILE *out);

/* Writes the simulation result of docs/scenario-format.md ("Simulation result") as JSON:
 * scenario, mode, steps, replans, loss_of_separation, deviation, effort, and per UAV id and
 * flown (steps + 1 samples [t, x, y, z]). Extra fields, beyond the contract: when lost,
 * "first_loss": {"vehicle": id, "step": k, "t": s}; per UAV "deviation" and "effort" when
 * eval has the per-vehicle arrays, and "unknown_samples" (samples no intent covered) when
 * known is not NULL. Numbers are printed in the shortest form that reads back to the same
 * double (cJSON's own printer settles for one within an epsilon: parsing this document
 * with cJSON and printing it again loses the exactness; splice text into it instead).
 * Returns COA_OK, COA_ERR_ARGUMENT (NULL; counts, steps or dt out of range; NULL arrays;
 * a loss without a valid first_vehicle) or COA_ERR_WORKSPACE (out of memory, write
 * failed). Cost O(K n); allocates the document, O(K n), while printing. */
int coavoid_flight_json(const coavoid_flight_t *flight, const coavoid_flight_eval_t *eval,
                        FILE *out);

/* A member a command adds to the result beyond the record's: its key and its value as
 * JSON text, written as given (e.g. "3", or an object printed by cJSON). */
typedef struct {
    const char *key;
    const char *json;
} coavoid_flight_extra_t;

/* coavoid_flight_json with extra[0..extra_count) appended to the object, in order, the way
 * `coavoid sim` adds "fallbacks" and `coavoid summary` its "log": so no command has to
 * parse the document and print it again. The json texts are not checked. Returns, costs
 * and allocates as coavoid_flight_json; COA_ERR_ARGUMENT also for an extra without a key or
 * text. */
int coavoid_flight_json_extra(const coavoid_flight_t *flight, const coavoid_flight_eval_t *eval,
                              const coavoid_flight_extra_t *extra, size_t extra_count, FILE *out);

/* Writes the result for a reader, one fact a line ("loss of separation: no", "deviation:
 * ... m^2", per UAV its costs), as `coavoid sim` and `coavoid summary` print it without
 * --json; a loss names both sides ("UAV 1 and obstacle 0") from coavoid_flight_conflicts.
 * Returns COA_OK, COA_ERR_ARGUMENT (NULL, or counts out of range as coavoid_flight_json) or
 * COA_ERR_WORKSPACE (write failed). Cost O(K n), plus the pairwise listing when lost,
 * which it allocates and frees. */
int coavoid_flight_text(const coavoid_flight_t *flight, const coavoid_flight_eval_t *eval,
                        FILE *out);

#endif /* COAVOID_FLIGHT_H */
