/* SPDX-License-Identifier: MIT */
/*
 * replay.c: the vehicle protocol on the part, replaying a vehicle's records (coavoid sim
 * --record-vehicle, src/replay) read from the host through ARM semihosting: the same
 * vehicle built in a static block, every recorded call made again at its time with its
 * datagrams, what it sends and its state compared with the record, and each call counted
 * with check_io.h's clock (under qemu -icount shift=0: instructions). tests/firmware/qemu.sh
 * runs it on records the single-precision host build made. For each record, lines:
 *   replay FILE uav ID MODE block NEED of HAVE        (NEED > HAVE: not replayed)
 *   replay FILE cycles C polls P received R sent S: all as recorded | differs at record K: why
 *   instructions FILE cycle MAX TOTAL poll MAX TOTAL receive MAX TOTAL period MAX at cycle K
 * where a period is a cycle call and every call after it until the next cycle's, and the
 * instructions are the clock's ticks times the calibration's ratio (first line: calibrate
 * 2000001 TICKS, a loop of 2,000,001 instructions).
 */
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "check_io.h"
#include "replay.h"

#ifndef FW_REPLAY_BLOCK_BYTES
#define FW_REPLAY_BLOCK_BYTES 111104u
#endif
/* A record's largest piece on the part: a datagram, or a configuration of its capacities. */
#define FW_REPLAY_RECORD_BYTES 2048u

static uint8_t block[FW_REPLAY_BLOCK_BYTES] __attribute__((aligned(8)));
static coavoid_replay_t replay;
static uint8_t record[FW_REPLAY_RECORD_BYTES];
static uint64_t calibration; /* ticks of 2,000,001 instructions */

typedef struct {
    uint64_t max[3];
    uint64_t total[3];
    uint64_t period;
    uint64_t worst_period;
    uint64_t worst_cycle;
} ticks_t;

static size_t file_read(void *user, void *out, size_t n)
{
    return fwc_file_read(*(const int32_t *)user, out, n);
}

/* The magic, the configuration and the vehicle built: true when it can be replayed. */
static bool open_record(const char *name, int32_t *file)
{
    fwc_put("replay ");
    fwc_put(name);
    if (*file < 0 ||
        coavoid_replay_open(&replay, file_read, file, record, sizeof record) != COA_OK) {
        fwc_put(" unreadable");
        fwc_end_line();
        return false;
    }
    const size_t need = coavoid_vehicle_node_size(&replay.config);
    fwc_put(" uav ");
    fwc_put_u64(replay.config.vehicle.id);
    fwc_put(replay.config.mode == COAVOID_NODE_DECOUPLED ? " decoupled" : " centralised");
    fwc_put(" block ");
    fwc_put_u64(need);
    fwc_put(" of ");
    fwc_put_u64(sizeof block);
    fwc_end_line();
    return need > 0u && need <= sizeof block &&
           coavoid_replay_start(&replay, block, sizeof block) == COA_OK;
}

static void count(ticks_t *t, coavoid_replay_kind_t kind, uint64_t ticks)
{
    const size_t k = kind == COAVOID_REPLAY_CYCLE ? 0u : kind == COAVOID_REPLAY_POLL ? 1u : 2u;
    if (kind == COAVOID_REPLAY_CYCLE) {
        t->period = 0;
    }
    t->max[k] = ticks > t->max[k] ? ticks : t->max[k];
    t->total[k] += ticks;
    t->period += ticks;
    if (t->period > t->worst_period) {
        t->worst_period = t->period;
        t->worst_cycle = replay.cycles > 0u ? replay.cycles - 1u : 0u;
    }
}

static uint64_t instructions(uint64_t ticks)
{
    return calibration > 0u ? ticks * 2000001u / calibration : 0u;
}

static void put_ticks(const char *name, const ticks_t *t)
{
    static const char *const kinds[3] = {" cycle ", " poll ", " receive "};
    fwc_put("instructions ");
    fwc_put(name);
    for (size_t k = 0; k < 3u; k++) {
        fwc_put(kinds[k]);
        fwc_put_u64(instructions(t->max[k]));
        fwc_put(" ");
        fwc_put_u64(instructions(t->total[k]));
    }
    fwc_put(" period ");
    fwc_put_u64(instructions(t->worst_period));
    fwc_put(" at cycle ");
    fwc_put_u64(t->worst_cycle);
    fwc_end_line();
}

/* Every record after the configuration; true when the vehicle did all as recorded. */
static bool replay_rest(const char *name, int32_t *file)
{
    ticks_t ticks;
    coavoid_replay_record_t rec;
    int got;
    int rc = COA_OK;
    memset(&ticks, 0, sizeof ticks);
    while (rc == COA_OK &&
           (got = coavoid_replay_next(file_read, file, record, sizeof record, &rec)) == 1) {
        const bool call = rec.kind == COAVOID_REPLAY_CYCLE || rec.kind == COAVOID_REPLAY_POLL ||
                          rec.kind == COAVOID_REPLAY_RECEIVE;
        const uint64_t start = fwc_ticks_now();
        rc = coavoid_replay_apply(&replay, &rec);
        if (call) {
            count(&ticks, rec.kind, fwc_ticks_now() - start);
        }
    }
    rc = rc == COA_OK ? (got == 0 ? coavoid_replay_finish(&replay) : got) : rc;
    fwc_put("replay ");
    fwc_put(name);
    fwc_put(" cycles ");
    fwc_put_u64(replay.cycles);
    fwc_put(" polls ");
    fwc_put_u64(replay.polls);
    fwc_put(" received ");
    fwc_put_u64(replay.receives);
    fwc_put(" sent ");
    fwc_put_u64(replay.sent);
    if (rc == COA_OK) {
        fwc_put(": all as recorded");
    } else {
        fwc_put(": differs at record ");
        fwc_put_u64(replay.records);
        fwc_put(": ");
        fwc_put(replay.differs ? replay.difference : "a record unreadable or out of place");
    }
    fwc_end_line();
    put_ticks(name, &ticks);
    return rc == COA_OK;
}

int main(void)
{
    /* The paper's UAV 1 in each mode; UAV 9 of nine converging, with 8 neighbours. */
    static const char *const records[] = {"decoupled.rec", "centralised.rec", "nine.rec"};
    bool ok = true;
    fwc_ticks_start();
    const uint64_t start = fwc_ticks_now();
    fwc_spin(1000000u);
    calibration = fwc_ticks_now() - start;
    fwc_put("calibrate 2000001 ");
    fwc_put_u64(calibration);
    fwc_end_line();
    for (size_t i = 0; i < sizeof records / sizeof records[0]; i++) {
        int32_t file = fwc_file_open(records[i]);
        bool replayed = open_record(records[i], &file);
        if (replayed) {
            ok = replay_rest(records[i], &file) && ok;
            coavoid_vehicle_node_fini(replay.node);
        } else if (i != 1u) {
            ok = false; /* a decoupled vehicle must fit the part */
        }
        if (file >= 0) {
            fwc_file_close(file);
        }
    }
    fwc_put(ok ? "done" : "done with errors");
    fwc_end_line();
    fwc_exit(ok);
    return ok ? 0 : 1;
}
