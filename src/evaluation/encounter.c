/* SPDX-License-Identifier: MIT */
/*
 * encounter.c: the seeded random encounters of bench plan and montecarlo (encounter.h).
 */
#include "encounter.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

#include "evaluation_internal.h"
#include "prng.h"

#define ENC_PI 3.14159265358979323846

/* bench plan's design: docs/benchmarks.md's figures are for exactly these problems, so
 * a change here changes every one of them. */
const coavoid_encounter_design_t coavoid_encounter_bench = {
    .name = "bench encounter",
    .horizon = 20u,
    .dt = 1.0,
    .speed_min = 8.0,
    .speed_max = 12.0,
    .climb_min = 1.5,
    .climb_max = 3.0,
    .arrive_min = 8.0,
    .arrive_max = 12.0,
    .jitter = 0.3,
    .base_altitude = 100.0,
    .altitude_grid = 2.0,
    .max_stagger = 3u,
    .radius = 15.0,
    .half_height = 5.0,
    .quantum = 0.0,
    .box_half = true,
    .terrain_hills = false,
    .max_tracks = 0u,
    .max_offset_min = 0u,
    .max_offset_max = 0u,
};

/* montecarlo's design; docs/evaluation.md ("The encounters") says why each number. */
const coavoid_encounter_design_t coavoid_encounter_montecarlo = {
    .name = "montecarlo encounter",
    .horizon = 12u,
    .dt = 1.0,
    .speed_min = 8.0,
    .speed_max = 12.0,
    .climb_min = 3.0,
    .climb_max = 5.0,
    .arrive_min = 4.0,
    .arrive_max = 8.0,
    .jitter = 0.3,
    .base_altitude = 100.0,
    .altitude_grid = 2.5,
    .max_stagger = 2u,
    .radius = 15.0,
    .half_height = 5.0,
    .quantum = 0.125,
    .box_half = false,
    .terrain_hills = true,
    .max_tracks = 2u,
    .track_radius = 10.0,
    .track_half_height = 3.0,
    .max_offset_min = 4u,
    .max_offset_max = 7u,
};

/* Appends to buf; false when it would not fit. */
static bool append(char *buf, size_t size, size_t *used, const char *fmt, ...)
    COAVOID_EVALUATION_PRINTF_LIKE(4, 5);

static bool append(char *buf, size_t size, size_t *used, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf + *used, size - *used, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= size - *used) {
        return false;
    }
    *used += (size_t)n;
    return true;
}

/* x on the design's grid. Printed with %.3f, a multiple of 1/8 is written exactly. */
static double quantise(const coavoid_encounter_design_t *d, double x)
{
    return d->quantum > 0 ? round(x / d->quantum) * d->quantum : x;
}

/* A hill near the origin: a box, or a pyramid (a square base on the ground turned by a
 * random angle, its apex over a point near the centre), its top `top` m high. */
static bool hill_json(const coavoid_encounter_design_t *d, coavoid_prng_t *r, double top, char *buf,
                      size_t size, size_t *used)
{
    bool pyramid = coavoid_prng_below(r, 2u) == 1u;
    double cx = coavoid_prng_uniform(r, -60.0, 60.0);
    double cy = coavoid_prng_uniform(r, -60.0, 60.0);
    double w = coavoid_prng_uniform(r, 15.0, 40.0); /* half the base's side */
    top = quantise(d, top);
    if (!pyramid) {
        return append(buf, size, used,
                      "{\"type\": \"box\", \"min\": [%.3f, %.3f, 0], \"max\": [%.3f, %.3f, %.3f]}",
                      quantise(d, cx - w), quantise(d, cy - w), quantise(d, cx + w),
                      quantise(d, cy + w), top);
    }
    double turn = coavoid_prng_uniform(r, 0.0, 0.5 * ENC_PI);
    double ax = cx + coavoid_prng_uniform(r, -0.3, 0.3) * w;
    double ay = cy + coavoid_prng_uniform(r, -0.3, 0.3) * w;
    bool ok = append(buf, size, used, "{\"type\": \"polytope\", \"vertices\": [");
    for (uint32_t c = 0; ok && c < 4u; c++) {
        double a = turn + 0.5 * ENC_PI * c;
        ok = append(buf, size, used, "[%.3f, %.3f, 0], ", quantise(d, cx + w * cos(a)),
                    quantise(d, cy + w * sin(a)));
    }
    return ok &&
           append(buf, size, used, "[%.3f, %.3f, %.3f]]}", quantise(d, ax), quantise(d, ay), top);
}

/* A non-cooperative aircraft flying level and straight through a point near the origin
 * at a time when the UAVs are about there, at an altitude within or near their stagger. */
static bool track_json(const coavoid_encounter_design_t *d, coavoid_prng_t *r, uint32_t id,
                       char *buf, size_t size, size_t *used)
{
    double heading = coavoid_prng_uniform(r, 0.0, 2.0 * ENC_PI);
    double speed = coavoid_prng_uniform(r, 10.0, 20.0);
    double when = coavoid_prng_uniform(r, d->arrive_min, d->arrive_max);
    double px = coavoid_prng_uniform(r, -30.0, 30.0);
    double py = coavoid_prng_uniform(r, -30.0, 30.0);
    /* Above or below the UAVs' stagger band, overlapping its edge: in the way of a UAV
     * that climbs or dives away from the others. */
    double band = d->altitude_grid * d->max_stagger;
    double side = coavoid_prng_below(r, 2u) == 0 ? 1.0 : -1.0;
    double z = d->base_altitude + side * (band + coavoid_prng_uniform(r, 0.0, 10.0));
    double vx = quantise(d, speed * cos(heading));
    double vy = quantise(d, speed * sin(heading));
    return append(buf, size, used,
                  "{\"id\": %u, \"radius\": %.3f, \"half_height\": %.3f, "
                  "\"position\": [%.3f, %.3f, %.3f], \"velocity\": [%.3f, %.3f, 0]}",
                  id, d->track_radius, d->track_half_height, quantise(d, px - vx * when),
                  quantise(d, py - vy * when), quantise(d, z), vx, vy);
}

bool coavoid_encounter_json(const coavoid_encounter_design_t *d, uint64_t seed, uint32_t n,
                            uint32_t index, uint32_t attempt, char *buf, size_t size,
                            coavoid_encounter_info_t *info)
{
    /* Attempt 0 is bench plan's original stream; a redraw moves to another. */
    coavoid_prng_t r = {seed ^ ((uint64_t)n << 56) ^ ((uint64_t)index * 0x9e3779b97f4a7c15u) ^
                        ((uint64_t)attempt * 0xd1b54a32d192ed03u)};
    coavoid_prng_next(&r);
    coavoid_encounter_info_t drawn = {0u, 0u};
    size_t used = 0;
    const double horizon_s = d->horizon * d->dt;
    bool ok = append(buf, size, &used,
                     "{\"name\": \"%s %u of %u UAVs\", \"dt\": %g, \"horizon\": %u, "
                     "\"vehicles\": [",
                     d->name, index, n, d->dt, d->horizon);
    double heading0 = coavoid_prng_uniform(&r, 0.0, 2.0 * ENC_PI);
    double lowest = 1e300;
    for (uint32_t i = 0; ok && i < n; i++) {
        double heading =
            heading0 + 2.0 * ENC_PI * i / n + coavoid_prng_uniform(&r, -d->jitter, d->jitter);
        double speed = quantise(d, coavoid_prng_uniform(&r, d->speed_min, d->speed_max));
        double climb = quantise(d, coavoid_prng_uniform(&r, d->climb_min, d->climb_max));
        double arrive = coavoid_prng_uniform(&r, d->arrive_min, d->arrive_max);
        double z = quantise(d, d->base_altitude +
                                   d->altitude_grid *
                                       ((double)coavoid_prng_below(&r, 2u * d->max_stagger + 1u) -
                                        (double)d->max_stagger));
        lowest = z < lowest ? z : lowest;
        double ux = cos(heading), uy = sin(heading);
        /* Flying along (ux, uy) through the origin at t = arrive, and on past the horizon. */
        double before = speed * arrive;
        double after = speed * (horizon_s - arrive + 10.0);
        ok = append(buf, size, &used,
                    "%s{\"id\": %u, \"priority\": %u, \"cruise_speed\": %.3f, "
                    "\"climb_rate\": %.3f, \"steep_factor\": 2, \"radius\": %g, "
                    "\"half_height\": %g, \"route\": [[%.3f, %.3f, %.3f], [%.3f, %.3f, %.3f]]",
                    i == 0 ? "" : ", ", i + 1u, i + 1u, speed, climb, d->radius, d->half_height,
                    quantise(d, -before * ux), quantise(d, -before * uy), z,
                    quantise(d, after * ux), quantise(d, after * uy), z);
        if (ok && d->max_offset_max > 0) {
            uint32_t bound = d->max_offset_min +
                             coavoid_prng_below(&r, d->max_offset_max - d->max_offset_min + 1u);
            ok = append(buf, size, &used, ", \"max_offset\": %u", bound);
        }
        ok = ok && append(buf, size, &used, "}");
    }
    ok = ok && append(buf, size, &used, "]");
    if (ok && d->box_half && coavoid_prng_below(&r, 2u) == 0) {
        /* Its top 4 m below the lowest UAV's volume, so diving there is limited. */
        ok = append(buf, size, &used,
                    ", \"obstacles\": [{\"type\": \"box\", \"min\": [-40, -40, 0], "
                    "\"max\": [40, 40, %.1f]}]",
                    lowest - d->half_height - 4.0);
    }
    if (ok && d->terrain_hills) {
        /* Tops from 8 m below the lowest UAV's volume up to touching it: diving over a
         * hill is limited or impossible. */
        drawn.hills = 1u + coavoid_prng_below(&r, 3u);
        ok = append(buf, size, &used, ", \"obstacles\": [");
        for (uint32_t h = 0; ok && h < drawn.hills; h++) {
            double top = lowest - d->half_height - coavoid_prng_uniform(&r, 0.0, 8.0);
            ok = append(buf, size, &used, "%s", h == 0 ? "" : ", ") &&
                 hill_json(d, &r, top, buf, size, &used);
        }
        ok = ok && append(buf, size, &used, "]");
    }
    if (ok && d->max_tracks > 0) {
        drawn.tracks = coavoid_prng_below(&r, d->max_tracks + 1u);
        ok = append(buf, size, &used, ", \"tracks\": [");
        for (uint32_t t = 0; ok && t < drawn.tracks; t++) {
            ok = append(buf, size, &used, "%s", t == 0 ? "" : ", ") &&
                 track_json(d, &r, 101u + t, buf, size, &used);
        }
        ok = ok && append(buf, size, &used, "]");
    }
    if (info != NULL) {
        *info = drawn;
    }
    return ok && append(buf, size, &used, "}");
}

int coavoid_encounter_save(const char *dir, const char *prefix, uint64_t seed, uint32_t n,
                           uint32_t index, const char *json)
{
    char path[4096];
    int length = snprintf(path, sizeof path, "%s/%s-%llu-%lu-%lu.json", dir, prefix,
                          (unsigned long long)seed, (unsigned long)n, (unsigned long)index);
    if (length < 0 || (size_t)length >= sizeof path) {
        return -1;
    }
    FILE *f = fopen(path, "w");
    if (f == NULL) {
        return -1;
    }
    bool ok = fputs(json, f) >= 0 && fputc('\n', f) != EOF;
    return fclose(f) == 0 && ok ? 0 : -1;
}
