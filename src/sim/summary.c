/* SPDX-License-Identifier: MIT */
/*
 * summary.c: what a real-time run flew, rebuilt from an lcm-logger log and judged exactly
 * as coavoid_sim_run judges its own runs (sim.h, coavoid_sim_summarise).
 *
 * What the log says, and how it becomes a flight record:
 *   - Every UAV publishes an intent at each cycle's start: its reference and offsets for
 *     samples from plan_utime on, sample 0 being where it is. The flown sample k of a UAV
 *     is taken from the latest intent (largest plan_utime, later in the log on a tie) with
 *     plan_utime <= cycle k's start that has a sample at exactly that time. Usually that
 *     is the cycle's own intent; when it is missing (a dropped datagram, a late process)
 *     an earlier plan that reaches k stands in for it. Where no intent covers k, the
 *     scenario's reference is used with the offset held (the initial offset before the
 *     first intent, the last covered one after): that sample is marked not known, counted,
 *     and drawn as such.
 *   - The epoch (cycle 0's start) is, unless --epoch gives it, the earliest plan_utime of
 *     the scenario's UAVs on the run's cycle grid: the grid (plan_utime modulo dt) that
 *     most of their accepted intents are on. Every intent of a run is on one grid; an
 *     intent off it (a bit flip in plan_utime that still validates) is counted off the
 *     grid instead of moving the epoch off it. The step is the scenario's dt.
 *   - K, the last sample judged, is the last cycle for which the log holds every UAV's own
 *     intent ("complete"), and at most the scenario's 2N (the default length of a sim).
 *   - Replans: every node's heartbeat (status_t) carries plans_run, its planning calls
 *     since it started; the replans of a run are the sum over its nodes (the scenario's
 *     UAVs and the run's coordinator) of the largest plans_run among their accepted
 *     heartbeats up to cycle K, which is what `coavoid sim` counts.
 *
 * Valid messages that cannot be this run's are ignored, counted, and the first one's
 * reason reported, so that one such message (a forgery, a bit flip that still validates)
 * neither refuses the whole log nor inflates a count:
 *   - an intent of a scenario UAV whose step, performance or volume disagrees with the
 *     scenario. The log is not a run of the
 *     scenario only when some scenario UAV has no accepted intent at all: that is an
 *     error naming the first disagreement when its intents were all ignored;
 *   - an intent whose reference is off the scenario's route sampled from the run's start
 *     (found in pass 2, once the start is known: its samples are not used);
 *   - a heartbeat of a UAV not in the scenario, or of a coordinator other than the run's
 *     (the coordinator id that sent the most heartbeats);
 *   - a heartbeat whose plans_run goes back from the node's last accepted heartbeat, or
 *     grows from it by more than the node can plan in the cycles between them
 *     (PLANS_PER_CYCLE, cycles_between). A node restarted mid-run counts from 0 again:
 *     its heartbeats are ignored until its new count passes the old one, so its replans
 *     are the larger of the two.
 *
 * With a trust list (--trust) every intent, heartbeat and plan must also be signed by a key
 * that may send it and be newer than the last of its type from that key, in log order (as
 * the nodes judge them, without their clock window: the logger's clock is not the run's):
 * the others (forgeries, copies, replays) are ignored and counted as unauthenticated.
 *
 * The log is untrusted. LCM 1.3.1's reader skips anything until it finds an event's
 * magic number, reports truncation as a normal end, prints its own complaints on stderr
 * (bad lengths; no magic right after an event) and, for a data length near 2^31, hands a
 * failed allocation to fread. So each event's header is read and checked here first
 * (magic exactly where the previous event ended and right after this one, lengths within
 * bounds and within the file) and only then is the event read with
 * lcm_eventlog_read_next_event. Messages are decoded with the generated decoders and
 * validated by src/lcm before anything is used; refused ones are counted and reported.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#include <cjson/cJSON.h>
#include <lcm/eventlog.h>

#include "coavoid/coavoid.h"
#include "coavoid_lcm.h"
#include "flight.h"
#include "judge.h"
#include "node.h"
#include "scenario.h"
#include "sim.h"
#include "sim_internal.h"

/* An event's header in the file: magic, event number, time stamp, channel and data
 * lengths, all big-endian. */
#define LOG_MAGIC 0xEDA1DA01u
#define LOG_HEADER_BYTES 28
/* The reader's own bound on a channel name (1.3.1 refuses >= 1000). */
#define LOG_MAX_CHANNEL 999
/* Larger events are taken as corruption: the biggest message of ours is about 17 kB, and
 * the reader allocates what the header claims before it reads. */
#define LOG_MAX_DATA (64 * 1024 * 1024)
/* The first ignored message's reason, as text. */
#define IGNORED_REASON_MAX 200
/* uav_id and node_id are 1..65535 (src/lcm). */
#define MAX_NODE_ID 65535u

/*
 * PLANS_PER_CYCLE: the most planning calls (plans_run increments) a node makes in one of its
 * cycles, from src/protocol and src/node:
 *   - a UAV (src/protocol/vehicle_decide.c): it plans in coavoid_vehicle_decide() only,
 *     through plan_self(), which is followed at once by finish() (its intent and the
 *     cycle's heartbeat); after that the cycle
 *     is over for it (poll() does nothing unless it waits, and a second call of the same
 *     cycle returns at once). plan_self() searches once (search_self) and, when that
 *     fails with lower priorities outside its cluster in the way, once more around the
 *     higher priorities only: 2 a cycle;
 *   - the coordinator (coordinator.c, coavoid_coordinator_cycle): cluster_plan() counts
 *     1, or 2 when the joint search ran out of beta and the cluster is planned again
 *     decoupled; plan_clusters() plans each cluster that has a member once, and
 *     escalate() at most twice more (every clustered UAV, then every UAV): 2 x clusters
 *     + 4 a cycle. Clusters are disjoint and each has a UAV that published an intent of
 *     the cycle, at most COAVOID_NODE_MAX_PEERS in its view: so 2 x U + 4, U the UAVs
 *     whose valid intents the log holds (the scenario's and others), at most that.
 * Both publish exactly one heartbeat (sequence + 1) per cycle they run, after its
 * planning, so a node's plans_run grows by at most PLANS_PER_CYCLE per heartbeat.
 */
#define VEHICLE_PLANS_PER_CYCLE 2
#define COORDINATOR_PLANS_PER_CLUSTER 2
#define COORDINATOR_ESCALATION_PLANS 4

/* ---- reading the log ---- */

typedef struct {
    const char *path;
    coavoid_run_error_t *err;
    lcm_eventlog_t *log;
    int64_t size;   /* bytes to read: the file's size when opened */
    int64_t offset; /* where the next event starts */
    int64_t events; /* events read so far */
} log_reader_t;

static int log_open(log_reader_t *r, coavoid_run_error_t *err, const char *path, int64_t limit)
{
    struct stat st;
    memset(r, 0, sizeof *r);
    r->err = err;
    r->path = path;
    if (stat(path, &st) != 0) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT, "%s: cannot open: %s", path,
                                strerror(errno));
    }
    if (!S_ISREG(st.st_mode)) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: not a regular file (an lcm-logger log is one)", path);
    }
    errno = 0;
    r->log = lcm_eventlog_create(path, "r");
    if (r->log == NULL) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT, "%s: cannot open: %s", path,
                                errno != 0 ? strerror(errno) : "lcm_eventlog_create failed");
    }
    /* The size of what was opened (the path may have been replaced since stat). */
    if (fstat(fileno(r->log->f), &st) != 0) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT, "%s: cannot read: %s", path,
                                strerror(errno));
    }
    r->size = (int64_t)st.st_size;
    if (limit >= 0 && limit < r->size) {
        r->size = limit;
    }
    if (r->size == 0) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT, "%s: empty file, not an LCM log",
                                path);
    }
    return SIM_GO_ON;
}

static void log_close(log_reader_t *r)
{
    if (r->log != NULL) {
        lcm_eventlog_destroy(r->log);
        r->log = NULL;
    }
}

static uint32_t be32(const unsigned char *b)
{
    return (uint32_t)b[0] << 24 | (uint32_t)b[1] << 16 | (uint32_t)b[2] << 8 | (uint32_t)b[3];
}

/* The next event: 1 with *event (free it with lcm_eventlog_free_event), 0 at the end of
 * the log, or the exit status after the message. */
/* The event header at the reader's offset (`left` bytes remain): its length in *length, or
 * an error naming what is wrong there. */
static int log_header(log_reader_t *r, int64_t left, int32_t *channel_length, int32_t *data_length,
                      int64_t *length)
{
    unsigned char header[LOG_HEADER_BYTES];
    if (fseeko(r->log->f, (off_t)r->offset, SEEK_SET) != 0) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: cannot seek to byte %" PRId64 ": %s", r->path, r->offset,
                                strerror(errno));
    }
    size_t want = left < LOG_HEADER_BYTES ? (size_t)left : (size_t)LOG_HEADER_BYTES;
    size_t got = fread(header, 1, want, r->log->f);
    if (got != want) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT, "%s: read error at byte %" PRId64,
                                r->path, r->offset);
    }
    /* Whether the bytes there are (the start of) an event header. */
    bool magic = true;
    for (size_t j = 0; j < 4u && j < got; j++) {
        magic = magic && header[j] == (unsigned char)(LOG_MAGIC >> (24u - 8u * j));
    }
    if (!magic && r->offset == 0) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: not an LCM log (it does not start with an event header)",
                                r->path);
    }
    if (!magic) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: corrupt: no event header at byte %" PRId64 " (after %" PRId64
                                " events)",
                                r->path, r->offset, r->events);
    }
    if (got < (size_t)LOG_HEADER_BYTES) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: truncated: event %" PRId64 " at byte %" PRId64
                                " is cut off in its header (was the logger stopped mid-write?)",
                                r->path, r->events, r->offset);
    }
    *channel_length = (int32_t)be32(header + 20);
    *data_length = (int32_t)be32(header + 24);
    if (*channel_length < 1 || *channel_length > LOG_MAX_CHANNEL || *data_length < 0 ||
        *data_length > LOG_MAX_DATA) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: corrupt: event %" PRId64 " at byte %" PRId64
                                " claims a %ld-byte channel name and %ld bytes of data",
                                r->path, r->events, r->offset, (long)*channel_length,
                                (long)*data_length);
    }
    *length = LOG_HEADER_BYTES + (int64_t)*channel_length + (int64_t)*data_length;
    if (*length > left) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: truncated: event %" PRId64 " at byte %" PRId64
                                " needs %" PRId64 " bytes, the file has %" PRId64
                                " left (was the logger stopped "
                                "mid-write?)",
                                r->path, r->events, r->offset, *length, left);
    }
    return SIM_GO_ON;
}

/* Debian's 1.3.1 reader also looks at the 4 bytes after the event and, when they are not the
 * next header's magic, prints a complaint and drops the event: judge them here first, so
 * the message is ours and names the place. */
static int log_check_next(log_reader_t *r, int64_t left, int64_t length)
{
    if (length + 4 > left) {
        return SIM_GO_ON;
    }
    unsigned char next[4];
    if (fseeko(r->log->f, (off_t)(r->offset + length), SEEK_SET) != 0 ||
        fread(next, 1, 4u, r->log->f) != 4u) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT, "%s: read error at byte %" PRId64,
                                r->path, r->offset + length);
    }
    if (be32(next) != LOG_MAGIC) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: corrupt: no event header at byte %" PRId64 " (after %" PRId64
                                " events)",
                                r->path, r->offset + length, r->events + 1);
    }
    return SIM_GO_ON;
}

static int log_next(log_reader_t *r, lcm_eventlog_event_t **event)
{
    int64_t left = r->size - r->offset;
    int32_t channel_length = 0;
    int32_t data_length = 0;
    int64_t length = 0;
    *event = NULL;
    if (left <= 0) {
        return 0;
    }
    int status = log_header(r, left, &channel_length, &data_length, &length);
    if (status == SIM_GO_ON) {
        status = log_check_next(r, left, length);
    }
    if (status != SIM_GO_ON) {
        return status;
    }
    if (fseeko(r->log->f, (off_t)r->offset, SEEK_SET) != 0) {
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: cannot seek to byte %" PRId64 ": %s", r->path, r->offset,
                                strerror(errno));
    }
    lcm_eventlog_event_t *e = lcm_eventlog_read_next_event(r->log);
    if (e == NULL || e->channellen != channel_length || e->datalen != data_length) {
        if (e != NULL) {
            lcm_eventlog_free_event(e);
        }
        return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INPUT,
                                "%s: cannot read event %" PRId64 " at byte %" PRId64, r->path,
                                r->events, r->offset);
    }
    r->offset += length;
    r->events++;
    *event = e;
    return 1;
}

/* ---- what the log says ---- */

/* items, of *capacity items of item_size bytes, holding count, with room for one more:
 * doubled (from 256) when full. NULL out of memory, items then unchanged. */
static void *room_for_one(void *items, size_t count, size_t *capacity, size_t item_size)
{
    if (count < *capacity) {
        return items;
    }
    size_t grown = *capacity > 0u ? *capacity * 2u : 256u;
    if (grown > SIZE_MAX / item_size) {
        return NULL;
    }
    void *moved = realloc(items, grown * item_size);
    if (moved != NULL) {
        *capacity = grown;
    }
    return moved;
}

/* A valid heartbeat, kept in log order. */
typedef struct {
    int64_t utime;
    int64_t sequence;
    int32_t plans_run;
    uint16_t node;
    int8_t kind;
    int8_t mode; /* COAVOID_STATUS_T_MODE_*: a UAV's says whether it follows a coordinator */
} heartbeat_t;

typedef struct {
    heartbeat_t *items;
    size_t count;
    size_t capacity;
} heartbeat_list_t;

static bool heartbeat_add(heartbeat_list_t *list, heartbeat_t item)
{
    heartbeat_t *items = room_for_one(list->items, list->count, &list->capacity, sizeof item);
    if (items == NULL) {
        return false;
    }
    list->items = items;
    list->items[list->count++] = item;
    return true;
}

/* The first field of an intent that disagrees with its UAV in the scenario (field NULL:
 * none). */
typedef struct {
    const char *field;
    double theirs;
    double ours;
} disagreement_t;

/* One accepted intent's place on the time line. */
typedef struct {
    size_t vehicle;
    int64_t plan_utime;
} intent_seen_t;

typedef struct {
    intent_seen_t *items;
    size_t count;
    size_t capacity;
} intent_list_t;

static bool intent_add(intent_list_t *list, intent_seen_t item)
{
    intent_seen_t *items = room_for_one(list->items, list->count, &list->capacity, sizeof item);
    if (items == NULL) {
        return false;
    }
    list->items = items;
    list->items[list->count++] = item;
    return true;
}

typedef struct {
    const coavoid_sim_log_config_t *o;
    coavoid_run_error_t *err;
    FILE *out;
    const coavoid_scenario_t *s;
    int64_t dt_us;

    /* Decoding space (the plan type is 16.6 kB). */
    coavoid_intent_t intent;
    coavoid_status_t status;
    coavoid_plan_t plan;

    /* Counts over the whole log. */
    int64_t events;
    int64_t other_events;
    int64_t intents;           /* on the intent channel */
    int64_t intents_refused;   /* did not decode or failed validation */
    const char *intent_reason; /* the first refusal's reason */
    int64_t intents_foreign;   /* valid, from a UAV that is not in the scenario */
    int64_t statuses;
    int64_t statuses_refused;
    int64_t plans;
    int64_t plans_refused;
    const char *other_reason; /* the first refusal of a status or plan */

    /* Valid intents of the scenario's UAVs that disagree with it: ignored. */
    int64_t intents_ignored;
    char intent_ignored[IGNORED_REASON_MAX]; /* the first one's reason ("": none) */
    int64_t ignored_of[COA_MAX_VEHICLES];
    disagreement_t disagreement_of[COA_MAX_VEHICLES]; /* each UAV's first */
    /* The UAVs not in the scenario that sent valid intents (a bit per id) and how many. */
    uint8_t other_uav[(MAX_NODE_ID + 1u) / 8u];
    size_t other_uavs;
    /* Valid heartbeats ignored (judge_heartbeats), by reason. */
    int64_t heartbeats_other_node; /* of a node that is not one of the run's */
    int64_t heartbeats_backwards;  /* plans_run below the node's last accepted one */
    int64_t heartbeats_too_fast;   /* plans_run beyond what the node can plan */
    char heartbeat_ignored[IGNORED_REASON_MAX];

    /* Signatures (o->trust given): the trust list with the freshness marks of the pass
     * under way (each pass starts from o->trust's), and what was not authentic. */
    coavoid_auth_trust_t trust;
    int64_t intents_unauthenticated;
    int64_t plans_unauthenticated;
    int64_t statuses_unauthenticated;
    const char *unauthenticated_reason; /* the first one's */

    intent_list_t seen;          /* accepted intents of the scenario's UAVs */
    heartbeat_list_t heartbeats; /* valid heartbeats, in log order */
    int64_t intents_of[COA_MAX_VEHICLES];
} log_summary_t;

static const coavoid_lcm_context_t no_clock = {0, 0, 0, 0};

/* The first field of intent m that disagrees with UAV v of the scenario: its step (the
 * scenario's dt), performance and volume. An intent of another scenario (or another dt)
 * cannot be judged against this one. */
static disagreement_t disagreement(const log_summary_t *ls, const coavoid_intent_t *m,
                                   const coa_vehicle_t *v)
{
    disagreement_t d = {NULL, 0.0, 0.0};
    if (llround(m->step * 1e6) != ls->dt_us) {
        d = (disagreement_t){"step (the scenario's dt)", m->step, (double)ls->s->dt};
    } else if ((coa_real_t)m->climb_rate != v->climb_rate) {
        d = (disagreement_t){"climb_rate", m->climb_rate, (double)v->climb_rate};
    } else if ((coa_real_t)m->cruise_speed != v->cruise_speed) {
        d = (disagreement_t){"cruise_speed", m->cruise_speed, (double)v->cruise_speed};
    } else if ((coa_real_t)m->radius != v->volume.radius) {
        d = (disagreement_t){"radius", m->radius, (double)v->volume.radius};
    } else if ((coa_real_t)m->half_height != v->volume.half_height) {
        d = (disagreement_t){"half_height", m->half_height, (double)v->volume.half_height};
    } else if ((uint32_t)m->steep_factor != v->steep_factor) {
        d = (disagreement_t){"steep_factor", m->steep_factor, v->steep_factor};
    }
    return d;
}

/* Counts an ignored intent of scenario UAV `index` (id uav), disagreeing as d. */
static void ignore_intent(log_summary_t *ls, size_t index, long uav, const disagreement_t *d)
{
    ls->intents_ignored++;
    if (ls->ignored_of[index]++ == 0) {
        ls->disagreement_of[index] = *d;
    }
    if (ls->intent_ignored[0] == '\0') {
        snprintf(ls->intent_ignored, sizeof ls->intent_ignored,
                 "intent: UAV %ld's %s %.17g disagrees with the scenario (%.17g)", uav, d->field,
                 d->theirs, d->ours);
    }
}

/* Counts a valid intent of a UAV not in the scenario, and its id once. */
static void note_other_uav(log_summary_t *ls, int32_t uav)
{
    /* uav_id is 1..65535 once the intent is valid. */
    uint8_t *byte = &ls->other_uav[(uint32_t)uav / 8u];
    const uint8_t bit = (uint8_t)(1u << ((uint32_t)uav % 8u));
    ls->intents_foreign++;
    if ((*byte & bit) == 0u) {
        *byte |= bit;
        ls->other_uavs++;
    }
}

/* Where every pass over the log starts: no message accepted from any key yet. */
static void auth_restart(log_summary_t *ls)
{
    if (ls->o->trust != NULL) {
        ls->trust = *ls->o->trust;
    }
}

/* Whether a valid message (its raw bytes in e, its decoded auth) is authentic: the fleet's
 * tag, signed by a key of the trust list that may send it as (role, id), and newer than the last of its
 * stream from that key. Always true without a trust list. Counts into *counter (when
 * `count`) what is not. */
static bool authentic(log_summary_t *ls, const lcm_eventlog_event_t *e, size_t stream,
                      coavoid_auth_role_t role, int32_t id, const coavoid_auth_t *auth,
                      int64_t *counter, bool count)
{
    if (ls->o->trust == NULL) {
        return true;
    }
    size_t key = 0;
    int rc = coavoid_auth_tag_check(&ls->trust, e->data, (size_t)e->datalen);
    if (rc == COA_OK) {
        rc = coavoid_auth_verify(&ls->trust, e->data, (size_t)e->datalen, &key);
    }
    if (rc == COA_OK) {
        /* Order only (now = its own time, no window): the logger's clock is not the
         * nodes' (a run may be sped up). */
        rc = coavoid_auth_accept(&ls->trust, key, stream, role, id, auth->timestamp_us,
                                 auth->sequence, auth->timestamp_us, 0, 0);
    }
    if (rc != COA_OK && count) {
        (*counter)++;
        if (ls->unauthenticated_reason == NULL) {
            ls->unauthenticated_reason = coavoid_lcm_error_name(rc);
        }
    }
    return rc == COA_OK;
}

/* Decodes and validates an intent. Returns the scenario's index of its UAV (>= 0), -1
 * refused, -2 a valid intent of another UAV, -3 a valid intent of a scenario UAV that
 * disagrees with the scenario, or -4 not authentic (ignored); each counted when `count`. */
static long accept_intent(log_summary_t *ls, const lcm_eventlog_event_t *e, bool count)
{
    const char *reason = "intent: does not decode (wrong type or truncated)";
    coavoid_intent_t *m = &ls->intent;
    int used = coavoid_intent_t_decode(e->data, 0, e->datalen, m);
    int rc = used == e->datalen ? coavoid_lcm_intent_check(m, &no_clock, &reason)
                                : COAVOID_LCM_ERR_DECODE;
    if (used >= 0) {
        coavoid_intent_t_decode_cleanup(m);
    }
    if (count) {
        ls->intents++;
    }
    if (rc != COA_OK) {
        if (count) {
            ls->intents_refused++;
            if (ls->intent_reason == NULL) {
                ls->intent_reason = reason;
            }
        }
        return -1;
    }
    if (!authentic(ls, e, COAVOID_AUTH_STREAM_INTENT, COAVOID_AUTH_VEHICLE, m->uav_id, &m->auth,
                   &ls->intents_unauthenticated, count)) {
        return -4;
    }
    long index = coavoid_scenario_vehicle_index(ls->s, (long)m->uav_id);
    if (index < 0) {
        if (count) {
            note_other_uav(ls, m->uav_id);
        }
        return -2;
    }
    disagreement_t d = disagreement(ls, m, &ls->s->vehicles[index]);
    if (d.field != NULL) {
        if (count) {
            ignore_intent(ls, (size_t)index, (long)m->uav_id, &d);
        }
        return -3;
    }
    return index;
}

static void note_other(log_summary_t *ls, const char *reason)
{
    if (ls->other_reason == NULL) {
        ls->other_reason = reason;
    }
}

/* An event on the heartbeat channel: counted, and kept when valid. False out of memory. */
static bool read_status(log_summary_t *ls, const lcm_eventlog_event_t *e)
{
    const char *reason = "status: does not decode (wrong type or truncated)";
    coavoid_status_t *m = &ls->status;
    int used = coavoid_status_t_decode(e->data, 0, e->datalen, m);
    int rc = used == e->datalen ? coavoid_lcm_status_check(m, &no_clock, &reason)
                                : COAVOID_LCM_ERR_DECODE;
    if (used >= 0) {
        coavoid_status_t_decode_cleanup(m);
    }
    ls->statuses++;
    if (rc != COA_OK) {
        ls->statuses_refused++;
        note_other(ls, reason);
        return true;
    }
    if (!authentic(ls, e, COAVOID_AUTH_STREAM_STATUS, coavoid_lcm_status_role(m->node_kind),
                   m->node_id, &m->auth, &ls->statuses_unauthenticated, true)) {
        return true;
    }
    /* node_id is 1..65535 once the heartbeat is valid. */
    heartbeat_t item = {m->utime,     m->sequence, m->plans_run, (uint16_t)m->node_id,
                        m->node_kind, m->mode};
    return heartbeat_add(&ls->heartbeats, item);
}

/* An event on the plan channel: counted (refused, unauthenticated or accepted). Always
 * true: a plan keeps nothing (replans come from the heartbeats). */
static bool read_plan(log_summary_t *ls, const lcm_eventlog_event_t *e)
{
    const char *reason = "plan: does not decode (wrong type or truncated)";
    int used = coavoid_plan_t_decode(e->data, 0, e->datalen, &ls->plan);
    int rc = used == e->datalen ? coavoid_lcm_plan_check(&ls->plan, &no_clock, &reason)
                                : COAVOID_LCM_ERR_DECODE;
    if (used >= 0) {
        coavoid_plan_t_decode_cleanup(&ls->plan);
    }
    ls->plans++;
    if (rc != COA_OK) {
        ls->plans_refused++;
        note_other(ls, reason);
        return true;
    }
    (void)authentic(ls, e, COAVOID_AUTH_STREAM_PLAN, COAVOID_AUTH_COORDINATOR,
                    ls->plan.coordinator_id, &ls->plan.auth, &ls->plans_unauthenticated, true);
    return true;
}

/* Pass 1: every event of the log. Returns SIM_GO_ON or the exit status. */
static int read_log(log_summary_t *ls, log_reader_t *r)
{
    auth_restart(ls);
    for (;;) {
        lcm_eventlog_event_t *e = NULL;
        int rc = log_next(r, &e);
        if (rc == 0) {
            break;
        }
        if (rc != 1) {
            return rc;
        }
        ls->events++;
        bool ok = true;
        if (strcmp(e->channel, COAVOID_CHANNEL_INTENT) == 0) {
            long index = accept_intent(ls, e, true);
            if (index >= 0) {
                size_t i = (size_t)index;
                ls->intents_of[i]++;
                intent_seen_t seen = {i, ls->intent.plan_utime};
                ok = intent_add(&ls->seen, seen);
            }
        } else if (strcmp(e->channel, COAVOID_CHANNEL_STATUS) == 0) {
            ok = read_status(ls, e);
        } else if (strcmp(e->channel, COAVOID_CHANNEL_PLAN) == 0) {
            ok = read_plan(ls, e);
        } else {
            ls->other_events++;
        }
        lcm_eventlog_free_event(e);
        if (!ok) {
            return coavoid_run_fail(r->err, COAVOID_RUN_ERR_INTERNAL, "out of memory reading %s",
                                    r->path);
        }
    }
    return SIM_GO_ON;
}

/* ---- the heartbeats: replans ---- */

/* The run's coordinator: the coordinator id that sent the most valid heartbeats (ties: the
 * smallest), 0 when none did. -1 out of memory. */
static long run_coordinator(const log_summary_t *ls)
{
    uint32_t *count = calloc(MAX_NODE_ID + 1u, sizeof *count);
    if (count == NULL) {
        return -1;
    }
    long best = 0;
    for (size_t h = 0; h < ls->heartbeats.count; h++) {
        const heartbeat_t *hb = &ls->heartbeats.items[h];
        if (hb->kind != COAVOID_STATUS_T_NODE_COORDINATOR) {
            continue;
        }
        count[hb->node]++;
        if (best == 0 || count[hb->node] > count[best] ||
            (count[hb->node] == count[best] && hb->node < best)) {
            best = hb->node;
        }
    }
    free(count);
    return best;
}

/* Where a node of the run stands: its last accepted heartbeat (none before its first),
 * and the largest plans_run of its accepted heartbeats stamped before the end of the
 * judged cycles. */
typedef struct {
    bool heard;
    heartbeat_t last;
    int32_t most;
} node_count_t;

/* A heartbeat's node in the run: what it is called, and the planning calls it can make
 * in a cycle. */
typedef struct {
    const char *name; /* "UAV" or "coordinator" */
    int64_t per_cycle;
} node_kind_t;

/* Clamps a count of cycles to +-2^40: enough for any log, and no product overflows. */
static int64_t clamp_cycles(int64_t n)
{
    const int64_t most = INT64_C(1) << 40;
    return n > most ? most : (n < -most ? -most : n);
}

/* The cycles node c can have run from its last accepted heartbeat to h, whose planning
 * h's plans_run can include: as many as their sequence numbers say (one heartbeat per cycle
 * the node runs), but no more than their times allow (the cycle starts between them, plus
 * one: a heartbeat can be stamped just after its cycle's end), and by their times alone
 * when the sequence did not move forward (a restart, a corrupt sequence number); at least
 * one, so that a heartbeat with a corrupt time blocks none after it. Before its first
 * heartbeat: sequence + 1, the cycles up to h's. */
static int64_t cycles_between(const log_summary_t *ls, const node_count_t *c, const heartbeat_t *h)
{
    if (!c->heard) {
        return clamp_cycles(h->sequence) + 1;
    }
    /* Times and sequence numbers are positive: the differences do not overflow. */
    int64_t d = h->utime - c->last.utime;
    int64_t by_time = d >= 0 ? clamp_cycles(d / ls->dt_us) + (d % ls->dt_us != 0 ? 1 : 0) + 1
                             : 1 - clamp_cycles(-d / ls->dt_us);
    int64_t by_sequence = clamp_cycles(h->sequence - c->last.sequence);
    int64_t n = by_sequence >= 1 && by_sequence < by_time ? by_sequence : by_time;
    return n > 1 ? n : 1;
}

static void note_heartbeat(log_summary_t *ls, int64_t *counter, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Counts an ignored heartbeat in *counter, with the reason when it is the first. */
static void note_heartbeat(log_summary_t *ls, int64_t *counter, const char *format, ...)
{
    (*counter)++;
    if (ls->heartbeat_ignored[0] == '\0') {
        va_list args;
        va_start(args, format);
        vsnprintf(ls->heartbeat_ignored, sizeof ls->heartbeat_ignored, format, args);
        va_end(args);
    }
}

/* Judges heartbeat h of node c (kind k): accepted, or ignored when its plans_run goes back
 * from c's last accepted one or grows from it by more than k.per_cycle a cycle. */
static void count_heartbeat(log_summary_t *ls, node_count_t *c, node_kind_t k, const heartbeat_t *h,
                            int64_t to)
{
    const int32_t from = c->heard ? c->last.plans_run : 0;
    const int64_t cycles = cycles_between(ls, c, h);
    if (h->plans_run < from) {
        note_heartbeat(ls, &ls->heartbeats_backwards,
                       "heartbeat: %s %u's plans_run goes back from %ld to %ld", k.name,
                       (unsigned)h->node, (long)from, (long)h->plans_run);
        return;
    }
    if ((int64_t)h->plans_run - from > cycles * k.per_cycle) {
        note_heartbeat(ls, &ls->heartbeats_too_fast,
                       "heartbeat: %s %u's plans_run goes from %ld to %ld in %lld cycles; it "
                       "plans at most %lld times a cycle",
                       k.name, (unsigned)h->node, (long)from, (long)h->plans_run, (long long)cycles,
                       (long long)k.per_cycle);
        return;
    }
    c->last = *h;
    c->heard = true;
    if (h->utime < to && h->plans_run > c->most) {
        c->most = h->plans_run;
    }
}

/* Replans up to `to` in *replans: per node of the run, the largest plans_run of its
 * accepted heartbeats stamped before `to`, summed over the nodes. The nodes of the run are
 * the scenario's UAVs and the run's coordinator; every heartbeat is judged in log order
 * (count_heartbeat). Returns SIM_GO_ON or the exit status. */
static int judge_heartbeats(log_summary_t *ls, int64_t to, uint32_t *replans)
{
    const size_t n = ls->s->vehicle_count;
    long coordinator = run_coordinator(ls);
    if (coordinator < 0) {
        return coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INTERNAL, "out of memory");
    }
    size_t uavs = n + ls->other_uavs;
    uavs = uavs < COAVOID_NODE_MAX_PEERS ? uavs : COAVOID_NODE_MAX_PEERS;
    const node_kind_t vehicle = {"UAV", VEHICLE_PLANS_PER_CYCLE};
    const node_kind_t coord = {"coordinator", COORDINATOR_PLANS_PER_CLUSTER * (int64_t)uavs +
                                                  COORDINATOR_ESCALATION_PLANS};
    node_count_t counts[COA_MAX_VEHICLES + 1u];
    memset(counts, 0, sizeof counts);
    for (size_t q = 0; q < ls->heartbeats.count; q++) {
        const heartbeat_t *h = &ls->heartbeats.items[q];
        if (h->kind == COAVOID_STATUS_T_NODE_COORDINATOR && h->node == coordinator) {
            count_heartbeat(ls, &counts[n], coord, h, to);
        } else if (h->kind == COAVOID_STATUS_T_NODE_COORDINATOR) {
            note_heartbeat(ls, &ls->heartbeats_other_node,
                           "heartbeat: coordinator %u is not the run's (%ld, which sent the most "
                           "heartbeats)",
                           (unsigned)h->node, coordinator);
        } else {
            long i = coavoid_scenario_vehicle_index(ls->s, (long)h->node);
            if (i >= 0) {
                count_heartbeat(ls, &counts[i], vehicle, h, to);
            } else {
                note_heartbeat(ls, &ls->heartbeats_other_node,
                               "heartbeat: UAV %u is not in the scenario", (unsigned)h->node);
            }
        }
    }
    uint64_t total = 0;
    for (size_t i = 0; i <= n; i++) {
        total += (uint64_t)counts[i].most;
    }
    *replans = total > UINT32_MAX ? UINT32_MAX : (uint32_t)total;
    return SIM_GO_ON;
}

/* A run said to be decoupled whose UAVs followed a coordinator was not: a UAV of the
 * scenario reports MODE_CENTRALISED only while it flies a coordinator's plan, and a
 * decoupled vehicle never does, whatever it hears. Only heartbeats of the run's cycles
 * [from, to) count, so that an earlier run's log played into this one (an attack the
 * fleet survives) is not taken for this run's. The converse cannot be told: a centralised
 * fleet whose coordinator never spoke logs what a decoupled one does. */
static int check_mode(log_summary_t *ls, int64_t from, int64_t to)
{
    if (strcmp(ls->o->mode, "decoupled") != 0) {
        return SIM_GO_ON;
    }
    for (size_t q = 0; q < ls->heartbeats.count; q++) {
        const heartbeat_t *h = &ls->heartbeats.items[q];
        if (h->kind == COAVOID_STATUS_T_NODE_VEHICLE &&
            h->mode == COAVOID_STATUS_T_MODE_CENTRALISED && h->utime >= from && h->utime < to &&
            coavoid_scenario_vehicle_index(ls->s, (long)h->node) >= 0) {
            return coavoid_run_fail(
                ls->err, COAVOID_RUN_ERR_INPUT,
                "%s: UAV %u followed a coordinator at %.3f s (its heartbeat): the run was "
                "centralised, not --mode decoupled",
                ls->o->log_path, (unsigned)h->node, (double)(h->utime - from) / 1e6);
        }
    }
    return SIM_GO_ON;
}

/* ---- the flight ---- */

typedef struct {
    uint32_t steps;        /* K */
    int64_t *best;         /* n rows of K + 1: plan_utime of the sample's source */
    bool *own;             /* n rows of K + 1: from the cycle's own intent */
    bool *known;           /* n rows of K + 1 */
    coa_vec3_t *reference; /* n rows */
    coa_vec3_t *route;     /* n rows: the scenario's reference, sampled from the epoch */
    /* The routes from the run's own start (`origin`, the earliest plan_utime on its grid),
     * where the intents' references are: cycle c is row entry c + shift (truth_steps + 1
     * entries a row; no check when the epoch is off the origin's grid). */
    coa_vec3_t *truth;
    int64_t origin;
    int64_t shift;
    uint32_t truth_steps;
    bool truth_known;
    int32_t *offsets; /* n rows */
    int64_t own_samples;
    int64_t earlier_samples;
    int64_t missing_samples;
    int64_t off_grid; /* accepted intents whose plan_utime is not a cycle start */
} rebuilt_t;

static void rebuilt_free(rebuilt_t *b)
{
    free(b->best);
    free(b->own);
    free(b->known);
    free(b->reference);
    free(b->route);
    free(b->truth);
    free(b->offsets);
}

/* The cycle whose start is utime, or -1 when utime is not a cycle start at or after the
 * epoch. */
static int64_t cycle_at(int64_t utime, int64_t epoch, int64_t dt_us)
{
    if (utime < epoch || (utime - epoch) % dt_us != 0) {
        return -1;
    }
    return (utime - epoch) / dt_us;
}

/* K: the last cycle, at most cap, in which every UAV's own intent was logged; 0 when
 * none after cycle 0 is. Returns -1 out of memory. */
static int64_t last_complete_cycle(const log_summary_t *ls, int64_t epoch, uint32_t cap,
                                   int64_t *off_grid)
{
    const size_t n = ls->s->vehicle_count;
    const size_t row = (size_t)cap + 1u;
    bool *own = calloc(n * row, sizeof *own);
    if (own == NULL) {
        return -1;
    }
    *off_grid = 0;
    for (size_t q = 0; q < ls->seen.count; q++) {
        int64_t c = cycle_at(ls->seen.items[q].plan_utime, epoch, ls->dt_us);
        if (c < 0) {
            /* Before the epoch is fine (--epoch later than the run's start); off the grid
             * is worth reporting. */
            if (ls->seen.items[q].plan_utime >= epoch ||
                (epoch - ls->seen.items[q].plan_utime) % ls->dt_us != 0) {
                (*off_grid)++;
            }
            continue;
        }
        if (c <= (int64_t)cap) {
            own[ls->seen.items[q].vehicle * row + (size_t)c] = true;
        }
    }
    int64_t k = cap;
    for (; k > 0; k--) {
        bool all = true;
        for (size_t i = 0; i < n && all; i++) {
            all = own[i * row + (size_t)k];
        }
        if (all) {
            break;
        }
    }
    free(own);
    return k;
}

/* Whether an intent's reference point r is the route's point p, within what the two
 * precisions' arithmetic can make of one position (1 mm, and 1e-5 of its size). */
static bool on_route(const double *r, coa_vec3_t p)
{
    const double at[3] = {(double)p.x, (double)p.y, (double)p.z};
    for (size_t i = 0; i < 3u; i++) {
        if (!(fabs(r[i] - at[i]) <= 1e-3 + 1e-5 * fabs(at[i]))) {
            return false;
        }
    }
    return true;
}

/* Whether the accepted intent m of scenario UAV `index` flies the scenario's route: every
 * reference sample it has on cycles 0..K is the route's point there. A well-formed intent
 * from its UAV's own key that lies about where the UAV is would otherwise be believed. The
 * first that does not is ignored as one that disagrees with the scenario. */
static bool reference_agrees(log_summary_t *ls, const rebuilt_t *b, long index,
                             const coavoid_intent_t *m, int64_t epoch)
{
    for (int32_t j = 0; b->truth_known && j < m->sample_count; j++) {
        int64_t c = cycle_at(m->plan_utime + (int64_t)j * ls->dt_us, epoch, ls->dt_us);
        if (c < 0 || c > (int64_t)b->steps) {
            continue;
        }
        const int64_t t = c + b->shift;
        if (t < 0 || t > (int64_t)b->truth_steps) {
            continue;
        }
        const coa_vec3_t p = b->truth[(size_t)index * ((size_t)b->truth_steps + 1u) + (size_t)t];
        if (on_route(m->reference[j], p)) {
            continue;
        }
        ls->intents_ignored++;
        if (ls->intent_ignored[0] == '\0') {
            snprintf(ls->intent_ignored, sizeof ls->intent_ignored,
                     "intent: UAV %ld's reference at cycle %lld (%.3f, %.3f, %.3f) is off the "
                     "scenario's route (%.3f, %.3f, %.3f)",
                     (long)m->uav_id, (long long)c, m->reference[j][0], m->reference[j][1],
                     m->reference[j][2], (double)p.x, (double)p.y, (double)p.z);
        }
        return false;
    }
    return true;
}

/* Pass 2: the samples of every accepted intent onto the cycles 0..K. */
static int fill_samples(log_summary_t *ls, log_reader_t *r, rebuilt_t *b, int64_t epoch)
{
    const size_t row = (size_t)b->steps + 1u;
    auth_restart(ls);
    for (;;) {
        lcm_eventlog_event_t *e = NULL;
        int rc = log_next(r, &e);
        if (rc == 0) {
            break;
        }
        if (rc != 1) {
            return rc;
        }
        if (strcmp(e->channel, COAVOID_CHANNEL_INTENT) == 0) {
            long index = accept_intent(ls, e, false); /* ignored ones (-3) too are skipped */
            const coavoid_intent_t *m = &ls->intent;
            if (index >= 0 && !reference_agrees(ls, b, index, m, epoch)) {
                index = -3;
            }
            for (int32_t j = 0; index >= 0 && j < m->sample_count; j++) {
                /* The check bounds plan_utime to within an hour of a positive utime and j
                 * below 128, so this cannot overflow. */
                int64_t c = cycle_at(m->plan_utime + (int64_t)j * ls->dt_us, epoch, ls->dt_us);
                if (c < 0 || c > (int64_t)b->steps) {
                    continue;
                }
                size_t at = (size_t)index * row + (size_t)c;
                if (b->known[at] && m->plan_utime < b->best[at]) {
                    continue; /* a later plan already covers this sample */
                }
                b->known[at] = true;
                b->best[at] = m->plan_utime;
                b->own[at] = j == 0;
                b->reference[at].x = (coa_real_t)m->reference[j][0];
                b->reference[at].y = (coa_real_t)m->reference[j][1];
                b->reference[at].z = (coa_real_t)m->reference[j][2];
                b->offsets[at] = m->offsets[j];
            }
        }
        lcm_eventlog_free_event(e);
    }
    return SIM_GO_ON;
}

/* Every UAV's route sampled on cycles 0..K from the epoch (b->route), and from the run's
 * start over as many more cycles as the epoch is after it (b->truth). */
static int sample_routes(const coavoid_scenario_t *s, rebuilt_t *b, int64_t epoch, int64_t dt_us)
{
    const size_t row = (size_t)b->steps + 1u;
    b->truth_known = b->origin > 0 && (epoch - b->origin) % dt_us == 0;
    b->shift = b->truth_known ? (epoch - b->origin) / dt_us : 0;
    b->truth_known = b->truth_known && b->shift <= (int64_t)COA_MAX_HORIZON - (int64_t)b->steps;
    b->truth_steps = b->steps + (uint32_t)(b->truth_known && b->shift > 0 ? b->shift : 0);
    const size_t truth_row = (size_t)b->truth_steps + 1u;
    b->truth = calloc(s->vehicle_count * truth_row, sizeof *b->truth);
    if (b->truth == NULL) {
        return COA_ERR_WORKSPACE;
    }
    for (size_t i = 0; i < s->vehicle_count; i++) {
        int rc = coa_reference_sample(&s->vehicles[i], s->dt, b->steps, &b->route[i * row]);
        if (rc == COA_OK) {
            rc = coa_reference_sample(&s->vehicles[i], s->dt, b->truth_steps,
                                      &b->truth[i * truth_row]);
        }
        if (rc != COA_OK) {
            return rc;
        }
    }
    return COA_OK;
}

/* Samples no intent covered: the scenario's reference, the offset held. */
static void fill_gaps(const coavoid_scenario_t *s, rebuilt_t *b)
{
    const size_t row = (size_t)b->steps + 1u;
    for (size_t i = 0; i < s->vehicle_count; i++) {
        int32_t held = s->vehicles[i].initial_offset;
        for (size_t k = 0; k < row; k++) {
            size_t at = i * row + k;
            if (b->known[at]) {
                held = b->offsets[at];
                if (b->own[at]) {
                    b->own_samples++;
                } else {
                    b->earlier_samples++;
                }
                continue;
            }
            b->missing_samples++;
            b->reference[at] = b->route[at];
            b->offsets[at] = held;
        }
    }
}

/* ---- output ---- */

static int64_t heartbeats_ignored(const log_summary_t *ls)
{
    return ls->heartbeats_other_node + ls->heartbeats_backwards + ls->heartbeats_too_fast;
}

/* What was ignored, after the log's other lines and only when something was. */
static void print_ignored_text(const log_summary_t *ls)
{
    if (ls->intents_ignored == 0 && heartbeats_ignored(ls) == 0) {
        return;
    }
    fprintf(ls->out,
            "ignored: %" PRId64
            " intents (of scenario UAVs, disagreeing with the scenario); %" PRId64
            " heartbeats (%" PRId64 " of nodes not in the run, %" PRId64
            " with plans_run going back, %" PRId64
            " with plans_run growing faster than the node can plan)\n",
            ls->intents_ignored, heartbeats_ignored(ls), ls->heartbeats_other_node,
            ls->heartbeats_backwards, ls->heartbeats_too_fast);
    if (ls->intent_ignored[0] != '\0') {
        fprintf(ls->out, "first ignored intent: %s\n", ls->intent_ignored);
    }
    if (ls->heartbeat_ignored[0] != '\0') {
        fprintf(ls->out, "first ignored heartbeat: %s\n", ls->heartbeat_ignored);
    }
}

static void print_log_text(const log_summary_t *ls, const rebuilt_t *b, int64_t epoch)
{
    fprintf(ls->out,
            "log: %s: %" PRId64 " events; %" PRId64 " intents (%" PRId64 " refused, %" PRId64
            " from UAVs not in the scenario, %" PRId64 " off the cycle grid); %" PRId64
            " plans (%" PRId64 " refused); %" PRId64 " heartbeats (%" PRId64 " refused); %" PRId64
            " on other channels\n",
            ls->o->log_path, ls->events, ls->intents, ls->intents_refused, ls->intents_foreign,
            b->off_grid, ls->plans, ls->plans_refused, ls->statuses, ls->statuses_refused,
            ls->other_events);
    if (ls->intent_reason != NULL) {
        fprintf(ls->out, "first refused intent: %s\n", ls->intent_reason);
    }
    if (ls->other_reason != NULL) {
        fprintf(ls->out, "first refused plan or heartbeat: %s\n", ls->other_reason);
    }
    fprintf(ls->out, "epoch: %" PRId64 " us (%s); cycles 0..%lu judged\n", epoch,
            ls->o->has_epoch ? "--epoch" : "earliest plan_utime", (unsigned long)b->steps);
    fprintf(ls->out,
            "samples: %" PRId64 " from their cycle's own intent, %" PRId64
            " from an earlier plan, %" PRId64 " not covered by any intent (scenario reference, "
            "offset held)\n",
            b->own_samples, b->earlier_samples, b->missing_samples);
    print_ignored_text(ls);
    if (ls->o->trust != NULL) {
        fprintf(ls->out,
                "signatures: checked; unauthenticated (ignored): %" PRId64 " intents, %" PRId64
                " plans, %" PRId64 " heartbeats%s%s\n",
                ls->intents_unauthenticated, ls->plans_unauthenticated,
                ls->statuses_unauthenticated, ls->unauthenticated_reason != NULL ? "; first: " : "",
                ls->unauthenticated_reason != NULL ? ls->unauthenticated_reason : "");
    }
}

/* An integer printed as one: cJSON would print a microsecond time as 1.7e+15. */
static bool add_count(cJSON *obj, const char *key, int64_t value)
{
    char text[24];
    snprintf(text, sizeof text, "%" PRId64, value);
    return cJSON_AddRawToObject(obj, key, text) != NULL;
}

/* The counts of what was ignored, and the first reasons, into the log object. */
static bool add_ignored(cJSON *log, const log_summary_t *ls)
{
    return add_count(log, "intents_ignored", ls->intents_ignored) &&
           add_count(log, "heartbeats_ignored", heartbeats_ignored(ls)) &&
           add_count(log, "heartbeats_ignored_other_nodes", ls->heartbeats_other_node) &&
           add_count(log, "heartbeats_ignored_backwards", ls->heartbeats_backwards) &&
           add_count(log, "heartbeats_ignored_too_fast", ls->heartbeats_too_fast) &&
           (ls->intent_ignored[0] == '\0' ||
            cJSON_AddStringToObject(log, "first_ignored_intent", ls->intent_ignored) != NULL) &&
           (ls->heartbeat_ignored[0] == '\0' ||
            cJSON_AddStringToObject(log, "first_ignored_heartbeat", ls->heartbeat_ignored) !=
                NULL) &&
           (ls->o->trust == NULL ||
            (add_count(log, "intents_unauthenticated", ls->intents_unauthenticated) &&
             add_count(log, "plans_unauthenticated", ls->plans_unauthenticated) &&
             add_count(log, "heartbeats_unauthenticated", ls->statuses_unauthenticated) &&
             (ls->unauthenticated_reason == NULL ||
              cJSON_AddStringToObject(log, "first_unauthenticated", ls->unauthenticated_reason) !=
                  NULL)));
}

/* The flight's JSON with a "log" object added. The log object holds only integers and
 * strings, which cJSON prints exactly. */
static int print_json(const log_summary_t *ls, const rebuilt_t *b, int64_t epoch,
                      const coavoid_flight_t *flight, const coavoid_flight_eval_t *eval)
{
    cJSON *log = cJSON_CreateObject();
    bool ok = log != NULL && cJSON_AddStringToObject(log, "file", ls->o->log_path) != NULL &&
              add_count(log, "events", ls->events) && add_count(log, "intents", ls->intents) &&
              add_count(log, "intents_refused", ls->intents_refused) &&
              add_count(log, "intents_other_uavs", ls->intents_foreign) &&
              add_count(log, "intents_off_grid", b->off_grid) &&
              add_count(log, "plans", ls->plans) &&
              add_count(log, "plans_refused", ls->plans_refused) &&
              add_count(log, "heartbeats", ls->statuses) &&
              add_count(log, "heartbeats_refused", ls->statuses_refused) &&
              add_count(log, "epoch_utime", epoch) &&
              add_count(log, "samples_own_intent", b->own_samples) &&
              add_count(log, "samples_earlier_plan", b->earlier_samples) &&
              add_count(log, "samples_missing", b->missing_samples) &&
              (ls->intent_reason == NULL ||
               cJSON_AddStringToObject(log, "first_refused_intent", ls->intent_reason) != NULL) &&
              add_ignored(log, ls);
    char *log_text = ok ? cJSON_PrintUnformatted(log) : NULL;
    cJSON_Delete(log);
    if (log_text == NULL) {
        return coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INTERNAL,
                                "out of memory printing the result");
    }
    const coavoid_flight_extra_t extra = {"log", log_text};
    errno = 0;
    int rc = coavoid_flight_json_extra(flight, eval, &extra, 1u, ls->out);
    free(log_text);
    if (rc == COA_ERR_ARGUMENT) {
        return coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INTERNAL,
                                "internal error: cannot print the result (%s)",
                                coa_status_name(rc));
    }
    if (rc != COA_OK) {
        return coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INTERNAL, "cannot write the result: %s",
                                errno != 0 ? strerror(errno) : "write error");
    }
    return SIM_GO_ON;
}

static int write_svg(coavoid_run_error_t *err, const char *path, const coavoid_flight_t *flight,
                     const coavoid_flight_eval_t *eval)
{
    FILE *out = fopen(path, "w");
    if (out == NULL) {
        return coavoid_run_fail(err, COAVOID_RUN_ERR_INPUT, "--svg %s: cannot write: %s", path,
                                strerror(errno));
    }
    int rc = coavoid_flight_svg(flight, eval, out);
    if (fclose(out) != 0 && rc == COA_OK) {
        rc = COA_ERR_WORKSPACE;
    }
    if (rc != COA_OK) {
        return coavoid_run_fail(err, COAVOID_RUN_ERR_INTERNAL,
                                "--svg %s: cannot write the figure (%s)", path,
                                coa_status_name(rc));
    }
    return SIM_GO_ON;
}

/* The evaluation refused the record: name the step no action makes, if that is why. */
static int refused_record(coavoid_run_error_t *err, const coavoid_sim_log_config_t *o,
                          const coavoid_flight_t *f, const rebuilt_t *b)
{
    const size_t row = (size_t)f->steps + 1u;
    for (size_t i = 0; i < f->vehicle_count; i++) {
        const int32_t *offsets = f->vehicles[i].offsets;
        for (uint32_t k = 0; k < f->steps; k++) {
            if (coa_action_between(offsets[k], offsets[k + 1u],
                                   f->vehicles[i].vehicle.steep_factor) < 0) {
                bool gap = !b->own[i * row + k] || !b->own[i * row + k + 1u];
                return coavoid_run_fail(
                    err, COAVOID_RUN_ERR_INPUT,
                    "%s: UAV %u's offset goes from %ld at cycle %lu to %ld at cycle "
                    "%lu, which no action does%s",
                    o->log_path, (unsigned)f->vehicles[i].vehicle.id, (long)offsets[k],
                    (unsigned long)k, (long)offsets[k + 1u], (unsigned long)k + 1ul,
                    gap ? " (a cycle's own intent is missing from the log there)" : "");
            }
        }
    }
    return coavoid_run_fail(err, COAVOID_RUN_ERR_INTERNAL,
                            "internal error: the flight record was refused");
}

/* Everything after the options and the scenario. Returns the exit status. */
/* The scenario's dt as whole microseconds, and its UAV count, as a log can carry them. */
static int summary_check(log_summary_t *ls)
{
    const coavoid_sim_log_config_t *o = ls->o;
    const coavoid_scenario_t *s = ls->s;
    double dt_us = (double)s->dt * 1e6;
    if (!(dt_us >= 1.0) || dt_us > 3.6e9) {
        return coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INPUT,
                                "%s: dt: %g s cannot be a cycle of whole microseconds "
                                "(1 us to 1 h)",
                                o->scenario_path, (double)s->dt);
    }
    ls->dt_us = llround(dt_us);
    if (s->vehicle_count > COA_MAX_VEHICLES) {
        return coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INPUT, "%s: %zu vehicles, at most %u",
                                o->scenario_path, s->vehicle_count, COA_MAX_VEHICLES);
    }
    return SIM_GO_ON;
}

/* Every scenario UAV has an accepted intent, else the log is not a run of the scenario:
 * SIM_GO_ON, or the exit status after naming the first UAV without one (and why, when
 * its intents were all ignored). */
static int check_every_uav(log_summary_t *ls)
{
    const coavoid_sim_log_config_t *o = ls->o;
    const coavoid_scenario_t *s = ls->s;
    for (size_t i = 0; i < s->vehicle_count; i++) {
        if (ls->intents_of[i] > 0) {
            continue;
        }
        const disagreement_t *d = &ls->disagreement_of[i];
        if (ls->ignored_of[i] == 0) {
            return coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INPUT,
                                    "%s: UAV %u of %s never published an accepted intent "
                                    "(%" PRId64 " intents in the log, %" PRId64 " refused)",
                                    o->log_path, (unsigned)s->vehicles[i].id, o->scenario_path,
                                    ls->intents, ls->intents_refused);
        }
        return coavoid_run_fail(
            ls->err, COAVOID_RUN_ERR_INPUT,
            "%s: UAV %u of %s never published an accepted intent: its intents have %s %.17g, "
            "%s says %.17g: not a run of this scenario (%" PRId64 " intents in the log, %" PRId64
            " refused, %" PRId64 " ignored)",
            o->log_path, (unsigned)s->vehicles[i].id, o->scenario_path, d->field, d->theirs,
            o->scenario_path, d->ours, ls->intents, ls->intents_refused, ls->intents_ignored);
    }
    return SIM_GO_ON;
}

/* An accepted intent's plan_utime and its residue modulo dt: which cycle grid it is on. */
typedef struct {
    int64_t residue;
    int64_t plan_utime;
} grid_point_t;

static int grid_point_compare(const void *a, const void *b)
{
    const grid_point_t *p = a;
    const grid_point_t *q = b;
    if (p->residue != q->residue) {
        return p->residue < q->residue ? -1 : 1;
    }
    if (p->plan_utime != q->plan_utime) {
        return p->plan_utime < q->plan_utime ? -1 : 1;
    }
    return 0;
}

/* The epoch the log shows: the earliest plan_utime of the scenario's UAVs' accepted intents
 * on the run's cycle grid, the residue of plan_utime modulo dt that most of them have (ties:
 * the grid that starts earliest). -1 out of memory. */
static int64_t run_epoch(const log_summary_t *ls)
{
    const size_t count = ls->seen.count; /* > 0: every UAV has one */
    grid_point_t *grid = malloc(count * sizeof *grid);
    if (grid == NULL) {
        return -1;
    }
    for (size_t q = 0; q < count; q++) {
        int64_t p = ls->seen.items[q].plan_utime; /* positive */
        grid[q] = (grid_point_t){p % ls->dt_us, p};
    }
    qsort(grid, count, sizeof *grid, grid_point_compare);
    size_t best_count = 0;
    int64_t best = INT64_MAX;
    for (size_t q = 0; q < count;) {
        size_t end = q;
        while (end < count && grid[end].residue == grid[q].residue) {
            end++;
        }
        /* grid[q] is the earliest on its grid. */
        if (end - q > best_count || (end - q == best_count && grid[q].plan_utime < best)) {
            best_count = end - q;
            best = grid[q].plan_utime;
        }
        q = end;
    }
    free(grid);
    return best;
}

/* Pass 1: counts, who was seen, the epoch (the earliest plan time on the run's grid unless
 * --epoch), the log's size (pass 2 reads the same bytes) and the last cycle every UAV's
 * intent covers. */
static int summary_pass1(log_summary_t *ls, rebuilt_t *b, int64_t *epoch, int64_t *size)
{
    const coavoid_sim_log_config_t *o = ls->o;
    const coavoid_scenario_t *s = ls->s;
    log_reader_t r;
    memset(&r, 0, sizeof r);
    int status = log_open(&r, ls->err, o->log_path, -1);
    if (status == SIM_GO_ON) {
        status = read_log(ls, &r);
    }
    *size = r.size;
    log_close(&r);
    if (status == SIM_GO_ON) {
        status = check_every_uav(ls);
    }
    if (status != SIM_GO_ON) {
        return status;
    }
    b->origin = run_epoch(ls);
    *epoch = o->has_epoch ? o->epoch : b->origin;
    if (*epoch < 0) {
        return coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INTERNAL, "out of memory");
    }
    uint32_t cap = s->horizon > COA_MAX_HORIZON / 2u ? COA_MAX_HORIZON : 2u * s->horizon;
    int64_t k = last_complete_cycle(ls, *epoch, cap, &b->off_grid);
    if (k < 0) {
        return coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INTERNAL, "out of memory");
    }
    if (k == 0) {
        return coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INPUT,
                                "%s: no cycle after cycle 0 (epoch %" PRId64
                                " us, dt %g s) has every UAV's own intent: nothing to judge",
                                o->log_path, *epoch, (double)s->dt);
    }
    b->steps = (uint32_t)k;
    return SIM_GO_ON;
}

/* Pass 2: the samples of cycles 0..steps, from the same bytes pass 1 checked, and the gaps
 * no intent covered from the scenario's reference. */
static int summary_pass2(log_summary_t *ls, rebuilt_t *b, int64_t epoch, int64_t size)
{
    const coavoid_sim_log_config_t *o = ls->o;
    size_t cells = ls->s->vehicle_count * ((size_t)b->steps + 1u);
    b->best = calloc(cells, sizeof *b->best);
    b->own = calloc(cells, sizeof *b->own);
    b->known = calloc(cells, sizeof *b->known);
    b->reference = calloc(cells, sizeof *b->reference);
    b->route = calloc(cells, sizeof *b->route);
    b->offsets = calloc(cells, sizeof *b->offsets);
    if (b->best == NULL || b->own == NULL || b->known == NULL || b->reference == NULL ||
        b->route == NULL || b->offsets == NULL) {
        return coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INTERNAL, "out of memory");
    }
    if (sample_routes(ls->s, b, epoch, ls->dt_us) != COA_OK) {
        return coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INPUT,
                                "%s: a route cannot be sampled over %lu steps", o->scenario_path,
                                (unsigned long)b->steps);
    }
    log_reader_t r;
    memset(&r, 0, sizeof r);
    int status = log_open(&r, ls->err, o->log_path, size);
    if (status == SIM_GO_ON) {
        status = fill_samples(ls, &r, b, epoch);
    }
    log_close(&r);
    if (status == SIM_GO_ON) {
        fill_gaps(ls->s, b);
    }
    return status;
}

/* Judges the rebuilt flight, writes the figure (first: a file that cannot be written is a
 * usage error, reported before anything is printed) and the result; the exit status. */
static int summary_report(log_summary_t *ls, rebuilt_t *b, int64_t epoch)
{
    const coavoid_sim_log_config_t *o = ls->o;
    coavoid_judged_t judged;
    const coavoid_flight_t *flight = &judged.flight;
    const coavoid_flight_eval_t *eval = &judged.eval;
    int status = SIM_GO_ON;
    uint32_t replans = 0;
    status = check_mode(ls, epoch, epoch + ((int64_t)b->steps + 1) * ls->dt_us);
    if (status == SIM_GO_ON) {
        status = judge_heartbeats(ls, epoch + ((int64_t)b->steps + 1) * ls->dt_us, &replans);
    }
    if (status != SIM_GO_ON) {
        return status;
    }
    int rc = coavoid_judge_run(&judged, ls->s, o->mode, b->steps, replans, b->reference, b->offsets,
                               b->known);
    if (rc == COA_ERR_ARGUMENT) {
        status = refused_record(ls->err, o, flight, b);
    } else if (rc != COA_OK) {
        status = coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INTERNAL, "cannot judge the flight (%s)",
                                  coa_status_name(rc));
    }
    if (status == SIM_GO_ON && o->svg_path != NULL) {
        status = write_svg(ls->err, o->svg_path, flight, eval);
    }
    if (status == SIM_GO_ON && o->json) {
        status = print_json(ls, b, epoch, flight, eval);
    } else if (status == SIM_GO_ON) {
        print_log_text(ls, b, epoch);
        if (coavoid_flight_text(flight, eval, ls->out) != COA_OK) {
            status = coavoid_run_fail(ls->err, COAVOID_RUN_ERR_INTERNAL, "cannot write the result");
        }
    }
    if (status == SIM_GO_ON) {
        status = eval->loss_of_separation ? COAVOID_SIM_LOSS : COAVOID_SIM_SEPARATED;
    }
    return status;
}

int coavoid_sim_summarise(const coavoid_sim_log_config_t *c, coavoid_scenario_t *s, FILE *out,
                          coavoid_run_error_t *e)
{
    log_summary_t *ls = calloc(1, sizeof *ls);
    rebuilt_t b;
    memset(&b, 0, sizeof b);
    if (ls == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "out of memory");
    }
    e->text[0] = '\0';
    ls->o = c;
    ls->err = e;
    ls->out = out;
    ls->s = s;
    int64_t epoch = 0;
    int64_t size = 0;
    int status = summary_check(ls);
    if (status == SIM_GO_ON) {
        status = summary_pass1(ls, &b, &epoch, &size);
    }
    if (status == SIM_GO_ON) {
        status = summary_pass2(ls, &b, epoch, size);
    }
    if (status == SIM_GO_ON) {
        status = summary_report(ls, &b, epoch);
    }
    rebuilt_free(&b);
    free(ls->seen.items);
    free(ls->heartbeats.items);
    free(ls);
    return status;
}
