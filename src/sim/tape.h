/* SPDX-License-Identifier: MIT */
/*
 * tape.h: a recording of one node's messages in a one-process run (sim.c), call by call,
 * inside coavoid::sim. A run with the coordinator stopped is, up to the cut, the run
 * without the stop (the same nodes, messages and network draws), so its coordinator need
 * not run there: its messages can be played from a recording of the unstopped run at the
 * same calls. That spares a sweep of stop points (montecarlo --coordinator-stops-sweep)
 * repeating the coordinator's searches, most of a centralised run's time, at every point.
 *
 * Each call records the network's digest (net.h) before it, so that a replay checks at
 * every call that it is still the recorded run, and the coordinator's plans_run after it.
 * Memory: heap, the messages' bytes (a few hundred kB for 25 cycles of 5 UAVs).
 */
#ifndef COAVOID_SIM_TAPE_H
#define COAVOID_SIM_TAPE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <lcm/lcm.h>

typedef struct coavoid_sim_tape coavoid_sim_tape_t;

/* An empty tape, or NULL (out of memory). */
coavoid_sim_tape_t *coavoid_sim_tape_create(void);
/* NULL is fine. */
void coavoid_sim_tape_destroy(coavoid_sim_tape_t *t);
/* Empties it, to record another run. */
void coavoid_sim_tape_clear(coavoid_sim_tape_t *t);

/* Recording: a call begins with the network's digest (then its messages go to it, as the
 * network lets them out: coavoid_sim_tape_message, the shape of a net.h tap), and ends with
 * the node's plans_run. False when out of memory (the tape is then unusable). */
bool coavoid_sim_tape_begin(coavoid_sim_tape_t *t, uint64_t digest, int64_t at, bool poll);
void coavoid_sim_tape_message(void *tape, const char *channel, const void *data, uint32_t size);
void coavoid_sim_tape_end(coavoid_sim_tape_t *t, uint32_t plans_run);
/* False when a recording ran out of memory. */
bool coavoid_sim_tape_ok(const coavoid_sim_tape_t *t);

/* Call `call`'s time and kind (a poll of the node, else its cycle): false past the last.
 * A replay makes each call when the recorded run made it: a poll when the clock reaches
 * its time, a cycle at the cycle's call. O(1). */
bool coavoid_sim_tape_next(const coavoid_sim_tape_t *t, size_t call, int64_t *at, bool *poll);

/* Replaying call `call` (0, 1, ... in order), when the network's digest is `digest`:
 * publishes its messages on tx and sets *plans_run. COA_OK; COA_ERR_ARGUMENT when the
 * tape has no such call or the digest is not the recorded one (the runs differ), or
 * LCM refused a message. */
int coavoid_sim_tape_play(const coavoid_sim_tape_t *t, size_t call, uint64_t digest, lcm_t *tx,
                          uint32_t *plans_run);

#endif /* COAVOID_SIM_TAPE_H */
