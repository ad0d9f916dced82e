/* SPDX-License-Identifier: MIT */
/*
 * montecarlo_report.c: the reports of a Monte Carlo run (montecarlo.h): per UAV count and
 * method the outcomes, the success rate with its Wilson interval, the distributions of the
 * times, the nodes and the decoupled/centralised deviation ratio, printed as text or JSON,
 * and the figure (success rates, the decoupled/centralised ratio's cumulative distribution
 * and the centralised plan over its lower bound's) as SVG.
 */
#include "montecarlo.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "coavoid/coavoid.h"
#include "encounter.h"
#include "evaluation_internal.h"
#include "montecarlo_internal.h"
#include "output.h"
#include "run.h"

#define MC_Z95 1.959963984540054 /* the normal quantile of a two-sided 95 % interval */

/* ---- the summary ---- */

typedef struct {
    uint32_t count;
    double min, p25, median, p75, p90, max, mean;
    double equal_share; /* ratio exactly 1 (the same exact deviation) */
} mc_dist_t;

/* The p-quantile of sorted x[0..m-1] (m >= 1), interpolating linearly between order
 * statistics (numpy's default, "type 7"), so scripts can recompute it. */
static double quantile(const double *x, uint32_t m, double p)
{
    double h = (double)(m - 1u) * p;
    double lo = floor(h);
    uint32_t k = (uint32_t)lo;
    return k + 1u < m ? x[k] + (h - lo) * (x[k + 1u] - x[k]) : x[m - 1u];
}

/* Sorts x and summarises it; equal: how many were exactly equal. */
static mc_dist_t distribution(double *x, uint32_t m, uint32_t equal)
{
    mc_dist_t d;
    memset(&d, 0, sizeof d);
    d.count = m;
    if (m == 0) {
        return d;
    }
    qsort(x, m, sizeof *x, coavoid_timing_compare);
    double sum = 0;
    for (uint32_t k = 0; k < m; k++) {
        sum += x[k];
    }
    d.min = x[0];
    d.p25 = quantile(x, m, 0.25);
    d.median = quantile(x, m, 0.5);
    d.p75 = quantile(x, m, 0.75);
    d.p90 = quantile(x, m, 0.9);
    d.max = x[m - 1u];
    d.mean = sum / m;
    d.equal_share = (double)equal / m;
    return d;
}

typedef struct {
    uint32_t solved, infeasible, budget;
    double rate, low, high; /* success rate and its 95 % Wilson interval */
    mc_dist_t time_ms;      /* of every encounter */
    mc_dist_t expanded;
    mc_dist_t ratio; /* decoupled methods: deviation / centralised's, both solved */
    uint32_t fails_where_central_solves, solves_where_central_fails;
    double mean_deviation_both; /* mean deviation (m^2) over the encounters both solve */
    double central_mean_deviation_both;
    /* Centralised: the plans proven optimal and the others, and each plan's deviation over
     * its lower bound (1 when optimal) where the bound is positive. */
    uint32_t optimal, bounded;
    mc_dist_t bound_ratio;
} mc_method_summary_t;

/* One closed-loop mode (fly) over a UAV count's encounters. */
typedef struct {
    uint32_t losses;
    double rate, low, high; /* loss-of-separation rate and its 95 % Wilson interval */
    /* The encounters the one-shot centralised plan solves, and those that some priority
     * order solves (decoupled_reordered), and the losses among each. */
    uint32_t central_solved, losses_central_solved;
    uint32_t order_solved, losses_order_solved;
    uint64_t fallbacks, sent, delivered, dropped;
} mc_fly_summary_t;

/* The coordinator-stop sweep (config stops_sweep) over a UAV count's encounters. */
typedef struct {
    uint32_t runs, losses, encounters_lost;
    /* The encounters the decoupled closed loop (same network) keeps separated, and the
     * stopped runs and encounters that lose separation among them: the target is none. */
    uint32_t kept, kept_losses, kept_encounters_lost;
} mc_sweep_summary_t;

typedef struct {
    coavoid_mc_size_t size;
    uint32_t encounters, redraws;
    mc_method_summary_t m[COAVOID_MC_METHODS];
    mc_fly_summary_t fly[COAVOID_MC_FLY_MODES];
    mc_sweep_summary_t sweep;
} mc_summary_t;

void coavoid_mc_wilson(uint32_t k, uint32_t n, double *rate, double *low, double *high)
{
    double p = (double)k / n, z2 = MC_Z95 * MC_Z95, nn = (double)n;
    double centre = (p + z2 / (2.0 * nn)) / (1.0 + z2 / nn);
    double half = MC_Z95 * sqrt(p * (1.0 - p) / nn + z2 / (4.0 * nn * nn)) / (1.0 + z2 / nn);
    *rate = p;
    /* Exactly 0 and 1 at the ends, where rounding would leave a few ulps. */
    *low = k == 0 || centre - half < 0 ? 0 : centre - half;
    *high = k == n || centre + half > 1 ? 1 : centre + half;
}

/* The closed-loop modes of count results (config fly) into s->fly. */
static void summarise_fly(const coavoid_mc_result_t *results, uint32_t count, mc_summary_t *s)
{
    for (int mode = 0; mode < COAVOID_MC_FLY_MODES; mode++) {
        mc_fly_summary_t *f = &s->fly[mode];
        for (uint32_t j = 0; j < count; j++) {
            const coavoid_mc_result_t *r = &results[j];
            const coavoid_mc_flown_t *flown = &r->flown[mode];
            const bool lost = flown->loss_of_separation;
            const bool central = r->m[COAVOID_MC_CENTRALISED].status == COA_PLAN_SOLVED;
            const bool order = r->m[COAVOID_MC_REORDERED].status == COA_PLAN_SOLVED;
            f->losses += lost;
            f->central_solved += central;
            f->losses_central_solved += central && lost;
            f->order_solved += order;
            f->losses_order_solved += order && lost;
            f->fallbacks += flown->fallbacks;
            f->sent += flown->sent;
            f->delivered += flown->delivered;
            f->dropped += flown->dropped;
        }
        coavoid_mc_wilson(f->losses, count, &f->rate, &f->low, &f->high);
    }
}

/* The coordinator-stop sweeps of count results (config stops_sweep) into s->sweep. */
static void summarise_sweep(const coavoid_mc_result_t *results, uint32_t count, mc_summary_t *s)
{
    mc_sweep_summary_t *w = &s->sweep;
    for (uint32_t j = 0; j < count; j++) {
        const coavoid_mc_sweep_t *r = &results[j].sweep;
        const bool kept = !results[j].flown[COAVOID_MC_FLY_DECOUPLED].loss_of_separation;
        w->runs += r->runs;
        w->losses += r->losses;
        w->encounters_lost += r->losses > 0u;
        w->kept += kept;
        w->kept_losses += kept ? r->losses : 0u;
        w->kept_encounters_lost += kept && r->losses > 0u;
    }
}

/* Each centralised plan's deviation over its positive lower bound into x; the count, and
 * in *optimal (when not NULL) how many of them are proven optimal. */
static uint32_t bound_values(const coavoid_mc_result_t *results, uint32_t count, double *x,
                             uint32_t *optimal)
{
    uint32_t n = 0, proven = 0;
    for (uint32_t j = 0; j < count; j++) {
        const coavoid_mc_outcome_t *c = &results[j].m[COAVOID_MC_CENTRALISED];
        if (c->status == COA_PLAN_SOLVED && c->bound_deviation > 0) {
            x[n++] = coavoid_bound_ratio(c->optimal, c->deviation, c->bound_deviation);
            proven += c->optimal;
        }
    }
    if (optimal != NULL) {
        *optimal = proven;
    }
    return n;
}

/* The centralised plans' outcomes: proven optimal or bounded, and plan over bound. */
static void bound_ratios(const coavoid_mc_result_t *results, uint32_t count, double *x,
                         mc_method_summary_t *ms)
{
    for (uint32_t j = 0; j < count; j++) {
        const coavoid_mc_outcome_t *c = &results[j].m[COAVOID_MC_CENTRALISED];
        ms->optimal += c->status == COA_PLAN_SOLVED && c->optimal;
        ms->bounded += c->status == COA_PLAN_SOLVED && !c->optimal;
    }
    uint32_t equal = 0;
    uint32_t n = bound_values(results, count, x, &equal);
    ms->bound_ratio = distribution(x, n, equal);
}

/* Summarises the count results of one size; x: room for count doubles. */
static void summarise(const coavoid_mc_result_t *results, uint32_t count,
                      const coavoid_mc_size_t *size, double *x, mc_summary_t *s)
{
    memset(s, 0, sizeof *s);
    s->size = *size;
    s->encounters = count;
    for (uint32_t j = 0; j < count; j++) {
        s->redraws += results[j].redraws;
    }
    for (int m = 0; m < COAVOID_MC_METHODS; m++) {
        mc_method_summary_t *ms = &s->m[m];
        for (uint32_t j = 0; j < count; j++) {
            coa_plan_status_t st = results[j].m[m].status;
            ms->solved += st == COA_PLAN_SOLVED;
            ms->infeasible += st == COA_PLAN_INFEASIBLE;
            ms->budget += st == COA_PLAN_BUDGET_EXHAUSTED;
            x[j] = results[j].m[m].time_us * 1e-3;
        }
        coavoid_mc_wilson(ms->solved, count, &ms->rate, &ms->low, &ms->high);
        ms->time_ms = distribution(x, count, 0u);
        for (uint32_t j = 0; j < count; j++) {
            x[j] = (double)results[j].m[m].expanded;
        }
        ms->expanded = distribution(x, count, 0u);
        if (m == COAVOID_MC_CENTRALISED) {
            bound_ratios(results, count, x, ms);
            continue;
        }
        uint32_t both = 0, equal = 0;
        double dev = 0, cdev = 0;
        for (uint32_t j = 0; j < count; j++) {
            const coavoid_mc_outcome_t *c = &results[j].m[COAVOID_MC_CENTRALISED],
                                       *d = &results[j].m[m];
            bool cs = c->status == COA_PLAN_SOLVED, ds = d->status == COA_PLAN_SOLVED;
            ms->fails_where_central_solves += cs && !ds;
            ms->solves_where_central_fails += ds && !cs;
            if (cs && ds) {
                x[both++] = coavoid_mc_cost_real(d->units) / coavoid_mc_cost_real(c->units);
                equal += coa_cost_compare(d->units, c->units) == 0;
                dev += d->deviation;
                cdev += c->deviation;
            }
        }
        ms->mean_deviation_both = both > 0 ? dev / both : 0;
        ms->central_mean_deviation_both = both > 0 ? cdev / both : 0;
        ms->ratio = distribution(x, both, equal);
    }
}

static void text_summary(FILE *f, const coavoid_montecarlo_config_t *o, const mc_summary_t *s,
                         uint32_t sizes)
{
    const coavoid_encounter_design_t *d = &coavoid_encounter_montecarlo;
    fprintf(f, "montecarlo: seed %llu, %lu encounters per UAV count", (unsigned long long)o->seed,
            (unsigned long)o->count);
    if (o->first > 0) {
        fprintf(f, " (%lu to %lu)", (unsigned long)o->first,
                (unsigned long)(o->first + o->count - 1u));
    }
    fprintf(f, ", %u steps of %g s\n", d->horizon, d->dt);
    for (uint32_t k = 0; k < sizes; k++) {
        const mc_summary_t *z = &s[k];
        fprintf(f, "\n%lu UAVs: %lu encounters (%lu redraws), beta %lu, max orders %lu\n",
                (unsigned long)z->size.n, (unsigned long)z->encounters, (unsigned long)z->redraws,
                (unsigned long)z->size.beta, (unsigned long)z->size.max_orders);
        fprintf(f, "  %-20s %7s %10s %7s %8s %16s %10s %10s %10s %12s\n", "method", "solved",
                "infeasible", "budget", "success", "95% Wilson", "median_ms", "p90_ms", "max_ms",
                "median_nodes");
        for (int m = 0; m < COAVOID_MC_METHODS; m++) {
            const mc_method_summary_t *ms = &z->m[m];
            fprintf(f,
                    "  %-20s %7lu %10lu %7lu %7.1f%% %7.1f-%5.1f%% %10.3f %10.3f %10.3f %12.0f\n",
                    coavoid_mc_method_names[m], (unsigned long)ms->solved,
                    (unsigned long)ms->infeasible, (unsigned long)ms->budget, 100 * ms->rate,
                    100 * ms->low, 100 * ms->high, ms->time_ms.median, ms->time_ms.p90,
                    ms->time_ms.max, ms->expanded.median);
        }
        const mc_method_summary_t *cm = &z->m[COAVOID_MC_CENTRALISED];
        fprintf(f,
                "  centralised plans: %lu proven optimal, %lu bounded; plan / lower bound: "
                "median %.3f, p90 %.3f, max %.3f\n",
                (unsigned long)cm->optimal, (unsigned long)cm->bounded,
                cm->bound_ratio.count > 0 ? cm->bound_ratio.median : 0.0,
                cm->bound_ratio.count > 0 ? cm->bound_ratio.p90 : 0.0,
                cm->bound_ratio.count > 0 ? cm->bound_ratio.max : 0.0);
        fprintf(f, "  deviation ratio to centralised, over the encounters both solve:\n");
        fprintf(f, "  %-20s %6s %7s %7s %7s %7s %7s %7s %7s %7s %9s %9s\n", "method", "both", "min",
                "p25", "median", "p75", "p90", "max", "mean", "=1", "fails*", "solves*");
        for (int m = COAVOID_MC_FIXED; m < COAVOID_MC_METHODS; m++) {
            const mc_method_summary_t *ms = &z->m[m];
            const mc_dist_t *r = &ms->ratio;
            double fails = 100.0 * ms->fails_where_central_solves / z->encounters;
            double solves = 100.0 * ms->solves_where_central_fails / z->encounters;
            if (r->count == 0) {
                /* No ratio at all, not ratios of 0 (a ratio is at least 1). */
                fprintf(f, "  %-20s %6lu %7s %7s %7s %7s %7s %7s %7s %7s %8.1f%% %8.1f%%\n",
                        coavoid_mc_method_names[m], 0ul, "-", "-", "-", "-", "-", "-", "-", "-",
                        fails, solves);
                continue;
            }
            fprintf(f,
                    "  %-20s %6lu %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %6.1f%% %8.1f%% "
                    "%8.1f%%\n",
                    coavoid_mc_method_names[m], (unsigned long)r->count, r->min, r->p25, r->median,
                    r->p75, r->p90, r->max, r->mean, 100 * r->equal_share, fails, solves);
        }
    }
    fprintf(f, "\nbudget: no plan found within beta or the work budget (nothing proven); "
               "bounded: a plan\nnot proven optimal; =1: the same exact deviation as "
               "centralised;\nfails*: share of encounters it fails and centralised solves; "
               "solves*: it solves and centralised fails\n");
}

/* The closed loop's table (config fly). */
static void text_fly(FILE *f, const coavoid_montecarlo_config_t *o, const mc_summary_t *s,
                     uint32_t sizes)
{
    fprintf(f,
            "\nclosed loop: each encounter flown by the nodes (insecure) over a network with "
            "loss %g, delay %g s, jitter %g s",
            o->loss, o->delay, o->jitter);
    if (o->has_net_seed) {
        fprintf(f, ", network seed %llu", (unsigned long long)o->net_seed);
    }
    fputc('\n', f);
    fprintf(f, "  %4s %-12s %7s %7s %16s %9s %7s %9s %7s %10s %8s\n", "UAVs", "mode", "losses",
            "rate", "95% Wilson", "c-solved", "losses", "o-solved", "losses", "fallbacks",
            "dropped");
    for (uint32_t k = 0; k < sizes; k++) {
        for (int mode = 0; mode < COAVOID_MC_FLY_MODES; mode++) {
            const mc_fly_summary_t *z = &s[k].fly[mode];
            const uint64_t copies = z->delivered + z->dropped;
            fprintf(f,
                    "  %4lu %-12s %7lu %6.1f%% %7.1f-%5.1f%% %9lu %7lu %9lu %7lu %10.2f %7.1f%%\n",
                    (unsigned long)s[k].size.n, coavoid_mc_fly_mode_names[mode],
                    (unsigned long)z->losses, 100 * z->rate, 100 * z->low, 100 * z->high,
                    (unsigned long)z->central_solved, (unsigned long)z->losses_central_solved,
                    (unsigned long)z->order_solved, (unsigned long)z->losses_order_solved,
                    (double)z->fallbacks / s[k].encounters,
                    copies > 0 ? 100.0 * (double)z->dropped / (double)copies : 0.0);
        }
    }
    fprintf(f, "losses: encounters with a loss of separation; c-solved, o-solved: encounters the "
               "one-shot\ncentralised plan, or some priority order, solves, and the losses among "
               "them;\nfallbacks: per encounter; dropped: share of the copies to other nodes\n");
}

/* The sweep's table (config stops_sweep), and the first stop points that lost separation
 * where decoupled kept it, each with what replays it. */
static void text_sweep(FILE *f, const coavoid_montecarlo_t *mc, const mc_summary_t *s)
{
    const coavoid_montecarlo_config_t *o = &mc->config;
    fprintf(f,
            "\ncoordinator stopped (centralised, same network): at every cycle and %s\n"
            "  %4s %10s %8s %7s %10s %10s %10s %10s\n",
            o->stops_ends ? "cut points 0, 1, middle, last of its messages"
                          : "every cut point of its messages",
            "UAVs", "runs", "losses", "rate", "enc_lost", "d-kept", "losses", "enc_lost");
    for (uint32_t k = 0; k < o->size_count; k++) {
        const mc_sweep_summary_t *w = &s[k].sweep;
        fprintf(f, "  %4lu %10lu %8lu %6.2f%% %10lu %10lu %10lu %10lu\n",
                (unsigned long)s[k].size.n, (unsigned long)w->runs, (unsigned long)w->losses,
                w->runs > 0u ? 100.0 * w->losses / w->runs : 0.0, (unsigned long)w->encounters_lost,
                (unsigned long)w->kept, (unsigned long)w->kept_losses,
                (unsigned long)w->kept_encounters_lost);
    }
    fprintf(f, "losses, rate: stopped runs that lost separation; enc_lost: encounters with one; "
               "d-kept: encounters\nthe decoupled closed loop keeps separated, then the runs and "
               "encounters lost among them\n");
    uint32_t listed = 0;
    for (uint32_t j = 0; j < mc->total && listed < 10u; j++) {
        const coavoid_mc_result_t *r = &mc->results[j];
        if (r->sweep.losses == 0u || r->flown[COAVOID_MC_FLY_DECOUPLED].loss_of_separation) {
            continue;
        }
        fprintf(f,
                "  %lu UAVs, encounter %lu: %lu runs lost, first --coordinator-stops %lu:%lu "
                "(coavoid sim --insecure --net-seed %llu)\n",
                (unsigned long)r->vehicles, (unsigned long)r->index, (unsigned long)r->sweep.losses,
                (unsigned long)r->sweep.loss_step, (unsigned long)r->sweep.loss_messages,
                (unsigned long long)r->net_seed);
        listed++;
    }
}

static bool add_dist(cJSON *parent, const char *name, const mc_dist_t *d, bool with_equal)
{
    cJSON *o = cJSON_AddObjectToObject(parent, name);
    bool ok = o != NULL && cJSON_AddNumberToObject(o, "count", d->count) != NULL;
    if (ok && d->count > 0) {
        ok = cJSON_AddNumberToObject(o, "min", d->min) != NULL &&
             cJSON_AddNumberToObject(o, "p25", d->p25) != NULL &&
             cJSON_AddNumberToObject(o, "median", d->median) != NULL &&
             cJSON_AddNumberToObject(o, "p75", d->p75) != NULL &&
             cJSON_AddNumberToObject(o, "p90", d->p90) != NULL &&
             cJSON_AddNumberToObject(o, "max", d->max) != NULL &&
             cJSON_AddNumberToObject(o, "mean", d->mean) != NULL;
    }
    if (ok && with_equal) {
        ok = cJSON_AddNumberToObject(o, "equal_share", d->count > 0 ? d->equal_share : 0) != NULL;
    }
    return ok;
}

/* A UAV count's closed loop (config fly): "closed_loop", one object per mode. */
static bool json_fly(cJSON *item, const mc_summary_t *z)
{
    cJSON *list = cJSON_AddArrayToObject(item, "closed_loop");
    bool ok = list != NULL;
    for (int mode = 0; ok && mode < COAVOID_MC_FLY_MODES; mode++) {
        const mc_fly_summary_t *f = &z->fly[mode];
        cJSON *m = cJSON_CreateObject();
        ok = m != NULL && cJSON_AddItemToArray(list, m) &&
             cJSON_AddStringToObject(m, "mode", coavoid_mc_fly_mode_names[mode]) != NULL &&
             cJSON_AddNumberToObject(m, "losses", f->losses) != NULL &&
             cJSON_AddNumberToObject(m, "loss_rate", f->rate) != NULL &&
             cJSON_AddNumberToObject(m, "wilson_low", f->low) != NULL &&
             cJSON_AddNumberToObject(m, "wilson_high", f->high) != NULL &&
             cJSON_AddNumberToObject(m, "centralised_solved", f->central_solved) != NULL &&
             cJSON_AddNumberToObject(m, "losses_where_centralised_solved",
                                     f->losses_central_solved) != NULL &&
             cJSON_AddNumberToObject(m, "some_order_solved", f->order_solved) != NULL &&
             cJSON_AddNumberToObject(m, "losses_where_some_order_solved", f->losses_order_solved) !=
                 NULL &&
             cJSON_AddNumberToObject(m, "fallbacks", (double)f->fallbacks) != NULL &&
             cJSON_AddNumberToObject(m, "sent", (double)f->sent) != NULL &&
             cJSON_AddNumberToObject(m, "delivered", (double)f->delivered) != NULL &&
             cJSON_AddNumberToObject(m, "dropped", (double)f->dropped) != NULL;
    }
    return ok;
}

/* A UAV count's coordinator-stop sweep (config stops_sweep): "coordinator_stops". */
static bool json_sweep(cJSON *item, const mc_summary_t *z)
{
    const mc_sweep_summary_t *w = &z->sweep;
    cJSON *o = cJSON_AddObjectToObject(item, "coordinator_stops");
    return o != NULL && cJSON_AddNumberToObject(o, "runs", w->runs) != NULL &&
           cJSON_AddNumberToObject(o, "losses", w->losses) != NULL &&
           cJSON_AddNumberToObject(o, "encounters_with_losses", w->encounters_lost) != NULL &&
           cJSON_AddNumberToObject(o, "decoupled_separated", w->kept) != NULL &&
           cJSON_AddNumberToObject(o, "losses_where_decoupled_separated", w->kept_losses) != NULL &&
           cJSON_AddNumberToObject(o, "encounters_with_losses_where_decoupled_separated",
                                   w->kept_encounters_lost) != NULL;
}

/* The closed loop's network settings (config fly): "network". */
static bool json_network(cJSON *root, const coavoid_montecarlo_config_t *o)
{
    cJSON *n = cJSON_AddObjectToObject(root, "network");
    char seed[32];
    snprintf(seed, sizeof seed, "%llu", (unsigned long long)o->net_seed);
    return n != NULL && cJSON_AddNumberToObject(n, "loss", o->loss) != NULL &&
           cJSON_AddNumberToObject(n, "delay", o->delay) != NULL &&
           cJSON_AddNumberToObject(n, "jitter", o->jitter) != NULL &&
           cJSON_AddBoolToObject(n, "insecure", true) != NULL &&
           (!o->has_net_seed || cJSON_AddRawToObject(n, "net_seed", seed) != NULL) &&
           (!o->stops_sweep || cJSON_AddStringToObject(n, "coordinator_stops",
                                                       o->stops_ends ? "ends" : "all") != NULL);
}

static int json_summary(FILE *f, const coavoid_montecarlo_config_t *o, const mc_summary_t *s,
                        uint32_t sizes)
{
    char seed[32];
    snprintf(seed, sizeof seed, "%llu", (unsigned long long)o->seed);
    cJSON *root = cJSON_CreateObject();
    cJSON *list = NULL;
    bool ok =
        root != NULL && cJSON_AddStringToObject(root, "command", "montecarlo") != NULL &&
        cJSON_AddRawToObject(root, "seed", seed) != NULL &&
        cJSON_AddNumberToObject(root, "count", o->count) != NULL &&
        cJSON_AddNumberToObject(root, "first", o->first) != NULL &&
        cJSON_AddNumberToObject(root, "horizon", coavoid_encounter_montecarlo.horizon) != NULL &&
        cJSON_AddNumberToObject(root, "dt", coavoid_encounter_montecarlo.dt) != NULL &&
        (list = cJSON_AddArrayToObject(root, "sizes")) != NULL;
    for (uint32_t k = 0; ok && k < sizes; k++) {
        const mc_summary_t *z = &s[k];
        cJSON *item = cJSON_CreateObject();
        cJSON *methods = NULL;
        ok = item != NULL && cJSON_AddItemToArray(list, item) &&
             cJSON_AddNumberToObject(item, "vehicles", z->size.n) != NULL &&
             cJSON_AddNumberToObject(item, "encounters", z->encounters) != NULL &&
             cJSON_AddNumberToObject(item, "redraws", z->redraws) != NULL &&
             cJSON_AddNumberToObject(item, "beta", z->size.beta) != NULL &&
             cJSON_AddNumberToObject(item, "max_orders", z->size.max_orders) != NULL &&
             (methods = cJSON_AddArrayToObject(item, "methods")) != NULL;
        for (int m = 0; ok && m < COAVOID_MC_METHODS; m++) {
            const mc_method_summary_t *ms = &z->m[m];
            cJSON *mo = cJSON_CreateObject();
            ok = mo != NULL && cJSON_AddItemToArray(methods, mo) &&
                 cJSON_AddStringToObject(mo, "method", coavoid_mc_method_names[m]) != NULL &&
                 cJSON_AddNumberToObject(mo, "solved", ms->solved) != NULL &&
                 cJSON_AddNumberToObject(mo, "infeasible", ms->infeasible) != NULL &&
                 cJSON_AddNumberToObject(mo, "budget_exhausted", ms->budget) != NULL &&
                 cJSON_AddNumberToObject(mo, "success_rate", ms->rate) != NULL &&
                 cJSON_AddNumberToObject(mo, "wilson_low", ms->low) != NULL &&
                 cJSON_AddNumberToObject(mo, "wilson_high", ms->high) != NULL &&
                 add_dist(mo, "time_ms", &ms->time_ms, false) &&
                 add_dist(mo, "nodes_expanded", &ms->expanded, false);
            if (ok && m == COAVOID_MC_CENTRALISED) {
                ok = cJSON_AddNumberToObject(mo, "optimal", ms->optimal) != NULL &&
                     cJSON_AddNumberToObject(mo, "bounded", ms->bounded) != NULL &&
                     add_dist(mo, "bound_ratio", &ms->bound_ratio, true);
            }
            if (ok && m != COAVOID_MC_CENTRALISED) {
                ok = add_dist(mo, "deviation_ratio", &ms->ratio, true) &&
                     cJSON_AddNumberToObject(mo, "fails_where_centralised_solves",
                                             ms->fails_where_central_solves) != NULL &&
                     cJSON_AddNumberToObject(mo, "solves_where_centralised_fails",
                                             ms->solves_where_central_fails) != NULL &&
                     cJSON_AddNumberToObject(mo, "mean_deviation_both_solved",
                                             ms->mean_deviation_both) != NULL &&
                     cJSON_AddNumberToObject(mo, "centralised_mean_deviation_both_solved",
                                             ms->central_mean_deviation_both) != NULL;
            }
        }
        ok = ok && (!o->fly || json_fly(item, z)) && (!o->stops_sweep || json_sweep(item, z));
    }
    ok = ok && (!o->fly || json_network(root, o));
    if (!ok) {
        cJSON_Delete(root);
        return -1;
    }
    return coavoid_output_json(f, root, NULL, 0);
}

/* ---- the figure ---- */

#define SVG_W 1420.0
#define SVG_H 420.0
#define SVG_PANEL_TOP 60.0
#define SVG_PANEL_H 260.0
#define SVG_BAR_LEFT 70.0
#define SVG_BAR_W 330.0
#define SVG_CDF_LEFT 520.0
#define SVG_CDF_W 400.0
#define SVG_BOUND_LEFT 1000.0
#define SVG_BOUND_W 380.0

static const char *const method_colours[COAVOID_MC_METHODS] = {"#1f77b4", "#ff7f0e", "#2ca02c"};
static const char *const size_colours[COAVOID_MONTECARLO_MAX_SIZES] = {
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#8c564b"};

/* The ratio axis, logarithmic: from 1 to the largest ratio seen, at least 2 and at most
 * 10 (a longer tail is drawn against the edge and said in the caption). */
static double cdf_right(const mc_summary_t *s, uint32_t sizes)
{
    double right = 2.0;
    for (uint32_t k = 0; k < sizes; k++) {
        for (int m = COAVOID_MC_FIXED; m < COAVOID_MC_METHODS; m++) {
            if (s[k].m[m].ratio.count > 0 && s[k].m[m].ratio.max > right) {
                right = s[k].m[m].ratio.max;
            }
        }
    }
    return right > 10.0 ? 10.0 : right;
}

/* A CDF panel: its left edge and width, and the largest ratio on its log axis. */
typedef struct {
    double left;
    double width;
    double right;
} cdf_panel_t;

static double cdf_x(const cdf_panel_t *p, double v)
{
    v = v > p->right ? p->right : v;
    return p->left + log(v) / log(p->right) * p->width;
}

/* The step function of the CDF of x[0..n-1] (ratios >= 1, sorted here), merging steps
 * closer than half a pixel so that 1000 encounters stay a few hundred points. */
static void svg_steps(FILE *f, const cdf_panel_t *p, double *x, uint32_t n, const char *colour,
                      bool dashed)
{
    if (n == 0) {
        return;
    }
    qsort(x, n, sizeof *x, coavoid_timing_compare);
    const double y0 = SVG_PANEL_TOP + SVG_PANEL_H;
    fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.8\"%s points=\"", colour,
            dashed ? " stroke-dasharray=\"6 4\"" : "");
    double last_px = p->left, last_py = y0;
    fprintf(f, "%.1f,%.1f", last_px, last_py);
    for (uint32_t j = 0; j < n;) {
        uint32_t k = j;
        while (k < n && x[k] == x[j]) {
            k++;
        }
        double px = cdf_x(p, x[j]);
        double py = y0 - (double)k / n * SVG_PANEL_H;
        if (px - last_px >= 0.5 || k == n) {
            fprintf(f, " %.1f,%.1f %.1f,%.1f", px, last_py, px, py);
            last_px = px;
        }
        last_py = py;
        j = k;
    }
    fprintf(f, " %.1f,%.1f\"/>\n", p->left + p->width, last_py);
}

/* The decoupled method m's deviation over the centralised plan's, both solved. */
static void svg_cdf(FILE *f, const cdf_panel_t *p, const coavoid_mc_result_t *results,
                    uint32_t count, int m, double *x, const char *colour, bool dashed)
{
    uint32_t both = 0;
    for (uint32_t j = 0; j < count; j++) {
        const coavoid_mc_outcome_t *c = &results[j].m[COAVOID_MC_CENTRALISED],
                                   *d = &results[j].m[m];
        if (c->status == COA_PLAN_SOLVED && d->status == COA_PLAN_SOLVED) {
            x[both++] = coavoid_mc_cost_real(d->units) / coavoid_mc_cost_real(c->units);
        }
    }
    svg_steps(f, p, x, both, colour, dashed);
}

/* A CDF panel's frame: the title, the share grid, the ratio ticks and the box. */
static void svg_cdf_frame(FILE *f, const cdf_panel_t *p, const char *title, const char *xlabel)
{
    const double y0 = SVG_PANEL_TOP + SVG_PANEL_H;
    fprintf(f, "<text x=\"%.0f\" y=\"%.0f\" font-weight=\"bold\">%s</text>\n", p->left,
            SVG_PANEL_TOP - 10, title);
    for (int t = 0; t <= 4; t++) {
        double py = y0 - t / 4.0 * SVG_PANEL_H;
        fprintf(f,
                "<line x1=\"%.0f\" y1=\"%.1f\" x2=\"%.0f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n"
                "<text x=\"%.0f\" y=\"%.1f\" text-anchor=\"end\">%.2f</text>\n",
                p->left, py, p->left + p->width, py, p->left - 6, py + 4, t / 4.0);
    }
    static const double ticks[] = {1.0, 1.25, 1.5, 2.0, 3.0, 5.0, 10.0};
    for (size_t t = 0; t < sizeof ticks / sizeof ticks[0] && ticks[t] <= p->right * 1.0001; t++) {
        double px = cdf_x(p, ticks[t]);
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.0f\" x2=\"%.1f\" y2=\"%.0f\" stroke=\"#ddd\"/>\n"
                "<text x=\"%.1f\" y=\"%.0f\" text-anchor=\"middle\">%g</text>\n",
                px, SVG_PANEL_TOP, px, y0, px, y0 + 18, ticks[t]);
    }
    fprintf(f, "<text x=\"%.0f\" y=\"%.0f\" text-anchor=\"middle\">%s (log scale)</text>\n",
            p->left + p->width / 2, y0 + 34, xlabel);
    fprintf(f,
            "<text transform=\"translate(%.0f %.0f) rotate(-90)\" text-anchor=\"middle\">"
            "share of encounters</text>\n",
            p->left - 44, SVG_PANEL_TOP + SVG_PANEL_H / 2);
    fprintf(f,
            "<rect x=\"%.0f\" y=\"%.0f\" width=\"%.0f\" height=\"%.0f\" fill=\"none\" "
            "stroke=\"black\"/>\n",
            p->left, SVG_PANEL_TOP, p->width, SVG_PANEL_H);
}

/* The figure's header and title (seed, count, the betas used). */
static void svg_head(FILE *f, const coavoid_montecarlo_config_t *o, const mc_summary_t *s,
                     uint32_t sizes)
{
    fprintf(f,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
            "viewBox=\"0 0 %.0f %.0f\" font-family=\"sans-serif\" font-size=\"13\">\n"
            "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
            SVG_W, SVG_H, SVG_W, SVG_H);
    char betas[64] = "";
    for (uint32_t k = 0, used = 0; k < sizes && used < sizeof betas; k++) {
        if (k == 0 || s[k].size.beta != s[k - 1].size.beta) {
            int w = snprintf(betas + used, sizeof betas - used, "%s%lu", k == 0 ? "" : "/",
                             (unsigned long)s[k].size.beta);
            used += w > 0 ? (uint32_t)w : 0u;
        }
    }
    fprintf(f,
            "<text x=\"%.0f\" y=\"24\" font-size=\"15\" font-weight=\"bold\">coavoid "
            "montecarlo: seed %llu, %lu encounters per UAV count, beta %s</text>\n",
            SVG_BAR_LEFT, (unsigned long long)o->seed, (unsigned long)o->count, betas);
}

/* Left: success rates, a group of three bars per UAV count, with Wilson intervals; budget
 * exhausted shown pale above a bar (unknown, not failed). */
static void svg_rates(FILE *f, const mc_summary_t *s, uint32_t sizes)
{
    const double y0 = SVG_PANEL_TOP + SVG_PANEL_H;
    fprintf(f,
            "<text x=\"%.0f\" y=\"%.0f\" font-weight=\"bold\">success rate (95%% Wilson "
            "interval)</text>\n",
            SVG_BAR_LEFT, SVG_PANEL_TOP - 10);
    for (int t = 0; t <= 10; t += 2) {
        double py = y0 - t / 10.0 * SVG_PANEL_H;
        fprintf(f,
                "<line x1=\"%.0f\" y1=\"%.1f\" x2=\"%.0f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n"
                "<text x=\"%.0f\" y=\"%.1f\" text-anchor=\"end\">%d%%</text>\n",
                SVG_BAR_LEFT, py, SVG_BAR_LEFT + SVG_BAR_W, py, SVG_BAR_LEFT - 6, py + 4, t * 10);
    }
    double group = SVG_BAR_W / sizes, bar = group / (COAVOID_MC_METHODS + 1.5);
    for (uint32_t k = 0; k < sizes; k++) {
        double gx = SVG_BAR_LEFT + k * group + 0.75 * bar;
        for (int m = 0; m < COAVOID_MC_METHODS; m++) {
            const mc_method_summary_t *ms = &s[k].m[m];
            double bx = gx + m * bar, top = y0 - ms->rate * SVG_PANEL_H;
            double cx = bx + 0.45 * bar;
            if (ms->budget > 0) { /* above the bar, pale: unknown, not failed */
                double h = (double)ms->budget / s[k].encounters * SVG_PANEL_H;
                fprintf(f,
                        "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" "
                        "fill=\"%s\" fill-opacity=\"0.3\"/>\n",
                        bx, top - h, 0.9 * bar, h, method_colours[m]);
            }
            fprintf(f,
                    "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" "
                    "fill=\"%s\"/>\n"
                    "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n",
                    bx, top, 0.9 * bar, y0 - top, method_colours[m], cx, y0 - ms->low * SVG_PANEL_H,
                    cx, y0 - ms->high * SVG_PANEL_H);
        }
        fprintf(f, "<text x=\"%.1f\" y=\"%.0f\" text-anchor=\"middle\">%lu UAVs</text>\n",
                gx + 1.5 * bar, y0 + 18, (unsigned long)s[k].size.n);
    }
    fprintf(f, "<line x1=\"%.0f\" y1=\"%.0f\" x2=\"%.0f\" y2=\"%.0f\" stroke=\"black\"/>\n",
            SVG_BAR_LEFT, y0, SVG_BAR_LEFT + SVG_BAR_W, y0);
    for (int m = 0; m < COAVOID_MC_METHODS; m++) {
        double ly = y0 + 44 + 16 * m;
        fprintf(f,
                "<rect x=\"%.0f\" y=\"%.0f\" width=\"12\" height=\"12\" fill=\"%s\"/>"
                "<text x=\"%.0f\" y=\"%.0f\">%s</text>\n",
                SVG_BAR_LEFT, ly - 10, method_colours[m], SVG_BAR_LEFT + 18, ly,
                coavoid_mc_method_names[m]);
    }
    fprintf(f, "<text x=\"%.0f\" y=\"%.0f\">pale above a bar: budget exhausted</text>\n",
            SVG_BAR_LEFT + 170, y0 + 44);
}

/* Middle: the CDF of the deviation ratio per UAV count, fixed solid, reordered dashed. */
static void svg_ratios(FILE *f, const coavoid_montecarlo_config_t *o,
                       const coavoid_montecarlo_t *run, const mc_summary_t *s, uint32_t sizes,
                       double *x)
{
    const double y0 = SVG_PANEL_TOP + SVG_PANEL_H;
    const cdf_panel_t p = {SVG_CDF_LEFT, SVG_CDF_W, cdf_right(s, sizes)};
    svg_cdf_frame(f, &p, "decoupled / centralised deviation, both solved (CDF)", "deviation ratio");
    for (uint32_t k = 0; k < sizes; k++) {
        const coavoid_mc_result_t *first = &run->results[k * o->count];
        const char *colour = size_colours[(s[k].size.n - COAVOID_ENCOUNTER_MIN_VEHICLES) %
                                          COAVOID_MONTECARLO_MAX_SIZES];
        svg_cdf(f, &p, first, o->count, COAVOID_MC_FIXED, x, colour, false);
        svg_cdf(f, &p, first, o->count, COAVOID_MC_REORDERED, x, colour, true);
        double ly = y0 + 56 + 16 * k;
        fprintf(f,
                "<line x1=\"%.0f\" y1=\"%.0f\" x2=\"%.0f\" y2=\"%.0f\" stroke=\"%s\" "
                "stroke-width=\"2\"/><text x=\"%.0f\" y=\"%.0f\">%lu UAVs</text>\n",
                SVG_CDF_LEFT, ly - 4, SVG_CDF_LEFT + 24, ly - 4, colour, SVG_CDF_LEFT + 30, ly,
                (unsigned long)s[k].size.n);
    }
    fprintf(f,
            "<text x=\"%.0f\" y=\"%.0f\">solid: decoupled_fixed</text>\n"
            "<text x=\"%.0f\" y=\"%.0f\">dashed: decoupled_reordered</text>\n",
            SVG_CDF_LEFT + 110, y0 + 56, SVG_CDF_LEFT + 110, y0 + 72);
    if (p.right >= 10.0) {
        fprintf(f, "<text x=\"%.0f\" y=\"%.0f\">ratios above 10 at the right edge</text>\n",
                SVG_CDF_LEFT + 110, y0 + 88);
    }
}

/* Right: the CDF of each centralised plan's deviation over its proven lower bound, per UAV
 * count (1: proven optimal), from 1 to the largest seen (at least 2, at most 10). */
static void svg_bounds(FILE *f, const coavoid_montecarlo_config_t *o,
                       const coavoid_montecarlo_t *run, const mc_summary_t *s, uint32_t sizes,
                       double *x)
{
    cdf_panel_t p = {SVG_BOUND_LEFT, SVG_BOUND_W, 2.0};
    for (uint32_t k = 0; k < sizes; k++) {
        const mc_dist_t *d = &s[k].m[COAVOID_MC_CENTRALISED].bound_ratio;
        p.right = d->count > 0 && d->max > p.right ? d->max : p.right;
    }
    p.right = p.right > 10.0 ? 10.0 : p.right;
    svg_cdf_frame(f, &p, "centralised plan / its lower bound (CDF)", "plan / bound");
    for (uint32_t k = 0; k < sizes; k++) {
        const char *colour = size_colours[(s[k].size.n - COAVOID_ENCOUNTER_MIN_VEHICLES) %
                                          COAVOID_MONTECARLO_MAX_SIZES];
        svg_steps(f, &p, x, bound_values(&run->results[k * o->count], o->count, x, NULL), colour,
                  false);
    }
}

static int write_svg(const char *path, const coavoid_montecarlo_config_t *o,
                     const coavoid_montecarlo_t *run, const mc_summary_t *s, uint32_t sizes,
                     double *x)
{
    FILE *f = fopen(path, "w");
    if (f == NULL) {
        return -1;
    }
    svg_head(f, o, s, sizes);
    svg_rates(f, s, sizes);
    svg_ratios(f, o, run, s, sizes, x);
    svg_bounds(f, o, run, s, sizes, x);
    fprintf(f, "</svg>\n");
    bool ok = !ferror(f);
    return fclose(f) == 0 && ok ? 0 : -1;
}

/* The summaries of every UAV count, the figure and the table; the exit status. */
int coavoid_montecarlo_report(coavoid_montecarlo_t *mc, FILE *out, bool json,
                              coavoid_run_error_t *e)
{
    const coavoid_montecarlo_config_t *o = &mc->config;
    bool defects = false;
    for (uint32_t j = 0; j < mc->total; j++) {
        defects = defects || mc->results[j].defect[0] != '\0';
    }
    mc_summary_t summary[COAVOID_MONTECARLO_MAX_SIZES];
    for (uint32_t k = 0; k < o->size_count; k++) {
        summarise(&mc->results[k * o->count], o->count, &mc->sizes[k], mc->x, &summary[k]);
        if (o->fly) {
            summarise_fly(&mc->results[k * o->count], o->count, &summary[k]);
        }
        if (o->stops_sweep) {
            summarise_sweep(&mc->results[k * o->count], o->count, &summary[k]);
        }
    }
    if (o->svg != NULL && write_svg(o->svg, o, mc, summary, o->size_count, mc->x) != 0) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "--svg: cannot write '%.200s'",
                                o->svg);
    }
    int rc = 0;
    if (json) {
        rc = json_summary(out, o, summary, o->size_count);
    } else {
        text_summary(out, o, summary, o->size_count);
        if (o->fly) {
            text_fly(out, o, summary, o->size_count);
        }
        if (o->stops_sweep) {
            text_sweep(out, mc, summary);
        }
    }
    if (rc != 0 || fflush(out) != 0 || ferror(out)) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "cannot write the summary");
    }
    return defects
               ? coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "montecarlo: defects found (above)")
               : COAVOID_RUN_DONE;
}
