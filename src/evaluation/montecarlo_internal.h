/* SPDX-License-Identifier: MIT */
/*
 * montecarlo_internal.h: what the Monte Carlo engine (montecarlo.c: drawing, solving,
 * cross-checking, the CSV) hands its reports (montecarlo_report.c: statistics, text, JSON,
 * SVG): each encounter's outcomes. Not part of the library's interface (montecarlo.h).
 */
#ifndef COAVOID_EVALUATION_MONTECARLO_INTERNAL_H
#define COAVOID_EVALUATION_MONTECARLO_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "coavoid/coavoid.h"
#include "encounter.h"
#include "montecarlo.h"

/* The three ways each encounter is solved, in the order of every report. */
enum { COAVOID_MC_CENTRALISED, COAVOID_MC_FIXED, COAVOID_MC_REORDERED, COAVOID_MC_METHODS };
extern const char *const coavoid_mc_method_names[COAVOID_MC_METHODS];

/* One method's plan of one encounter. */
typedef struct {
    coa_plan_status_t status;
    double deviation;
    coa_cost_t units;
    uint32_t effort;
    uint64_t expanded, generated;
    uint32_t orders_tried;
    double time_us;
    bool optimal;           /* centralised: the plan is proven optimal */
    double bound_deviation; /* centralised: the proven lower bound on the optimum (m^2) */
    uint64_t work;          /* work units spent */
} coavoid_mc_outcome_t;

/* The two closed-loop modes of fly, in the order of every report. */
enum { COAVOID_MC_FLY_CENTRALISED, COAVOID_MC_FLY_DECOUPLED, COAVOID_MC_FLY_MODES };
extern const char *const coavoid_mc_fly_mode_names[COAVOID_MC_FLY_MODES];

/* One closed-loop run of one encounter (montecarlo fly). */
typedef struct {
    bool loss_of_separation;
    uint32_t fallbacks;
    uint64_t sent, delivered, dropped;
} coavoid_mc_flown_t;

/* The cycles a closed-loop run may fly (2N + 1 of the design), and the stop points of a
 * sweep, at most: far more than the design's 25 cycles of at most a few dozen messages. */
#define COAVOID_MC_MAX_CYCLES 64u
#define COAVOID_MC_MAX_STOPS 4096u

/* An encounter's coordinator-stop sweep (config stops_sweep). */
typedef struct {
    uint32_t runs, losses; /* stopped runs, and those that lost separation */
    /* The first stop point (cycle, messages) that lost separation, when losses > 0. */
    uint32_t loss_step, loss_messages;
    uint32_t cycles;                        /* cycles of the unstopped centralised run */
    uint16_t sent[COAVOID_MC_MAX_CYCLES];   /* its messages in each */
    uint8_t lost[COAVOID_MC_MAX_STOPS / 8]; /* bit j: stop point j (coavoid_mc_stop_flown) lost */
} coavoid_mc_sweep_t;

/* Whether the sweep flies cut point m of a cycle in which the coordinator sent `sent`
 * messages unstopped (m < sent, or m = 0 when it sent none): every one, or with ends only
 * the first two, the middle and the last. Stop points are numbered in order of cycle,
 * then m, over the flown ones. */
static inline bool coavoid_mc_stop_flown(uint32_t m, uint32_t sent, bool ends)
{
    return !ends || m <= 1u || m == sent / 2u || m + 1u == sent;
}

typedef struct {
    uint32_t vehicles, index;
    uint32_t redraws;
    coavoid_encounter_info_t info;
    uint32_t first_conflict_step;
    coavoid_mc_outcome_t m[COAVOID_MC_METHODS];
    coavoid_mc_flown_t flown[COAVOID_MC_FLY_MODES]; /* with fly */
    uint64_t net_seed; /* with fly: its runs' network seed (coavoid sim --seed replays them) */
    coavoid_mc_sweep_t sweep; /* with stops_sweep */
    char defect[256];         /* empty unless a check failed */
} coavoid_mc_result_t;

/* A UAV count and the planners' limits for it. */
typedef struct {
    uint32_t n;
    uint32_t beta;
    uint32_t max_orders;
    uint64_t work; /* each planning call's work budget; 0: none */
} coavoid_mc_size_t;

struct coavoid_montecarlo {
    coavoid_montecarlo_config_t config; /* paths and callbacks still the caller's */
    coavoid_mc_size_t sizes[COAVOID_MONTECARLO_MAX_SIZES];
    uint32_t total; /* count per size, sizes in the config's order */
    coavoid_mc_result_t *results;
    double *x; /* room for count doubles: the reports sort a size's values in it */
};

/* Flies encounter (size, index) of seed, drawn as r says (r->redraws), in both modes as
 * c says, into r->flown. Returns 0, or -1 with err (a simulation error: of the tool, not
 * of the flight). Memory and cost: two simulations (sim.h), freed before return.
 * Defined only with the messaging library (COAVOID_HAVE_LCM). */
int coavoid_mc_fly(const coavoid_montecarlo_config_t *c, const coavoid_mc_size_t *size,
                   coavoid_mc_result_t *r, char *err, size_t err_size);

/* The CSV's columns (docs/cli.md): a plan run's rows are PLAN then MORE; a --fly run's
 * PLAN, NETWORK, MORE then FLOWN. MORE and FLOWN hold what the summary needs beyond the
 * first columns (montecarlo --merge rebuilds it from them); CSVs written before them end
 * after PLAN or NETWORK, which --figure-from still reads. */
#define COAVOID_MC_CSV_PLAN                                                       \
    "seed,vehicles,index,redraws,hills,tracks,first_conflict_step,method,status," \
    "deviation,deviation_units,effort,expanded,generated,orders_tried,time_us"
#define COAVOID_MC_CSV_NETWORK ",loss,delay,jitter,net_seed,stop_step,stop_messages"
#define COAVOID_MC_CSV_MORE ",optimal,bound_deviation,beta,max_orders,work,first,count"
#define COAVOID_MC_CSV_FLOWN \
    ",fallbacks,sent,delivered,dropped,coordinator_stops_sweep,net_seed_option"
/* The headers, without their newline. */
#define COAVOID_MC_CSV_HEADER_LINE COAVOID_MC_CSV_PLAN COAVOID_MC_CSV_MORE
#define COAVOID_MC_CSV_HEADER_FLY_LINE \
    COAVOID_MC_CSV_PLAN COAVOID_MC_CSV_NETWORK COAVOID_MC_CSV_MORE COAVOID_MC_CSV_FLOWN
#define COAVOID_MC_CSV_OLD_HEADER_LINE COAVOID_MC_CSV_PLAN
#define COAVOID_MC_CSV_OLD_HEADER_FLY_LINE COAVOID_MC_CSV_PLAN COAVOID_MC_CSV_NETWORK
/* Their columns: 16 in PLAN, 6 in NETWORK, 7 in MORE, 6 in FLOWN. */
enum {
    COAVOID_MC_CSV_PLAN_FIELDS = 16,
    COAVOID_MC_CSV_NETWORK_FIELDS = 6,
    COAVOID_MC_CSV_MORE_FIELDS = 7,
    COAVOID_MC_CSV_FLOWN_FIELDS = 6,
    COAVOID_MC_CSV_FIELDS = COAVOID_MC_CSV_PLAN_FIELDS + COAVOID_MC_CSV_MORE_FIELDS,
    COAVOID_MC_CSV_FLY_FIELDS = COAVOID_MC_CSV_PLAN_FIELDS + COAVOID_MC_CSV_NETWORK_FIELDS +
                                COAVOID_MC_CSV_MORE_FIELDS + COAVOID_MC_CSV_FLOWN_FIELDS,
};

/* The measured and computed values the CSV rounds (time_us to 0.1 us, deviations to
 * 1e-6 m^2), rounded so in the results too: the summary of a run is then the summary of
 * its CSV, to the last digit. */
double coavoid_mc_round(double value, double scale);

/* The defects an encounter's outcomes show against each other (montecarlo.h): into
 * r->defect, unless it already holds one. */
void coavoid_mc_cross_check(coavoid_mc_result_t *r);

/* Hands r's defect, if any, to c's defect callback as the line of a run. */
void coavoid_mc_report_defect(const coavoid_montecarlo_config_t *c, const coavoid_mc_result_t *r);

/* k successes of n (n >= 1): the rate and its 95 % Wilson interval. */
void coavoid_mc_wilson(uint32_t k, uint32_t n, double *rate, double *low, double *high);

/* A 128-bit cost as a double, for ratios: exact enough for them, and it never overflows. */
static inline double coavoid_mc_cost_real(coa_cost_t c)
{
    return (double)c.hi * 18446744073709551616.0 + (double)c.lo;
}

#endif /* COAVOID_EVALUATION_MONTECARLO_INTERNAL_H */
