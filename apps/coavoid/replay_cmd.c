/* SPDX-License-Identifier: MIT */
/*
 * coavoid replay: a vehicle's record (coavoid sim --record-vehicle) made again on the
 * protocol library, and compared (src/replay, replay.h).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "replay.h"

#define REPLAY_USAGE                                                                        \
    "usage: coavoid replay RECORD\n"                                                        \
    "\n"                                                                                    \
    "Builds the vehicle a record describes (coavoid sim --record-vehicle ID:RECORD) from\n" \
    "its configuration and keys, makes every recorded call again with the recorded\n"       \
    "datagrams at the recorded times, and compares what it sends and its state after\n"     \
    "each call with the record. Prints what it replayed.\n"                                 \
    "\n"                                                                                    \
    "exit status: 0 all as recorded, 1 the vehicle did something else (the first\n"         \
    "difference on stderr), 2 invalid input or usage, 3 internal error\n"

typedef struct {
    const char *path;
} replay_options_t;

static void replay_help(void)
{
    fputs(REPLAY_USAGE, stdout);
}

static int replay_option(int argc, char **argv, int *i, void *options)
{
    (void)argc;
    (void)argv;
    (void)i;
    (void)options;
    return CLI_UNKNOWN_OPTION;
}

static const coavoid_cli_command_t replay_command = {
    "replay",    "coavoid replay", 2,    {"RECORD", NULL}, "one record only",
    replay_help, replay_option,    false};

static size_t file_read(void *user, void *out, size_t n)
{
    return fread(out, 1, n, user);
}

#define REPLAY_BUFFER \
    (COAVOID_REPLAY_HEADER_BYTES + COAVOID_REPLAY_MAX_CHANNEL + COAVOID_REPLAY_MAX_PAYLOAD)

/* The record's configuration, and the vehicle it describes in *memory. */
static int replay_open(FILE *f, const char *path, uint8_t *buf, coavoid_replay_t *r, void **memory)
{
    int rc = coavoid_replay_open(r, file_read, f, buf, REPLAY_BUFFER);
    if (rc == COAVOID_REPLAY_ERR_FORMAT) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%.200s: not a vehicle's record", path);
    }
    if (rc != COA_OK) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%.200s: its configuration does not read (%d)",
                                path, rc);
    }
    const size_t size = coavoid_vehicle_node_size(&r->config);
    /* malloc's alignment is the workspace's, as coavoid_vehicle_node_create relies on. */
    *memory = size > 0u ? malloc(size) : NULL;
    rc = *memory != NULL ? coavoid_replay_start(r, *memory, size) : COA_ERR_ARGUMENT;
    if (rc != COA_OK) {
        return coavoid_cli_fail(CLI_EXIT_INVALID,
                                "%.200s: the recorded vehicle cannot be built (%d, %zu bytes)",
                                path, rc, size);
    }
    return CLI_CONTINUE;
}

static int replay_all(FILE *f, const char *path, uint8_t *buf, coavoid_replay_t *r)
{
    coavoid_replay_record_t rec;
    int got;
    int rc = COA_OK;
    while (rc == COA_OK &&
           (got = coavoid_replay_next(file_read, f, buf, REPLAY_BUFFER, &rec)) == 1) {
        rc = coavoid_replay_apply(r, &rec);
    }
    rc = rc == COA_OK ? (got == 0 ? coavoid_replay_finish(r) : got) : rc;
    if (rc == COAVOID_REPLAY_ERR_FORMAT) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%.200s: record %llu is truncated or bad", path,
                                (unsigned long long)r->records + 1u);
    }
    printf("replay: UAV %u (%s), %llu cycles, %llu polls, %llu datagrams received, %llu sent: "
           "%s\n",
           (unsigned)r->config.vehicle.id,
           r->config.mode == COAVOID_NODE_DECOUPLED ? "decoupled" : "centralised",
           (unsigned long long)r->cycles, (unsigned long long)r->polls,
           (unsigned long long)r->receives, (unsigned long long)r->sent,
           r->differs ? "differs" : "all as recorded");
    if (r->differs) {
        fprintf(stderr, "coavoid replay: %.200s: record %llu: %s\n", path,
                (unsigned long long)r->first_difference, r->difference);
        return CLI_EXIT_NOT_SOLVED;
    }
    return CLI_EXIT_OK;
}

int coavoid_command_replay(int argc, char **argv)
{
    replay_options_t o = {NULL};
    int status = coavoid_cli_parse_args(&replay_command, argc, argv, &o, &o.path);
    if (status != CLI_CONTINUE) {
        return status;
    }
    FILE *f = fopen(o.path, "rb");
    if (f == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "%.200s: cannot be read", o.path);
    }
    static uint8_t
        buf[COAVOID_REPLAY_HEADER_BYTES + COAVOID_REPLAY_MAX_CHANNEL + COAVOID_REPLAY_MAX_PAYLOAD];
    coavoid_replay_t *r = calloc(1, sizeof *r);
    void *memory = NULL;
    status = r != NULL ? replay_open(f, o.path, buf, r, &memory)
                       : coavoid_cli_fail(CLI_EXIT_INTERNAL, "out of memory");
    if (status == CLI_CONTINUE) {
        status = replay_all(f, o.path, buf, r);
    }
    if (r != NULL && r->node != NULL) {
        coavoid_vehicle_node_fini(r->node);
    }
    free(memory);
    free(r);
    fclose(f);
    return status;
}
