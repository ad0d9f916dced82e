/* SPDX-License-Identifier: MIT */
/*
 * montecarlo_fly.c: montecarlo's closed loop (montecarlo.h, fly): an encounter flown by
 * the nodes in one process (coavoid::sim), in both modes, over the simulated network.
 * Built only with the messaging library.
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "encounter.h"
#include "montecarlo.h"
#include "montecarlo_internal.h"
#include "prng.h"
#include "scenario.h"
#include "sim.h"

/* The network's seed of encounter (n, index) of seed: one splitmix64 step over the three,
 * so that neighbouring encounters do not share streams. */
static uint64_t fly_seed(uint64_t seed, uint32_t n, uint32_t index)
{
    coavoid_prng_t p = {seed ^ ((uint64_t)n << 56) ^ ((uint64_t)index << 24)};
    return coavoid_prng_next(&p);
}

/* One mode's run into *f. 0, or -1 with err. */
static int fly_mode(const coavoid_montecarlo_config_t *c, const char *json, int mode,
                    const coavoid_mc_result_t *r, coavoid_mc_flown_t *f, char *err, size_t err_size)
{
    coavoid_scenario_t s;
    char why[COAVOID_SCENARIO_ERROR_MAX];
    memset(&s, 0, sizeof s);
    if (coavoid_scenario_parse(json, strlen(json), &s, why, sizeof why) != 0) {
        snprintf(err, err_size, "internal error: encounter %lu of %lu UAVs: %s",
                 (unsigned long)r->index, (unsigned long)r->vehicles, why);
        return -1;
    }
    coavoid_sim_config_t sc;
    memset(&sc, 0, sizeof sc);
    sc.scenario_path = "montecarlo";
    sc.mode = coavoid_mc_fly_mode_names[mode];
    sc.decoupled = mode == COAVOID_MC_FLY_DECOUPLED;
    sc.insecure = true; /* nothing but the run's own nodes is on its bus (montecarlo.h) */
    sc.network = true;
    sc.loss = c->loss;
    sc.delay = c->delay;
    sc.jitter = c->jitter;
    sc.seed = fly_seed(c->seed, r->vehicles, r->index);
    coavoid_sim_outcome_t outcome;
    coavoid_run_error_t e;
    int rc = coavoid_sim_fly(&sc, &s, NULL, &outcome, &e);
    coavoid_scenario_free(&s);
    if (rc != COAVOID_SIM_SEPARATED && rc != COAVOID_SIM_LOSS) {
        /* The settings are the caller's: an input error names the option. */
        snprintf(err, err_size, "%sencounter %lu of %lu UAVs, flown %s: %s",
                 rc == COAVOID_RUN_ERR_INPUT ? "" : "internal error: ", (unsigned long)r->index,
                 (unsigned long)r->vehicles, sc.mode, e.text);
        return -1;
    }
    f->loss_of_separation = outcome.loss_of_separation;
    f->fallbacks = outcome.fallbacks;
    f->sent = outcome.sent;
    f->delivered = outcome.delivered;
    f->dropped = outcome.dropped;
    return 0;
}

int coavoid_mc_fly(const coavoid_montecarlo_config_t *c, const coavoid_mc_size_t *size,
                   coavoid_mc_result_t *r, char *err, size_t err_size)
{
    char json[COAVOID_ENCOUNTER_JSON_MAX];
    if (!coavoid_encounter_json(&coavoid_encounter_montecarlo, c->seed, size->n, r->index,
                                r->redraws, json, sizeof json, NULL)) {
        snprintf(err, err_size, "internal error: encounter %lu of %lu UAVs does not fit",
                 (unsigned long)r->index, (unsigned long)size->n);
        return -1;
    }
    for (int mode = 0; mode < COAVOID_MC_FLY_MODES; mode++) {
        if (fly_mode(c, json, mode, r, &r->flown[mode], err, err_size) != 0) {
            return -1;
        }
    }
    return 0;
}
