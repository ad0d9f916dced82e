/* SPDX-License-Identifier: MIT */
#include "record.h"

#include <stdlib.h>
#include <string.h>

static void put(coavoid_sim_record_t *rec, coavoid_replay_kind_t kind, int64_t time,
                const char *channel, const void *payload, size_t size)
{
    const size_t channel_length = channel != NULL ? strlen(channel) : 0u;
    uint8_t header[COAVOID_REPLAY_HEADER_BYTES];
    if (rec->file == NULL || channel_length > COAVOID_REPLAY_MAX_CHANNEL ||
        size > COAVOID_REPLAY_MAX_PAYLOAD) {
        rec->failed = true;
        return;
    }
    coavoid_replay_write_header(header, kind, time, channel_length, size);
    if (fwrite(header, 1, sizeof header, rec->file) != sizeof header ||
        (channel_length > 0u && fwrite(channel, 1, channel_length, rec->file) != channel_length) ||
        (size > 0u && fwrite(payload, 1, size, rec->file) != size)) {
        rec->failed = true;
    }
}

bool coavoid_sim_record_open(coavoid_sim_record_t *rec, const char *path,
                             const coavoid_vehicle_node_config_t *config)
{
    memset(rec, 0, sizeof *rec);
    uint8_t *payload = malloc(COAVOID_REPLAY_MAX_PAYLOAD);
    const size_t size =
        payload != NULL ? coavoid_replay_write_config(config, payload, COAVOID_REPLAY_MAX_PAYLOAD)
                        : 0u;
    if (size == 0u || (rec->file = fopen(path, "wb")) == NULL) {
        free(payload);
        return false;
    }
    rec->clock = config->common.clock;
    if (fwrite(COAVOID_REPLAY_MAGIC, 1, COAVOID_REPLAY_MAGIC_BYTES, rec->file) !=
        COAVOID_REPLAY_MAGIC_BYTES) {
        rec->failed = true;
    }
    put(rec, COAVOID_REPLAY_CONFIG, *rec->clock, NULL, payload, size);
    free(payload);
    return true;
}

void coavoid_sim_record_tap(void *user, bool sent, const char *channel, const void *data,
                            size_t size)
{
    coavoid_sim_record_t *rec = user;
    put(rec, sent ? COAVOID_REPLAY_SENT : COAVOID_REPLAY_RECEIVE, *rec->clock, channel, data, size);
}

int coavoid_sim_record_call(coavoid_sim_record_t *rec, coavoid_vehicle_node_t *node, bool cycle,
                            int64_t now)
{
    uint8_t state[COAVOID_REPLAY_STATE_BYTES];
    put(rec, cycle ? COAVOID_REPLAY_CYCLE : COAVOID_REPLAY_POLL, now, NULL, NULL, 0u);
    const int rc =
        cycle ? coavoid_vehicle_node_cycle(node, now) : coavoid_vehicle_node_poll(node, now);
    coavoid_replay_write_state(rc, coavoid_vehicle_node_state(node), state);
    put(rec, COAVOID_REPLAY_STATE, now, NULL, state, sizeof state);
    return rc;
}

bool coavoid_sim_record_close(coavoid_sim_record_t *rec)
{
    if (rec->file == NULL) {
        return true;
    }
    const bool ok = fclose(rec->file) == 0 && !rec->failed;
    rec->file = NULL;
    return ok;
}
