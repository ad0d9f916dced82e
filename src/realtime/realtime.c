/* SPDX-License-Identifier: MIT */
/*
 * realtime.c: the scenario clock, LCM's creation with one-line errors, the stop signals,
 * and the loop that calls the nodes at their times (realtime.h).
 */
#define _POSIX_C_SOURCE 200809L

#include "realtime.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/select.h>
#include <time.h>
#include <unistd.h>

#if defined(__GNUC__)
#define RT_PRINTF_LIKE(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define RT_PRINTF_LIKE(fmt, args)
#endif

/* Longest single wait: the stop flag is also looked at this often, whatever a signal's
 * delivery does to select. */
#define RT_MAX_WAIT_US 100000

/* Messages handled between two looks at the nodes' events. */
#define RT_MAX_DRAIN 256

static volatile sig_atomic_t rt_stop_signal = 0;

static void rt_on_signal(int sig)
{
    rt_stop_signal = sig;
}

int coavoid_rt_install_signal_handlers(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = rt_on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;
    if (sigaction(SIGINT, &sa, NULL) != 0 || sigaction(SIGTERM, &sa, NULL) != 0) {
        return -1;
    }
    return 0;
}

int64_t coavoid_rt_wall_utime(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + (int64_t)ts.tv_nsec / 1000;
}

int64_t coavoid_rt_stopwatch_us(void *user)
{
    (void)user;
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000 + (int64_t)ts.tv_nsec / 1000;
}

int64_t coavoid_rt_scenario_utime(const coavoid_rt_clock_t *clock, int64_t wall_utime)
{
    if (wall_utime < clock->epoch_utime) {
        return wall_utime;
    }
    double elapsed = floor((double)(wall_utime - clock->epoch_utime) * clock->speed);
    if (elapsed >= (double)(INT64_MAX - clock->epoch_utime) - 2.0) {
        return INT64_MAX;
    }
    return clock->epoch_utime + (int64_t)elapsed;
}

int64_t coavoid_rt_wall_at(const coavoid_rt_clock_t *clock, int64_t scenario_utime)
{
    if (scenario_utime <= clock->epoch_utime) {
        return scenario_utime;
    }
    double elapsed = ceil((double)(scenario_utime - clock->epoch_utime) / clock->speed);
    /* Slower than real time, a far scenario time (INT64_MAX: "never") lies beyond int64. */
    if (elapsed >= (double)(INT64_MAX - clock->epoch_utime) - 2.0) {
        return INT64_MAX;
    }
    int64_t wall = clock->epoch_utime + (int64_t)elapsed;
    /* Rounding in the division can leave it a microsecond short of the inverse. */
    while (coavoid_rt_scenario_utime(clock, wall) < scenario_utime) {
        wall++;
    }
    return wall;
}

/* ---- LCM ---- */

/* The first line of LCM's messages that says something (they start with blank lines). */
static void first_line(const char *text, char *out, size_t size)
{
    const char *c = text;
    while (*c == '\n' || *c == '\r' || *c == ' ') {
        c++;
    }
    size_t n = strcspn(c, "\r\n");
    if (n >= size) {
        n = size - 1u;
    }
    memcpy(out, c, n);
    out[n] = '\0';
}

lcm_t *coavoid_rt_lcm_create(const char *url, char *err, size_t err_size)
{
    char said[4096];
    size_t said_length = 0;
    said[0] = '\0';

    /* LCM explains a failure in a dozen lines on stderr; the drivers promise one. So its
     * output goes to a temporary file while it starts, and is read back. */
    fflush(stderr);
    FILE *capture = tmpfile();
    int saved = capture != NULL ? dup(STDERR_FILENO) : -1;
    bool captured = saved >= 0 && dup2(fileno(capture), STDERR_FILENO) >= 0;
    lcm_t *lcm = lcm_create(url);
    if (captured) {
        fflush(stderr);
        dup2(saved, STDERR_FILENO);
        rewind(capture);
        said_length = fread(said, 1, sizeof said - 1u, capture);
        said[said_length] = '\0';
    }
    if (saved >= 0) {
        close(saved);
    }
    if (capture != NULL) {
        fclose(capture);
    }

    if (lcm != NULL) {
        if (said_length > 0) {
            fwrite(said, 1, said_length, stderr);
        }
        return lcm;
    }
    char line[256];
    first_line(said, line, sizeof line);
    if (strstr(said, "multicast route") != NULL || strstr(said, "No route") != NULL ||
        strstr(said, "unreachable") != NULL) {
        snprintf(err, err_size,
                 "--lcm-url: cannot open '%.200s': this host has no multicast route "
                 "(as root: ip link set lo up multicast on && ip route add 224.0.0.0/4 dev lo)",
                 url);
    } else if (line[0] != '\0') {
        const char *text = strncmp(line, "Error: ", 7) == 0 ? line + 7 : line;
        snprintf(err, err_size, "--lcm-url: cannot open '%.200s' (LCM: %.200s)", url, text);
    } else {
        snprintf(err, err_size, "--lcm-url: cannot open '%.200s' (LCM refused it)", url);
    }
    return NULL;
}

typedef struct {
    const coavoid_rt_loop_t *loop;
    coavoid_rt_result_t *result;
    const coavoid_node_common_t *common;
} rt_run_t;

static int64_t rt_now(const rt_run_t *r)
{
    return coavoid_rt_scenario_utime(&r->loop->clock, coavoid_rt_wall_utime());
}

static void rt_warn(const rt_run_t *r, const char *fmt, ...) RT_PRINTF_LIKE(2, 3);

static void rt_warn(const rt_run_t *r, const char *fmt, ...)
{
    char line[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    if (r->loop->warnings != NULL) {
        fprintf(r->loop->warnings, "%s: %s\n", r->loop->name != NULL ? r->loop->name : "node",
                line);
        fflush(r->loop->warnings);
    }
}

static void rt_error(const rt_run_t *r, const char *what, int64_t cycle, int rc)
{
    r->result->errors++;
    if (r->result->first_error == 0) {
        r->result->first_error = rc;
    }
    rt_warn(r, "cycle %lld: %s failed (%s)", (long long)cycle, what, coavoid_lcm_error_name(rc));
}

/* Work that ended at `end` (scenario time) for an event whose successor is due at `next`;
 * `started` is the stopwatch when the call began. */
static void rt_check_overrun(const rt_run_t *r, const char *what, int64_t cycle, int64_t end,
                             int64_t next, int64_t started)
{
    if (end < next) {
        return;
    }
    r->result->overruns++;
    int64_t took = coavoid_rt_stopwatch_us(NULL) - started;
    rt_warn(r,
            "cycle %lld: %s overran: it ended %.0f ms (scenario time) after cycle %lld began, "
            "having taken %.0f ms of wall time at speed %g; lower --speed",
            (long long)cycle, what, (double)(end - next) * 1e-3, (long long)(cycle + 1),
            (double)took * 1e-3, r->loop->clock.speed);
}

/* Cycle k's start for the world and the vehicles. */
static void rt_cycle_start(const rt_run_t *r, int64_t k)
{
    const coavoid_rt_loop_t *loop = r->loop;
    int64_t next = coavoid_node_cycle_utime(r->common, k + 1);
    if (loop->world != NULL) {
        int64_t started = coavoid_rt_stopwatch_us(NULL);
        *loop->now = rt_now(r);
        /* Ahead of the cycle (world_lead_us), its messages still speak of the cycle. */
        int64_t at = *loop->now > coavoid_node_cycle_utime(r->common, k)
                         ? *loop->now
                         : coavoid_node_cycle_utime(r->common, k);
        int rc = coavoid_world_cycle(loop->world, at);
        if (rc < 0) {
            rt_error(r, "the world's cycle", k, rc);
        }
        rt_check_overrun(r, "publishing the world", k, rt_now(r), next, started);
    }
    for (size_t i = 0; i < loop->vehicle_count; i++) {
        int64_t started = coavoid_rt_stopwatch_us(NULL);
        *loop->now = rt_now(r);
        int rc = coavoid_vehicle_node_cycle(loop->vehicles[i], *loop->now);
        if (rc < 0) {
            rt_error(r, "the vehicle's cycle", k, rc);
        }
        rt_check_overrun(r, "the vehicle's cycle", k, rt_now(r), next, started);
    }
    r->result->cycles++;
}

/* Polls vehicle i at `now`; `deadline_polled` remembers the deadline it was polled for, so
 * that a deadline the node does not move cannot make the loop spin. */
static void rt_poll(const rt_run_t *r, size_t i, int64_t *deadline_polled)
{
    const coavoid_rt_loop_t *loop = r->loop;
    int64_t started = coavoid_rt_stopwatch_us(NULL);
    int64_t deadline = coavoid_vehicle_node_deadline(loop->vehicles[i]);
    *loop->now = rt_now(r);
    int64_t k = coavoid_node_cycle_of(r->common, *loop->now);
    int rc = coavoid_vehicle_node_poll(loop->vehicles[i], *loop->now);
    if (deadline <= *loop->now) {
        *deadline_polled = deadline;
    }
    if (rc < 0) {
        rt_error(r, "the vehicle's poll", k, rc);
    } else if (rc > 0) {
        rt_check_overrun(r, "the vehicle's planning", k, rt_now(r),
                         coavoid_node_cycle_utime(r->common, k + 1), started);
    }
}

/* The vehicle's deadline unless it was already polled for. */
static int64_t rt_pending_deadline(const rt_run_t *r, size_t i, int64_t deadline_polled)
{
    int64_t deadline = coavoid_vehicle_node_deadline(r->loop->vehicles[i]);
    return deadline == deadline_polled ? INT64_MAX : deadline;
}

int coavoid_rt_stop_signal(void)
{
    return (int)rt_stop_signal;
}

int coavoid_rt_deliver(lcm_t *lcm, coavoid_rt_rx_t *rx)
{
    if (rx != NULL) {
        return coavoid_rt_rx_deliver(rx);
    }
    errno = 0;
    int rc = lcm_handle_timeout(lcm, 0);
    if (rc < 0) {
        /* A signal during LCM's own select: the loop looks at the stop flag next. */
        return errno == EINTR ? 0 : COAVOID_RT_ERR_LCM;
    }
    return rc > 0 ? 1 : 0;
}

/* Dispatches the messages waiting, each with the clock set just before, until the next
 * event is due at scenario time `wake` (one message at least), and at most RT_MAX_DRAIN at
 * a time, so that a flood cannot delay the nodes' own events by more than one message's
 * handling. Returns how many, or COAVOID_RT_ERR_LCM. */
static int rt_drain(const rt_run_t *r, int64_t wake)
{
    int handled = 0;
    while (handled < RT_MAX_DRAIN) {
        *r->loop->now = rt_now(r);
        if (handled > 0 && *r->loop->now >= wake) {
            break;
        }
        int rc = coavoid_rt_deliver(r->loop->lcm, r->loop->rx);
        if (rc < 0) {
            return rc;
        }
        if (rc == 0) {
            break;
        }
        handled++;
    }
    return handled;
}

/* Waits until wall time `wake` or a message, whichever is first (fd -1: until wake).
 * Returns 1 when a message waits, 0 on time-out or a signal, COAVOID_RT_ERR_LCM on
 * failure. */
static int rt_wait(int fd, int64_t wake_wall)
{
    int64_t wait_us = wake_wall - coavoid_rt_wall_utime();
    if (wait_us < 0) {
        wait_us = 0;
    }
    if (wait_us > RT_MAX_WAIT_US) {
        wait_us = RT_MAX_WAIT_US;
    }
    fd_set fds;
    FD_ZERO(&fds);
    if (fd >= 0) {
        FD_SET(fd, &fds);
    }
    struct timeval tv;
    tv.tv_sec = (time_t)(wait_us / 1000000);
    tv.tv_usec = (suseconds_t)(wait_us % 1000000);
    int rc = select(fd + 1, &fds, NULL, NULL, &tv);
    if (rc < 0) {
        return errno == EINTR ? 0 : COAVOID_RT_ERR_LCM;
    }
    return rc > 0 ? 1 : 0;
}

/* Where a run's schedule stands: the next cycle to start and the next to collect. */
typedef struct {
    int64_t K;            /* the last cycle */
    int64_t next_start;   /* K + 1: none left */
    int64_t next_collect; /* K: none left */
    int64_t lead;         /* a world alone starts its cycles this early */
    bool has_starts;      /* a world or vehicles: cycles start */
    int64_t polled[COAVOID_NODE_MAX_PEERS];
} rt_sched_t;

static bool rt_loop_ok(const coavoid_rt_loop_t *loop, const coavoid_rt_result_t *result)
{
    return loop != NULL && result != NULL && loop->lcm != NULL && loop->now != NULL &&
           loop->common != NULL && loop->steps >= 1 && loop->clock.speed > 0 &&
           loop->vehicle_count <= COAVOID_NODE_MAX_PEERS &&
           (loop->vehicle_count == 0 || loop->vehicles != NULL) &&
           (loop->world != NULL || loop->coordinator != NULL || loop->vehicle_count > 0);
}

/* A process started late joins at the current cycle; the coordinator, if its collect time
 * for that cycle has passed, at the next one. */
static void rt_sched_init(const rt_run_t *r, rt_sched_t *sc)
{
    const coavoid_rt_loop_t *loop = r->loop;
    const coavoid_node_common_t *c = loop->common;
    int64_t now = rt_now(r);
    int64_t first = now < c->epoch_utime ? 0 : coavoid_node_cycle_of(c, now);
    first = first < 0 ? 0 : first;
    sc->K = loop->steps;
    sc->has_starts = loop->world != NULL || loop->vehicle_count > 0;
    sc->lead = (loop->world != NULL && loop->vehicle_count == 0 && loop->world_lead_us > 0 &&
                loop->world_lead_us < c->dt_us)
                   ? loop->world_lead_us
                   : 0;
    sc->next_start = sc->has_starts ? first : sc->K + 1;
    sc->next_collect = sc->K;
    if (loop->coordinator != NULL) {
        sc->next_collect = first;
        if (now > coavoid_node_cycle_utime(c, first) + loop->collect_us) {
            sc->next_collect++;
        }
    }
    for (size_t i = 0; i < loop->vehicle_count; i++) {
        sc->polled[i] = INT64_MIN;
    }
}

/* Starts the cycle that is due, if one is (skipping those the loop was too late for). */
static bool rt_due_start(const rt_run_t *r, rt_sched_t *sc, int64_t now)
{
    const coavoid_node_common_t *c = r->loop->common;
    if (sc->next_start > sc->K || now < coavoid_node_cycle_utime(c, sc->next_start) - sc->lead) {
        return false;
    }
    int64_t k = coavoid_node_cycle_of(c, now + sc->lead);
    k = k > sc->K ? sc->K : k;
    if (k > sc->next_start) {
        r->result->skipped += (uint32_t)(k - sc->next_start);
        rt_warn(r, "cycles %lld..%lld skipped: the loop was %.0f ms (scenario time) late",
                (long long)sc->next_start, (long long)(k - 1),
                (double)(now - coavoid_node_cycle_utime(c, sc->next_start)) * 1e-3);
    }
    rt_cycle_start(r, k);
    sc->next_start = k + 1;
    return true;
}

/* Runs the coordinator's collect that is due, if one is. */
static bool rt_due_collect(const rt_run_t *r, rt_sched_t *sc, int64_t now)
{
    const coavoid_rt_loop_t *loop = r->loop;
    const coavoid_node_common_t *c = loop->common;
    if (sc->next_collect >= sc->K ||
        now < coavoid_node_cycle_utime(c, sc->next_collect) + loop->collect_us) {
        return false;
    }
    int64_t k = coavoid_node_cycle_of(c, now);
    if (k > sc->next_collect) {
        /* Its plans would be valid until a cycle start already past: nobody could adopt
         * them. */
        int64_t missed = (k < sc->K ? k : sc->K) - sc->next_collect;
        r->result->skipped += (uint32_t)missed;
        rt_warn(r, "cycles %lld..%lld: no plans: the loop was %.0f ms (scenario time) late",
                (long long)sc->next_collect, (long long)(sc->next_collect + missed - 1),
                (double)(now - coavoid_node_cycle_utime(c, sc->next_collect) - loop->collect_us) *
                    1e-3);
        sc->next_collect += missed;
        return true;
    }
    int64_t started = coavoid_rt_stopwatch_us(NULL);
    *loop->now = now;
    int rc = coavoid_coordinator_cycle(loop->coordinator, now);
    if (rc < 0) {
        rt_error(r, "the coordinator's cycle", k, rc);
    }
    rt_check_overrun(r, "the coordinator's planning", k, rt_now(r),
                     coavoid_node_cycle_utime(c, k + 1), started);
    if (!sc->has_starts) {
        r->result->cycles++;
    }
    sc->next_collect = k + 1;
    return true;
}

/* Runs the coordinator's agreement steps that are due (resends, aborts, commits
 * re-sends); the time its next one is due, or INT64_MAX. */
static int64_t rt_coordinator_poll(const rt_run_t *r, int64_t now)
{
    const coavoid_rt_loop_t *loop = r->loop;
    if (coavoid_coordinator_deadline(loop->coordinator) <= now) {
        *loop->now = now;
        int rc = coavoid_coordinator_poll(loop->coordinator, now);
        if (rc < 0) {
            rt_error(r, "the coordinator's agreements", coavoid_node_cycle_of(loop->common, now),
                     rc);
        }
    }
    return coavoid_coordinator_deadline(loop->coordinator);
}

/* Polls the vehicles whose deadline has come; the next time anything is due (INT64_MAX:
 * nothing is left to do). */
static int64_t rt_next_wake(const rt_run_t *r, rt_sched_t *sc, int64_t now)
{
    const coavoid_rt_loop_t *loop = r->loop;
    const coavoid_node_common_t *c = loop->common;
    int64_t wake = INT64_MAX;
    for (size_t i = 0; i < loop->vehicle_count; i++) {
        int64_t deadline = rt_pending_deadline(r, i, sc->polled[i]);
        if (deadline <= now) {
            rt_poll(r, i, &sc->polled[i]);
            deadline = rt_pending_deadline(r, i, sc->polled[i]);
        }
        wake = deadline < wake ? deadline : wake;
    }
    if (sc->next_start <= sc->K) {
        int64_t t = coavoid_node_cycle_utime(c, sc->next_start) - sc->lead;
        wake = t < wake ? t : wake;
    }
    if (sc->next_collect < sc->K) {
        int64_t t = coavoid_node_cycle_utime(c, sc->next_collect) + loop->collect_us;
        wake = t < wake ? t : wake;
    }
    if (loop->coordinator != NULL) {
        int64_t t = rt_coordinator_poll(r, now);
        wake = t < wake ? t : wake;
    }
    return wake;
}

/* Waits until `wake` or a message; handles what arrived. Negative: an LCM failure. */
static int rt_wait_messages(const rt_run_t *r, rt_sched_t *sc, int fd, int64_t wake)
{
    const coavoid_rt_loop_t *loop = r->loop;
    /* A batch part delivered leaves the descriptor quiet while there is work. */
    if (loop->rx == NULL || !coavoid_rt_rx_pending(loop->rx)) {
        int rc = rt_wait(fd, coavoid_rt_wall_at(&loop->clock, wake));
        if (rc <= 0) {
            return rc;
        }
    }
    int rc = rt_drain(r, wake);
    if (rc < 0) {
        return rc;
    }
    /* A message may be the intent a waiting vehicle needed, or a raised rank that
     * overtakes a vehicle that already decided (it decides again: node.h, poll). */
    for (size_t i = 0; i < loop->vehicle_count; i++) {
        rt_poll(r, i, &sc->polled[i]);
    }
    return COA_OK;
}

int coavoid_rt_run(const coavoid_rt_loop_t *loop, coavoid_rt_result_t *result)
{
    if (result != NULL) {
        memset(result, 0, sizeof *result);
    }
    if (!rt_loop_ok(loop, result)) {
        return COA_ERR_ARGUMENT;
    }
    int fd = loop->deaf         ? -1
             : loop->rx != NULL ? coavoid_rt_rx_fd(loop->rx)
                                : lcm_get_fileno(loop->lcm);
    if ((fd < 0 && !loop->deaf) || fd >= FD_SETSIZE) {
        return COAVOID_RT_ERR_LCM;
    }
    rt_run_t run = {loop, result, loop->common};
    const rt_run_t *r = &run;
    rt_sched_t sc;
    rt_sched_init(r, &sc);
    for (;;) {
        if (rt_stop_signal != 0) {
            result->signal = (int)rt_stop_signal;
            break;
        }
        int64_t now = rt_now(r);
        if (rt_due_start(r, &sc, now) || rt_due_collect(r, &sc, now)) {
            continue;
        }
        int64_t wake = rt_next_wake(r, &sc, now);
        if (sc.next_start > sc.K && sc.next_collect >= sc.K && wake == INT64_MAX) {
            break;
        }
        int rc = rt_wait_messages(r, &sc, fd, wake);
        if (rc < 0) {
            return rc;
        }
    }
    *loop->now = rt_now(r);
    if (loop->rx != NULL) {
        result->received = true;
        result->rx = *coavoid_rt_rx_stats(loop->rx);
    }
    return COA_OK;
}

void coavoid_rt_result_text(const coavoid_rt_result_t *result, char *out, size_t size)
{
    const char *signal_name = result->signal == SIGINT    ? "SIGINT"
                              : result->signal == SIGTERM ? "SIGTERM"
                                                          : "a signal";
    int n = snprintf(out, size, ", overruns %u, skipped %u", (unsigned)result->overruns,
                     (unsigned)result->skipped);
    if (n >= 0 && (size_t)n < size && result->received) {
        const coavoid_rt_rx_stats_t *x = &result->rx;
        n += snprintf(out + n, size - (size_t)n,
                      ", datagrams %llu (dropped at the socket %llu; malformed %llu, fragments "
                      "%llu, oversize %llu, foreign %llu)",
                      (unsigned long long)x->datagrams, (unsigned long long)x->kernel_dropped,
                      (unsigned long long)x->malformed, (unsigned long long)x->fragments,
                      (unsigned long long)x->oversize, (unsigned long long)x->foreign);
    }
    if (n >= 0 && (size_t)n < size && result->errors > 0) {
        n += snprintf(out + n, size - (size_t)n, ", errors %u (first: %s)",
                      (unsigned)result->errors, coavoid_lcm_error_name(result->first_error));
    }
    if (n >= 0 && (size_t)n < size && result->signal != 0) {
        snprintf(out + n, size - (size_t)n, ", stopped by %s", signal_name);
    }
}
