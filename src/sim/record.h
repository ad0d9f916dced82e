/* SPDX-License-Identifier: MIT */
/*
 * record.h: the record of one vehicle of a one-process run (`coavoid sim
 * --record-vehicle`), inside coavoid::sim: the file src/replay reads (replay.h). sim.c
 * opens it before the vehicle is made, hands every call of the vehicle to it, and closes
 * it at the end; the vehicle's datagrams come through its transport's tap.
 */
#ifndef COAVOID_SIM_RECORD_H
#define COAVOID_SIM_RECORD_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "node.h"
#include "replay.h"

typedef struct {
    FILE *file;
    const int64_t *clock; /* the vehicle's */
    bool failed;          /* a write failed, or a datagram did not fit a record */
} coavoid_sim_record_t;

/* Opens path and writes the magic and the vehicle's configuration. False (and nothing
 * open) when the file cannot be written or the configuration does not fit a record. */
bool coavoid_sim_record_open(coavoid_sim_record_t *rec, const char *path,
                             const coavoid_vehicle_node_config_t *config);
/* The tap of the recorded vehicle (coavoid_vehicle_node_tap). */
void coavoid_sim_record_tap(void *rec, bool sent, const char *channel, const void *data,
                            size_t size);
/* A cycle (true) or poll of the vehicle at `now`: records the call, makes it, records its
 * state after it; returns the call's return value. */
int coavoid_sim_record_call(coavoid_sim_record_t *rec, coavoid_vehicle_node_t *node, bool cycle,
                            int64_t now);
/* Closes the file: false when anything failed since open (the record is then not whole). */
bool coavoid_sim_record_close(coavoid_sim_record_t *rec);

#endif /* COAVOID_SIM_RECORD_H */
