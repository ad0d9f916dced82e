/* SPDX-License-Identifier: MIT */
/*
 * scenario.h: reading a scenario file (docs/scenario-format.md, "Scenario file") into core types.
 *
 * The file is untrusted. Every field of the contract is checked for its JSON type and its
 * range before anything reaches the core, and the first problem is reported as one line
 * "path: reason" (for example "vehicles[1].route[2]: consecutive points have no
 * horizontal separation") that the caller prefixes with the program and file names.
 *
 * Fields the contract does not define are ignored, so that a newer scenario still loads;
 * a field the contract does define may appear only once in its object.
 *
 * Everything a coavoid_scenario_t points to is owned by it and released by coavoid_scenario_free.
 */
#ifndef COAVOID_SCENARIO_H
#define COAVOID_SCENARIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "coavoid/coavoid.h"

/* Larger files are refused before parsing: a scenario is a few kilobytes, and the cap
 * bounds the memory an input can make us allocate. */
#define COAVOID_SCENARIO_MAX_BYTES (16u * 1024u * 1024u)

/* Room for one error message ("path: reason"). */
#define COAVOID_SCENARIO_ERROR_MAX 512u

/* ---- how much a scenario may carry ----
 * Counts beyond these are refused, before any element of the array is read, with one line
 * such as "obstacles: at most 256 obstacles are supported (COAVOID_SCENARIO_MAX_OBSTACLES),
 * got 100000" (docs/scenario-format.md, "Limits"). The other counts are the core's:
 * vehicles COA_MAX_VEHICLES, polytope vertices COA_POLYTOPE_MAX_VERTICES. `coavoid plan`
 * takes up to these; the simulation and the real-time drivers refuse, with their own
 * messages, more than a node holds (COAVOID_NODE_MAX_CONFIGURED_OBSTACLES 80, an obstacle
 * map's 64 boxes and 16 polytopes, COAVOID_NODE_MAX_TRACKS 32). */

/* Every table the planner builds tests each obstacle against every step the UAV could
 * take (filtered by boxes first), so planning time grows in proportion to the obstacles,
 * to each polytope's vertices and to the tables' size. 256, three times a node's 80,
 * leaves room for terrain studies with `coavoid plan`; 256 polytopes of 256 vertices
 * beside the routes of 6 UAVs, the dearest case measured, plan in about 30 s over 24 steps
 * and 130 s over 48 (docs/security.md: only COAVOID_DEFAULT_WORKSPACE_MAX bounds the
 * tables). */
#define COAVOID_SCENARIO_MAX_OBSTACLES 256u

/* Tests against a track are closed-form cylinder tests, far cheaper than a polytope's,
 * and the track samples take horizon + 1 points each. 64, twice what a node holds
 * (COAVOID_NODE_MAX_TRACKS 32): 64 tracks beside the routes of 6 UAVs over 24 steps plan
 * in 0.1 s. */
#define COAVOID_SCENARIO_MAX_TRACKS 64u

/* Per vehicle. A reference position is found by walking the route from its first point
 * (coa_reference_at, in every cycle of the nodes and for every check of the simulation),
 * so each costs O(route points). The scenarios and encounters use 2 or 3 points; 256
 * leaves room for survey patterns and keeps each walk short. */
#define COAVOID_SCENARIO_MAX_ROUTE_POINTS 256u

/* Per track path. As for routes, a track's position is found by walking its path
 * (coa_track_at) and the simulation checks it leg by leg. A track message carries at most
 * 16 points of it (track_t.MAX_PATH, resampled over the horizon by the world); 256 holds
 * a tracker's prediction at one point per second for over four minutes. */
#define COAVOID_SCENARIO_MAX_TRACK_POINTS 256u

/* The largest |min_altitude|, in metres: the bound the messages put on every coordinate
 * (COAVOID_LCM_MAX_COORDINATE), so that a node can fly any floor a scenario sets. */
#define COAVOID_SCENARIO_MAX_ALTITUDE 1.0e7

typedef struct {
    char *name;
    coa_real_t dt;
    uint32_t horizon;
    bool has_beta;
    uint32_t beta;
    /* "min_altitude": the floor no UAV's protected volume may reach below (coa_problem_t's
     * has_floor and floor_z); has_floor false when the field is absent. */
    bool has_floor;
    coa_real_t min_altitude;

    coa_vehicle_t *vehicles;
    size_t vehicle_count;
    coa_obstacle_t *obstacles;
    size_t obstacle_count;
    coa_track_t *tracks;
    size_t track_count;

    /* Filled by coavoid_scenario_sample: horizon+1 samples per vehicle reference and per track. */
    const coa_vec3_t **references;
    const coa_vec3_t **track_samples;

    /* Every block the fields above point into, freed together by coavoid_scenario_free. */
    void **owned;
    size_t owned_count;
    size_t owned_capacity;
} coavoid_scenario_t;

/* Reads and validates the file at `path`. Returns 0 with *s filled, or -1 with the reason
 * in err (the file name is not part of it) and *s empty. Either way coavoid_scenario_free(s) is
 * safe afterwards. */
int coavoid_scenario_load(const char *path, coavoid_scenario_t *s, char *err, size_t err_size);

/* As coavoid_scenario_load, from `length` bytes of JSON text in memory. */
int coavoid_scenario_parse(const char *text, size_t length, coavoid_scenario_t *s, char *err,
                           size_t err_size);

/* Samples every vehicle's reference and every track at t_k = k*dt, k = 0..horizon, into
 * s->references and s->track_samples, refusing samples that are not finite (a route or a
 * track that runs off to infinity within the horizon). Returns 0 or -1 with err set. */
int coavoid_scenario_sample(coavoid_scenario_t *s, char *err, size_t err_size);

/* The core's view of a sampled scenario; it points into *s. */
coa_problem_t coavoid_scenario_problem(const coavoid_scenario_t *s);

/* Index of the vehicle with this id, or -1. */
long coavoid_scenario_vehicle_index(const coavoid_scenario_t *s, long id);

/* ---- sizing a scenario's planners ----
 * The policy every program shares for a planner's beta (`coavoid plan`, `coavoid sim`,
 * coavoid-coordinator, bench plan, montecarlo): the scenario's "beta" or an option when one
 * is given, taken as given; otherwise COAVOID_DEFAULT_BETA, lowered until the workspace fits
 * COAVOID_DEFAULT_WORKSPACE_MAX (a default that asks a laptop for gigabytes is a trap).
 * Why 200,000: no montecarlo search of up to 5 UAVs runs out of it in 15-17 MB of workspace
 * (docs/evaluation.md, "Without a work budget"). */
#define COAVOID_DEFAULT_BETA 200000u
/* The programs' default work budget of one planning call (plan.h, "Work"), in work units:
 * below a second of one core at the slowest unit measured (docs/benchmarks.md, "Within a
 * work budget"), and enough to prove every 4-UAV montecarlo encounter's plan optimal. */
#define COAVOID_DEFAULT_WORK UINT64_C(20000000)
#define COAVOID_DEFAULT_WORKSPACE_MAX ((size_t)1u << 30)

/* The planner config of a scenario (coa_planner_config_of: its horizon, largest steep
 * factor and offset bound) for `searched` UAVs a search and `beta`. The scenario need not
 * be sampled. For a scenario that coavoid_scenario_load accepted and searched in
 * 1..COA_MAX_CENTRALISED it is filled whatever beta is; with a beta beyond the planner's
 * limits coa_planner_workspace_size() of it is 0, which the caller must check. */
coa_planner_config_t coavoid_scenario_planner_config(const coavoid_scenario_t *s, size_t searched,
                                                     uint32_t beta);

/* Widens *into so that it also takes every problem `with` takes: the longer horizon, the
 * larger steep factor and offset bound (unbounded when either is). */
void coavoid_planner_config_widen(coa_planner_config_t *into, const coa_planner_config_t *with);

/* Whether a planner of this config has a size and fits COAVOID_DEFAULT_WORKSPACE_MAX.
 * O(1), no memory, cannot fail. */
bool coavoid_workspace_fits(const coa_planner_config_t *config);

/* The default beta for planners of this config (its beta ignored): COAVOID_DEFAULT_BETA, or
 * the largest beta whose workspace fits COAVOID_DEFAULT_WORKSPACE_MAX when that is smaller;
 * 0 when none does (the cost-to-go tables alone are too large: a very long horizon). */
uint32_t coavoid_default_beta(const coa_planner_config_t *config);

void coavoid_scenario_free(coavoid_scenario_t *s);

#endif /* COAVOID_SCENARIO_H */
