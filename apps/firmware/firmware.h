/* SPDX-License-Identifier: MIT */
/*
 * firmware.h: the example firmware's collision-avoidance task (task.c), which is plain C
 * on the core, and the board glue that drives it (main.c, startup.c).
 *
 * Everything is sized here, at compile time, and lives in static storage: the planner's
 * and the predictor's workspaces, the neighbours' intents, the plan. Nothing is allocated.
 */
#ifndef COAVOID_FIRMWARE_H
#define COAVOID_FIRMWARE_H

#include <stdint.h>

#include "coavoid/coavoid.h"

#define FW_HORIZON 24u                /* N: steps planned and predicted ahead */
#define FW_DT 1.0f                    /* s per step; the task runs once per step */
#define FW_SAMPLES (FW_HORIZON + 1u)  /* samples of a plan, k = 0..N */
#define FW_ROUTE_POINTS 8u            /* route ahead, current reference position first */
#define FW_NEIGHBOURS 7u              /* co-operative UAVs whose intents are held */
#define FW_TRACKS 2u                  /* non-co-operative tracks (transponder, radar) */
#define FW_PLANS (1u + FW_NEIGHBOURS) /* the predictor's plans: ours first */
#define FW_MAX_PAIRS 64u              /* distinct candidate pairs per prediction */
#define FW_MAX_CONFLICTS 16u

/* Workspaces (bytes). The predictor's must hold coa_predictor_workspace_size(FW_PLANS,
 * FW_TRACKS, FW_HORIZON, FW_MAX_PAIRS), checked once at start-up; the planner takes the
 * largest beta that fits its buffer (coa_planner_max_beta). */
#define FW_PLANNER_BYTES (32u * 1024u)
#define FW_PREDICTOR_BYTES (8u * 1024u)

/* A neighbour's intent as the radio delivers it (times on the mission clock). */
typedef struct {
    bool valid;
    uint16_t id;
    uint32_t priority; /* 1 is highest, as coa_vehicle_t */
    coa_volume_t volume;
    coa_real_t t0;   /* s, time of samples[0] */
    coa_real_t step; /* s between samples */
    uint32_t count;  /* 1..FW_SAMPLES */
    coa_vec3_t samples[FW_SAMPLES];
} fw_intent_t;

/* What the rest of the autopilot writes between two cycles (never during one). */
typedef struct {
    coa_vec3_t route[FW_ROUTE_POINTS]; /* route ahead from the current reference position */
    uint32_t route_count;              /* 2..FW_ROUTE_POINTS */
    int32_t offset;                    /* current altitude offset, climb steps */
    fw_intent_t neighbours[FW_NEIGHBOURS];
    coa_track_t tracks[FW_TRACKS]; /* constant-velocity tracks, times relative to now */
    uint32_t track_count;
} fw_inputs_t;

typedef enum {
    FW_CLEAR = 0,     /* no conflict of ours predicted: the plan stands */
    FW_REPLANNED = 1, /* a conflict was predicted and a new plan avoids it */
    FW_NO_PLAN = 2,   /* the planner found none within beta, or none exists: failsafe */
    FW_ERROR = 3      /* bad input or a workspace too small: failsafe */
} fw_status_t;

/* What the cycle leaves for the rest of the autopilot. */
typedef struct {
    int32_t offsets[FW_SAMPLES];   /* the plan in force, climb steps from the reference */
    coa_vec3_t intent[FW_SAMPLES]; /* its positions, for the radio to publish */
    coa_real_t altitude_setpoint;  /* m, for the end of the coming step */
    fw_status_t status;
    int error;              /* the core's status code when status is FW_ERROR */
    uint32_t conflicts;     /* conflicts of ours in the last prediction */
    uint32_t beta;          /* the planner's closed-node budget */
    coa_plan_result_t plan; /* the last planner call's result */
} fw_outputs_t;

extern fw_inputs_t fw_inputs;
extern fw_outputs_t fw_outputs;

/* Builds both workspaces in their static buffers. Returns COA_OK or COA_ERR_WORKSPACE when
 * a buffer is too small for the sizes above. Call once, before the first cycle. */
int fw_task_init(void);

/* One cycle at mission time `now`: predict, and replan our own vertical manoeuvre around
 * the plans of higher-priority neighbours when we are in a conflict. Returns the status
 * it also leaves in fw_outputs. Bounded by FW_* and beta (docs/embedded.md). */
fw_status_t fw_task_cycle(coa_real_t now);

/* The example's inputs: a higher-priority neighbour head-on at our altitude, a
 * lower-priority one crossing behind, one track far off. */
void fw_example_inputs(void);

void fw_systick_handler(void);
void fw_usart1_handler(void);

#endif /* COAVOID_FIRMWARE_H */
