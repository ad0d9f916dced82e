/*
 * flight.h: what a closed loop flew, judged and drawn. Filled by `coavoid sim` from its
 * nodes, and by `coavoid summary` from an lcm-logger log of a real-time run (the intents
 * each UAV published: its reference and offset at each cycle's start).
 *
 *   - coa_flight_evaluate: loss of separation by the contract's semantics (the flown
 *     samples, straight between consecutive samples, against each other, the tracks and
 *     the obstacles: the same tests the planner uses, via coa_plan_find_conflict over a
 *     problem whose references are the flown references), and the deviation and effort
 *     of what was flown (coa_plan_vehicle_cost over the flown offsets).
 *   - coa_flight_svg: the figure: a top view (routes, terrain footprints, tracks, where
 *     the references would have conflicted, where separation was lost) and, per UAV, its
 *     altitude against time: reference dashed, flown solid, the terrain under its path
 *     and the tracks near it drawn, conflicts marked, as in the paper's figures.
 *
 * Memory: the record's arrays are the caller's; evaluate and svg allocate only their own
 * scratch (apps layer), and free it before returning.
 */
#ifndef COAVOID_APP_FLIGHT_H
#define COAVOID_APP_FLIGHT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "coavoid/coavoid.h"

typedef struct {
    coa_vehicle_t vehicle;      /* as in the scenario (route, speeds, volume, priority) */
    coa_vec3_t *reference;      /* steps + 1: reference at t_k = k * dt */
    int32_t *offsets;           /* steps + 1: offset flown at t_k */
    bool *known;                /* steps + 1, or NULL (all known): false where a log had
                                   no intent for that sample (filled from earlier plans
                                   when they covered it, else from the reference) */
} coa_flight_vehicle_t;

typedef struct {
    const char *scenario;       /* name */
    const char *mode;           /* "centralised" or "decoupled" */
    coa_real_t dt;
    uint32_t steps;             /* K: samples 0..K */
    coa_flight_vehicle_t *vehicles;
    size_t vehicle_count;
    const coa_obstacle_t *obstacles;
    size_t obstacle_count;
    const coa_track_t *tracks;  /* positions at t = 0, as the scenario gives them */
    size_t track_count;
    uint32_t replans;           /* planning calls during the run */
} coa_flight_t;

typedef struct {
    bool loss_of_separation;
    size_t first_vehicle;       /* when lost: index of a UAV involved, and the step */
    uint32_t first_step;
    double deviation;           /* m^2, total over what was flown */
    uint32_t effort;
    double *vehicle_deviation;  /* caller's array of vehicle_count, or NULL */
    uint32_t *vehicle_effort;   /* caller's array of vehicle_count, or NULL */
} coa_flight_eval_t;

/* Returns COA_OK, COA_ERR_ARGUMENT (a flown step is not an action, more than
 * COA_MAX_VEHICLES UAVs, steps out of range, NULL) or COA_ERR_WORKSPACE (out of memory). */
int coa_flight_evaluate(const coa_flight_t *flight, coa_flight_eval_t *eval);

/* Writes the SVG document to out. Returns COA_OK, COA_ERR_ARGUMENT, or COA_ERR_WORKSPACE
 * (out of memory or a write failed). */
int coa_flight_svg(const coa_flight_t *flight, const coa_flight_eval_t *eval, FILE *out);

/* Writes the simulation result of SCENARIO_FORMAT.md ("Simulation result") as JSON:
 * scenario, mode, steps, replans, loss_of_separation, deviation, effort, and per UAV id and
 * flown (steps + 1 samples [t, x, y, z]). Returns COA_OK or COA_ERR_WORKSPACE (write
 * failed). */
int coa_flight_json(const coa_flight_t *flight, const coa_flight_eval_t *eval, FILE *out);

#endif /* COAVOID_APP_FLIGHT_H */
