/* SPDX-License-Identifier: MIT */
/*
 * montecarlo.h: the engine of `coavoid montecarlo`: the paper's question (does centralised
 * planning succeed more often and more cheaply than decoupled planning?) asked of
 * thousands of seeded random encounters instead of a few illustrations
 * (docs/evaluation.md).
 *
 * Each encounter (encounter.h, design coavoid_encounter_montecarlo: UAVs converging on a
 * point over hills, with non-cooperative tracks crossing) is solved three ways on the same
 * problem: centralised (coa_plan_centralised), decoupled in the fixed priority order
 * (coa_plan_decoupled, one order) and decoupled with reordering (up to max_orders orders).
 * A draw whose reference plan (every offset 0) has no conflict, or has one in its first
 * step (which includes t = 0, where nothing can be done), is replaced by the next draw of
 * the same encounter; the redraws are counted.
 *
 * Every result is cross-checked. The centralised plan is optimal, so wherever both solve,
 * a decoupled plan's exact deviation must be at least the centralised one's,
 * lexicographically with the effort; a decoupled plan is a plan for the group, so the
 * centralised search cannot have proven one absent (infeasible); every solved plan must be
 * conflict-free by coa_plan_find_conflict, and must move someone (the reference
 * conflicts). A violation is a defect of the planner: it is handed to the config's defect
 * callback as it is found, and coavoid_montecarlo_report returns
 * COAVOID_RUN_ERR_INTERNAL after writing everything else.
 *
 * Jobs. Encounters are independent: `jobs` worker threads take them in order, each with
 * its own planner workspaces, while the calling thread writes the CSV rows in encounter
 * order as they complete and reports progress. So nothing but the times depends on jobs,
 * and a seed gives the same encounters and results on every machine with the same C maths
 * library.
 *
 * Use: fill a coavoid_montecarlo_config_t, coavoid_montecarlo_run, then
 * coavoid_montecarlo_report (any number of times) and coavoid_montecarlo_free.
 */
#ifndef COAVOID_EVALUATION_MONTECARLO_H
#define COAVOID_EVALUATION_MONTECARLO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "encounter.h"
#include "run.h"

/* UAV counts one run compares: each of COAVOID_ENCOUNTER_MIN_VEHICLES..MAX once. */
#define COAVOID_MONTECARLO_MAX_SIZES \
    (COAVOID_ENCOUNTER_MAX_VEHICLES - COAVOID_ENCOUNTER_MIN_VEHICLES + 1u)
/* Worker threads at most: beyond a machine's cores they only add workspaces. */
#define COAVOID_MONTECARLO_MAX_JOBS 64u
/* Encounters per UAV count that `coavoid montecarlo --count` runs, and --merge merges,
 * at most. */
#define COAVOID_MONTECARLO_MAX_COUNT 100000u

typedef struct {
    /* The UAV counts, in the order of the reports, each of COAVOID_ENCOUNTER_MIN_VEHICLES to
     * COAVOID_ENCOUNTER_MAX_VEHICLES and distinct; count encounters of each. */
    uint32_t vehicles[COAVOID_MONTECARLO_MAX_SIZES];
    uint32_t size_count;
    uint32_t count;
    /* The first encounter's index: each UAV count runs encounters first..first+count-1 of
     * the seed's sequence (each is drawn from its own index, so a long run can be split
     * into parts that together give the same rows); first + count <= UINT32_MAX. */
    uint32_t first;
    uint64_t seed;
    /* The closed-set bound of every search, >= 1; 0: per UAV count, coavoid_default_beta
     * of its centralised planner (the programs' sizing policy, scenario.h). */
    uint32_t beta;
    /* Reordering's limit on priority orders, >= 1; 0: every order (N!). */
    uint32_t max_orders;
    /* Work units each planning call may spend (coa_planner_set_work); 0: no limit. */
    uint64_t work;
    uint32_t jobs;   /* worker threads, 1..COAVOID_MONTECARLO_MAX_JOBS */
    const char *csv; /* a file for one row per encounter and method, or NULL */
    const char *svg; /* a file for the figure, written by the report, or NULL */
    /* An existing directory for every encounter as DIR/montecarlo-SEED-N-INDEX.json (for
     * `coavoid plan` to replay), or NULL. */
    const char *save;
    /* Progress lines while it runs (updated in place every second when it is a terminal,
     * a line every 10 % otherwise), or NULL for none. */
    FILE *progress;
    /* Called on the calling thread with one line per defect found, in encounter order;
     * NULL: defects are only counted. */
    void (*defect)(void *context, const char *line);
    void *context;
    /* The closed loop (built with the messaging library only): each encounter is also
     * flown by the nodes (sim.h's coavoid_sim_fly, as `coavoid sim` flies it), once
     * centralised and once decoupled, over the simulated network with these settings
     * (loss 0 <= loss < 1, delay and jitter in seconds, >= 0, together under the
     * design's dt), its random stream seeded from (seed, UAV count, index): the same for
     * both modes, so that they meet the same draws. The nodes run insecure: signatures
     * cost a millisecond a cycle and protect nothing on an in-process bus that only the
     * run's own nodes are on; the flight is the same either way. The report then gives,
     * per UAV count and mode, the rate of loss of separation, overall and over the
     * encounters that the one-shot centralised plan, or some priority order, solves. */
    bool fly;
    double loss, delay, jitter;
    /* The network's seed (fly): each encounter's stream is drawn from (net_seed, UAV
     * count, index), so that one set of encounters can meet other networks; has_net_seed
     * false: from seed. */
    bool has_net_seed;
    uint64_t net_seed;
    /* With fly: each encounter is also flown centralised with the
     * coordinator stopped at every cycle s = 0..2N and, in each, at every cut point
     * M = 0..C(s)-1 (C(s): the messages it sent in cycle s of the unstopped run; the run
     * is that run up to the cut, so these are all the places it can stop; M = C(s) is
     * s+1:0), or with stops_ends only M = 0, 1, C(s)/2 and C(s)-1; a cycle it sent nothing
     * in, M = 0 (sim.h, stop_step and stop_messages). The same network seed as the other
     * runs. The report counts the runs that lose separation, and those in encounters the
     * decoupled closed loop keeps separated. */
    bool stops_sweep;
    bool stops_ends;
} coavoid_montecarlo_config_t;

/* The encounters of a run and their outcomes; opaque. */
typedef struct coavoid_montecarlo coavoid_montecarlo_t;

/* Checks the config (every UAV count's centralised planner can be sized) and the outputs
 * before the run rather than after an hour of it (save is a directory we can write in,
 * csv is created, svg can be created), then draws, solves and cross-checks every
 * encounter, writing csv's rows as they complete. Returns COAVOID_RUN_DONE with *out
 * set, or an error (evaluation.h, "Errors") with e set and *out NULL
 * (csv may then be partly written). Memory: a result of about 500 bytes per encounter,
 * kept until coavoid_montecarlo_free, and per job two planner workspaces (as beta sizes
 * them) and two offset tables of about 240 KB, freed before it returns; flying, per job a
 * simulation's nodes at a time (about 3 MB a UAV and the coordinator's planner). Cost:
 * count times size_count encounters, each a centralised search and up to 1 + max_orders
 * decoupled ones, and with fly two closed-loop runs of 2 * horizon cycles (a planning
 * call per conflicting cluster per cycle), spread over the jobs. Without the messaging
 * library, fly is an input error. */
int coavoid_montecarlo_run(const coavoid_montecarlo_config_t *config, coavoid_montecarlo_t **out,
                           coavoid_run_error_t *e);

/* Summarises the run per UAV count and method (outcomes, the success rate and its 95 %
 * Wilson interval, the distribution of the decoupled/centralised deviation ratio over the
 * encounters both solve, times, nodes), writes the config's svg and prints the summary on
 * out as text or, with json, a JSON object (docs/evaluation.md). Returns
 * COAVOID_RUN_DONE, or COAVOID_RUN_ERR_INTERNAL with e set when a write failed
 * or the run found defects (after writing everything). Cost O(count log count) per UAV
 * count and method; no memory beyond cJSON's tree for json. */
int coavoid_montecarlo_report(coavoid_montecarlo_t *mc, FILE *out, bool json,
                              coavoid_run_error_t *e);

/* CSV files montecarlo_figure reads at most: one run per loss level. */
#define COAVOID_MC_FIGURE_MAX_FILES 16u

/* The closed loop's figure across runs: reads the CSV files of montecarlo --fly runs
 * (each at one loss; those at the same loss add up; every one with the first's delay and
 * jitter) and writes svg_path: per UAV count (colour) and mode (solid centralised, dashed
 * decoupled) the rate of encounters that lose separation, with its 95 % Wilson interval,
 * against the loss; prints the points as a table on out. The files are untrusted: each is
 * checked line by line (the --fly header, 22 fields, or 35 in a CSV --merge reads, the UAV
 * count, status and network of every flown row, lines of at most 1,023 bytes and 5e7
 * lines), and the first problem is COAVOID_RUN_ERR_INPUT with e naming the file and line.
 * Memory: about 6 kB. */
int coavoid_montecarlo_figure(const char *const *csv_paths, size_t count, const char *svg_path,
                              FILE *out, coavoid_run_error_t *e);

/* CSV files montecarlo_merge reads at most: the parts of one run. */
#define COAVOID_MC_MERGE_MAX_FILES 1024u

/* A run rebuilt from the CSVs of its parts (runs of one config but first and count, whose
 * encounters follow each other: a run split with --first), in any order, for
 * coavoid_montecarlo_report to print and draw as the whole run's, times aside (each part
 * timed its own plans), to svg_path when not NULL. The rows are checked against each
 * other: one kind of run (the header), the same seed, planners' limits, network, sweep
 * and network seed, the UAV counts in the same order, no encounter twice nor left out,
 * every encounter's rows in order (its methods, flown modes and every cycle's stop
 * points), at most COAVOID_MONTECARLO_MAX_COUNT encounters per UAV count. Every field is
 * checked, lines are at most 1,023 bytes and 5e7 per file; the first problem is
 * COAVOID_RUN_ERR_INPUT with e naming the file (and line). The cross-checks of the run
 * (montecarlo.h) are made again on the rows, their defects handed to the callback as the
 * run would, so that the report returns COAVOID_RUN_ERR_INTERNAL; only the plans'
 * conflict check is not (the CSV has no plans). Returns COAVOID_RUN_DONE with *out set,
 * to free with coavoid_montecarlo_free. Memory: the run's results (about 1.3 kB an
 * encounter) and the files' first rows; each file is read twice, a line at a time. */
int coavoid_montecarlo_merge(const char *const *csv_paths, size_t count, const char *svg_path,
                             void (*defect)(void *context, const char *line), void *context,
                             coavoid_montecarlo_t **out, coavoid_run_error_t *e);

/* Frees a run (NULL is fine). */
void coavoid_montecarlo_free(coavoid_montecarlo_t *mc);

#endif /* COAVOID_EVALUATION_MONTECARLO_H */
