/* SPDX-License-Identifier: MIT */
/*
 * montecarlo.c: the Monte Carlo engine (montecarlo.h): each encounter drawn, solved three
 * ways and cross-checked on a worker thread, the CSV written and progress reported by the
 * calling thread in encounter order. The statistics and reports are montecarlo_report.c's.
 */
#define _POSIX_C_SOURCE 200809L

#include "montecarlo.h"

#include <math.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "coavoid/coavoid.h"
#include "encounter.h"
#include "evaluation_internal.h"
#include "montecarlo_internal.h"
#include "output.h"
#include "run.h"
#include "scenario.h"

/* Draws per encounter before giving up (a design bug). Ten UAVs that start 32-96 m from
 * the crossing often meet at t = 0: an encounter of ten takes about 120 draws on average
 * and, now and then, more than a thousand. */
#define MC_MAX_ATTEMPTS 100000u

const char *const coavoid_mc_method_names[COAVOID_MC_METHODS] = {"centralised", "decoupled_fixed",
                                                                 "decoupled_reordered"};
const char *const coavoid_mc_fly_mode_names[COAVOID_MC_FLY_MODES] = {"centralised", "decoupled"};

/* ---- one encounter ---- */

double coavoid_mc_round(double value, double scale)
{
    return round(value * scale) / scale;
}

/* A planner for every encounter of the design: its horizon, steep factor 2 (the
 * generator's) and its offset band (unbounded when it draws none). */
static coa_planner_config_t mc_config(uint32_t searched, uint32_t beta)
{
    const coavoid_encounter_design_t *d = &coavoid_encounter_montecarlo;
    coa_planner_config_t c;
    c.vehicles = searched;
    c.beta = beta;
    c.horizon = d->horizon;
    c.steep_factor = 2u;
    c.max_offset = d->max_offset_max > 0u ? (int32_t)d->max_offset_max : -1;
    return c;
}

static uint32_t factorial(uint32_t n)
{
    uint32_t f = 1u;
    for (uint32_t k = 2u; k <= n; k++) {
        f *= k;
    }
    return f;
}

/* One worker's planners, rebuilt when the UAV count changes (the items come in order, so
 * at most once per count). */
typedef struct {
    uint32_t n;
    void *central_buffer, *decoupled_buffer;
    coa_planner_t *central, *decoupled;
    int32_t *offsets; /* COAVOID_ENCOUNTER_MAX_VEHICLES * (COA_MAX_HORIZON + 1) */
    int32_t *zeros;
} mc_planners_t;

static void planners_free(mc_planners_t *p)
{
    free(p->central_buffer);
    free(p->decoupled_buffer);
    free(p->offsets);
    free(p->zeros);
    memset(p, 0, sizeof *p);
}

/* Returns 0, or -1 with the reason in err. */
static int planners_ready(mc_planners_t *p, const coavoid_mc_size_t *size, char *err,
                          size_t err_size)
{
    if (p->n == size->n && p->central != NULL) {
        return 0;
    }
    free(p->central_buffer);
    free(p->decoupled_buffer);
    p->central_buffer = p->decoupled_buffer = NULL;
    p->central = p->decoupled = NULL;
    p->n = size->n;
    size_t rows = (size_t)COAVOID_ENCOUNTER_MAX_VEHICLES * (COA_MAX_HORIZON + 1u);
    if (p->offsets == NULL) {
        p->offsets = calloc(rows, sizeof *p->offsets);
        p->zeros = calloc(rows, sizeof *p->zeros);
    }
    coa_planner_config_t central_config = mc_config(size->n, size->beta);
    coa_planner_config_t decoupled_config = mc_config(1u, size->beta);
    size_t central = coa_planner_workspace_size(&central_config);
    size_t decoupled = coa_planner_workspace_size(&decoupled_config);
    if (central == 0 || decoupled == 0) {
        snprintf(err, err_size,
                 "--beta: %lu is too large for %lu UAVs centralised (the node "
                 "pool would pass 2^30)",
                 (unsigned long)size->beta, (unsigned long)size->n);
        return -1;
    }
    p->central_buffer = malloc(central);
    p->decoupled_buffer = malloc(decoupled);
    if (p->central_buffer == NULL || p->decoupled_buffer == NULL || p->offsets == NULL ||
        p->zeros == NULL) {
        snprintf(err, err_size,
                 "out of memory for %zu bytes of workspace (%lu UAVs at beta "
                 "%lu; lower --beta or --jobs)",
                 central, (unsigned long)size->n, (unsigned long)size->beta);
        return -1;
    }
    p->central = coa_planner_init(p->central_buffer, central, &central_config);
    p->decoupled = coa_planner_init(p->decoupled_buffer, decoupled, &decoupled_config);
    if (p->central == NULL || p->decoupled == NULL) {
        snprintf(err, err_size, "internal error: the planner refused its workspace");
        return -1;
    }
    return 0;
}

/* DIR/montecarlo-SEED-N-INDEX.json, so that `coavoid plan` can replay an encounter. */
/* The accepted draw of encounter (n, index), sampled, in *s; saved in save_dir unless
 * NULL. Returns 0 or -1 with err. */
static int draw_encounter(uint64_t seed, const coavoid_mc_size_t *size, uint32_t index,
                          const char *save_dir, mc_planners_t *p, coavoid_scenario_t *s,
                          coavoid_mc_result_t *r, char *err, size_t err_size)
{
    const uint32_t n = size->n;
    size_t which[COAVOID_ENCOUNTER_MAX_VEHICLES];
    for (size_t i = 0; i < n; i++) {
        which[i] = i;
    }
    for (uint32_t attempt = 0; attempt < MC_MAX_ATTEMPTS; attempt++) {
        char json[COAVOID_ENCOUNTER_JSON_MAX];
        char why[COAVOID_SCENARIO_ERROR_MAX];
        if (!coavoid_encounter_json(&coavoid_encounter_montecarlo, seed, n, index, attempt, json,
                                    sizeof json, &r->info)) {
            snprintf(err, err_size,
                     "internal error: encounter %lu of %lu UAVs does not fit %u "
                     "bytes",
                     (unsigned long)index, (unsigned long)n, COAVOID_ENCOUNTER_JSON_MAX);
            return -1;
        }
        memset(s, 0, sizeof *s);
        if (coavoid_scenario_parse(json, strlen(json), s, why, sizeof why) != 0 ||
            coavoid_scenario_sample(s, why, sizeof why) != 0) {
            coavoid_scenario_free(s);
            snprintf(err, err_size, "internal error: encounter %lu of %lu UAVs: %s",
                     (unsigned long)index, (unsigned long)n, why);
            return -1;
        }
        coa_problem_t problem = coavoid_scenario_problem(s);
        size_t vehicle = 0;
        uint32_t step = 0;
        int rc = coa_plan_find_conflict(&problem, p->zeros, which, n, &vehicle, &step);
        if (rc < 0) {
            coavoid_scenario_free(s);
            snprintf(err, err_size,
                     "internal error: encounter %lu of %lu UAVs: the conflict "
                     "check failed (%s)",
                     (unsigned long)index, (unsigned long)n, coa_status_name(rc));
            return -1;
        }
        if (rc == 1 && step > 0) {
            if (save_dir != NULL &&
                coavoid_encounter_save(save_dir, "montecarlo", seed, n, index, json) != 0) {
                coavoid_scenario_free(s);
                snprintf(err, err_size,
                         "--save: cannot write encounter %lu of %lu UAVs in "
                         "'%.200s'",
                         (unsigned long)index, (unsigned long)n, save_dir);
                return -1;
            }
            r->redraws = attempt;
            r->first_conflict_step = step;
            return 0;
        }
        coavoid_scenario_free(s);
    }
    snprintf(err, err_size,
             "internal error: encounter %lu of %lu UAVs: no draw in %u has a "
             "conflict after its first step",
             (unsigned long)index, (unsigned long)n, MC_MAX_ATTEMPTS);
    return -1;
}

/* Solves encounter (size, index) three ways into *r. Returns 0 or -1 with err (an error
 * of the tool, not of a plan: plans' defects go to r->defect). */
/* Plans the encounter with method m into r->m[m], and records a defect when a solved plan
 * has a conflict. -1 with err set when the planner failed. */
static int solve_method(int m, const coa_problem_t *problem, const coavoid_mc_size_t *size,
                        uint32_t index, mc_planners_t *p, coavoid_mc_result_t *r, char *err,
                        size_t err_size)
{
    size_t which[COAVOID_ENCOUNTER_MAX_VEHICLES];
    coa_plan_result_t result;
    struct timespec start, end;
    memset(&result, 0, sizeof result);
    (void)coa_planner_set_work(m == COAVOID_MC_CENTRALISED ? p->central : p->decoupled, size->work);
    clock_gettime(CLOCK_MONOTONIC, &start);
    int rc = m == COAVOID_MC_CENTRALISED
                 ? coa_plan_centralised(p->central, problem, p->offsets, &result)
                 : coa_plan_decoupled(p->decoupled, problem, NULL,
                                      m == COAVOID_MC_FIXED ? 1u : size->max_orders, p->offsets,
                                      &result);
    clock_gettime(CLOCK_MONOTONIC, &end);
    if (rc != COA_OK) {
        snprintf(err, err_size,
                 "internal error: encounter %lu of %lu UAVs, %s: the "
                 "planner failed (%s)",
                 (unsigned long)index, (unsigned long)size->n, coavoid_mc_method_names[m],
                 coa_status_name(rc));
        return -1;
    }
    coavoid_mc_outcome_t *o = &r->m[m];
    o->status = result.status;
    o->deviation = coavoid_mc_round(result.deviation, 1e6);
    o->units = result.deviation_units;
    o->effort = result.effort;
    o->expanded = result.nodes_expanded;
    o->generated = result.nodes_generated;
    o->orders_tried = result.orders_tried;
    o->time_us = coavoid_mc_round(coavoid_timing_elapsed_ms(&start, &end) * 1e3, 10.0);
    o->optimal = result.optimal;
    o->bound_deviation = coavoid_mc_round(result.bound_deviation, 1e6);
    o->work = result.work;
    if (result.status == COA_PLAN_SOLVED && r->defect[0] == '\0') {
        size_t vehicle = 0;
        uint32_t step = 0;
        for (size_t i = 0; i < size->n; i++) {
            which[i] = i;
        }
        rc = coa_plan_find_conflict(problem, p->offsets, which, size->n, &vehicle, &step);
        if (rc != 0) {
            snprintf(r->defect, sizeof r->defect,
                     "the %s plan has a conflict (check %d) "
                     "at step %lu",
                     coavoid_mc_method_names[m], rc, (unsigned long)step);
        }
    }
    return 0;
}

/* The defects the methods' outcomes can show against each other: the reference plan
 * conflicts, so every plan moves someone (a deviation of 0 would be wrong, and the ratios
 * divide by it); a decoupled plan is a plan for the whole group, which the centralised
 * search cannot have proven absent, nor beaten. */
void coavoid_mc_cross_check(coavoid_mc_result_t *r)
{
    const coavoid_mc_outcome_t *c = &r->m[COAVOID_MC_CENTRALISED];
    if (r->defect[0] == '\0' && c->status == COA_PLAN_SOLVED && c->units.hi == 0 &&
        c->units.lo == 0) {
        snprintf(r->defect, sizeof r->defect,
                 "the centralised plan has no deviation although "
                 "the reference plan conflicts at step %lu",
                 (unsigned long)r->first_conflict_step);
    }
    for (int m = COAVOID_MC_FIXED; m < COAVOID_MC_METHODS && r->defect[0] == '\0'; m++) {
        const coavoid_mc_outcome_t *d = &r->m[m];
        if (c->status == COA_PLAN_INFEASIBLE && d->status == COA_PLAN_SOLVED) {
            snprintf(r->defect, sizeof r->defect,
                     "%s solved an encounter the centralised "
                     "search proved infeasible",
                     coavoid_mc_method_names[m]);
            continue;
        }
        if (c->status != COA_PLAN_SOLVED || d->status != COA_PLAN_SOLVED) {
            continue;
        }
        int cmp = coa_cost_compare(d->units, c->units);
        if (cmp < 0 || (cmp == 0 && d->effort < c->effort)) {
            snprintf(r->defect, sizeof r->defect,
                     "%s plan (deviation %.17g units, effort %lu) "
                     "is cheaper than the optimal centralised one (%.17g units, effort %lu)",
                     coavoid_mc_method_names[m], coavoid_mc_cost_real(d->units),
                     (unsigned long)d->effort, coavoid_mc_cost_real(c->units),
                     (unsigned long)c->effort);
        }
    }
}

void coavoid_mc_report_defect(const coavoid_montecarlo_config_t *c, const coavoid_mc_result_t *r)
{
    if (r->defect[0] == '\0' || c->defect == NULL) {
        return;
    }
    char line[COAVOID_RUN_ERROR_MAX];
    snprintf(line, sizeof line, "montecarlo: defect: seed %llu, %lu UAVs, encounter %lu: %s",
             (unsigned long long)c->seed, (unsigned long)r->vehicles, (unsigned long)r->index,
             r->defect);
    c->defect(c->context, line);
}

static int solve_encounter(uint64_t seed, const coavoid_mc_size_t *size, uint32_t index,
                           const char *save_dir, mc_planners_t *p, coavoid_mc_result_t *r,
                           char *err, size_t err_size)
{
    memset(r, 0, sizeof *r);
    r->vehicles = size->n;
    r->index = index;
    if (planners_ready(p, size, err, err_size) != 0) {
        return -1;
    }
    coavoid_scenario_t s;
    if (draw_encounter(seed, size, index, save_dir, p, &s, r, err, err_size) != 0) {
        return -1;
    }
    coa_problem_t problem = coavoid_scenario_problem(&s);
    int status = 0;
    for (int m = 0; m < COAVOID_MC_METHODS && status == 0; m++) {
        status = solve_method(m, &problem, size, index, p, r, err, err_size);
    }
    coavoid_scenario_free(&s);
    if (status == 0) {
        coavoid_mc_cross_check(r);
    }
    return status;
}

/* The closed loop of the encounter just solved (config fly), when the library has it. */
static int fly_encounter(const coavoid_montecarlo_config_t *c, const coavoid_mc_size_t *size,
                         coavoid_mc_result_t *r, char *err, size_t err_size)
{
#ifdef COAVOID_HAVE_LCM
    return coavoid_mc_fly(c, size, r, err, err_size);
#else
    (void)c;
    (void)size;
    (void)r;
    snprintf(err, err_size, "--fly: this build has no simulation (no messaging library)");
    return -1;
#endif
}

/* ---- the run: workers and the main thread's writing and progress ---- */

typedef struct {
    coavoid_montecarlo_t *mc;
    bool *done;
    pthread_mutex_t lock;
    uint32_t next; /* the next item a worker takes */
    bool stop;     /* an error: workers take nothing more */
    char error[COAVOID_SCENARIO_ERROR_MAX + 128];
} mc_run_t;

static const coavoid_mc_size_t *item_size(const mc_run_t *run, uint32_t item)
{
    return &run->mc->sizes[item / run->mc->config.count];
}

static void *worker(void *arg)
{
    mc_run_t *run = arg;
    mc_planners_t planners;
    memset(&planners, 0, sizeof planners);
    for (;;) {
        pthread_mutex_lock(&run->lock);
        uint32_t item = run->next;
        bool go = !run->stop && item < run->mc->total;
        if (go) {
            run->next++;
        }
        pthread_mutex_unlock(&run->lock);
        if (!go) {
            break;
        }
        coavoid_mc_result_t result;
        char err[sizeof run->error];
        const coavoid_montecarlo_config_t *c = &run->mc->config;
        int rc = solve_encounter(c->seed, item_size(run, item), c->first + item % c->count, c->save,
                                 &planners, &result, err, sizeof err);
        if (rc == 0 && c->fly) {
            rc = fly_encounter(c, item_size(run, item), &result, err, sizeof err);
        }
        pthread_mutex_lock(&run->lock);
        if (rc != 0) {
            if (!run->stop) {
                snprintf(run->error, sizeof run->error, "%s", err);
            }
            run->stop = true;
        } else {
            run->mc->results[item] = result;
            run->done[item] = true;
        }
        pthread_mutex_unlock(&run->lock);
    }
    planners_free(&planners);
    return NULL;
}

/* The decimal digits of a 128-bit cost. */
static void cost_text(coa_cost_t c, char *buf, size_t size)
{
    char digits[48];
    size_t k = 0;
    uint32_t limb[4] = {(uint32_t)(c.hi >> 32), (uint32_t)c.hi, (uint32_t)(c.lo >> 32),
                        (uint32_t)c.lo};
    do {
        uint64_t rem = 0;
        bool zero = true;
        for (int j = 0; j < 4; j++) {
            uint64_t cur = (rem << 32) | limb[j];
            limb[j] = (uint32_t)(cur / 10u);
            rem = cur % 10u;
            zero = zero && limb[j] == 0;
        }
        digits[k++] = (char)('0' + rem);
        if (zero) {
            break;
        }
    } while (k < sizeof digits);
    size_t j = 0;
    for (; j < k && j + 1 < size; j++) {
        buf[j] = digits[k - 1 - j];
    }
    buf[j] = '\0';
}

#define MC_CSV_HEADER COAVOID_MC_CSV_HEADER_LINE "\n"
#define MC_CSV_HEADER_FLY COAVOID_MC_CSV_HEADER_FLY_LINE "\n"

/* A setting as the fewest of 15 or 17 digits that read back as the same double. */
static void real_text(double v, char *buf, size_t size)
{
    snprintf(buf, size, "%.15g", v);
    if (strtod(buf, NULL) != v) {
        snprintf(buf, size, "%.17g", v);
    }
}

/* What every row of an encounter carries besides its own columns (montecarlo_internal.h):
 * with fly the network (loss, delay, jitter) and the encounter's network seed, so that a
 * file says what it measured (--figure-from reads the loss) and `coavoid sim --net-seed
 * --coordinator-stops` replays a run; the planners' limits and the run's encounters
 * (MORE); with fly the sweep and --net-seed as given (FLOWN): --merge checks the parts of
 * a run against each other with them. Empty strings where the run has no such columns. */
typedef struct {
    char network[128]; /* ",loss,delay,jitter,net_seed" */
    char run[128];     /* ",beta,max_orders,work,first,count" */
    char options[64];  /* ",coordinator_stops_sweep,net_seed_option" */
} mc_row_tail_t;

static void row_tail(const coavoid_montecarlo_config_t *c, const coavoid_mc_size_t *size,
                     const coavoid_mc_result_t *r, mc_row_tail_t *t)
{
    memset(t, 0, sizeof *t);
    snprintf(t->run, sizeof t->run, ",%lu,%lu,%llu,%lu,%lu", (unsigned long)size->beta,
             (unsigned long)size->max_orders, (unsigned long long)size->work,
             (unsigned long)c->first, (unsigned long)c->count);
    if (!c->fly) {
        return;
    }
    char loss[32], delay[32], jitter[32];
    real_text(c->loss, loss, sizeof loss);
    real_text(c->delay, delay, sizeof delay);
    real_text(c->jitter, jitter, sizeof jitter);
    snprintf(t->network, sizeof t->network, ",%s,%s,%s,%llu", loss, delay, jitter,
             (unsigned long long)r->net_seed);
    char net_seed[32] = "";
    if (c->has_net_seed) {
        snprintf(net_seed, sizeof net_seed, "%llu", (unsigned long long)c->net_seed);
    }
    snprintf(t->options, sizeof t->options, ",%s,%s",
             !c->stops_sweep ? "" : (c->stops_ends ? "ends" : "all"), net_seed);
}

/* A row per method: its costs only of a plan (a failed decoupled attempt's partial costs
 * are not one), and centralised, whether the plan is proven optimal and the lower bound. */
static void csv_rows(FILE *f, const coavoid_montecarlo_config_t *c, const coavoid_mc_size_t *size,
                     const coavoid_mc_result_t *r)
{
    mc_row_tail_t t;
    row_tail(c, size, r, &t);
    for (int m = 0; m < COAVOID_MC_METHODS; m++) {
        const coavoid_mc_outcome_t *o = &r->m[m];
        char costs[128] = ",,";
        if (o->status == COA_PLAN_SOLVED) {
            char units[48];
            cost_text(o->units, units, sizeof units);
            snprintf(costs, sizeof costs, "%.6f,%s,%lu", o->deviation, units,
                     (unsigned long)o->effort);
        }
        char bound[64] = ","; /* optimal, bound_deviation */
        if (m == COAVOID_MC_CENTRALISED) {
            snprintf(bound, sizeof bound, "%d,%.6f", o->optimal ? 1 : 0, o->bound_deviation);
        }
        fprintf(f, "%llu,%lu,%lu,%lu,%lu,%lu,%lu,%s,%s,%s,%llu,%llu,%lu,%.1f%s%s,%s%s%s%s\n",
                (unsigned long long)c->seed, (unsigned long)r->vehicles, (unsigned long)r->index,
                (unsigned long)r->redraws, (unsigned long)r->info.hills,
                (unsigned long)r->info.tracks, (unsigned long)r->first_conflict_step,
                coavoid_mc_method_names[m], coavoid_output_status_name(o->status), costs,
                (unsigned long long)o->expanded, (unsigned long long)o->generated,
                (unsigned long)o->orders_tried, o->time_us, t.network, c->fly ? ",," : "", bound,
                t.run, c->fly ? ",,,," : "", t.options);
    }
}

/* A closed-loop row: method flown_NAME, status separated or loss_of_separation, the
 * plan's columns empty, the stop point (stop: "S,M", or ","), and the run's network
 * traffic (counts: ",fallbacks,sent,delivered,dropped", or ",,,," on a stopped run's). */
static void csv_flown_row(FILE *f, const coavoid_montecarlo_config_t *c,
                          const coavoid_mc_result_t *r, const char *name, bool lost,
                          const mc_row_tail_t *t, const char *stop, const char *counts)
{
    fprintf(f, "%llu,%lu,%lu,%lu,%lu,%lu,%lu,flown_%s,%s,,,,,,,%s,%s,,%s%s%s\n",
            (unsigned long long)c->seed, (unsigned long)r->vehicles, (unsigned long)r->index,
            (unsigned long)r->redraws, (unsigned long)r->info.hills, (unsigned long)r->info.tracks,
            (unsigned long)r->first_conflict_step, name, lost ? "loss_of_separation" : "separated",
            t->network, stop, t->run, counts, t->options);
}

/* With fly: a row per closed-loop mode; with the sweep, a row flown_centralised_stop per
 * stop point (stop_step, stop_messages: `coavoid sim --coordinator-stops S:M`). */
static void csv_flown_rows(FILE *f, const coavoid_montecarlo_config_t *c,
                           const coavoid_mc_size_t *size, const coavoid_mc_result_t *r)
{
    mc_row_tail_t t;
    row_tail(c, size, r, &t);
    for (int mode = 0; mode < COAVOID_MC_FLY_MODES; mode++) {
        const coavoid_mc_flown_t *flown = &r->flown[mode];
        char counts[96];
        snprintf(counts, sizeof counts, ",%lu,%llu,%llu,%llu", (unsigned long)flown->fallbacks,
                 (unsigned long long)flown->sent, (unsigned long long)flown->delivered,
                 (unsigned long long)flown->dropped);
        csv_flown_row(f, c, r, coavoid_mc_fly_mode_names[mode], flown->loss_of_separation, &t, ",",
                      counts);
    }
    const coavoid_mc_sweep_t *w = &r->sweep;
    uint32_t j = 0;
    for (uint32_t k = 0; c->stops_sweep && k < w->cycles; k++) {
        const uint32_t points = w->sent[k] > 0u ? w->sent[k] : 1u;
        for (uint32_t m = 0; m < points && j < w->runs; m++) {
            if (!coavoid_mc_stop_flown(m, w->sent[k], c->stops_ends)) {
                continue;
            }
            char stop[32];
            snprintf(stop, sizeof stop, "%lu,%lu", (unsigned long)k, (unsigned long)m);
            const bool lost = (((unsigned)w->lost[j / 8u] >> (j % 8u)) & 1u) != 0u;
            csv_flown_row(f, c, r, "centralised_stop", lost, &t, stop, ",,,,");
            j++;
        }
    }
}

static double seconds_since(const struct timespec *start)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return coavoid_timing_elapsed_ms(start, &now) * 1e-3;
}

typedef struct {
    FILE *f; /* NULL: quiet */
    bool tty;
    uint32_t reported_tenth; /* not a tty: the last 10 % step reported */
    double reported_at;      /* a tty: when the line was last updated, s */
    bool line_open;          /* a tty: the line has no newline yet */
} mc_progress_t;

static void progress(mc_progress_t *p, uint32_t done, uint32_t total, double elapsed, bool last)
{
    if (p->f == NULL || (done == 0 && !last)) {
        return;
    }
    uint32_t tenth = (uint32_t)((uint64_t)done * 10u / total);
    if (p->tty ? !(last || elapsed - p->reported_at >= 1.0) : tenth == p->reported_tenth) {
        return;
    }
    double eta = done > 0 ? elapsed * (double)(total - done) / (double)done : 0.0;
    fprintf(p->f, "%smontecarlo: %lu/%lu encounters (%.0f%%), %.0f s elapsed, ETA %.0f s%s",
            p->tty ? "\r" : "", (unsigned long)done, (unsigned long)total, 100.0 * done / total,
            elapsed, eta, p->tty && !last ? "   " : "\n");
    fflush(p->f);
    p->reported_tenth = tenth;
    p->reported_at = elapsed;
    p->line_open = p->tty && !last;
}

/* The items from *written up to ready, which are final (workers write each result once,
 * before done): their CSV rows, and their defects to the config's callback. */
static void write_ready(mc_run_t *run, FILE *csv, mc_progress_t *prog, uint32_t *written,
                        uint32_t ready)
{
    const coavoid_montecarlo_config_t *c = &run->mc->config;
    for (; *written < ready; (*written)++) {
        const coavoid_mc_result_t *r = &run->mc->results[*written];
        const coavoid_mc_size_t *size = item_size(run, *written);
        if (csv != NULL) {
            csv_rows(csv, c, size, r);
        }
        if (csv != NULL && c->fly) {
            csv_flown_rows(csv, c, size, r);
        }
        if (r->defect[0] != '\0' && prog->line_open) {
            fputc('\n', prog->f);
            prog->line_open = false;
        }
        coavoid_mc_report_defect(c, r);
    }
}

/* Runs every item; writes CSV rows (when csv is not NULL) in order as they complete.
 * Returns COAVOID_RUN_DONE, or an error with e set. */
static int run_all(mc_run_t *run, FILE *csv, coavoid_run_error_t *e)
{
    const coavoid_montecarlo_config_t *c = &run->mc->config;
    const uint32_t total = run->mc->total;
    uint32_t jobs = c->jobs < total ? c->jobs : total;
    pthread_t threads[COAVOID_MONTECARLO_MAX_JOBS];
    uint32_t started = 0;
    pthread_mutex_init(&run->lock, NULL);
    for (; started < jobs; started++) {
        if (pthread_create(&threads[started], NULL, worker, run) != 0) {
            break;
        }
    }
    if (started == 0) {
        pthread_mutex_destroy(&run->lock);
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "cannot start a worker thread");
    }
    mc_progress_t prog = {c->progress, c->progress != NULL && isatty(fileno(c->progress)) == 1, 0u,
                          0.0, false};
    struct timespec start;
    clock_gettime(CLOCK_MONOTONIC, &start);
    uint32_t written = 0;
    for (;;) {
        pthread_mutex_lock(&run->lock);
        uint32_t ready = written;
        while (ready < total && run->done[ready]) {
            ready++;
        }
        bool stop = run->stop;
        pthread_mutex_unlock(&run->lock);
        write_ready(run, csv, &prog, &written, ready);
        if (csv != NULL) {
            fflush(csv);
        }
        double elapsed = seconds_since(&start);
        if (written == total || stop) {
            progress(&prog, written, total, elapsed, true);
            break;
        }
        progress(&prog, written, total, elapsed, false);
        struct timespec pause = {0, 50 * 1000 * 1000};
        nanosleep(&pause, NULL);
    }
    for (uint32_t t = 0; t < started; t++) {
        pthread_join(threads[t], NULL);
    }
    pthread_mutex_destroy(&run->lock);
    if (run->stop) {
        return coavoid_run_fail(e,
                                strncmp(run->error, "internal error", 14) == 0
                                    ? COAVOID_RUN_ERR_INTERNAL
                                    : COAVOID_RUN_ERR_INPUT,
                                "montecarlo: %s", run->error);
    }
    return COAVOID_RUN_DONE;
}

/* ---- the run's set-up ---- */

/* What the app's option parser already refuses, checked again because the library trusts
 * no caller with its arrays' bounds. */
static int check_config(const coavoid_montecarlo_config_t *c, coavoid_run_error_t *e)
{
    if (c->size_count == 0 || c->size_count > COAVOID_MONTECARLO_MAX_SIZES || c->count == 0 ||
        c->jobs == 0 || c->jobs > COAVOID_MONTECARLO_MAX_JOBS ||
        c->count > UINT32_MAX / COAVOID_MONTECARLO_MAX_SIZES || c->first > UINT32_MAX - c->count) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "montecarlo: UAV counts, --count, --first or --jobs out of range");
    }
    const double dt = coavoid_encounter_montecarlo.dt;
    if (c->fly && (!(c->loss >= 0.0 && c->loss < 1.0) || !(c->delay >= 0.0) ||
                   !(c->jitter >= 0.0) || !(c->delay + c->jitter < dt))) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "--loss, --delay, --jitter: a loss from 0 to below 1, and a "
                                "delay plus jitter (s, each >= 0) under the encounters' dt of %g s",
                                dt);
    }
    if (!c->fly && (c->stops_sweep || c->has_net_seed)) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "%s: only with --fly (the closed loop)",
                                c->stops_sweep ? "--coordinator-stops-sweep" : "--net-seed");
    }
#ifndef COAVOID_HAVE_LCM
    if (c->fly) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "--fly: this build has no simulation (no messaging library)");
    }
#endif
    for (uint32_t k = 0; k < c->size_count; k++) {
        bool repeated = false;
        for (uint32_t j = 0; j < k; j++) {
            repeated = repeated || c->vehicles[j] == c->vehicles[k];
        }
        if (repeated || c->vehicles[k] < COAVOID_ENCOUNTER_MIN_VEHICLES ||
            c->vehicles[k] > COAVOID_ENCOUNTER_MAX_VEHICLES) {
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                    "--vehicles: each entry must be an integer from %u to "
                                    "%u, each once",
                                    COAVOID_ENCOUNTER_MIN_VEHICLES, COAVOID_ENCOUNTER_MAX_VEHICLES);
        }
    }
    return COAVOID_RUN_DONE;
}

/* Each UAV count's beta and order limit; refused when its centralised planner cannot be
 * sized. */
static int mc_sizes(const coavoid_montecarlo_config_t *c, coavoid_mc_size_t *sizes,
                    coavoid_run_error_t *e)
{
    for (uint32_t k = 0; k < c->size_count; k++) {
        uint32_t n = c->vehicles[k];
        sizes[k].n = n;
        coa_planner_config_t shape = mc_config(n, COAVOID_DEFAULT_BETA);
        sizes[k].beta = c->beta != 0 ? c->beta : coavoid_default_beta(&shape);
        sizes[k].max_orders = c->max_orders != 0 ? c->max_orders : factorial(n);
        sizes[k].work = c->work;
        shape.beta = sizes[k].beta;
        if (coa_planner_workspace_size(&shape) == 0) {
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                    "--beta: %lu is too large for %lu UAVs "
                                    "centralised (the node pool would pass 2^30)",
                                    (unsigned long)sizes[k].beta, (unsigned long)n);
        }
    }
    return COAVOID_RUN_DONE;
}

/* The output files, checked before an hour's run rather than after: save's directory,
 * csv opened (in *csv) and svg writable. */
static int mc_outputs(const coavoid_montecarlo_config_t *c, FILE **csv, coavoid_run_error_t *e)
{
    struct stat info;
    if (c->save != NULL && (stat(c->save, &info) != 0 || !S_ISDIR(info.st_mode) ||
                            access(c->save, W_OK | X_OK) != 0)) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "--save: '%.200s' is not a directory we can write in", c->save);
    }
    if (c->csv != NULL && (*csv = fopen(c->csv, "w")) == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--csv: cannot write '%.200s'", c->csv);
    }
    if (c->svg != NULL) {
        FILE *probe = fopen(c->svg, "w");
        if (probe == NULL) {
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--svg: cannot write '%.200s'",
                                    c->svg);
        }
        fclose(probe);
    }
    return COAVOID_RUN_DONE;
}

/* Closes csv's file; a write that failed is an error unless one came first. */
static int mc_close_csv(const coavoid_montecarlo_config_t *c, FILE *csv, int status,
                        coavoid_run_error_t *e)
{
    if (csv == NULL) {
        return status;
    }
    bool ok = !ferror(csv);
    if ((fclose(csv) != 0 || !ok) && status == COAVOID_RUN_DONE) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "--csv: cannot write '%.200s'",
                                c->csv);
    }
    return status;
}

/* The run's results and the report's scratch, or NULL when memory is short. */
static coavoid_montecarlo_t *mc_new(const coavoid_montecarlo_config_t *c,
                                    const coavoid_mc_size_t *sizes)
{
    coavoid_montecarlo_t *mc = calloc(1u, sizeof *mc);
    if (mc == NULL) {
        return NULL;
    }
    mc->config = *c;
    memcpy(mc->sizes, sizes, c->size_count * sizeof *sizes);
    mc->total = c->count * c->size_count;
    mc->results = calloc(mc->total, sizeof *mc->results);
    mc->x = calloc(c->count, sizeof *mc->x);
    if (mc->results == NULL || mc->x == NULL) {
        coavoid_montecarlo_free(mc);
        return NULL;
    }
    return mc;
}

int coavoid_montecarlo_run(const coavoid_montecarlo_config_t *config, coavoid_montecarlo_t **out,
                           coavoid_run_error_t *e)
{
    *out = NULL;
    coavoid_mc_size_t sizes[COAVOID_MONTECARLO_MAX_SIZES];
    FILE *csv = NULL;
    int status = check_config(config, e);
    if (status == COAVOID_RUN_DONE) {
        status = mc_sizes(config, sizes, e);
    }
    if (status == COAVOID_RUN_DONE) {
        status = mc_outputs(config, &csv, e);
    }
    if (status != COAVOID_RUN_DONE) {
        if (csv != NULL) {
            fclose(csv);
        }
        return status;
    }
    coavoid_montecarlo_t *mc = mc_new(config, sizes);
    const uint32_t total = config->count * config->size_count;
    bool *done = calloc(total, sizeof *done);
    if (mc == NULL || done == NULL) {
        status =
            coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--count: out of memory for %lu encounters",
                             (unsigned long)total);
    }
    if (status == COAVOID_RUN_DONE && csv != NULL &&
        fputs(config->fly ? MC_CSV_HEADER_FLY : MC_CSV_HEADER, csv) < 0) {
        status = coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "--csv: cannot write '%.200s'",
                                  config->csv);
    }
    if (status == COAVOID_RUN_DONE) {
        mc_run_t run;
        memset(&run, 0, sizeof run);
        run.mc = mc;
        run.done = done;
        status = run_all(&run, csv, e);
    }
    status = mc_close_csv(config, csv, status, e);
    free(done);
    if (status != COAVOID_RUN_DONE) {
        coavoid_montecarlo_free(mc);
        return status;
    }
    *out = mc;
    return COAVOID_RUN_DONE;
}

void coavoid_montecarlo_free(coavoid_montecarlo_t *mc)
{
    if (mc == NULL) {
        return;
    }
    free(mc->results);
    free(mc->x);
    free(mc);
}
