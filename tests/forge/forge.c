/* SPDX-License-Identifier: MIT */
/*
 * forge.c: an attacker on the multicast group, for the tests that fly the real processes
 * (tests/cli/multiprocess.sh). It speaks the project's messages with valid ids, times and
 * sequence numbers, which is all an unauthenticated network asks of it:
 *
 *   map      every 200 ms an obstacle map with the world's id, the largest version and
 *            no obstacles: it would erase the terrain, and lock the real map out as older;
 *   collide  for every intent of UAV --target, a plan from the configured coordinator for
 *            that cycle (a plan_id near the top) that flies it to the altitude of UAV
 *            --other, which was not told to move.
 *
 * Its messages carry the nodes' time, taken from the intents it hears (a test's run is sped
 * up, so the wall clock would make them stale).
 *
 * usage: coavoid_test_forge --lcm-url URL --attack map|collide --seconds S
 *                           [--target ID] [--other ID] [--coordinator-id ID]
 * Prints how many messages it forged on stdout when it stops.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <lcm/lcm.h>

#include "coavoid_lcm.h"
#include "node.h"

typedef struct {
    lcm_t *lcm;
    const char *attack;
    int32_t target, other, coordinator;
    double other_z; /* the other UAV's altitude now, once heard */
    int have_other;
    int64_t forged;
    int64_t clock_utime; /* the nodes' clock (a run may be sped up): the latest intent's */
} forger_t;

static int64_t wall_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static void forge_map(forger_t *f)
{
    coavoid_obstacle_map_t m;
    memset(&m, 0, sizeof m);
    m.utime = f->clock_utime;
    m.map_id = (int32_t)COAVOID_NODE_WORLD_ID;
    m.version = INT64_MAX;
    m.tile_count = 1; /* a whole map in one tile */
    if (coavoid_obstacle_map_t_publish(f->lcm, COAVOID_CHANNEL_OBSTACLES, &m) == 0) {
        f->forged++;
    }
}

/* The offsets of the forged row from the target's current offset o0: towards the other
 * UAV's altitude (rounded to the target's climb steps), as steeply as it can. */
static int32_t forged_offset(const forger_t *f, const coavoid_intent_t *t, int32_t k)
{
    const int32_t o0 = t->offsets[0];
    const int32_t s = t->steep_factor;
    const double dh = t->climb_rate * t->step;
    const double steps = (f->other_z - t->position[2]) / dh;
    const int32_t goal = o0 + (int32_t)lround(steps);
    const int32_t reach = s * k;
    return goal > o0 ? (o0 + reach < goal ? o0 + reach : goal)
                     : (o0 - reach > goal ? o0 - reach : goal);
}

static void forge_plan(forger_t *f, const coavoid_intent_t *t)
{
    static coavoid_plan_t m;
    memset(&m, 0, sizeof m);
    m.utime = t->utime + 1;
    m.coordinator_id = f->coordinator;
    m.plan_id = INT64_MAX - 1 - f->forged;
    m.valid_from_utime = t->plan_utime;
    m.valid_until_utime = t->plan_utime + llround(t->step * 1e6);
    m.dt = t->step;
    m.horizon = t->sample_count - 1;
    m.mode = COAVOID_PLAN_T_MODE_CENTRALISED;
    m.status = COAVOID_PLAN_T_STATUS_SOLVED;
    m.vehicle_count = 1;
    m.planned_count = 1;
    m.uav_ids[0] = f->target;
    m.row_uav_id = f->target; /* a whole plan of one UAV in one message */
    for (int32_t k = 0; k <= m.horizon; k++) {
        int32_t o = forged_offset(f, t, k);
        m.offsets[k] = o > 32767 ? 32767 : (o < -32767 ? -32767 : o);
    }
    if (coavoid_plan_t_publish(f->lcm, COAVOID_CHANNEL_PLAN, &m) == 0) {
        f->forged++;
    }
}

static void on_intent(const lcm_recv_buf_t *rbuf, const char *channel, const coavoid_intent_t *msg,
                      void *user)
{
    forger_t *f = user;
    (void)rbuf;
    (void)channel;
    f->clock_utime = msg->utime > f->clock_utime ? msg->utime : f->clock_utime;
    if (msg->uav_id == f->other) {
        f->other_z = msg->position[2];
        f->have_other = 1;
    }
    if (msg->uav_id == f->target && strcmp(f->attack, "collide") == 0 && f->have_other) {
        forge_plan(f, msg);
    }
}

static int parse(int argc, char **argv, forger_t *f, const char **url, double *seconds)
{
    for (int i = 1; i + 1 < argc; i += 2) {
        const char *k = argv[i], *v = argv[i + 1];
        if (strcmp(k, "--lcm-url") == 0) {
            *url = v;
        } else if (strcmp(k, "--attack") == 0) {
            f->attack = v;
        } else if (strcmp(k, "--seconds") == 0) {
            *seconds = atof(v);
        } else if (strcmp(k, "--target") == 0) {
            f->target = atoi(v);
        } else if (strcmp(k, "--other") == 0) {
            f->other = atoi(v);
        } else if (strcmp(k, "--coordinator-id") == 0) {
            f->coordinator = atoi(v);
        } else {
            return -1;
        }
    }
    return (argc % 2 == 1 && f->attack != NULL && *seconds > 0) ? 0 : -1;
}

int main(int argc, char **argv)
{
    forger_t f = {NULL, NULL, 1, 2, (int32_t)COAVOID_NODE_COORDINATOR_ID, 0, 0, 0, 0};
    const char *url = NULL;
    double seconds = 0;
    if (parse(argc, argv, &f, &url, &seconds) != 0) {
        fprintf(stderr, "usage: coavoid_test_forge --lcm-url URL --attack map|collide "
                        "--seconds S [--target ID] [--other ID] [--coordinator-id ID]\n");
        return 2;
    }
    f.lcm = lcm_create(url);
    if (f.lcm == NULL) {
        fprintf(stderr, "forge: cannot open %s\n", url != NULL ? url : "(default)");
        return 2;
    }
    coavoid_intent_t_subscription_t *sub =
        coavoid_intent_t_subscribe(f.lcm, COAVOID_CHANNEL_INTENT, on_intent, &f);
    const int64_t end = wall_us() + (int64_t)(seconds * 1e6);
    int64_t next_map = 0;
    while (wall_us() < end) {
        if (strcmp(f.attack, "map") == 0 && f.clock_utime > 0 && wall_us() >= next_map) {
            forge_map(&f);
            next_map = wall_us() + 200000;
        }
        lcm_handle_timeout(f.lcm, 50);
    }
    printf("forged %lld\n", (long long)f.forged);
    coavoid_intent_t_unsubscribe(f.lcm, sub);
    lcm_destroy(f.lcm);
    return 0;
}
