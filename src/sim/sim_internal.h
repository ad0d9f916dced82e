/* SPDX-License-Identifier: MIT */
/* What sim.c and summary.c share inside coavoid::sim. */
#ifndef COAVOID_SIM_INTERNAL_H
#define COAVOID_SIM_INTERNAL_H

/* A step's "go on": every other value is the run's final return (a verdict or an
 * error), so that a step reads `if (rc == SIM_GO_ON) rc = next(...)`. */
#define SIM_GO_ON (-1)

#endif /* COAVOID_SIM_INTERNAL_H */
