/* SPDX-License-Identifier: MIT */
/*
 * evaluation.h: coavoid::evaluation, the measurements of the core on seeded random
 * problems, in one include. The library holds the engines; the `coavoid` command (apps/)
 * only parses options into their configs, calls them and turns their returns into exit
 * statuses, so that another program (a script's driver, a test) gets the same problems
 * and figures from the same seed.
 *
 *   - prng.h: the seeded generator every random problem comes from (splitmix64);
 *   - encounter.h: random encounters of 2-10 UAVs as scenario JSON, in two designs;
 *   - montecarlo.h: `coavoid montecarlo`, centralised against decoupled planning over
 *     thousands of encounters (docs/evaluation.md);
 *   - bench_predict.h, bench_plan.h: `coavoid bench predict` and `coavoid bench plan`,
 *     the timings of the predictor and the planner (docs/benchmarks.md).
 *
 * Errors. A harness prints nothing of its own on stderr: like coavoid::scenario's runs
 * (run.h) it returns COAVOID_RUN_DONE, or COAVOID_RUN_ERR_INPUT (the config cannot be run:
 * a size past a limit, memory the machine does not have, an output that cannot be
 * created, an input file that does not load) or COAVOID_RUN_ERR_INTERNAL (a defect, of the
 * harness or of the planner it checks, or an output that failed while it was written)
 * with one line in the caller's coavoid_run_error_t. The line names the command-line
 * option that sets the config field at fault ("--beta: ...", "--csv: cannot write ..."),
 * since that is what a user changes; the program prefixes it with its own name.
 */
#ifndef COAVOID_EVALUATION_EVALUATION_H
#define COAVOID_EVALUATION_EVALUATION_H

#include "bench_plan.h"
#include "bench_predict.h"
#include "encounter.h"
#include "montecarlo.h"
#include "prng.h"
#include "run.h"

#endif /* COAVOID_EVALUATION_EVALUATION_H */
