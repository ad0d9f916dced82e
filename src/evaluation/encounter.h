/* SPDX-License-Identifier: MIT */
/*
 * encounter.h: seeded random encounters of n UAVs converging on one point, written as
 * scenario JSON (docs/scenario-format.md) so that they go through the scenario loader and are
 * checked like any file. `coavoid bench plan` times the planner on them and `coavoid
 * montecarlo` evaluates the planners over thousands of them; one generator serves both so
 * that "an encounter" means the same thing in docs/benchmarks.md and docs/evaluation.md.
 *
 * The shape. UAV i's heading is heading0 + 2 pi i / n plus jitter; it flies a straight
 * level route through the origin, reaching it `arrive` seconds into the window, at an
 * altitude staggered on a grid around a base altitude. A design
 * (coavoid_encounter_design_t) sets the ranges; with terrain_hills it adds hills under the
 * crossing area, with max_tracks non-cooperative aircraft crossing it, and with
 * max_offset_max a vertical band per UAV.
 *
 * Everything comes from splitmix64 (prng.h), one stream per (seed, n, index, attempt), so
 * a seed gives the same problems on every machine with the same libm (headings go through
 * cos and sin, which C does not require to round correctly), and adding problems or UAV
 * counts changes none of the others. The draws are made in a fixed order and a design's
 * optional parts draw nothing when they are off, so coavoid_encounter_bench's problems (no
 * quantum, one box half the time) do not depend on the parts only montecarlo's design
 * uses.
 */
#ifndef COAVOID_EVALUATION_ENCOUNTER_H
#define COAVOID_EVALUATION_ENCOUNTER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* One problem's JSON: 10 vehicles of about 330 characters, 3 hills of about 250, 2 tracks. */
#define COAVOID_ENCOUNTER_JSON_MAX 12288u
#define COAVOID_ENCOUNTER_MIN_VEHICLES 2u
#define COAVOID_ENCOUNTER_MAX_VEHICLES 10u

typedef struct {
    const char *name;              /* "bench encounter", in each problem's name */
    uint32_t horizon;              /* steps */
    double dt;                     /* s */
    double speed_min, speed_max;   /* cruise speed, m/s */
    double climb_min, climb_max;   /* climb rate, m/s */
    double arrive_min, arrive_max; /* when each reaches the origin, s */
    double jitter;                 /* heading jitter, rad either side */
    double base_altitude;          /* m */
    double altitude_grid;          /* m per stagger step */
    uint32_t max_stagger;          /* stagger steps either side of the base */
    double radius, half_height;    /* every UAV's protected volume, m */
    /* 0: numbers as drawn (printed to 3 decimals); otherwise every coordinate, speed and
     * rate is rounded to a multiple of it. A power of two such as 1/8 makes each one a
     * float exactly, so single- and double-precision builds read the same problem. */
    double quantum;
    bool box_half;       /* bench: half the encounters get a box under the origin */
    bool terrain_hills;  /* montecarlo: 1-3 hills (boxes or pyramids) near the origin */
    uint32_t max_tracks; /* 0..max_tracks non-cooperative tracks crossing near the origin */
    double track_radius, track_half_height; /* their protected volumes, m */
    /* 0: unbounded; otherwise each UAV's max_offset is drawn from min..max. */
    uint32_t max_offset_min, max_offset_max;
} coavoid_encounter_design_t;

/* bench plan's encounters (docs/benchmarks.md, "The encounters"). */
extern const coavoid_encounter_design_t coavoid_encounter_bench;
/* montecarlo's encounters (docs/evaluation.md, "The encounters"). */
extern const coavoid_encounter_design_t coavoid_encounter_montecarlo;

/* What coavoid_encounter_json drew beyond the vehicles, for reports. */
typedef struct {
    uint32_t hills;
    uint32_t tracks;
} coavoid_encounter_info_t;

/* Writes encounter `index` of n UAVs (COAVOID_ENCOUNTER_MIN_VEHICLES to
 * COAVOID_ENCOUNTER_MAX_VEHICLES) of design d, draw `attempt` (0 first; a caller that
 * rejects a draw asks for the next), as scenario JSON into buf[size]. info may be NULL.
 * Returns false when it does not fit (a bug: COAVOID_ENCOUNTER_JSON_MAX bounds a problem).
 * O(n + hills + tracks), no memory. */
bool coavoid_encounter_json(const coavoid_encounter_design_t *d, uint64_t seed, uint32_t n,
                            uint32_t index, uint32_t attempt, char *buf, size_t size,
                            coavoid_encounter_info_t *info);

/* Writes json and a newline to DIR/PREFIX-SEED-N-INDEX.json (for `coavoid plan` to
 * replay). Returns 0, or -1 when the path does not fit or the file cannot be written. */
int coavoid_encounter_save(const char *dir, const char *prefix, uint64_t seed, uint32_t n,
                           uint32_t index, const char *json);

#endif /* COAVOID_EVALUATION_ENCOUNTER_H */
