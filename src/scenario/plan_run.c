/* SPDX-License-Identifier: MIT */
/* A scenario planned and its plan result written (run.h, coavoid_scenario_plan). */
#define _POSIX_C_SOURCE 200809L

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "coavoid/coavoid.h"
#include "output.h"
#include "run.h"
#include "scenario.h"

/* The core's COA_ERR_RANGE from the problem check or the planner. Weights that cannot be
 * exact (the only cause the current limits allow) are named by the parser first, so what
 * is left is the worst-case cost over the horizon outgrowing the core's exact integers:
 * horizon is what the user is most likely to change. A backstop. */
static int range_error(coavoid_run_error_t *e, const char *file, const coavoid_scenario_t *s)
{
    return coavoid_run_fail(
        e, COAVOID_RUN_ERR_INPUT,
        "%s: horizon: %lu steps is too long for these vehicles' offsets and costs "
        "(beyond the core's integer range; shorten it or bound max_offset)",
        file, (unsigned long)s->horizon);
}

static int64_t elapsed_us(const struct timespec *start, const struct timespec *end)
{
    return (int64_t)(end->tv_sec - start->tv_sec) * 1000000 +
           (int64_t)(end->tv_nsec - start->tv_nsec) / 1000;
}

/* beta as given, else the scenario's, else the default; *source names it for messages. */
static uint32_t choose_beta(const coavoid_plan_config_t *c, const coavoid_scenario_t *s,
                            size_t searched, char *source, size_t source_size)
{
    if (c->has_beta) {
        snprintf(source, source_size, "--beta %lu", (unsigned long)c->beta);
        return c->beta;
    }
    if (s->has_beta) {
        snprintf(source, source_size, "%.400s: beta %lu", c->scenario_path, (unsigned long)s->beta);
        return s->beta;
    }
    coa_planner_config_t shape = coavoid_scenario_planner_config(s, searched, COAVOID_DEFAULT_BETA);
    uint32_t beta = coavoid_default_beta(&shape);
    snprintf(source, source_size, "default beta %lu", (unsigned long)beta);
    return beta;
}

/* The planner for `searched` UAVs at `beta`, in a workspace of its exact size, and the
 * offsets' rows; *workspace and *offsets are the caller's to free, also on failure.
 * Returns 0, or an error with e set. */
static int plan_allocate(coavoid_run_error_t *e, const char *file, const char *beta_source,
                         const coavoid_scenario_t *s, size_t searched, uint32_t beta,
                         void **workspace, int32_t **offsets, coa_planner_t **planner)
{
    coa_planner_config_t config = coavoid_scenario_planner_config(s, searched, beta);
    /* The tables alone (every reachable step and offset) do not depend on beta: when they
     * pass the limit no beta helps, whatever --beta or the scenario say. */
    if (beta == 0 || coa_planner_max_beta(&config, COAVOID_DEFAULT_WORKSPACE_MAX) == 0) {
        return coavoid_run_fail(
            e, COAVOID_RUN_ERR_INPUT,
            "%s: too large: the cost-to-go tables of a %lu-step horizon would not "
            "fit in %zu MiB of workspace (shorten the horizon or bound max_offset)",
            file, (unsigned long)s->horizon, COAVOID_DEFAULT_WORKSPACE_MAX >> 20);
    }
    size_t size = coa_planner_workspace_size(&config);
    if (size == 0) {
        return coavoid_run_fail(
            e, COAVOID_RUN_ERR_INPUT,
            "%s: too large: the workspace for %zu vehicle(s) over %lu steps would "
            "not fit in memory (lower it with --beta)",
            beta_source, searched, (unsigned long)s->horizon);
    }
    *workspace = malloc(size);
    if (*workspace == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "%s: cannot allocate %zu bytes of workspace for %zu vehicle(s) "
                                "(lower it with --beta)",
                                beta_source, size, searched);
    }
    *planner = coa_planner_init(*workspace, size, &config);
    *offsets = calloc(s->vehicle_count * ((size_t)s->horizon + 1u), sizeof **offsets);
    if (*planner == NULL || *offsets == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "%s",
                                *planner == NULL
                                    ? "internal error: the planner refused its workspace"
                                    : "out of memory for the plan");
    }
    return 0;
}

/* The scenario sampled and accepted by the core's problem check. Returns 0, or an error
 * with e set. */
static int plan_problem(coavoid_run_error_t *e, const char *file, coavoid_scenario_t *s,
                        coa_problem_t *problem)
{
    char err[COAVOID_SCENARIO_ERROR_MAX];
    if (coavoid_scenario_sample(s, err, sizeof err) != 0) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "%s: %s", file, err);
    }
    *problem = coavoid_scenario_problem(s);
    int rc = coa_problem_check(problem);
    if (rc == COA_ERR_RANGE) {
        return range_error(e, file, s);
    }
    if (rc != COA_OK) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "%s: rejected by the core's problem check (%s)", file,
                                coa_status_name(rc));
    }
    return 0;
}

/* Plans in the mode asked for and writes the result; the verdict, or an error with e
 * set. */
static int plan_search(const coavoid_plan_config_t *c, const coavoid_scenario_t *s,
                       const coa_problem_t *problem, coa_planner_t *planner, int32_t *offsets,
                       uint32_t beta, FILE *out, coavoid_run_error_t *e)
{
    char err[COAVOID_SCENARIO_ERROR_MAX];
    coa_plan_result_t result;
    memset(&result, 0, sizeof result);
    struct timespec start, end;
    int rc;
    (void)coa_planner_set_work(planner, c->work); /* a planner coa_planner_init built */
    clock_gettime(CLOCK_MONOTONIC, &start);
    if (c->decoupled) {
        rc = coa_plan_decoupled(planner, problem, c->order, c->max_orders, offsets, &result);
    } else {
        rc = coa_plan_centralised(planner, problem, offsets, &result);
    }
    clock_gettime(CLOCK_MONOTONIC, &end);
    if (rc == COA_ERR_RANGE) {
        return range_error(e, c->scenario_path, s);
    }
    if (rc != COA_OK) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: the planner failed (%s)", coa_status_name(rc));
    }
    coavoid_output_plan_t view = {s,    c->decoupled, &result, offsets, elapsed_us(&start, &end),
                                  beta, c->work};
    if (coavoid_output_plan(out, &view, err, sizeof err) != 0) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "%s", err);
    }
    return result.status == COA_PLAN_SOLVED ? COAVOID_RUN_DONE : COAVOID_RUN_NOT_SOLVED;
}

int coavoid_scenario_plan(const coavoid_plan_config_t *c, coavoid_scenario_t *s, FILE *out,
                          coavoid_run_error_t *e)
{
    const char *file = c->scenario_path;
    const size_t n = s->vehicle_count;
    e->text[0] = '\0';
    if (!c->decoupled && n > COA_MAX_CENTRALISED) {
        return coavoid_run_fail(
            e, COAVOID_RUN_ERR_INPUT,
            "--mode centralised: %zu vehicles, at most %u (COA_MAX_CENTRALISED) can be "
            "planned together",
            n, COA_MAX_CENTRALISED);
    }
    const size_t searched = c->decoupled ? 1u : n;
    char beta_source[COAVOID_SCENARIO_ERROR_MAX];
    uint32_t beta = choose_beta(c, s, searched, beta_source, sizeof beta_source);
    coa_problem_t problem;
    int status = plan_problem(e, file, s, &problem);
    if (status != 0) {
        return status;
    }
    void *workspace = NULL;
    int32_t *offsets = NULL;
    coa_planner_t *planner = NULL;
    status = plan_allocate(e, file, beta_source, s, searched, beta, &workspace, &offsets, &planner);
    if (status == 0) {
        status = plan_search(c, s, &problem, planner, offsets, beta, out, e);
    }
    free(workspace);
    free(offsets);
    return status;
}
