/* SPDX-License-Identifier: MIT */
/*
 * check.c: the firmware check (coavoid-firmware-check.elf). Runs fixed planning problems
 * (check_problems.h, generated from the scenarios in tests/firmware/qemu/) through the core on the
 * target, as the task does (coa_reference_sample, coa_track_sample, coa_plan_decoupled,
 * coa_plan_centralised), and reports every result over ARM semihosting, so that
 * tests/firmware/qemu.sh can run it on an emulated STM32F405 and compare it with the
 * host's `coavoid plan` on the same scenarios. Each problem is also predicted
 * (coa_predict) as `coavoid predict` does with its defaults. Same start-up and linker script as the
 * example firmware; no newlib stdio: the semihosting calls are written here.
 *
 * Output, one line per run (tokens separated by spaces, integers in decimal):
 *   run NAME MODE rc RC status S expanded E generated G effort F deviation_bits HEX
 *       units HI:LO order I,J,.. planned P failed V
 *   offsets NAME MODE VEHICLE_ID o0 o1 ... oN      (one line per planned vehicle)
 *   predict NAME rc RC conflicts C
 *   conflict NAME KIND A_ID B FIRST_STEP FIRST_TIME MIN_H MIN_V PROBABILITY
 *       (B an id, or an obstacle's index; the reals as the hexadecimal bits of the float,
 *       or of the double for the probability)
 *   crypto ...      the message checks on the part, when built with libsodium
 *                   (check_crypto.c, COAVOID_FW_CRYPTO)
 * then `done` and an exit through semihosting (status 0; 1 when a problem could not run
 * or a check gave a wrong result).
 *
 * Each `run` and `predict` line ends with `ticks T`: SysTick ticks of the processor clock
 * around the call. Under qemu -icount shift=0 (virtual time advances 1 ns per guest
 * instruction executed) they count instructions, not time; the first line, `calibrate
 * INSNS TICKS`, times a loop of a known instruction count so that the ratio comes from
 * the run itself rather than from qemu's clock settings. Not cycles: qemu is not
 * cycle-accurate (no wait states, no pipeline).
 */
#include <ccd/config.h>
#include <stdint.h>
#include <string.h>

#include "check_crypto.h"
#include "check_io.h"
#include "firmware.h"

#ifndef CCD_SINGLE
#error "the firmware check needs libccd's single-precision build (cmake/libccd_arm.cmake)"
#endif
#ifndef COA_SINGLE_PRECISION
#error "the firmware check needs the core in single precision (COA_SINGLE_PRECISION)"
#endif

typedef struct {
    const char *name;
    coa_real_t dt;
    uint32_t horizon;
    uint32_t beta;
    size_t planner_bytes; /* the buffer it plans in: 0, the whole of planner_buffer */
    bool decoupled;
    bool centralised;
    const coa_vehicle_t *vehicles;
    size_t vehicle_count;
    const coa_obstacle_t *obstacles;
    size_t obstacle_count;
    const coa_track_t *tracks;
    size_t track_count;
} fwc_problem_t;

#include "check_problems.h"

/* What SRAM leaves beside the 8 KiB stack and the rest: beta 340 for one UAV, 65 for two. */
#define FWC_PLANNER_BYTES (112u * 1024u)
#define FWC_SAMPLES (FWC_MAX_HORIZON + 1u)

static _Alignas(COA_WORKSPACE_ALIGNMENT) unsigned char planner_buffer[FWC_PLANNER_BYTES];
static coa_vec3_t references[FWC_MAX_VEHICLES][FWC_SAMPLES];
static const coa_vec3_t *reference_rows[FWC_MAX_VEHICLES];
static coa_vec3_t track_samples[FWC_MAX_TRACKS][FWC_SAMPLES];
static const coa_vec3_t *track_rows[FWC_MAX_TRACKS];
static int32_t offsets[FWC_MAX_VEHICLES * FWC_SAMPLES];
static coa_vec3_t intent_samples[FWC_MAX_VEHICLES][FWC_SAMPLES];
static coa_intent_plan_t intents[FWC_MAX_VEHICLES];
/* Every pair can conflict: n(n-1)/2 + n (tracks + obstacles), as `coavoid predict` sizes. */
#define FWC_MAX_PAIRS 32u
static coa_conflict_t conflicts[FWC_MAX_PAIRS];

/* The part of planner_buffer problem p plans in. */
static size_t buffer_bytes(const fwc_problem_t *p)
{
    return p->planner_bytes != 0u && p->planner_bytes < sizeof planner_buffer
               ? p->planner_bytes
               : sizeof planner_buffer;
}

static void put_field(const char *key, uint64_t v)
{
    fwc_put(" ");
    fwc_put(key);
    fwc_put(" ");
    fwc_put_u64(v);
}

static void report(const fwc_problem_t *p, const char *mode, int rc, const coa_plan_result_t *r,
                   uint64_t ticks)
{
    uint64_t bits;
    size_t j;
    size_t k;

    memcpy(&bits, &r->deviation, sizeof bits);
    fwc_put("run ");
    fwc_put(p->name);
    fwc_put(" ");
    fwc_put(mode);
    fwc_put(" rc ");
    fwc_put_i64(rc);
    put_field("status", (uint64_t)r->status);
    put_field("expanded", r->nodes_expanded);
    put_field("generated", r->nodes_generated);
    put_field("effort", r->effort);
    fwc_put(" deviation_bits ");
    fwc_put_hex64(bits);
    fwc_put(" units ");
    fwc_put_hex64(r->deviation_units.hi);
    fwc_put(":");
    fwc_put_hex64(r->deviation_units.lo);
    fwc_put(" order ");
    for (j = 0; j < p->vehicle_count; ++j) {
        fwc_put(j == 0u ? "" : ",");
        fwc_put_u64(p->vehicles[r->order[j] < p->vehicle_count ? r->order[j] : 0u].id);
    }
    put_field("planned", r->planned_count);
    fwc_put(" failed ");
    fwc_put(r->failed_vehicle < p->vehicle_count ? "" : "none");
    if (r->failed_vehicle < p->vehicle_count) {
        fwc_put_u64(p->vehicles[r->failed_vehicle].id);
    }
    put_field("ticks", ticks);
    fwc_end_line();
    /* The rows the result says are a plan: the first planned_count of `order`. */
    for (j = 0; j < r->planned_count && j < p->vehicle_count; ++j) {
        size_t i = r->order[j];
        fwc_put("offsets ");
        fwc_put(p->name);
        fwc_put(" ");
        fwc_put(mode);
        fwc_put(" ");
        fwc_put_u64(p->vehicles[i].id);
        for (k = 0; k <= p->horizon; ++k) {
            fwc_put(" ");
            fwc_put_i64(offsets[i * (p->horizon + 1u) + k]);
        }
        fwc_end_line();
    }
}

static void put_real_bits(coa_real_t x)
{
    uint32_t bits;
    memcpy(&bits, &x, sizeof bits);
    fwc_put(" ");
    fwc_put_hex64(bits);
}

static void fail(const fwc_problem_t *p, const char *why)
{
    fwc_put("error ");
    fwc_put(p->name);
    fwc_put(": ");
    fwc_put(why);
    fwc_end_line();
}

/* One prediction cycle as `coavoid predict` runs it with its defaults (predict_cmd.c):
 * each UAV's plan its reference at initial_offset, no sigma on the UAVs, the tracks' own,
 * no sigma growth, threshold 0.01, every pair sized for. The planner's buffer serves the
 * predictor first: the two never run at once. */
static bool run_predict(const fwc_problem_t *p)
{
    static const char *const kinds[] = {"vehicle", "track", "obstacle"};
    const size_t n = p->vehicle_count;
    size_t pairs = n * (n - 1u) / 2u + n * (p->track_count + p->obstacle_count);
    coa_predict_config_t config = {
        .t0 = 0.0f, .dt = p->dt, .horizon = p->horizon, .threshold = 0.01, .all_pairs = false};
    coa_predict_result_t result;
    coa_predictor_t *predictor;
    uint64_t start;
    size_t i;
    size_t k;
    int rc;

    pairs = pairs == 0u ? 1u : pairs;
    if (pairs > FWC_MAX_PAIRS) {
        fail(p, "more pairs than the check's conflict array");
        return false;
    }
    predictor = coa_predictor_init(planner_buffer, sizeof planner_buffer, n, p->track_count,
                                   p->horizon, pairs);
    if (predictor == NULL) {
        fail(p, "the predictor refused its workspace");
        return false;
    }
    for (i = 0; i < n; ++i) {
        const coa_vehicle_t *v = &p->vehicles[i];
        const coa_real_t lift = (coa_real_t)v->initial_offset * coa_climb_step(v, p->dt);
        for (k = 0; k <= p->horizon; ++k) {
            intent_samples[i][k] = references[i][k];
            intent_samples[i][k].z += lift;
        }
        intents[i] = (coa_intent_plan_t){.id = v->id,
                                         .volume = v->volume,
                                         .t0 = 0.0f,
                                         .step = p->dt,
                                         .samples = intent_samples[i],
                                         .count = p->horizon + 1u};
    }
    start = fwc_ticks_now();
    rc = coa_predict(predictor, &config, intents, n, p->obstacles, p->obstacle_count, p->tracks,
                     p->track_count, conflicts, pairs, &result);
    start = fwc_ticks_now() - start;
    fwc_put("predict ");
    fwc_put(p->name);
    fwc_put(" rc ");
    fwc_put_i64(rc);
    put_field("conflicts", rc == COA_OK ? result.conflict_count : 0u);
    put_field("ticks", start);
    fwc_end_line();
    for (i = 0; rc == COA_OK && i < result.conflict_count; ++i) {
        const coa_conflict_t *cf = &conflicts[i];
        uint64_t bits;
        fwc_put("conflict ");
        fwc_put(p->name);
        fwc_put(" ");
        fwc_put(kinds[cf->kind <= COA_CONFLICT_OBSTACLE ? cf->kind : 0]);
        fwc_put(" ");
        fwc_put_u64(p->vehicles[cf->a < n ? cf->a : 0u].id);
        fwc_put(" ");
        if (cf->kind == COA_CONFLICT_VEHICLE) {
            fwc_put_u64(p->vehicles[cf->b < n ? cf->b : 0u].id);
        } else if (cf->kind == COA_CONFLICT_TRACK) {
            fwc_put_u64(p->tracks[cf->b < p->track_count ? cf->b : 0u].id);
        } else {
            fwc_put_u64(cf->b);
        }
        fwc_put(" ");
        fwc_put_u64(cf->first_step);
        put_real_bits(cf->first_time);
        put_real_bits(cf->min_horizontal);
        put_real_bits(cf->min_vertical);
        memcpy(&bits, &cf->probability, sizeof bits);
        fwc_put(" ");
        fwc_put_hex64(bits);
        fwc_end_line();
    }
    return rc == COA_OK;
}

/* Samples the problem as `coavoid plan` does (scenario.c), then plans it in each mode. */
static bool run_problem(const fwc_problem_t *p)
{
    coa_problem_t problem;
    coa_plan_result_t result;
    uint64_t start;
    size_t i;
    int rc;

    if (p->vehicle_count > FWC_MAX_VEHICLES || p->track_count > FWC_MAX_TRACKS ||
        p->horizon > FWC_MAX_HORIZON) {
        fail(p, "larger than the check's arrays");
        return false;
    }
    for (i = 0; i < p->vehicle_count; ++i) {
        if (coa_reference_sample(&p->vehicles[i], p->dt, p->horizon, references[i]) != COA_OK) {
            fail(p, "coa_reference_sample refused a vehicle");
            return false;
        }
        reference_rows[i] = references[i];
    }
    for (i = 0; i < p->track_count; ++i) {
        if (coa_track_sample(&p->tracks[i], p->dt, p->horizon, track_samples[i]) != COA_OK) {
            fail(p, "coa_track_sample refused a track");
            return false;
        }
        track_rows[i] = track_samples[i];
    }
    if (!run_predict(p)) {
        return false;
    }
    problem = (coa_problem_t){.dt = p->dt,
                              .horizon = p->horizon,
                              .vehicles = p->vehicles,
                              .vehicle_count = p->vehicle_count,
                              .references = reference_rows,
                              .obstacles = p->obstacles,
                              .obstacle_count = p->obstacle_count,
                              .tracks = p->tracks,
                              .track_count = p->track_count,
                              .track_samples = track_rows};
    if (p->decoupled) {
        coa_planner_config_t config;
        coa_planner_t *planner = NULL;
        if (coa_planner_config_of(&problem, 1u, p->beta, &config) == COA_OK) {
            planner = coa_planner_init(planner_buffer, buffer_bytes(p), &config);
        }
        if (planner == NULL) {
            fail(p, "decoupled: the planner buffer is too small for this beta");
            return false;
        }
        memset(offsets, 0, sizeof offsets);
        start = fwc_ticks_now();
        rc = coa_plan_decoupled(planner, &problem, NULL, 1u, offsets, &result);
        report(p, "decoupled", rc, &result, fwc_ticks_now() - start);
    }
    if (p->centralised) {
        coa_planner_config_t config;
        coa_planner_t *planner = NULL;
        if (coa_planner_config_of(&problem, p->vehicle_count, p->beta, &config) == COA_OK) {
            planner = coa_planner_init(planner_buffer, buffer_bytes(p), &config);
        }
        if (planner == NULL) {
            fail(p, "centralised: the planner buffer is too small for this beta");
            return false;
        }
        memset(offsets, 0, sizeof offsets);
        start = fwc_ticks_now();
        rc = coa_plan_centralised(planner, &problem, offsets, &result);
        report(p, "centralised", rc, &result, fwc_ticks_now() - start);
    }
    return true;
}

int main(void)
{
    bool ok = true;
    uint64_t start;
    size_t p;

    fwc_put("coavoid firmware check: ");
    fwc_put_u64(FWC_PROBLEM_COUNT);
    fwc_put(" problems");
    fwc_end_line();
    fwc_ticks_start();
    start = fwc_ticks_now();
    fwc_spin(1000000u);
    start = fwc_ticks_now() - start;
    fwc_put("calibrate ");
    fwc_put_u64(2u * 1000000u + 1u);
    fwc_put(" ");
    fwc_put_u64(start);
    fwc_end_line();
    for (p = 0; p < FWC_PROBLEM_COUNT; ++p) {
        ok = run_problem(&fwc_problems[p]) && ok;
    }
#ifdef COAVOID_FW_CRYPTO
    ok = fwc_crypto_run(planner_buffer, sizeof planner_buffer) && ok;
#endif
    fwc_put(ok ? "done" : "done with errors");
    fwc_end_line();
    fwc_exit(ok);
    return ok ? 0 : 1;
}
