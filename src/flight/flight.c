/* SPDX-License-Identifier: MIT */
/*
 * flight.c: judging a flight record (flight.h) by the contract's conflict semantics and
 * printing it as the "Simulation result" JSON or as text.
 *
 * The judgement is the core's, not a copy of it: the flown record becomes a coa_problem_t
 * whose references are the flown references, and coa_plan_find_conflict checks the flown
 * offsets against it exactly as it checks a plan. The listing of every conflicting pair
 * (for the figure and for naming who lost separation with whom) uses the same geometry
 * tests pair by pair, and the tests check that the two agree.
 */
#define _POSIX_C_SOURCE 200809L

#include "flight.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "output.h"

/* The checks every entry point shares before it reads the arrays. The core's own checks
 * (vehicles, obstacles, tracks, finite samples) come later through the problem. */
static int check_record(const coavoid_flight_t *f)
{
    if (f == NULL || f->vehicles == NULL || f->vehicle_count == 0u ||
        f->vehicle_count > COA_MAX_VEHICLES || f->steps == 0u || f->steps > COA_MAX_HORIZON ||
        !isfinite((double)f->dt) || !(f->dt > (coa_real_t)0) ||
        (f->obstacle_count > 0u && f->obstacles == NULL) ||
        (f->track_count > 0u && f->tracks == NULL)) {
        return COA_ERR_ARGUMENT;
    }
    for (size_t i = 0; i < f->vehicle_count; i++) {
        if (f->vehicles[i].reference == NULL || f->vehicles[i].offsets == NULL) {
            return COA_ERR_ARGUMENT;
        }
    }
    return COA_OK;
}

coa_vec3_t coavoid_flight_position(const coavoid_flight_t *flight, size_t i, uint32_t k,
                                   int32_t offset)
{
    const coavoid_flight_vehicle_t *v = &flight->vehicles[i];
    coa_vec3_t p = v->reference[k];
    p.z += (coa_real_t)offset * coa_climb_step(&v->vehicle, flight->dt);
    return p;
}

/* The core's view of a record: the vehicles side by side, the flown references, the
 * tracks sampled over the run, and the offsets as one row per UAV. */
typedef struct {
    coa_vehicle_t vehicles[COA_MAX_VEHICLES];
    const coa_vec3_t *references[COA_MAX_VEHICLES];
    size_t which[COA_MAX_VEHICLES];
    coa_vec3_t *track_block;
    const coa_vec3_t **track_samples;
    int32_t *offsets;
    coa_problem_t problem;
} problem_view_t;

static void view_free(problem_view_t *pv)
{
    free(pv->track_block);
    free(pv->track_samples);
    free(pv->offsets);
    pv->track_block = NULL;
    pv->track_samples = NULL;
    pv->offsets = NULL;
}

/* Builds the view; with `which` REFERENCE every row holds offsets[0]. Returns COA_OK,
 * COA_ERR_ARGUMENT (a track the core refuses to sample) or COA_ERR_WORKSPACE. */
static int view_build(const coavoid_flight_t *f, coavoid_flight_trajectory_t which,
                      problem_view_t *pv)
{
    const size_t n = f->vehicle_count;
    const size_t row = (size_t)f->steps + 1u;
    memset(pv, 0, sizeof *pv);
    for (size_t i = 0; i < n; i++) {
        pv->vehicles[i] = f->vehicles[i].vehicle;
        pv->references[i] = f->vehicles[i].reference;
        pv->which[i] = i;
    }
    pv->offsets = malloc(n * row * sizeof *pv->offsets);
    if (pv->offsets == NULL) {
        return COA_ERR_WORKSPACE;
    }
    for (size_t i = 0; i < n; i++) {
        const int32_t *src = f->vehicles[i].offsets;
        for (size_t k = 0; k < row; k++) {
            pv->offsets[i * row + k] = which == COAVOID_FLIGHT_REFERENCE ? src[0] : src[k];
        }
    }
    if (f->track_count > 0u) {
        if (f->track_count > SIZE_MAX / sizeof(coa_vec3_t) / row) {
            view_free(pv);
            return COA_ERR_WORKSPACE;
        }
        pv->track_block = malloc(f->track_count * row * sizeof *pv->track_block);
        pv->track_samples = malloc(f->track_count * sizeof *pv->track_samples);
        if (pv->track_block == NULL || pv->track_samples == NULL) {
            view_free(pv);
            return COA_ERR_WORKSPACE;
        }
        for (size_t j = 0; j < f->track_count; j++) {
            coa_vec3_t *samples = pv->track_block + j * row;
            if (coa_track_sample(&f->tracks[j], f->dt, f->steps, samples) != COA_OK) {
                view_free(pv);
                return COA_ERR_ARGUMENT;
            }
            pv->track_samples[j] = samples;
        }
    }
    pv->problem.dt = f->dt;
    pv->problem.horizon = f->steps;
    pv->problem.vehicles = pv->vehicles;
    pv->problem.vehicle_count = n;
    pv->problem.references = pv->references;
    pv->problem.obstacles = f->obstacles;
    pv->problem.obstacle_count = f->obstacle_count;
    pv->problem.tracks = f->tracks;
    pv->problem.track_count = f->track_count;
    pv->problem.track_samples = (const coa_vec3_t *const *)pv->track_samples;
    return COA_OK;
}

int coavoid_flight_evaluate(const coavoid_flight_t *flight, coavoid_flight_eval_t *eval)
{
    if (eval == NULL || check_record(flight) != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    const size_t n = flight->vehicle_count;
    double deviation = 0.0;
    uint32_t effort = 0u;
    double vehicle_deviation[COA_MAX_VEHICLES];
    uint32_t vehicle_effort[COA_MAX_VEHICLES];
    for (size_t i = 0; i < n; i++) {
        /* Refuses a step that is no action: a record whose costs would be made up. */
        if (coa_plan_vehicle_cost(&flight->vehicles[i].vehicle, flight->dt, flight->steps,
                                  flight->vehicles[i].offsets, &vehicle_deviation[i],
                                  &vehicle_effort[i]) != COA_OK) {
            return COA_ERR_ARGUMENT;
        }
        deviation += vehicle_deviation[i];
        effort += vehicle_effort[i]; /* at most 3 * 10000 * 32: no wrap */
    }

    problem_view_t pv;
    int rc = view_build(flight, COAVOID_FLIGHT_FLOWN, &pv);
    if (rc != COA_OK) {
        return rc;
    }
    size_t vehicle = COA_NO_VEHICLE;
    uint32_t step = 0u;
    rc = coa_plan_find_conflict(&pv.problem, pv.offsets, pv.which, n, &vehicle, &step);
    view_free(&pv);
    if (rc < 0) {
        return COA_ERR_ARGUMENT;
    }
    eval->loss_of_separation = rc == 1;
    eval->first_vehicle = rc == 1 ? vehicle : COA_NO_VEHICLE;
    eval->first_step = rc == 1 ? step : 0u;
    eval->deviation = deviation;
    eval->effort = effort;
    for (size_t i = 0; i < n; i++) {
        if (eval->vehicle_deviation != NULL) {
            eval->vehicle_deviation[i] = vehicle_deviation[i];
        }
        if (eval->vehicle_effort != NULL) {
            eval->vehicle_effort[i] = vehicle_effort[i];
        }
    }
    return COA_OK;
}

static coa_sweep_t sweep_of(const problem_view_t *pv, size_t i, uint32_t k)
{
    const size_t row = (size_t)pv->problem.horizon + 1u;
    const coa_real_t dh = coa_climb_step(&pv->vehicles[i], pv->problem.dt);
    coa_sweep_t s;
    s.volume = pv->vehicles[i].volume;
    s.p0 = pv->references[i][k];
    s.p0.z += (coa_real_t)pv->offsets[i * row + k] * dh;
    s.p1 = pv->references[i][k + 1u];
    s.p1.z += (coa_real_t)pv->offsets[i * row + k + 1u] * dh;
    return s;
}

static void note(coavoid_flight_conflict_t *out, size_t capacity, size_t *found,
                 coa_conflict_kind_t kind, size_t vehicle, size_t other, uint32_t step)
{
    if (*found < capacity) {
        out[*found].kind = kind;
        out[*found].vehicle = vehicle;
        out[*found].other = other;
        out[*found].step = step;
    }
    (*found)++;
}

int coavoid_flight_conflicts(const coavoid_flight_t *flight, coavoid_flight_trajectory_t which,
                             coavoid_flight_conflict_t *out, size_t capacity, size_t *found)
{
    if (found == NULL || (capacity > 0u && out == NULL) ||
        (which != COAVOID_FLIGHT_FLOWN && which != COAVOID_FLIGHT_REFERENCE) ||
        check_record(flight) != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    problem_view_t pv;
    int rc = view_build(flight, which, &pv);
    if (rc != COA_OK) {
        return rc;
    }
    /* The core's own argument checks (the same coa_plan_find_conflict runs), so that the
     * geometry below only sees what it may: over an empty selection they cost nothing
     * else. */
    if (coa_plan_find_conflict(&pv.problem, pv.offsets, NULL, 0u, NULL, NULL) < 0) {
        view_free(&pv);
        return COA_ERR_ARGUMENT;
    }
    const size_t n = flight->vehicle_count;
    *found = 0u;
    for (uint32_t k = 0; k < flight->steps; k++) {
        for (size_t i = 0; i < n; i++) {
            coa_sweep_t a = sweep_of(&pv, i, k);
            for (size_t j = i + 1u; j < n; j++) {
                coa_sweep_t b = sweep_of(&pv, j, k);
                if (coa_conflict_volumes(&a, &b)) {
                    note(out, capacity, found, COA_CONFLICT_VEHICLE, i, j, k);
                }
            }
            for (size_t j = 0; j < flight->track_count; j++) {
                coa_sweep_t t;
                t.volume = flight->tracks[j].volume;
                t.p0 = pv.track_samples[j][k];
                t.p1 = pv.track_samples[j][k + 1u];
                if (coa_conflict_volumes(&a, &t)) {
                    note(out, capacity, found, COA_CONFLICT_TRACK, i, j, k);
                }
            }
            for (size_t j = 0; j < flight->obstacle_count; j++) {
                /* As the planner: an error of the polytope test counts as a conflict. */
                if (coa_conflict_obstacle(&a, &flight->obstacles[j]) != 0) {
                    note(out, capacity, found, COA_CONFLICT_OBSTACLE, i, j, k);
                }
            }
        }
    }
    view_free(&pv);
    return COA_OK;
}

/* ---- JSON ---- */

/* A number as the shortest of %.15g, %.16g and %.17g that reads back to the same double.
 * cJSON's own printer settles for %.15g when it reads back within a relative DBL_EPSILON,
 * which is not always the same double, and positions must round-trip to the bit. */
static cJSON *exact_number(double value)
{
    char text[40];
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(text, sizeof text, "%.*g", digits, value);
        if (strtod(text, NULL) == value) {
            break;
        }
    }
    return cJSON_CreateRaw(text);
}

static bool add_number(cJSON *obj, const char *key, double value)
{
    cJSON *item = exact_number(value);
    if (item == NULL) {
        return false;
    }
    if (!cJSON_AddItemToObject(obj, key, item)) {
        cJSON_Delete(item);
        return false;
    }
    return true;
}

static double sample_time(const coavoid_flight_t *f, uint32_t k)
{
    return (double)k * (double)f->dt;
}

static bool add_vehicle(cJSON *vehicles, const coavoid_flight_t *f,
                        const coavoid_flight_eval_t *eval, size_t i)
{
    const coavoid_flight_vehicle_t *v = &f->vehicles[i];
    cJSON *entry = cJSON_CreateObject();
    if (!coavoid_output_append(vehicles, entry) || !add_number(entry, "id", v->vehicle.id)) {
        return false;
    }
    cJSON *flown = cJSON_AddArrayToObject(entry, "flown");
    if (flown == NULL) {
        return false;
    }
    for (uint32_t k = 0; k <= f->steps; k++) {
        coa_vec3_t p = coavoid_flight_position(f, i, k, v->offsets[k]);
        double sample[4] = {sample_time(f, k), (double)p.x, (double)p.y, (double)p.z};
        cJSON *point = cJSON_CreateArray();
        if (!coavoid_output_append(flown, point)) {
            return false;
        }
        for (int q = 0; q < 4; q++) {
            if (!coavoid_output_append(point, exact_number(sample[q]))) {
                return false;
            }
        }
    }
    if (eval->vehicle_deviation != NULL &&
        !add_number(entry, "deviation", eval->vehicle_deviation[i])) {
        return false;
    }
    if (eval->vehicle_effort != NULL && !add_number(entry, "effort", eval->vehicle_effort[i])) {
        return false;
    }
    if (v->known != NULL) {
        double unknown = 0;
        for (uint32_t k = 0; k <= f->steps; k++) {
            unknown += v->known[k] ? 0.0 : 1.0;
        }
        if (!add_number(entry, "unknown_samples", unknown)) {
            return false;
        }
    }
    return true;
}

static cJSON *build_json(const coavoid_flight_t *f, const coavoid_flight_eval_t *eval)
{
    cJSON *root = cJSON_CreateObject();
    if (root == NULL ||
        cJSON_AddStringToObject(root, "scenario", f->scenario != NULL ? f->scenario : "") == NULL ||
        cJSON_AddStringToObject(root, "mode", f->mode != NULL ? f->mode : "") == NULL ||
        !add_number(root, "steps", f->steps) || !add_number(root, "replans", f->replans) ||
        cJSON_AddBoolToObject(root, "loss_of_separation", eval->loss_of_separation) == NULL ||
        !add_number(root, "deviation", eval->deviation) ||
        !add_number(root, "effort", eval->effort)) {
        goto fail;
    }
    if (eval->loss_of_separation) {
        cJSON *first = cJSON_AddObjectToObject(root, "first_loss");
        if (first == NULL || eval->first_vehicle >= f->vehicle_count ||
            !add_number(first, "vehicle", f->vehicles[eval->first_vehicle].vehicle.id) ||
            !add_number(first, "step", eval->first_step) ||
            !add_number(first, "t", sample_time(f, eval->first_step))) {
            goto fail;
        }
    }
    cJSON *vehicles = cJSON_AddArrayToObject(root, "vehicles");
    if (vehicles == NULL) {
        goto fail;
    }
    for (size_t i = 0; i < f->vehicle_count; i++) {
        if (!add_vehicle(vehicles, f, eval, i)) {
            goto fail;
        }
    }
    return root;
fail:
    cJSON_Delete(root);
    return NULL;
}

int coavoid_flight_json(const coavoid_flight_t *flight, const coavoid_flight_eval_t *eval,
                        FILE *out)
{
    return coavoid_flight_json_extra(flight, eval, NULL, 0u, out);
}

int coavoid_flight_json_extra(const coavoid_flight_t *flight, const coavoid_flight_eval_t *eval,
                              const coavoid_flight_extra_t *extra, size_t extra_count, FILE *out)
{
    if (eval == NULL || out == NULL || check_record(flight) != COA_OK ||
        (eval->loss_of_separation && eval->first_vehicle >= flight->vehicle_count) ||
        (extra_count > 0u && extra == NULL)) {
        return COA_ERR_ARGUMENT;
    }
    for (size_t i = 0; i < extra_count; i++) {
        if (extra[i].key == NULL || extra[i].json == NULL) {
            return COA_ERR_ARGUMENT;
        }
    }
    cJSON *root = build_json(flight, eval);
    if (root == NULL) {
        return COA_ERR_WORKSPACE;
    }
    for (size_t i = 0; i < extra_count; i++) {
        if (cJSON_AddRawToObject(root, extra[i].key, extra[i].json) == NULL) {
            cJSON_Delete(root);
            return COA_ERR_WORKSPACE;
        }
    }
    return coavoid_output_json(out, root, NULL, 0) == 0 ? COA_OK : COA_ERR_WORKSPACE;
}

/* ---- text ---- */

/* "UAV 3 and track 7": who UAV first_vehicle lost separation with at first_step, from the
 * pairwise list (the core names only one side). Empty when the list cannot be made. */
static void describe_first_loss(const coavoid_flight_t *f, const coavoid_flight_eval_t *eval,
                                char *buf, size_t size)
{
    size_t found = 0;
    buf[0] = '\0';
    if (coavoid_flight_conflicts(f, COAVOID_FLIGHT_FLOWN, NULL, 0u, &found) != COA_OK ||
        found == 0u) {
        return;
    }
    coavoid_flight_conflict_t *list = malloc(found * sizeof *list);
    if (list == NULL) {
        return;
    }
    size_t again = 0;
    if (coavoid_flight_conflicts(f, COAVOID_FLIGHT_FLOWN, list, found, &again) == COA_OK) {
        const size_t me = eval->first_vehicle;
        for (size_t c = 0; c < found && c < again; c++) {
            const coavoid_flight_conflict_t *x = &list[c];
            bool mine = x->vehicle == me || (x->kind == COA_CONFLICT_VEHICLE && x->other == me);
            if (x->step != eval->first_step || !mine) {
                continue;
            }
            if (x->kind == COA_CONFLICT_VEHICLE) {
                size_t other = x->vehicle == me ? x->other : x->vehicle;
                snprintf(buf, size, "UAV %u and UAV %u", (unsigned)f->vehicles[me].vehicle.id,
                         (unsigned)f->vehicles[other].vehicle.id);
            } else if (x->kind == COA_CONFLICT_TRACK) {
                snprintf(buf, size, "UAV %u and track %lu", (unsigned)f->vehicles[me].vehicle.id,
                         (unsigned long)f->tracks[x->other].id);
            } else {
                snprintf(buf, size, "UAV %u and obstacle %zu (index in the scenario)",
                         (unsigned)f->vehicles[me].vehicle.id, x->other);
            }
            break;
        }
    }
    free(list);
}

int coavoid_flight_text(const coavoid_flight_t *flight, const coavoid_flight_eval_t *eval,
                        FILE *out)
{
    if (eval == NULL || out == NULL || check_record(flight) != COA_OK) {
        return COA_ERR_ARGUMENT;
    }
    const coavoid_flight_t *f = flight;
    fprintf(out, "scenario: %s\n", f->scenario != NULL ? f->scenario : "");
    fprintf(out, "mode: %s\n", f->mode != NULL ? f->mode : "");
    fprintf(out, "steps: %lu (dt %.9g s, %.9g s flown)\n", (unsigned long)f->steps, (double)f->dt,
            sample_time(f, f->steps));
    fprintf(out, "replans: %lu\n", (unsigned long)f->replans);
    if (eval->loss_of_separation && eval->first_vehicle < f->vehicle_count) {
        char who[160];
        describe_first_loss(f, eval, who, sizeof who);
        if (who[0] == '\0') {
            snprintf(who, sizeof who, "UAV %u",
                     (unsigned)f->vehicles[eval->first_vehicle].vehicle.id);
        }
        fprintf(out, "loss of separation: yes, first over step %lu (t = %.9g s): %s\n",
                (unsigned long)eval->first_step, sample_time(f, eval->first_step), who);
    } else {
        fprintf(out, "loss of separation: %s\n", eval->loss_of_separation ? "yes" : "no");
    }
    fprintf(out, "deviation: %.10g m^2\n", eval->deviation);
    fprintf(out, "effort: %lu\n", (unsigned long)eval->effort);
    for (size_t i = 0; i < f->vehicle_count; i++) {
        const coavoid_flight_vehicle_t *v = &f->vehicles[i];
        fprintf(out, "UAV %u:", (unsigned)v->vehicle.id);
        if (eval->vehicle_deviation != NULL) {
            fprintf(out, " deviation %.10g m^2", eval->vehicle_deviation[i]);
        }
        if (eval->vehicle_effort != NULL) {
            fprintf(out, "%s effort %lu", eval->vehicle_deviation != NULL ? "," : "",
                    (unsigned long)eval->vehicle_effort[i]);
        }
        if (v->known != NULL) {
            unsigned long unknown = 0;
            for (uint32_t k = 0; k <= f->steps; k++) {
                unknown += v->known[k] ? 0u : 1u;
            }
            fprintf(out, "%s %lu of %lu samples not covered by any intent",
                    (eval->vehicle_deviation != NULL || eval->vehicle_effort != NULL) ? "," : "",
                    unknown, (unsigned long)f->steps + 1ul);
        }
        fputc('\n', out);
    }
    errno = 0;
    return (fflush(out) == 0 && !ferror(out)) ? COA_OK : COA_ERR_WORKSPACE;
}
