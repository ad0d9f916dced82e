/* SPDX-License-Identifier: MIT */
/*
 * sim.h: closed-loop runs of a scenario, judged (docs/scenario-format.md, "Simulation
 * result"), from two sources:
 *
 *   - coavoid_sim_run flies the scenario in one process: the world, one vehicle node per
 *     UAV and (centralised) the coordinator are the nodes the real-time programs run
 *     (coavoid::node), here over LCM's in-process provider (memq) on a simulated clock, so
 *     that a run is repeatable bit for bit (`coavoid sim`);
 *   - coavoid_sim_summarise rebuilds what each UAV flew from an lcm-logger log of a
 *     real-time run and judges it the same way (`coavoid summary`).
 *
 * Both write the result (text or JSON) to a stream and the figure to a file, and report
 * the first problem with their input as one line in a coavoid_run_error_t, naming the
 * file and field (or the option, by its command-line name) and why; the program prefixes
 * it with its own name. The scenario and the log are untrusted (docs/security.md): every
 * bound a message or the run has is checked before the run starts, and a log's events are
 * checked before LCM's reader sees them.
 *
 * Memory: heap, for the run's record (UAVs x steps) and the nodes' planners (their betas),
 * released before return. Time: the run's, dominated by the planners.
 */
#ifndef COAVOID_SIM_H
#define COAVOID_SIM_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "auth.h"
#include "node.h"
#include "run.h"
#include "scenario.h"
#include "tape.h"

/* What both return: the run's verdict (the values of run.h's verdicts, so that one mapping
 * to exit statuses serves every program), or run.h's COAVOID_RUN_ERR_INPUT (the scenario,
 * the log or a setting is refused) or COAVOID_RUN_ERR_INTERNAL (a bug, out of memory, or
 * the output was not written) with the report in a coavoid_run_error_t. */
enum {
    COAVOID_SIM_SEPARATED = COAVOID_RUN_DONE,  /* judged: no loss of separation */
    COAVOID_SIM_LOSS = COAVOID_RUN_NOT_SOLVED, /* judged: a loss of separation */
};

/* A one-process run. */
typedef struct {
    const char *scenario_path; /* names the scenario in reports */
    const char *mode;          /* "centralised" or "decoupled", as the result names it */
    bool decoupled;
    bool has_steps;     /* steps given; otherwise 2 * horizon */
    uint32_t steps;     /* samples 0..steps are flown, >= 1 */
    bool has_stop;      /* centralised: the coordinator stops in cycle stop_step */
    uint32_t stop_step; /* 0..steps */
    /* With has_stop: the coordinator's first stop_messages messages published in cycle
     * stop_step go out (to whom the network delivers them), whatever their kinds, and then
     * it is gone: the network copies nothing more of it (net.h, coavoid_sim_net_stop_after)
     * and it is destroyed. 0 (and has_stop_messages false: `--coordinator-stops STEP`):
     * before it publishes anything in the cycle. A cycle runs from its start to the next's
     * (what a node publishes while the clock runs up to the next start is of this cycle);
     * has_stop_messages only adds the count to the result. */
    bool has_stop_messages;
    uint32_t stop_messages;
    /* NULL, or where to record, for each cycle k < coordinator_messages_size, how many
     * messages the coordinator put on the network in it (a sweep's cut points). */
    uint32_t *coordinator_messages;
    size_t coordinator_messages_size;
    /* NULL, or a tape (tape.h) of the coordinator. replay false: this run's coordinator is
     * recorded on it (cleared first). replay true, with has_stop: the coordinator is not
     * run; the tape's messages, recorded in a run of the same scenario and settings
     * without the stop, are published at its calls instead, until the cut. The run is the
     * same (the stopped run is the unstopped one up to the cut) without repeating the
     * coordinator's searches; a run that is not the recorded one (the network's digest
     * before a call is not the tape's) is an internal error, never a silent difference. */
    coavoid_sim_tape_t *tape;
    bool replay;
    /* NULL, or a memo of the joint searches that found no plan (node.h,
     * coavoid_node_joint_memo_t) for the run's vehicles, kept by the caller across runs of
     * the same scenario (a sweep's stopped runs repeat the unstopped run's searches); NULL:
     * the run's own, shared by its vehicles. The flight is the same either way. */
    coavoid_node_joint_memo_t *joint_memo;
    /* Centralised: with has_joint_members, every vehicle's joint_members (node.h: 0, never,
     * or 2..COA_MAX_CENTRALISED), as coavoid-vehicle --joint-members gives a fleet; else
     * coavoid_node_joint_members's. */
    bool has_joint_members;
    size_t joint_members;
    bool json;            /* the result as JSON (default: text) */
    const char *svg_path; /* NULL, or where the figure goes */
    /* NULL, or where the record of UAV record_uav goes (src/replay, replay.h): its
     * configuration and keys, every datagram it received and call it was given with their
     * times, what it sent and its state after each call. That UAV searches jointly without
     * the run's memo (joint_memo), which changes nothing of the flight. */
    const char *record_path;
    uint16_t record_uav;
    /* The nodes sign and check every message (default), with the simulation's fixed keys
     * (fixed, public, derived from the key ids: they make a run repeatable and protect nothing, as
     * nothing but the run's own nodes is on its in-process bus), or, insecure, neither: the flight is the same either way. */
    bool insecure;
    /* The network between the nodes (net.h): each message a node publishes reaches each
     * other node independently, lost with probability loss (0 <= loss < 1), else after
     * delay + a uniform jitter in [0, jitter] seconds (delay, jitter >= 0, delay + jitter
     * less than dt, so that a message is never more than a cycle late: later, a plan is no
     * longer of use), drawn from seed; a node hears its own at once. All 0 (the default):
     * every message reaches every node at once, the run of a quiet network. `network`:
     * the result reports the network's settings and counts (a "network" object in JSON, a
     * line in text); otherwise it is as without one. */
    bool network;
    double loss;
    double delay;  /* s */
    double jitter; /* s */
    uint64_t seed;
    /* Optional (scripted loss, for tests): asked about every copy of a message the network
     * would deliver to another node, with the sender's and receiver's node ids (a UAV's
     * id, COAVOID_NODE_COORDINATOR_ID or COAVOID_NODE_WORLD_ID), the channel, the bytes
     * and the time; true drops it. It must not publish. NULL: none. */
    bool (*drop)(void *user, const char *channel, uint32_t from_id, uint32_t to_id,
                 const void *data, size_t size, int64_t now);
    void *drop_user;
} coavoid_sim_config_t;

/* What a run did, for a caller that tabulates runs rather than prints them. */
typedef struct {
    bool loss_of_separation;
    uint32_t fallbacks; /* the UAVs' switches from the coordinator to planning for themselves */
    uint64_t sent;      /* messages the nodes published */
    uint64_t delivered; /* copies that reached another node */
    uint64_t dropped;   /* copies lost */
    uint64_t in_flight; /* copies still on their way when the run ended */
    /* The agreement on the coordinator's plans (docs/protocol.md): the coordinator's
     * counts (node.h's coavoid_coordinator_state_t; 0 decoupled) and the UAVs' sums. */
    uint32_t plans_proposed;
    uint32_t plans_committed;
    uint32_t plans_aborted;
    uint32_t plans_replanned;
    uint32_t plans_resent;
    uint32_t plans_switched; /* UAVs that switched to a committed plan */
    uint32_t plans_in_doubt; /* UAVs whose accepted plan got no decision in its cycle */
    uint32_t plans_standby;  /* ... of which flew the standby they planned at the answer wait */
    uint32_t joint_plans;    /* the UAVs' rows flown of their group's joint plan, no
                                priority order solving it (node.h's joint_members) */
} coavoid_sim_outcome_t;

/* The largest --steps, and with it --coordinator-stops: more is more likely a typo than a
 * simulation anyone waits for. */
#define COAVOID_SIM_MAX_STEPS 1000000u

/* Flies scenario s (loaded, not yet sampled: sampled here) as c says and writes the
 * result to out (NULL: nothing is written, and c->svg_path must be NULL). Returns a verdict,
 * or an error with e set; *outcome (when not NULL) is set with a verdict. Memory beyond the
 * file comment's: with a delay or jitter, the network's queue of two cycles of messages
 * (about 1.5 kB a message; 0.2 MB for 5 UAVs). */
int coavoid_sim_run(const coavoid_sim_config_t *c, coavoid_scenario_t *s, FILE *out,
                    coavoid_run_error_t *e);
/* coavoid_sim_run, with the outcome. */
int coavoid_sim_fly(const coavoid_sim_config_t *c, coavoid_scenario_t *s, FILE *out,
                    coavoid_sim_outcome_t *outcome, coavoid_run_error_t *e);

/* A log's run. */
typedef struct {
    const char *scenario_path; /* names the scenario in reports */
    const char *log_path;
    const char *mode;     /* the mode the run was started in, as the result names it */
    bool json;            /* the result as JSON, with a "log" object */
    const char *svg_path; /* NULL, or where the figure goes */
    /* NULL, or where the record of UAV record_uav goes (src/replay, replay.h): its
     * configuration and keys, every datagram it received and call it was given with their
     * times, what it sent and its state after each call. That UAV searches jointly without
     * the run's memo (joint_memo), which changes nothing of the flight. */
    const char *record_path;
    uint16_t record_uav;
    bool has_epoch; /* cycle 0's start given; otherwise the earliest plan_utime */
    int64_t epoch;  /* microseconds, >= 1 */
    /* The run's trust list (the caller's), or NULL: then signatures are not checked. With
     * one, an intent, heartbeat or plan counts only when signed by a key that may send it
     * and newer (timestamp, sequence) than the last one of its type from that key in log
     * order; the others are ignored and counted as unauthenticated. */
    const coavoid_auth_trust_t *trust;
} coavoid_sim_log_config_t;

/* Judges the run of scenario s (loaded) that the lcm-logger log c->log_path recorded, and
 * writes the result to out. Returns a verdict, or an error with e set. */
int coavoid_sim_summarise(const coavoid_sim_log_config_t *c, coavoid_scenario_t *s, FILE *out,
                          coavoid_run_error_t *e);

#endif /* COAVOID_SIM_H */
