/* SPDX-License-Identifier: MIT */
/*
 * test_flight.c: the flight record (src/flight/flight.h): loss of separation by the
 * contract's semantics on hand-made flights whose answers are known (an exact touch is
 * not a loss, a centimetre closer is, at the step where it happens), costs against hand
 * values and coa_plan_vehicle_cost, the pairwise listing against the core's answer on
 * random flights, the JSON read back field by field, and the SVG's shape.
 *
 * The same executable writes lcm-logger-format logs for tests/cli/summary.sh when run as
 *     test_flight --write-log OUT.log SCENARIO.json reference|planned [OPTION...]
 * (see write_log below), so that the command's tests need no logger and no network.
 */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <math.h>

#include <time.h>

#include <cjson/cJSON.h>
#include <lcm/eventlog.h>
#include <lcm/lcm.h>

#include "coavoid_lcm.h"
#include "flight.h"
#include "node.h"
#include "scenario.h"
#include "test_support.h"

/* ---- hand-made flights ---- */

#define MAX_K 64u

typedef struct {
    coa_vec3_t route[COA_MAX_VEHICLES][2];
    coa_vec3_t reference[COA_MAX_VEHICLES][MAX_K + 1u];
    int32_t offsets[COA_MAX_VEHICLES][MAX_K + 1u];
    coavoid_flight_vehicle_t vehicles[COA_MAX_VEHICLES];
    coa_obstacle_t obstacles[4];
    coa_track_t tracks[4];
    coavoid_flight_t flight;
    double vehicle_deviation[COA_MAX_VEHICLES];
    uint32_t vehicle_effort[COA_MAX_VEHICLES];
    coavoid_flight_eval_t eval;
} fixture_t;

static void fixture_init(fixture_t *f, uint32_t steps)
{
    memset(f, 0, sizeof *f);
    f->flight.scenario = "hand-made";
    f->flight.mode = "centralised";
    f->flight.dt = (coa_real_t)1;
    f->flight.steps = steps;
    f->flight.vehicles = f->vehicles;
    f->flight.obstacles = f->obstacles;
    f->flight.tracks = f->tracks;
    f->eval.vehicle_deviation = f->vehicle_deviation;
    f->eval.vehicle_effort = f->vehicle_effort;
}

static coa_vec3_t vec(double x, double y, double z)
{
    coa_vec3_t v = {(coa_real_t)x, (coa_real_t)y, (coa_real_t)z};
    return v;
}

/* A UAV of the paper's kind (10 m/s, climbs 2 m/s, radius 15, half-height 5) flying from
 * a to b, its reference sampled over the run, level at offset 0. */
static size_t add_uav(fixture_t *f, coa_vec3_t a, coa_vec3_t b)
{
    size_t i = f->flight.vehicle_count++;
    coa_vehicle_t *v = &f->vehicles[i].vehicle;
    f->route[i][0] = a;
    f->route[i][1] = b;
    v->id = (uint16_t)(i + 1u);
    v->priority = (uint32_t)(i + 1u);
    v->cruise_speed = (coa_real_t)10;
    v->climb_rate = (coa_real_t)2;
    v->steep_factor = 2u;
    v->volume.radius = (coa_real_t)15;
    v->volume.half_height = (coa_real_t)5;
    v->route = f->route[i];
    v->route_count = 2u;
    v->max_offset = -1;
    ck_assert_int_eq(coa_reference_sample(v, f->flight.dt, f->flight.steps, f->reference[i]),
                     COA_OK);
    f->vehicles[i].reference = f->reference[i];
    f->vehicles[i].offsets = f->offsets[i];
    f->vehicles[i].known = NULL;
    return i;
}

static void add_box(fixture_t *f, coa_vec3_t min, coa_vec3_t max)
{
    coa_obstacle_t *o = &f->obstacles[f->flight.obstacle_count++];
    o->kind = COA_OBSTACLE_BOX;
    o->box.min = min;
    o->box.max = max;
}

static void set_offsets(fixture_t *f, size_t i, const int32_t *values, size_t count)
{
    for (uint32_t k = 0; k <= f->flight.steps; k++) {
        f->offsets[i][k] = values[k < count ? k : count - 1u];
    }
}

/* ---- evaluation ---- */

/* Two UAVs on parallel lines exactly r_a + r_b = 30 m apart pass each other head-on at
 * the same altitude: touching all the way through the pass, never a loss. */
START_TEST(test_exact_touch_is_not_a_loss)
{
    fixture_t f;
    fixture_init(&f, 30u);
    add_uav(&f, vec(0, 0, 100), vec(600, 0, 100));
    add_uav(&f, vec(305, 30, 100), vec(-295, 30, 100));
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(!f.eval.loss_of_separation);
    ck_assert_uint_eq(f.eval.first_vehicle, COA_NO_VEHICLE);
    ck_assert(f.eval.deviation == 0.0);
    ck_assert_uint_eq(f.eval.effort, 0u);
    size_t found = 99;
    ck_assert_int_eq(coavoid_flight_conflicts(&f.flight, COAVOID_FLIGHT_FLOWN, NULL, 0u, &found),
                     COA_OK);
    ck_assert_uint_eq(found, 0u);

    /* Vertically as well: one above the other by exactly h_a + h_b = 10 m, on one line. */
    fixture_init(&f, 30u);
    add_uav(&f, vec(0, 0, 100), vec(600, 0, 100));
    add_uav(&f, vec(305, 0, 110), vec(-295, 0, 110));
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(!f.eval.loss_of_separation);
}
END_TEST

/* A centimetre closer, horizontally or vertically, is a loss, over the step in which they
 * meet: x = 10 t and x = 305 - 10 t meet at t = 15.25, inside step 15. */
START_TEST(test_a_centimetre_closer_is_a_loss)
{
    fixture_t f;
    coavoid_flight_conflict_t list[8];
    size_t found = 0;
    fixture_init(&f, 30u);
    add_uav(&f, vec(0, 0, 100), vec(600, 0, 100));
    add_uav(&f, vec(305, 29.99, 100), vec(-295, 29.99, 100));
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(f.eval.loss_of_separation);
    ck_assert_uint_eq(f.eval.first_vehicle, 0u);
    ck_assert_uint_eq(f.eval.first_step, 15u);
    ck_assert_int_eq(coavoid_flight_conflicts(&f.flight, COAVOID_FLIGHT_FLOWN, list, 8u, &found),
                     COA_OK);
    /* Within 0.77 m of the meeting point only: one step. */
    ck_assert_uint_eq(found, 1u);
    ck_assert_int_eq(list[0].kind, COA_CONFLICT_VEHICLE);
    ck_assert_uint_eq(list[0].vehicle, 0u);
    ck_assert_uint_eq(list[0].other, 1u);
    ck_assert_uint_eq(list[0].step, 15u);

    fixture_init(&f, 30u);
    add_uav(&f, vec(0, 0, 100), vec(600, 0, 100));
    add_uav(&f, vec(305, 0, 109.99), vec(-295, 0, 109.99));
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(f.eval.loss_of_separation);
    /* Horizontal distance 30 is reached at t = 13.75 (x 137.5 and 167.5): step 13. */
    ck_assert_uint_eq(f.eval.first_step, 13u);

    /* The same pair, the second UAV climbing out of the way in time: flown offsets are
     * what is judged, not the references. */
    int32_t climb[] = {0, 1, 2, 3, 4, 5, 6};
    set_offsets(&f, 1, climb, sizeof climb / sizeof climb[0]);
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(!f.eval.loss_of_separation);
    ck_assert_int_eq(
        coavoid_flight_conflicts(&f.flight, COAVOID_FLIGHT_REFERENCE, list, 8u, &found), COA_OK);
    ck_assert_uint_ge(found, 1u); /* the references still would have */
}
END_TEST

/* The paper's terrain: a box 100..200 m east, up to 104 m. A UAV at 100 m with radius 15
 * reaches it at x = 85 (t = 8.5, step 8); one that has climbed to 110 m by then clears it
 * (half-height 5 above 104 is 109). */
START_TEST(test_through_a_box)
{
    fixture_t f;
    coavoid_flight_conflict_t list[64];
    size_t found = 0;
    fixture_init(&f, 30u);
    add_uav(&f, vec(0, 0, 100), vec(600, 0, 100));
    add_box(&f, vec(100, -60, 0), vec(200, 60, 104));
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(f.eval.loss_of_separation);
    ck_assert_uint_eq(f.eval.first_vehicle, 0u);
    ck_assert_uint_eq(f.eval.first_step, 8u);
    ck_assert_int_eq(coavoid_flight_conflicts(&f.flight, COAVOID_FLIGHT_FLOWN, list, 64u, &found),
                     COA_OK);
    /* Steps 8..21: x from 80 to 220 overlaps 85..215 in each. */
    ck_assert_uint_eq(found, 14u);
    for (size_t c = 0; c < found; c++) {
        ck_assert_int_eq(list[c].kind, COA_CONFLICT_OBSTACLE);
        ck_assert_uint_eq(list[c].other, 0u);
        ck_assert_uint_eq(list[c].step, 8u + c);
    }

    /* Up by 5 climb steps (10 m) by t = 5, held over the box, back down after it. */
    int32_t over[] = {0, 1, 2, 3, 4, 5, 5, 5, 5, 5, 5, 5, 5, 5,
                      5, 5, 5, 5, 5, 5, 5, 5, 5, 4, 3, 2, 1, 0};
    set_offsets(&f, 0, over, sizeof over / sizeof over[0]);
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(!f.eval.loss_of_separation);
    /* One step too late down (offset 4 at k = 21, x = 210 < 215): a loss at step 20. */
    over[21] = 4;
    over[22] = 3;
    over[23] = 2;
    over[24] = 1;
    over[25] = 0;
    set_offsets(&f, 0, over, 26u);
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(f.eval.loss_of_separation);
    ck_assert_uint_eq(f.eval.first_step, 20u);
}
END_TEST

/* A track crossing the UAV's path: x = 10 t against (150, -150 + 10 t); horizontal
 * distance sqrt(2) |10 t - 150| < 15 + 20 from t = 12.53: step 12. */
START_TEST(test_track_crossing)
{
    fixture_t f;
    coavoid_flight_conflict_t list[32];
    size_t found = 0;
    fixture_init(&f, 30u);
    add_uav(&f, vec(0, 0, 100), vec(400, 0, 100));
    coa_track_t *t = &f.tracks[f.flight.track_count++];
    t->id = 901u;
    t->volume.radius = (coa_real_t)20;
    t->volume.half_height = (coa_real_t)8;
    t->position = vec(150, -150, 102);
    t->velocity = vec(0, 10, 0);
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(f.eval.loss_of_separation);
    ck_assert_uint_eq(f.eval.first_step, 12u);
    ck_assert_int_eq(coavoid_flight_conflicts(&f.flight, COAVOID_FLIGHT_FLOWN, list, 32u, &found),
                     COA_OK);
    ck_assert_uint_ge(found, 1u);
    ck_assert_int_eq(list[0].kind, COA_CONFLICT_TRACK);
    ck_assert_uint_eq(list[0].other, 0u);
    ck_assert_uint_eq(list[0].step, 12u);

    /* Above it by the sum of half-heights (5 + 8 above 102: z 115, offset 7.5): offset 8
     * from t = 8 on clears it; offset 7 (z 114) does not. */
    int32_t up8[] = {0, 1, 2, 3, 4, 5, 6, 7, 8};
    set_offsets(&f, 0, up8, 9u);
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(!f.eval.loss_of_separation);
    int32_t up7[] = {0, 1, 2, 3, 4, 5, 6, 7};
    set_offsets(&f, 0, up7, 8u);
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(f.eval.loss_of_separation);
}
END_TEST

/* Costs: L = cruise_speed * dt = 10 m, dh = 2 m; deviation = L dh sum A(a, b). */
START_TEST(test_costs_by_hand)
{
    fixture_t f;
    fixture_init(&f, 10u);
    add_uav(&f, vec(0, 0, 100), vec(600, 0, 100));
    add_uav(&f, vec(0, 500, 100), vec(600, 500, 100));
    /* UAV 1: steep climb 0->2 (A 1, effort 3), climb 2->3 (2.5, 1), level 3->3 (3, 0),
     * steep dive 3->1 (2, 3), steep dive 1->-1 (crosses: (1 + 1) / 4 = 0.5, 3), climb
     * -1->0 (0.5, 1), then level at 0: A 9.5, effort 11, deviation 20 * 9.5 = 190. */
    int32_t a[] = {0, 2, 3, 3, 1, -1, 0};
    /* UAV 2: dive 0->-1 (0.5, 1), level -1 for the 9 remaining steps (9, 0): A 9.5,
     * effort 1. */
    int32_t b[] = {0, -1};
    set_offsets(&f, 0, a, sizeof a / sizeof a[0]);
    set_offsets(&f, 1, b, sizeof b / sizeof b[0]);
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(!f.eval.loss_of_separation);
    ck_assert(f.vehicle_deviation[0] == 190.0);
    ck_assert_uint_eq(f.vehicle_effort[0], 11u);
    ck_assert(f.vehicle_deviation[1] == 190.0);
    ck_assert_uint_eq(f.vehicle_effort[1], 1u);
    ck_assert(f.eval.deviation == 380.0);
    ck_assert_uint_eq(f.eval.effort, 12u);
    for (size_t i = 0; i < 2u; i++) {
        double deviation = -1;
        uint32_t effort = 0;
        ck_assert_int_eq(coa_plan_vehicle_cost(&f.vehicles[i].vehicle, f.flight.dt, 10u,
                                               f.offsets[i], &deviation, &effort),
                         COA_OK);
        ck_assert(deviation == f.vehicle_deviation[i]);
        ck_assert_uint_eq(effort, f.vehicle_effort[i]);
    }
    /* The per-vehicle arrays are optional. */
    f.eval.vehicle_deviation = NULL;
    f.eval.vehicle_effort = NULL;
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(f.eval.deviation == 380.0);
}
END_TEST

START_TEST(test_refusals)
{
    fixture_t f;
    fixture_init(&f, 10u);
    add_uav(&f, vec(0, 0, 100), vec(600, 0, 100));
    /* 0 -> 3 with steep factor 2: no action does that. */
    int32_t jump[] = {0, 0, 3};
    set_offsets(&f, 0, jump, 3u);
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_ERR_ARGUMENT);
    /* The figure and the listing judge geometry only: they still work. */
    size_t found = 0;
    ck_assert_int_eq(coavoid_flight_conflicts(&f.flight, COAVOID_FLIGHT_FLOWN, NULL, 0u, &found),
                     COA_OK);
    int32_t ok[] = {0, 1, 3};
    set_offsets(&f, 0, ok, 3u);
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);

    ck_assert_int_eq(coavoid_flight_evaluate(NULL, &f.eval), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, NULL), COA_ERR_ARGUMENT);
    f.flight.steps = 0u;
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_ERR_ARGUMENT);
    f.flight.steps = COA_MAX_HORIZON + 1u;
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_ERR_ARGUMENT);
    f.flight.steps = 10u;
    f.flight.dt = (coa_real_t)0;
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_ERR_ARGUMENT);
    f.flight.dt = (coa_real_t)1;
    f.vehicles[0].offsets = NULL;
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_ERR_ARGUMENT);
    f.vehicles[0].offsets = f.offsets[0];
    /* A non-finite flown reference: what the core refuses. */
    f.reference[0][4].z = (coa_real_t)NAN;
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_ERR_ARGUMENT);
    ck_assert_int_eq(coavoid_flight_conflicts(&f.flight, COAVOID_FLIGHT_FLOWN, NULL, 0u, &found),
                     COA_ERR_ARGUMENT);
    ck_assert_int_eq(coavoid_flight_svg(&f.flight, NULL, stderr), COA_ERR_ARGUMENT);
    f.reference[0][4].z = (coa_real_t)100;
    /* Two UAVs with one id. */
    add_uav(&f, vec(0, 500, 100), vec(600, 500, 100));
    f.vehicles[1].vehicle.id = f.vehicles[0].vehicle.id;
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_ERR_ARGUMENT);
}
END_TEST

/* The pairwise listing is the evaluation's answer in full: on random flights among boxes
 * and a track, it is empty exactly when no separation is lost, and its first entry is the
 * core's first (step, UAV). */
START_TEST(test_listing_agrees_with_the_core)
{
    uint64_t seed = 0x5eed0f11u;
    int lost = 0;
    for (int trial = 0; trial < 300; trial++) {
        fixture_t f;
        uint32_t steps = 4u + pick(&seed, 20u);
        fixture_init(&f, steps);
        size_t n = 1u + pick(&seed, 4u);
        for (size_t i = 0; i < n; i++) {
            double x = unif(&seed, -100, 100), y = unif(&seed, -100, 100);
            double heading = unif(&seed, 0, 6.283185307179586);
            double z = unif(&seed, 90, 110);
            size_t v =
                add_uav(&f, vec(x, y, z), vec(x + 1000 * cos(heading), y + 1000 * sin(heading), z));
            int32_t o = (int32_t)pick(&seed, 5u) - 2;
            for (uint32_t k = 0; k <= steps; k++) {
                f.offsets[v][k] = o;
                static const int32_t deltas[] = {0, 1, -1, 2, -2};
                o += deltas[pick(&seed, 5u)];
            }
        }
        if (pick(&seed, 2u) == 0u) {
            double x = unif(&seed, -150, 150), y = unif(&seed, -150, 150);
            add_box(&f, vec(x, y, 0),
                    vec(x + unif(&seed, 5, 60), y + unif(&seed, 5, 60), unif(&seed, 80, 105)));
        }
        if (pick(&seed, 2u) == 0u) {
            coa_track_t *t = &f.tracks[f.flight.track_count++];
            t->id = 7u;
            t->volume.radius = (coa_real_t)10;
            t->volume.half_height = (coa_real_t)4;
            t->position = vec(unif(&seed, -150, 150), unif(&seed, -150, 150), unif(&seed, 90, 110));
            t->velocity = vec(unif(&seed, -15, 15), unif(&seed, -15, 15), unif(&seed, -1, 1));
        }
        REQUIRE(coavoid_flight_evaluate(&f.flight, &f.eval) == COA_OK);
        coavoid_flight_conflict_t list[512];
        size_t found = 0;
        REQUIRE(coavoid_flight_conflicts(&f.flight, COAVOID_FLIGHT_FLOWN, list, 512u, &found) ==
                COA_OK);
        REQUIRE((found > 0u) == f.eval.loss_of_separation);
        if (found > 0u) {
            lost++;
            REQUIRE(list[0].step == f.eval.first_step);
            REQUIRE(list[0].vehicle == f.eval.first_vehicle);
        }
    }
    /* Both answers occurred often enough to mean something. */
    ck_assert_int_gt(lost, 30);
    ck_assert_int_lt(lost, 270);
}
END_TEST

/* ---- JSON ---- */

static char *capture(int (*writer)(const coavoid_flight_t *, const coavoid_flight_eval_t *, FILE *),
                     const coavoid_flight_t *flight, const coavoid_flight_eval_t *eval, int *rc)
{
    char *text = NULL;
    size_t size = 0;
    FILE *mem = open_memstream(&text, &size);
    ck_assert_ptr_nonnull(mem);
    *rc = writer(flight, eval, mem);
    ck_assert_int_eq(fclose(mem), 0);
    return text;
}

static double number(const cJSON *obj, const char *key)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    ck_assert_msg(cJSON_IsNumber(item), "%s is not a number", key);
    return item->valuedouble;
}

START_TEST(test_json_fields)
{
    fixture_t f;
    int rc;
    fixture_init(&f, 12u);
    f.flight.dt = (coa_real_t)0.5;
    add_uav(&f, vec(0, 0, 100), vec(600, 0, 100));
    add_uav(&f, vec(100, 0, 100), vec(-500, 0, 100));
    int32_t climb[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    set_offsets(&f, 0, climb, 13u);
    f.flight.replans = 4u;
    bool known[2][13];
    for (int k = 0; k < 13; k++) {
        known[0][k] = true;
        known[1][k] = k != 3 && k != 4;
    }
    f.vehicles[0].known = known[0];
    f.vehicles[1].known = known[1];
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(f.eval.loss_of_separation);
    char *text = capture(coavoid_flight_json, &f.flight, &f.eval, &rc);
    ck_assert_int_eq(rc, COA_OK);
    cJSON *root = cJSON_Parse(text);
    ck_assert_ptr_nonnull(root);
    ck_assert_str_eq(cJSON_GetObjectItemCaseSensitive(root, "scenario")->valuestring, "hand-made");
    ck_assert_str_eq(cJSON_GetObjectItemCaseSensitive(root, "mode")->valuestring, "centralised");
    ck_assert(number(root, "steps") == 12.0);
    ck_assert(number(root, "replans") == 4.0);
    ck_assert(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(root, "loss_of_separation")));
    ck_assert(number(root, "deviation") == f.eval.deviation);
    ck_assert(number(root, "effort") == (double)f.eval.effort);
    const cJSON *first = cJSON_GetObjectItemCaseSensitive(root, "first_loss");
    ck_assert(number(first, "vehicle") == 1.0);
    ck_assert(number(first, "step") == (double)f.eval.first_step);
    ck_assert(number(first, "t") == (double)f.eval.first_step * 0.5);
    const cJSON *vehicles = cJSON_GetObjectItemCaseSensitive(root, "vehicles");
    ck_assert_int_eq(cJSON_GetArraySize(vehicles), 2);
    for (int i = 0; i < 2; i++) {
        const cJSON *v = cJSON_GetArrayItem(vehicles, i);
        ck_assert(number(v, "id") == (double)(i + 1));
        ck_assert(number(v, "deviation") == f.vehicle_deviation[i]);
        ck_assert(number(v, "effort") == (double)f.vehicle_effort[i]);
        ck_assert(number(v, "unknown_samples") == (i == 0 ? 0.0 : 2.0));
        const cJSON *flown = cJSON_GetObjectItemCaseSensitive(v, "flown");
        ck_assert_int_eq(cJSON_GetArraySize(flown), 13);
        for (int k = 0; k <= 12; k++) {
            const cJSON *s = cJSON_GetArrayItem(flown, k);
            ck_assert_int_eq(cJSON_GetArraySize(s), 4);
            coa_vec3_t p =
                coavoid_flight_position(&f.flight, (size_t)i, (uint32_t)k, f.offsets[i][k]);
            /* Round trip: exactly the planner's positions. */
            ck_assert(cJSON_GetArrayItem(s, 0)->valuedouble == (double)k * 0.5);
            ck_assert(cJSON_GetArrayItem(s, 1)->valuedouble == (double)p.x);
            ck_assert(cJSON_GetArrayItem(s, 2)->valuedouble == (double)p.y);
            ck_assert(cJSON_GetArrayItem(s, 3)->valuedouble == (double)p.z);
            coa_real_t z = f.reference[i][k].z +
                           (coa_real_t)f.offsets[i][k] * ((coa_real_t)2 * (coa_real_t)0.5);
            ck_assert(p.z == z);
        }
    }
    cJSON_Delete(root);
    free(text);

    /* No loss: no first_loss; no per-vehicle arrays or known: none of their fields. */
    fixture_init(&f, 12u);
    add_uav(&f, vec(0, 0, 100), vec(600, 0, 100));
    add_uav(&f, vec(0, 400, 100), vec(600, 400, 100));
    add_uav(&f, vec(0, 900, 100), vec(600, 900, 100));
    f.eval.vehicle_deviation = NULL;
    f.eval.vehicle_effort = NULL;
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(!f.eval.loss_of_separation);
    text = capture(coavoid_flight_json, &f.flight, &f.eval, &rc);
    ck_assert_int_eq(rc, COA_OK);
    root = cJSON_Parse(text);
    ck_assert_ptr_nonnull(root);
    ck_assert(cJSON_IsFalse(cJSON_GetObjectItemCaseSensitive(root, "loss_of_separation")));
    ck_assert_ptr_null(cJSON_GetObjectItemCaseSensitive(root, "first_loss"));
    const cJSON *v0 = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(root, "vehicles"), 0);
    ck_assert_ptr_null(cJSON_GetObjectItemCaseSensitive(v0, "deviation"));
    ck_assert_ptr_null(cJSON_GetObjectItemCaseSensitive(v0, "unknown_samples"));
    ck_assert_int_eq(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(root, "vehicles")), 3);
    cJSON_Delete(root);
    free(text);

    ck_assert_int_eq(coavoid_flight_json(&f.flight, NULL, stdout), COA_ERR_ARGUMENT);
}
END_TEST

/* ---- SVG ---- */

/* Whether the document's elements nest properly: every <name ...> is closed by </name>
 * (or is <.../>), comments and the XML declaration aside. A small check, not a parser:
 * the shell test runs a real one. */
static bool balanced(const char *doc)
{
    char stack[64][32];
    size_t depth = 0;
    const char *c = doc;
    while ((c = strchr(c, '<')) != NULL) {
        if (c[1] == '?' || c[1] == '!') {
            c++;
            continue;
        }
        bool closing = c[1] == '/';
        const char *name = c + (closing ? 2 : 1);
        size_t length = strcspn(name, " \t\n/>");
        const char *end = strchr(c, '>');
        if (end == NULL || length == 0 || length >= 32) {
            return false;
        }
        bool self = end[-1] == '/';
        if (closing) {
            if (depth == 0 || strncmp(stack[depth - 1], name, length) != 0 ||
                stack[depth - 1][length] != '\0') {
                return false;
            }
            depth--;
        } else if (!self) {
            if (depth == 64) {
                return false;
            }
            memcpy(stack[depth], name, length);
            stack[depth][length] = '\0';
            depth++;
        }
        c = end + 1;
    }
    return depth == 0;
}

START_TEST(test_svg_shape)
{
    fixture_t f;
    int rc;
    fixture_init(&f, 30u);
    /* A name that must be escaped, with a byte that is not UTF-8. */
    f.flight.scenario = "a <b> & \"c\" \xff\x01 d";
    add_uav(&f, vec(0, 0, 100), vec(600, 0, 100));
    add_uav(&f, vec(305, 29.99, 100), vec(-295, 29.99, 100));
    add_box(&f, vec(100, -60, 0), vec(200, 60, 104));
    static const coa_vec3_t hill[5] = {
        {300, -50, 0}, {400, -50, 0}, {400, 50, 0}, {300, 50, 0}, {350, 0, 60}};
    coa_obstacle_t *o = &f.obstacles[f.flight.obstacle_count++];
    o->kind = COA_OBSTACLE_POLYTOPE;
    o->polytope.vertices = hill;
    o->polytope.count = 5u;
    coa_track_t *t = &f.tracks[f.flight.track_count++];
    t->id = 901u;
    t->volume.radius = (coa_real_t)20;
    t->volume.half_height = (coa_real_t)8;
    t->position = vec(150, -150, 102);
    t->velocity = vec(0, 10, 0);
    bool known[31];
    for (int k = 0; k <= 30; k++) {
        known[k] = k < 20;
    }
    f.vehicles[1].known = known;
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    ck_assert(f.eval.loss_of_separation);
    char *doc = capture(coavoid_flight_svg, &f.flight, &f.eval, &rc);
    ck_assert_int_eq(rc, COA_OK);
    ck_assert_msg(strncmp(doc, "<svg", 4) == 0, "starts with %.20s", doc);
    size_t length = strlen(doc);
    ck_assert(length > 7u && strcmp(doc + length - 7u, "</svg>\n") == 0);
    ck_assert(balanced(doc));
    ck_assert_ptr_null(strstr(doc, "<script"));
    ck_assert_ptr_null(strstr(doc, "xlink"));
    ck_assert_ptr_nonnull(strstr(doc, "a &lt;b&gt; &amp; &quot;c&quot; ?? d"));
    ck_assert_ptr_null(strstr(doc, "\xff"));
    /* Every reference is to a clip path of its own. */
    for (const char *u = strstr(doc, "url("); u != NULL; u = strstr(u + 1, "url(")) {
        ck_assert(strncmp(u, "url(#clip-", 10) == 0);
    }
    ck_assert_ptr_nonnull(strstr(doc, "LOSS OF SEPARATION"));
    ck_assert_ptr_nonnull(strstr(doc, "no intent in the log"));
    ck_assert_ptr_nonnull(strstr(doc, "track 901"));
    ck_assert_ptr_nonnull(strstr(doc, "obstacle 1 (bounding box)"));
    free(doc);

    /* Without an evaluation: no result line, still a document. */
    doc = capture(coavoid_flight_svg, &f.flight, NULL, &rc);
    ck_assert_int_eq(rc, COA_OK);
    ck_assert(balanced(doc));
    ck_assert_ptr_null(strstr(doc, "LOSS OF SEPARATION"));
    free(doc);
}
END_TEST

START_TEST(test_text)
{
    fixture_t f;
    int rc;
    fixture_init(&f, 30u);
    add_uav(&f, vec(0, 0, 100), vec(600, 0, 100));
    add_box(&f, vec(100, -60, 0), vec(200, 60, 104));
    ck_assert_int_eq(coavoid_flight_evaluate(&f.flight, &f.eval), COA_OK);
    char *text = capture(coavoid_flight_text, &f.flight, &f.eval, &rc);
    ck_assert_int_eq(rc, COA_OK);
    ck_assert_ptr_nonnull(strstr(text, "loss of separation: yes, first over step 8 (t = 8 s): "
                                       "UAV 1 and obstacle 0"));
    free(text);
}
END_TEST

static Suite *flight_suite(void)
{
    Suite *s = suite_create("flight");
    TCase *tc = tcase_create("flight");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_exact_touch_is_not_a_loss);
    tcase_add_test(tc, test_a_centimetre_closer_is_a_loss);
    tcase_add_test(tc, test_through_a_box);
    tcase_add_test(tc, test_track_crossing);
    tcase_add_test(tc, test_costs_by_hand);
    tcase_add_test(tc, test_refusals);
    tcase_add_test(tc, test_listing_agrees_with_the_core);
    tcase_add_test(tc, test_json_fields);
    tcase_add_test(tc, test_svg_shape);
    tcase_add_test(tc, test_text);
    suite_add_tcase(s, tc);
    return s;
}

/* ---- writing logs for tests/cli/summary.sh ---- */

/*
 * test_flight --write-log OUT.log SCENARIO.json KIND [OPTION...]
 *
 * or, to publish the same messages instead of writing them (for a real lcm-logger),
 * test_flight --publish LCM_URL SCENARIO.json KIND [OPTION...]
 *
 * Writes what a run of the scenario would have put in an lcm-logger log: every UAV's intent
 * at each cycle c = 0..2N (sample 0 at cycle c's start, N + 1 samples), heartbeats of each
 * UAV and of a coordinator, and with KIND "planned" one plan_t at cycle 0. KIND:
 *   reference  every UAV flies its reference at its initial offset (no manoeuvre);
 *   planned    a centralised plan over N steps from cycle 0 (the coordinator's), flown
 *              to its end and held there.
 * OPTIONs:
 *   drop=ID:C   leave out UAV ID's intent of cycle C (up to 8 of them)
 *   skip=ID     never publish UAV ID's intents
 *   cycles=C    publish cycles 0..C-1 only
 *   junk        also a refused intent (NaN position), an intent of a UAV not in the
 *               scenario, and an event on another channel
 *   step=S      intents claim a step of S seconds
 *   stale=ID:C  at the end of the log, UAV ID's intent of cycle C again (a higher
 *               sequence number) but level from its sample 0: an abandoned plan logged
 *               late, which must not replace the samples of the intents after it
 * Times: the epoch is 1700000000000000 us; a UAV's intent is logged 100 us * its index
 * after its cycle's start.
 */
#define LOG_EPOCH INT64_C(1700000000000000)

typedef struct {
    lcm_eventlog_t *log; /* --write-log */
    lcm_t *lcm;          /* --publish */
    uint8_t buffer[20000];
} log_writer_t;

static int put_event(log_writer_t *w, int64_t utime, const char *channel, int size)
{
    if (w->lcm != NULL) {
        return size < 0 ? -1 : lcm_publish(w->lcm, channel, w->buffer, (unsigned int)size);
    }
    lcm_eventlog_event_t e;
    memset(&e, 0, sizeof e);
    e.timestamp = utime;
    e.channellen = (int32_t)strlen(channel);
    e.channel = (char *)channel;
    e.datalen = size;
    e.data = w->buffer;
    return size < 0 ? -1 : lcm_eventlog_write_event(w->log, &e);
}

static int fail_writer(const char *what)
{
    fprintf(stderr, "test_flight --write-log: %s\n", what);
    return 2;
}

static int write_log(int argc, char **argv)
{
    if (argc < 5) {
        return fail_writer("usage: test_flight --write-log OUT.log|--publish URL SCENARIO.json "
                           "reference|planned [OPTION...]");
    }
    const char *out_path = argv[2];
    const bool publish = strcmp(argv[1], "--publish") == 0;
    const char *kind = argv[4];
    bool planned = strcmp(kind, "planned") == 0;
    if (!planned && strcmp(kind, "reference") != 0) {
        return fail_writer("KIND must be reference or planned");
    }
    long drop_id[8], drop_cycle[8], skip_id = -1, cycles = -1;
    size_t drops = 0;
    double step_claim = 0.0;
    long stale_id = -1, stale_cycle = -1;
    bool junk = false;
    for (int a = 5; a < argc; a++) {
        if (drops < 8u &&
            sscanf(argv[a], "drop=%ld:%ld", &drop_id[drops], &drop_cycle[drops]) == 2) {
            drops++;
            continue;
        }
        if (sscanf(argv[a], "skip=%ld", &skip_id) == 1 ||
            sscanf(argv[a], "cycles=%ld", &cycles) == 1 ||
            sscanf(argv[a], "step=%lf", &step_claim) == 1 ||
            sscanf(argv[a], "stale=%ld:%ld", &stale_id, &stale_cycle) == 2) {
            continue;
        }
        if (strcmp(argv[a], "junk") == 0) {
            junk = true;
            continue;
        }
        return fail_writer("unknown option");
    }

    coavoid_scenario_t s;
    char err[COAVOID_SCENARIO_ERROR_MAX];
    if (coavoid_scenario_load(argv[3], &s, err, sizeof err) != 0 ||
        coavoid_scenario_sample(&s, err, sizeof err) != 0) {
        coavoid_scenario_free(&s);
        return fail_writer(err);
    }
    const size_t n = s.vehicle_count;
    const uint32_t N = s.horizon;
    const int64_t dt_us = llround((double)s.dt * 1e6);
    const size_t row = (size_t)N + 1u;
    if (N + 1u > (uint32_t)COAVOID_INTENT_T_MAX_SAMPLES) {
        coavoid_scenario_free(&s);
        return fail_writer("horizon too long for an intent");
    }
    int32_t *plan = calloc(n * row, sizeof *plan);
    coa_vec3_t *reference = calloc(n * (3u * row), sizeof *reference);
    log_writer_t *w = calloc(1, sizeof *w);
    coavoid_intent_t *msg = calloc(1, sizeof *msg);
    coavoid_plan_t *plan_msg = calloc(1, sizeof *plan_msg);
    coavoid_intent_t *stale = calloc(1, sizeof *stale);
    bool have_stale = false;
    int status = 0;
    if (plan == NULL || reference == NULL || w == NULL || msg == NULL || plan_msg == NULL ||
        stale == NULL) {
        status = fail_writer("out of memory");
        goto done;
    }
    for (size_t i = 0; i < n; i++) {
        for (size_t k = 0; k < row; k++) {
            plan[i * row + k] = s.vehicles[i].initial_offset;
        }
        if (coa_reference_sample(&s.vehicles[i], s.dt, 3u * N, &reference[i * 3u * row]) !=
            COA_OK) {
            status = fail_writer("cannot sample a reference");
            goto done;
        }
    }
    coa_plan_result_t result;
    memset(&result, 0, sizeof result);
    if (planned) {
        coa_problem_t problem = coavoid_scenario_problem(&s);
        uint32_t beta = s.has_beta ? s.beta : 20000u;
        coa_planner_config_t config;
        size_t size = coa_planner_config_of(&problem, n, beta, &config) == COA_OK
                          ? coa_planner_workspace_size(&config)
                          : 0u;
        void *buffer = size > 0u ? malloc(size) : NULL;
        coa_planner_t *planner = buffer != NULL ? coa_planner_init(buffer, size, &config) : NULL;
        int rc = planner != NULL ? coa_plan_centralised(planner, &problem, plan, &result) : -1;
        free(buffer);
        if (rc != COA_OK || result.status != COA_PLAN_SOLVED) {
            status = fail_writer("the scenario has no centralised plan");
            goto done;
        }
    }
    if (publish) {
        w->lcm = lcm_create(out_path);
        if (w->lcm == NULL) {
            status = fail_writer("lcm_create failed (no multicast route?)");
            goto done;
        }
    } else {
        w->log = lcm_eventlog_create(out_path, "w");
        if (w->log == NULL) {
            status = fail_writer("cannot create the log");
            goto done;
        }
    }
    const long last_cycle = cycles > 0 ? cycles - 1 : 2L * (long)N;
    const coavoid_lcm_context_t ctx = {0, 0, 0, LOG_EPOCH};
    const char *reason = "";
    for (long c = 0; c <= last_cycle && status == 0; c++) {
        const int64_t start = LOG_EPOCH + c * dt_us;
        for (size_t i = 0; i < n && status == 0; i++) {
            const coa_vehicle_t *v = &s.vehicles[i];
            int32_t offsets[COAVOID_INTENT_T_MAX_SAMPLES];
            const coa_vec3_t *ref = &reference[i * 3u * row + (size_t)c];
            bool dropped = (long)v->id == skip_id;
            for (size_t d = 0; d < drops; d++) {
                dropped = dropped || ((long)v->id == drop_id[d] && c == drop_cycle[d]);
            }
            if (dropped) {
                continue;
            }
            for (size_t j = 0; j < row; j++) {
                size_t k = (size_t)c + j;
                offsets[j] = plan[i * row + (k < row ? k : row - 1u)];
            }
            coavoid_lcm_intent_info_t info;
            memset(&info, 0, sizeof info);
            info.utime = start + 100 * (int64_t)(i + 1u);
            info.sequence = c;
            info.mode = COAVOID_INTENT_T_MODE_CENTRALISED;
            info.position = ref[0];
            info.position.z += (coa_real_t)offsets[0] * coa_climb_step(v, s.dt);
            info.plan_utime = start;
            info.step = s.dt;
            if (coavoid_lcm_intent_from_core(v, &info, ref, offsets, row, &ctx, msg, &reason) !=
                COA_OK) {
                status = fail_writer(reason);
                break;
            }
            if (step_claim > 0.0) {
                msg->step = step_claim;
            }
            if ((long)v->id == stale_id && c == stale_cycle) {
                *stale = *msg;
                stale->sequence = INT64_C(1000000);
                for (int32_t j = 1; j < stale->sample_count; j++) {
                    stale->offsets[j] = stale->offsets[0];
                }
                have_stale = true;
            }
            if (put_event(w, info.utime, COAVOID_CHANNEL_INTENT,
                          coavoid_intent_t_encode(w->buffer, 0, (int)sizeof w->buffer, msg)) != 0) {
                status = fail_writer("cannot write an intent");
            }
        }
        /* Heartbeats: the UAVs never plan; the coordinator planned at cycle 0. */
        for (size_t i = 0; i <= n && status == 0; i++) {
            coavoid_status_t hb;
            memset(&hb, 0, sizeof hb);
            hb.utime = start + 5000;
            hb.node_id = i < n ? s.vehicles[i].id : (int32_t)COAVOID_NODE_COORDINATOR_ID;
            hb.node_kind =
                i < n ? COAVOID_STATUS_T_NODE_VEHICLE : COAVOID_STATUS_T_NODE_COORDINATOR;
            hb.sequence = c;
            /* A UAV follows the coordinator's plan when there is one, as in a centralised
             * run; else it plans for itself. */
            hb.mode = i < n && !planned ? COAVOID_STATUS_T_MODE_DECOUPLED
                                        : COAVOID_STATUS_T_MODE_CENTRALISED;
            hb.outcome = COAVOID_STATUS_T_OUTCOME_NONE;
            if (i == n && planned) {
                hb.last_plan_utime = LOG_EPOCH + 1000;
                hb.outcome = COAVOID_STATUS_T_OUTCOME_SOLVED;
                hb.plans_run = 1;
            }
            if (coavoid_lcm_status_check(&hb, &ctx, &reason) != COA_OK ||
                put_event(w, hb.utime, COAVOID_CHANNEL_STATUS,
                          coavoid_status_t_encode(w->buffer, 0, (int)sizeof w->buffer, &hb)) != 0) {
                status = fail_writer(reason);
            }
        }
        if (c == 0 && planned && status == 0) {
            memset(plan_msg, 0, sizeof *plan_msg);
            plan_msg->utime = start + 1500;
            plan_msg->coordinator_id = (int32_t)COAVOID_NODE_COORDINATOR_ID;
            plan_msg->plan_id = 0;
            plan_msg->valid_from_utime = start;
            plan_msg->valid_until_utime = start + dt_us;
            plan_msg->dt = (double)s.dt;
            plan_msg->horizon = (int32_t)N;
            plan_msg->mode = COAVOID_PLAN_T_MODE_CENTRALISED;
            plan_msg->status = COAVOID_PLAN_T_STATUS_SOLVED;
            plan_msg->deviation = result.deviation;
            plan_msg->effort = (int32_t)result.effort;
            plan_msg->nodes_expanded = (int64_t)result.nodes_expanded;
            plan_msg->vehicle_count = (int32_t)n;
            plan_msg->planned_count = (int32_t)n;
            for (size_t i = 0; i < n; i++) {
                plan_msg->uav_ids[i] = s.vehicles[i].id;
            }
            /* One message per UAV, as the coordinator sends a plan. */
            for (size_t i = 0; i < n && status == 0; i++) {
                plan_msg->row_uav_id = s.vehicles[i].id;
                for (size_t k = 0; k < row; k++) {
                    plan_msg->offsets[k] = plan[i * row + k];
                }
                if (coavoid_lcm_plan_check(plan_msg, &ctx, &reason) != COA_OK ||
                    put_event(w, plan_msg->utime, COAVOID_CHANNEL_PLAN,
                              coavoid_plan_t_encode(w->buffer, 0, (int)sizeof w->buffer,
                                                    plan_msg)) != 0) {
                    status = fail_writer(reason);
                }
            }
        }
        if (publish) {
            /* Paced like a (very fast) run, so that a logger's socket buffer keeps up. */
            struct timespec pause = {0, 3000000};
            nanosleep(&pause, NULL);
        }
        if (junk && c == 1 && status == 0) {
            /* A copy of the last intent with a NaN position: refused. Then the same from a
             * UAV the scenario does not have: ignored. Then something else entirely. */
            msg->position[0] = NAN;
            if (put_event(w, start + 3000, COAVOID_CHANNEL_INTENT,
                          coavoid_intent_t_encode(w->buffer, 0, (int)sizeof w->buffer, msg)) != 0) {
                status = fail_writer("cannot write");
            }
            msg->position[0] = 0.0;
            msg->uav_id = 4242;
            if (put_event(w, start + 3001, COAVOID_CHANNEL_INTENT,
                          coavoid_intent_t_encode(w->buffer, 0, (int)sizeof w->buffer, msg)) != 0) {
                status = fail_writer("cannot write");
            }
            memcpy(w->buffer, "hello", 5);
            if (put_event(w, start + 3002, "SOMETHING_ELSE", 5) != 0) {
                status = fail_writer("cannot write");
            }
        }
    }
    if (have_stale && status == 0 &&
        put_event(w, LOG_EPOCH + (last_cycle + 1) * dt_us, COAVOID_CHANNEL_INTENT,
                  coavoid_intent_t_encode(w->buffer, 0, (int)sizeof w->buffer, stale)) != 0) {
        status = fail_writer("cannot write");
    }
done:
    if (w != NULL && w->log != NULL) {
        lcm_eventlog_destroy(w->log);
    }
    if (w != NULL && w->lcm != NULL) {
        lcm_destroy(w->lcm);
    }
    free(plan);
    free(reference);
    free(w);
    free(msg);
    free(plan_msg);
    free(stale);
    coavoid_scenario_free(&s);
    return status;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && (strcmp(argv[1], "--write-log") == 0 || strcmp(argv[1], "--publish") == 0)) {
        return write_log(argc, argv);
    }
    SRunner *sr = srunner_create(flight_suite());
    int failed;
    srunner_run_all(sr, CK_NORMAL);
    failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
