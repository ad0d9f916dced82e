/* SPDX-License-Identifier: MIT */
/*
 * run.h: one scenario planned or predicted, as `coavoid plan` and `coavoid predict` do it:
 *
 *   - coavoid_scenario_plan samples the scenario, sizes a planner for it (its beta from the
 *     caller, the scenario or the default of scenario.h's sizing policy), plans all UAVs
 *     together (centralised) or one after another (decoupled) and writes the "Plan
 *     result";
 *   - coavoid_scenario_predict samples the scenario, takes every UAV's plan to be its
 *     reference at its initial_offset (no manoeuvre), runs one coa_predict over it and
 *     writes the "Prediction result": the conflicts and the clusters of UAVs to plan
 *     together.
 *
 * Both follow docs/scenario-format.md, write the result to a stream the caller gives, and
 * report the first problem as one line in a coavoid_run_error_t, naming the file and field
 * (or the option, by its command-line name: --beta, --mode) and why; the program prefixes
 * it with its own name and turns the return into its exit status. Nothing goes to stderr.
 * The scenario is untrusted (docs/security.md): every size is checked before anything of
 * that size is allocated.
 */
#ifndef COAVOID_SCENARIO_RUN_H
#define COAVOID_SCENARIO_RUN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "scenario.h"

/* What both return: a verdict (>= 0), or why there is none (< 0). */
enum {
    COAVOID_RUN_DONE = 0,          /* plan: solved; predict: predicted, conflicts or not */
    COAVOID_RUN_NOT_SOLVED = 1,    /* plan: infeasible or budget exhausted */
    COAVOID_RUN_ERR_INPUT = -2,    /* the scenario or a setting is refused, or too large */
    COAVOID_RUN_ERR_INTERNAL = -3, /* a bug, out of memory, or the result was not written */
};

/* Room for one report line. */
#define COAVOID_RUN_ERROR_MAX 1024u

typedef struct {
    char text[COAVOID_RUN_ERROR_MAX]; /* "" until a problem is reported */
} coavoid_run_error_t;

/* Formats the report line into e and returns status, so that a check reads
 * `return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, ...)`. */
int coavoid_run_fail(coavoid_run_error_t *e, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* A plan. */
typedef struct {
    const char *scenario_path; /* names the scenario in reports */
    bool decoupled;            /* one UAV at a time; otherwise all together */
    const size_t *order;       /* decoupled: vehicle indices, each exactly once, in the
                                  order to plan; NULL: the scenario's priorities */
    bool has_beta;             /* beta given (--beta): it overrides the scenario's */
    uint32_t beta;
    uint64_t work;       /* the planning call's work budget (plan.h, "Work"); 0: no limit */
    uint32_t max_orders; /* decoupled: priority orders to try, >= 1; 1 plans just one */
} coavoid_plan_config_t;

/* Plans scenario s (loaded, not yet sampled: sampled here) as c says and writes the plan
 * result to out. Returns COAVOID_RUN_DONE (solved) or COAVOID_RUN_NOT_SOLVED, or an error
 * with e set: then nothing is written, unless writing the result is what failed.
 * Time: the planner's, up to max_orders decoupled passes or one joint search, bounded by
 * beta. Memory: heap, the planner's workspace (its cost-to-go tables capped at
 * COAVOID_DEFAULT_WORKSPACE_MAX, its closed set by beta) and one offset per UAV and step,
 * released before return. */
int coavoid_scenario_plan(const coavoid_plan_config_t *c, coavoid_scenario_t *s, FILE *out,
                          coavoid_run_error_t *e);

/* A prediction. */
typedef struct {
    const char *scenario_path; /* names the scenario in reports */
    double threshold;          /* a pair with uncertainty is listed from this probability,
                                  0 < threshold <= 1 */
    double growth_horizontal;  /* every track's one-sigma error grows by this, m/s, >= 0 */
    double growth_vertical;    /* m/s, >= 0 */
} coavoid_predict_config_t;

/* Predicts the conflicts of scenario s (loaded, not yet sampled: sampled here) over its
 * horizon as c says and writes the prediction result to out. Returns COAVOID_RUN_DONE, or
 * an error with e set: then nothing is written, unless writing the result is what failed.
 * Time: one coa_predict (predict.h), at worst O(UAVs x (UAVs + tracks + obstacles) x
 * steps), and sorting the conflicts. Memory: heap, sized for every pair to conflict (the
 * predictor's workspace, the plans' samples and one entry per pair), released before
 * return. */
int coavoid_scenario_predict(const coavoid_predict_config_t *c, coavoid_scenario_t *s, FILE *out,
                             coavoid_run_error_t *e);

#endif /* COAVOID_SCENARIO_RUN_H */
