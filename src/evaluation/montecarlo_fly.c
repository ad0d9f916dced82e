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

#define FLY_MAX_CYCLES COAVOID_MC_MAX_CYCLES

/* The encounter's memo of failed joint searches, kept across its runs (node.h): a 5-UAV
 * encounter's stopped runs repeat a few failing problems thousands of times. */
#define FLY_JOINT_MEMO_KEYS 4096u

/* Where a run's coordinator stops (none: has_stop false), where to record its messages
 * per cycle (NULL: nowhere), its tape (sim.h: recorded unstopped, replayed stopped;
 * NULL: none), and the encounter's memo of failed joint searches. */
typedef struct {
    bool has_stop;
    uint32_t step, messages;
    uint32_t *sent; /* FLY_MAX_CYCLES counts */
    coavoid_sim_tape_t *tape;
    coavoid_node_joint_memo_t *memo;
} fly_stop_t;

/* The network's seed of encounter r's runs. */
static uint64_t fly_net_seed(const coavoid_montecarlo_config_t *c, const coavoid_mc_result_t *r)
{
    return fly_seed(c->has_net_seed ? c->net_seed : c->seed, r->vehicles, r->index);
}

/* One mode's run into *f. 0, or -1 with err. */
static int fly_mode(const coavoid_montecarlo_config_t *c, const char *json, int mode,
                    const coavoid_mc_result_t *r, const fly_stop_t *stop, coavoid_mc_flown_t *f,
                    char *err, size_t err_size)
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
    sc.seed = r->net_seed;
    sc.has_stop = stop->has_stop;
    sc.has_stop_messages = stop->has_stop;
    sc.stop_step = stop->step;
    sc.stop_messages = stop->messages;
    sc.coordinator_messages = stop->sent;
    sc.coordinator_messages_size = stop->sent != NULL ? FLY_MAX_CYCLES : 0u;
    sc.tape = stop->tape;
    sc.joint_memo = stop->memo;
    sc.replay = stop->has_stop;
    coavoid_sim_outcome_t outcome;
    coavoid_run_error_t e;
    int rc = coavoid_sim_fly(&sc, &s, NULL, &outcome, &e);
    coavoid_scenario_free(&s);
    if (rc != COAVOID_SIM_SEPARATED && rc != COAVOID_SIM_LOSS) {
        /* The settings are the caller's: an input error names the option. */
        snprintf(err, err_size, "%sencounter %lu of %lu UAVs, flown %s%s: %s",
                 rc == COAVOID_RUN_ERR_INPUT ? "" : "internal error: ", (unsigned long)r->index,
                 (unsigned long)r->vehicles, sc.mode,
                 stop->has_stop ? " with the coordinator stopped" : "", e.text);
        return -1;
    }
    f->loss_of_separation = outcome.loss_of_separation;
    f->fallbacks = outcome.fallbacks;
    f->sent = outcome.sent;
    f->delivered = outcome.delivered;
    f->dropped = outcome.dropped;
    return 0;
}

/* One stopped run of the sweep (cycle k, cut m) into r->sweep. 0, or -1 with err. */
static int fly_stop(const coavoid_montecarlo_config_t *c, const char *json, coavoid_mc_result_t *r,
                    const fly_stop_t *unstopped, uint32_t k, uint32_t m, char *err, size_t err_size)
{
    coavoid_mc_sweep_t *w = &r->sweep;
    if (w->runs >= COAVOID_MC_MAX_STOPS) {
        snprintf(err, err_size,
                 "internal error: encounter %lu of %lu UAVs: more than %u stop points",
                 (unsigned long)r->index, (unsigned long)r->vehicles, COAVOID_MC_MAX_STOPS);
        return -1;
    }
    const fly_stop_t stop = {true, k, m, NULL, unstopped->tape, unstopped->memo};
    coavoid_mc_flown_t f;
    if (fly_mode(c, json, COAVOID_MC_FLY_CENTRALISED, r, &stop, &f, err, err_size) != 0) {
        return -1;
    }
    if (f.loss_of_separation) {
        w->lost[w->runs / 8u] |= (uint8_t)(1u << (w->runs % 8u));
        if (w->losses++ == 0u) {
            w->loss_step = k;
            w->loss_messages = m;
        }
    }
    w->runs++;
    return 0;
}

/* The coordinator-stop sweep of the encounter (config stops_sweep) into r->sweep: every
 * cycle of the unstopped centralised run, which sent sent[k] messages in cycle k and was
 * recorded on its tape, which every stopped run replays (with its memo). */
static int fly_sweep(const coavoid_montecarlo_config_t *c, const char *json, coavoid_mc_result_t *r,
                     const fly_stop_t *unstopped, char *err, size_t err_size)
{
    const uint32_t *sent = unstopped->sent;
    coavoid_mc_sweep_t *w = &r->sweep;
    w->cycles = 2u * coavoid_encounter_montecarlo.horizon + 1u;
    for (uint32_t k = 0; k < w->cycles; k++) {
        w->sent[k] = (uint16_t)(sent[k] < UINT16_MAX ? sent[k] : UINT16_MAX);
        const uint32_t points = w->sent[k] > 0u ? w->sent[k] : 1u;
        for (uint32_t m = 0; m < points; m++) {
            if (coavoid_mc_stop_flown(m, w->sent[k], c->stops_ends) &&
                fly_stop(c, json, r, unstopped, k, m, err, err_size) != 0) {
                return -1;
            }
        }
    }
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
    uint32_t sent[FLY_MAX_CYCLES] = {0};
    r->net_seed = fly_net_seed(c, r);
    if (2u * coavoid_encounter_montecarlo.horizon + 1u > FLY_MAX_CYCLES) {
        snprintf(err, err_size, "internal error: the design's horizon is beyond the sweep's");
        return -1;
    }
    coavoid_sim_tape_t *tape = c->stops_sweep ? coavoid_sim_tape_create() : NULL;
    if (c->stops_sweep && tape == NULL) {
        snprintf(err, err_size, "out of memory for the coordinator's tape");
        return -1;
    }
    uint64_t keys[FLY_JOINT_MEMO_KEYS];
    coavoid_node_joint_memo_t memo;
    (void)coavoid_node_joint_memo_init(&memo, keys, FLY_JOINT_MEMO_KEYS);
    /* The cut points and the tape are the centralised run's. */
    const fly_stop_t unstopped = {false, 0u, 0u, sent, tape, &memo};
    const fly_stop_t decoupled = {false, 0u, 0u, NULL, NULL, &memo};
    int rc = 0;
    for (int mode = 0; mode < COAVOID_MC_FLY_MODES && rc == 0; mode++) {
        const fly_stop_t *stop = mode == COAVOID_MC_FLY_CENTRALISED ? &unstopped : &decoupled;
        rc = fly_mode(c, json, mode, r, stop, &r->flown[mode], err, err_size);
    }
    if (rc == 0 && c->stops_sweep) {
        rc = fly_sweep(c, json, r, &unstopped, err, err_size);
    }
    coavoid_sim_tape_destroy(tape);
    return rc;
}
