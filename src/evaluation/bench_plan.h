/* SPDX-License-Identifier: MIT */
/*
 * bench_plan.h: the harness of `coavoid bench plan`: times the core's planner
 * (coa_plan_centralised and coa_plan_decoupled) on a scenario file (the paper's) and on
 * seeded random encounters of 2 to 10 UAVs (docs/benchmarks.md, "Planning").
 *
 * The encounters (encounter.h, design coavoid_encounter_bench, shared with montecarlo).
 * n UAVs converge on one point: their headings are spread evenly around it (plus up to
 * 0.3 rad of jitter), each at 8-12 m/s, arriving 8-12 s into a 20-step horizon (dt 1 s),
 * so every pair's paths cross near the point at about the same time. Altitudes are
 * staggered on a 2 m grid within 3 steps of 100 m (climb rates 1.5-3 m/s, so within a few
 * climb steps): against 10 m of combined half-heights most pairs conflict unless someone
 * moves, and some pairs already clear each other. Half the encounters have a terrain box
 * under the point whose top is 4 m below the lowest UAV's volume, so diving is limited
 * there. The problems are written as scenario JSON and go through the scenario loader, so
 * they are checked like any file; a seed gives the same problems on every machine with
 * the same libm (headings use cos and sin); only the times differ.
 *
 * What is timed: the planning call alone (clock_gettime around it). One run plans every
 * problem of a set once; a set's time is the sum over its problems, reported as the
 * median, min and max over `repeat` runs. Each (set, mode) gets one planner workspace,
 * allocated and initialised outside the timing and reused by every problem and run, as a
 * deployment would. One untimed run first warms caches and the workspace's pages; every
 * timed run must repeat its results exactly.
 */
#ifndef COAVOID_EVALUATION_BENCH_PLAN_H
#define COAVOID_EVALUATION_BENCH_PLAN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "encounter.h"
#include "run.h"

/* The scenario's set and one per UAV count of the encounters. */
#define COAVOID_BENCH_PLAN_MAX_SETS \
    (1u + COAVOID_ENCOUNTER_MAX_VEHICLES - COAVOID_ENCOUNTER_MIN_VEHICLES + 1u)
/* Each set in both modes, centralised first. */
#define COAVOID_BENCH_PLAN_MAX_ROWS (2u * COAVOID_BENCH_PLAN_MAX_SETS)

typedef struct {
    /* A scenario file timed first as the set "paper" (at most COA_MAX_CENTRALISED UAVs),
     * or NULL for none. */
    const char *scenario;
    /* The encounter sets, "N UAVs" for each N from min_vehicles to max_vehicles, within
     * COAVOID_ENCOUNTER_MIN_VEHICLES..MAX; count problems each. */
    uint32_t min_vehicles, max_vehicles;
    uint32_t count;
    uint64_t seed;
    uint32_t repeat; /* timed runs, >= 1 */
    /* The closed-set bound, >= 1; 0: the scenario's "beta" for its set, else
     * COAVOID_DEFAULT_BETA. Either way lowered to coavoid_default_beta where the workspace
     * would pass COAVOID_DEFAULT_WORKSPACE_MAX (the programs' sizing policy, scenario.h). */
    uint32_t beta;
    /* Work units each planning call may spend (coa_planner_set_work); 0: no limit. */
    uint64_t work;
    /* An existing directory for every random encounter as DIR/bench-SEED-N-INDEX.json, or
     * NULL. */
    const char *save;
} coavoid_bench_plan_config_t;

/* Room for a set's name with its NUL. */
#define COAVOID_BENCH_PLAN_LABEL_MAX 16u

/* One set in one mode. */
typedef struct {
    char set[COAVOID_BENCH_PLAN_LABEL_MAX]; /* "paper", "2 UAVs" */
    bool decoupled;
    uint32_t vehicles, problems, beta;
    bool beta_lowered; /* the chosen beta's workspace passed COAVOID_DEFAULT_WORKSPACE_MAX */
    double median_ms, min_ms, max_ms;
    uint64_t nodes_expanded, nodes_generated;
    size_t workspace_bytes;
    size_t touched_bytes; /* of the workspace, the most any problem's call had written */
    uint32_t solved, infeasible, budget_exhausted;
    /* Centralised: the solved plans proven optimal, and the others (bounded). */
    uint32_t optimal, bounded;
    /* Over the problems, each timed by its median over the runs: the median and largest. */
    double problem_median_ms, problem_max_ms;
    /* Over the centralised plans found: the median and largest ratio of the plan's
     * deviation to its proven lower bound (1 when optimal; 0 when no plan has a positive
     * bound). */
    double ratio_median, ratio_max;
    uint64_t work; /* work units spent in one run over the set */
} coavoid_bench_plan_row_t;

typedef struct {
    coavoid_bench_plan_row_t rows[COAVOID_BENCH_PLAN_MAX_ROWS];
    size_t row_count;
} coavoid_bench_plan_result_t;

/* Loads the scenario and draws the encounters (all before any timing), then times each
 * set centralised and decoupled. Returns COAVOID_RUN_DONE with *out filled, or an error
 * (evaluation.h, "Errors") with e set: COAVOID_RUN_ERR_INPUT when the scenario does not
 * load ("FILE: field: reason") or has too many UAVs, memory is short or the planner
 * refuses a problem's range, COAVOID_RUN_ERR_INTERNAL when an encounter or the planner
 * fails or a run differs from the first. Memory: the sampled problems and one planner
 * workspace at a time (as beta sizes it), all freed before it returns. Cost: (repeat + 1)
 * runs over every set in both modes. */
int coavoid_bench_plan_run(const coavoid_bench_plan_config_t *config,
                           coavoid_bench_plan_result_t *out, coavoid_run_error_t *e);

/* Prints the config's seed, repeat and count and the rows on f as a table or, with json,
 * a JSON object (the keys of docs/benchmarks.md). Returns 0, or -1 when a write (or
 * cJSON's memory) failed. */
int coavoid_bench_plan_report(FILE *f, const coavoid_bench_plan_config_t *config,
                              const coavoid_bench_plan_result_t *result, bool json);

#endif /* COAVOID_EVALUATION_BENCH_PLAN_H */
