/* SPDX-License-Identifier: MIT */
/*
 * evaluation.h: coavoid::evaluation, the measurements of the core on random problems, and
 * what its harnesses share. The library holds the engines; the `coavoid` command (apps/)
 * only parses options into their configs, calls them and turns their statuses into exit
 * statuses, so that another program (a script's driver, a test) gets the same problems and
 * figures from the same seed.
 *
 *   - prng.h: the seeded generator every random problem comes from (splitmix64);
 *   - encounter.h: random encounters of 2-6 UAVs as scenario JSON, in two designs;
 *   - montecarlo.h: `coavoid montecarlo`, centralised against decoupled planning over
 *     thousands of encounters (docs/evaluation.md);
 *   - bench_predict.h, bench_plan.h: `coavoid bench predict` and `coavoid bench plan`,
 *     the timings of the predictor and the planner (docs/benchmarks.md).
 *
 * Errors. A harness does not print its errors: it writes one line into the caller's
 * err[err_size] (COAVOID_EVALUATION_ERROR_MAX holds any) and returns one of the statuses
 * below, and the caller reports it in its own way. A line names the command-line option
 * that sets the config field at fault ("--beta: ...", "--csv: cannot write ..."), as
 * `coavoid` prints it, since that is what a user changes.
 */
#ifndef COAVOID_EVALUATION_EVALUATION_H
#define COAVOID_EVALUATION_EVALUATION_H

enum {
    COAVOID_EVALUATION_OK = 0,
    /* The config cannot be run: a size past a limit, memory the machine does not have, an
     * output that cannot be created, an input file that does not load. The caller's to
     * change (coavoid exits 2). */
    COAVOID_EVALUATION_INVALID = -1,
    /* A defect, of the harness or of the planner it checks, or an output that failed
     * while it was written (coavoid exits 3). */
    COAVOID_EVALUATION_INTERNAL = -2
};

/* Room for any error line of the library, with its terminating NUL. */
#define COAVOID_EVALUATION_ERROR_MAX 1024u

#endif /* COAVOID_EVALUATION_EVALUATION_H */
