/* SPDX-License-Identifier: MIT */
#include "scenario.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

/* The core's square root at the core's precision: leg lengths are checked here exactly as
 * coa_vehicle_check computes them. */
#ifdef COA_SINGLE_PRECISION
#define real_sqrt(x) sqrtf(x)
#else
#define real_sqrt(x) sqrt(x)
#endif

/* Longest field path we build ("tracks[123456].path[1234567][3]" and the like). */
#define PATH_SIZE 128u

typedef struct {
    coavoid_scenario_t *s;
    char *err;
    size_t err_size;
} parser_t;

#if defined(__GNUC__)
#define PRINTF_LIKE(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define PRINTF_LIKE(fmt, args)
#endif

/* Records "path: reason" and returns false, so that every check reads
 * `if (bad) return fail(...)`. */
static bool fail(parser_t *p, const char *path, const char *fmt, ...) PRINTF_LIKE(3, 4);

static bool fail(parser_t *p, const char *path, const char *fmt, ...)
{
    int used = snprintf(p->err, p->err_size, "%s: ", path);
    if (used >= 0 && (size_t)used < p->err_size) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(p->err + used, p->err_size - (size_t)used, fmt, ap);
        va_end(ap);
    }
    return false;
}

static void set_error(char *err, size_t err_size, const char *fmt, ...) PRINTF_LIKE(3, 4);

static void set_error(char *err, size_t err_size, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, err_size, fmt, ap);
    va_end(ap);
}

/* ---- memory: every block is recorded so that one call frees them all ---- */

static void *scenario_alloc(coavoid_scenario_t *s, size_t count, size_t size)
{
    if (count == 0) {
        count = 1;
    }
    if (size != 0 && count > SIZE_MAX / size) {
        return NULL;
    }
    if (s->owned_count == s->owned_capacity) {
        size_t capacity = s->owned_capacity == 0 ? 16u : 2u * s->owned_capacity;
        void **grown = realloc(s->owned, capacity * sizeof *grown);
        if (grown == NULL) {
            return NULL;
        }
        s->owned = grown;
        s->owned_capacity = capacity;
    }
    void *block = calloc(count, size);
    if (block != NULL) {
        s->owned[s->owned_count++] = block;
    }
    return block;
}

void coavoid_scenario_free(coavoid_scenario_t *s)
{
    if (s == NULL) {
        return;
    }
    for (size_t i = 0; i < s->owned_count; i++) {
        free(s->owned[i]);
    }
    free(s->owned);
    memset(s, 0, sizeof *s);
}

/* ---- paths ---- */

/* Paths are at most a few levels of short keys and indices, well within PATH_SIZE;
 * vsnprintf truncates safely should one ever not be. */
static void path_format(char *out, const char *fmt, ...) PRINTF_LIKE(2, 3);

static void path_format(char *out, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(out, PATH_SIZE, fmt, ap);
    va_end(ap);
}

static void path_key(char *out, const char *parent, const char *key)
{
    if (parent[0] == '\0') {
        path_format(out, "%s", key);
    } else {
        path_format(out, "%s.%s", parent, key);
    }
}

static void path_index(char *out, const char *parent, size_t index)
{
    path_format(out, "%s[%zu]", parent, index);
}

/* ---- one validator per JSON type ---- */

static const char *json_type_name(const cJSON *item)
{
    if (cJSON_IsNumber(item)) {
        return "a number";
    }
    if (cJSON_IsString(item)) {
        return "a string";
    }
    if (cJSON_IsBool(item)) {
        return "a boolean";
    }
    if (cJSON_IsNull(item)) {
        return "null";
    }
    if (cJSON_IsArray(item)) {
        return "an array";
    }
    if (cJSON_IsObject(item)) {
        return "an object";
    }
    return "an invalid value";
}

typedef enum { REQUIRED, OPTIONAL } presence_t;

/* Finds `key` in `obj` (case-sensitive). *item is NULL when an optional field is absent.
 * `path` receives the field's path for later messages. */
static bool get_field(parser_t *p, const cJSON *obj, const char *obj_path, const char *key,
                      presence_t presence, const cJSON **item, char *path)
{
    path_key(path, obj_path, key);
    *item = NULL;
    size_t seen = 0;
    const cJSON *child;
    cJSON_ArrayForEach(child, obj)
    {
        if (child->string != NULL && strcmp(child->string, key) == 0) {
            seen++;
            if (*item == NULL) {
                *item = child;
            }
        }
    }
    if (seen > 1) {
        return fail(p, path, "appears %zu times in the same object", seen);
    }
    if (*item == NULL && presence == REQUIRED) {
        return fail(p, path, "missing (required)");
    }
    return true;
}

static bool expect_object(parser_t *p, const cJSON *item, const char *path)
{
    if (!cJSON_IsObject(item)) {
        return fail(p, path, "must be an object, got %s", json_type_name(item));
    }
    return true;
}

static size_t array_length(const cJSON *array)
{
    size_t n = 0;
    const cJSON *child;
    cJSON_ArrayForEach(child, array)
    {
        n++;
    }
    return n;
}

/* "element" or "elements", for a count in a message. */
static const char *plural(const char *noun_singular, const char *noun_plural, size_t n)
{
    return n == 1 ? noun_singular : noun_plural;
}

/* An array of min..max elements; `what` names one element in messages ("point") and
 * `max_name` the constant behind max. Every caller checks the count here, before it
 * allocates or reads a single element, so an array past its limit costs only this count
 * (cJSON has already parsed the text, within COAVOID_SCENARIO_MAX_BYTES). */
static bool read_array(parser_t *p, const cJSON *item, const char *path, size_t min, size_t max,
                       const char *what, const char *max_name, size_t *count)
{
    if (!cJSON_IsArray(item)) {
        return fail(p, path, "must be an array, got %s", json_type_name(item));
    }
    size_t n = array_length(item);
    if (n < min) {
        return fail(p, path, "needs at least %zu %s%s, got %zu", min, what, min == 1 ? "" : "s", n);
    }
    if (n > max) {
        return fail(p, path, "at most %zu %ss are supported (%s), got %zu", max, what, max_name, n);
    }
    *count = n;
    return true;
}

typedef enum {
    ANY_REAL,    /* every finite number */
    POSITIVE,    /* > 0 */
    NON_NEGATIVE /* >= 0 */
} real_bound_t;

/* A finite JSON number that is also finite (and within the bound) as a coa_real_t, which
 * may be float: a double that overflows or underflows single precision is refused here
 * rather than turning into inf or 0 inside the core. */
static bool read_real(parser_t *p, const cJSON *item, const char *path, real_bound_t bound,
                      coa_real_t *out)
{
    if (!cJSON_IsNumber(item)) {
        return fail(p, path, "must be a number, got %s", json_type_name(item));
    }
    double d = item->valuedouble;
    if (!isfinite(d)) {
        return fail(p, path, "must be a finite number (too large to represent)");
    }
#ifdef COA_SINGLE_PRECISION
    if (fabs(d) > (double)FLT_MAX) {
        return fail(p, path, "%.15g is outside single precision range", d);
    }
#endif
    coa_real_t r = (coa_real_t)d;
    if (bound == POSITIVE && !(r > 0)) {
        return fail(p, path, "must be > 0, got %.15g", d);
    }
    if (bound == NON_NEGATIVE && !(r >= 0)) {
        return fail(p, path, "must be >= 0, got %.15g", d);
    }
    *out = r;
    return true;
}

typedef struct {
    int64_t min;
    int64_t max;
    const char *max_name; /* the core limit behind max, named in messages; or NULL */
} int_range_t;

/* A JSON number with no fractional part, within the range. Strings, booleans and 1.5 are
 * refused: the contract's "integer" is a number. */
static bool read_integer(parser_t *p, const cJSON *item, const char *path, int_range_t range,
                         int64_t *out)
{
    if (!cJSON_IsNumber(item)) {
        return fail(p, path, "must be an integer, got %s", json_type_name(item));
    }
    double d = item->valuedouble;
    if (!isfinite(d)) {
        return fail(p, path, "must be a finite integer (too large to represent)");
    }
    if (floor(d) != d) {
        return fail(p, path, "must be an integer, got %.15g", d);
    }
    if (d < (double)range.min) {
        return fail(p, path, "must be >= %lld, got %.15g", (long long)range.min, d);
    }
    if (d > (double)range.max) {
        if (range.max_name != NULL) {
            return fail(p, path, "must be <= %lld (%s), got %.15g", (long long)range.max,
                        range.max_name, d);
        }
        return fail(p, path, "must be <= %lld, got %.15g", (long long)range.max, d);
    }
    *out = (int64_t)d;
    return true;
}

/* An array of exactly `dim` numbers, each finite and within `bound`. */
static bool read_point(parser_t *p, const cJSON *item, const char *path, size_t dim,
                       const char *shape, real_bound_t bound, coa_real_t *out)
{
    if (!cJSON_IsArray(item) || array_length(item) != dim) {
        if (cJSON_IsArray(item)) {
            size_t n = array_length(item);
            return fail(p, path, "must be an array of %zu numbers %s, got %zu %s", dim, shape, n,
                        plural("element", "elements", n));
        }
        return fail(p, path, "must be an array of %zu numbers %s, got %s", dim, shape,
                    json_type_name(item));
    }
    size_t i = 0;
    const cJSON *child;
    cJSON_ArrayForEach(child, item)
    {
        char child_path[PATH_SIZE];
        path_index(child_path, path, i);
        if (!read_real(p, child, child_path, bound, &out[i])) {
            return false;
        }
        i++;
    }
    return true;
}

static bool read_vec3(parser_t *p, const cJSON *item, const char *path, coa_vec3_t *out)
{
    coa_real_t xyz[3];
    if (!read_point(p, item, path, 3, "[x, y, z]", ANY_REAL, xyz)) {
        return false;
    }
    out->x = xyz[0];
    out->y = xyz[1];
    out->z = xyz[2];
    return true;
}

/* Well-formed UTF-8 (no overlongs, surrogates or code points past U+10FFFF), so that the
 * name echoed in the result is valid JSON text. */
static bool utf8_valid(const unsigned char *s)
{
    while (*s != 0) {
        unsigned c = *s;
        size_t extra;
        unsigned min;
        if (c < 0x80u) {
            s++;
            continue;
        } else if ((c & 0xE0u) == 0xC0u) {
            extra = 1;
            min = 0x80u;
            c &= 0x1Fu;
        } else if ((c & 0xF0u) == 0xE0u) {
            extra = 2;
            min = 0x800u;
            c &= 0x0Fu;
        } else if ((c & 0xF8u) == 0xF0u) {
            extra = 3;
            min = 0x10000u;
            c &= 0x07u;
        } else {
            return false;
        }
        for (size_t i = 1; i <= extra; i++) {
            if ((s[i] & 0xC0u) != 0x80u) {
                return false;
            }
            c = (c << 6) | (s[i] & 0x3Fu);
        }
        if (c < min || c > 0x10FFFFu || (c >= 0xD800u && c <= 0xDFFFu)) {
            return false;
        }
        s += extra + 1;
    }
    return true;
}

static bool read_string(parser_t *p, const cJSON *item, const char *path, const char **out)
{
    if (!cJSON_IsString(item) || item->valuestring == NULL) {
        return fail(p, path, "must be a string, got %s", json_type_name(item));
    }
    if (!utf8_valid((const unsigned char *)item->valuestring)) {
        return fail(p, path, "is not valid UTF-8");
    }
    *out = item->valuestring;
    return true;
}

/* ---- the same validators, looking the field up first ---- */

static bool real_field(parser_t *p, const cJSON *obj, const char *obj_path, const char *key,
                       real_bound_t bound, coa_real_t *out)
{
    char path[PATH_SIZE];
    const cJSON *item;
    return get_field(p, obj, obj_path, key, REQUIRED, &item, path) &&
           read_real(p, item, path, bound, out);
}

/* *out is left alone (the caller's default) when an optional field is absent; *present
 * says whether it was there (may be NULL). */
static bool integer_field(parser_t *p, const cJSON *obj, const char *obj_path, const char *key,
                          presence_t presence, int_range_t range, int64_t *out, bool *present)
{
    char path[PATH_SIZE];
    const cJSON *item;
    if (!get_field(p, obj, obj_path, key, presence, &item, path)) {
        return false;
    }
    if (present != NULL) {
        *present = item != NULL;
    }
    return item == NULL || read_integer(p, item, path, range, out);
}

static bool vec3_field(parser_t *p, const cJSON *obj, const char *obj_path, const char *key,
                       coa_vec3_t *out)
{
    char path[PATH_SIZE];
    const cJSON *item;
    return get_field(p, obj, obj_path, key, REQUIRED, &item, path) && read_vec3(p, item, path, out);
}

static bool out_of_memory(parser_t *p, const char *path)
{
    return fail(p, path, "out of memory");
}

/* ---- the scenario's objects ---- */

static const int_range_t RANGE_VEHICLE_ID = {1, 65535, NULL};
static const int_range_t RANGE_PRIORITY = {1, UINT32_MAX, NULL};
static const int_range_t RANGE_STEEP = {2, COA_MAX_STEEP_FACTOR, "COA_MAX_STEEP_FACTOR"};
static const int_range_t RANGE_INITIAL_OFFSET = {-COA_MAX_OFFSET, COA_MAX_OFFSET, "COA_MAX_OFFSET"};
static const int_range_t RANGE_MAX_OFFSET = {0, COA_MAX_OFFSET, "COA_MAX_OFFSET"};
static const int_range_t RANGE_HORIZON = {1, COA_MAX_HORIZON, "COA_MAX_HORIZON"};
static const int_range_t RANGE_BETA = {1, UINT32_MAX, NULL};
static const int_range_t RANGE_TRACK_ID = {0, UINT32_MAX, NULL};

/* The leg from `prev` to `cur` (the route point at `path`), computed as the core's vehicle
 * check computes it: in coa_real_t, the horizontal length as sqrt(dx*dx + dy*dy), and the
 * running total of the lengths. Each of these can be 0 or overflow while every coordinate
 * is finite (1e-300 apart, or 1e200 apart), and the core would then refuse the vehicle as
 * a whole; here the message names the point and says which. */
static bool check_route_leg(parser_t *p, const coa_vec3_t *prev, const coa_vec3_t *cur,
                            coa_real_t *total, const char *path)
{
    /* Compared as coa_real_t: points distinct in the file may coincide in float. */
    if (cur->x == prev->x && cur->y == prev->y) {
        return fail(p, path, "consecutive points have no horizontal separation");
    }
    coa_real_t dx = cur->x - prev->x;
    coa_real_t dy = cur->y - prev->y;
    coa_real_t length = real_sqrt(dx * dx + dy * dy);
    if (!isfinite(length)) {
        return fail(p, path, "leg length is not finite (coordinates too large)");
    }
    if (!(length > 0)) {
        return fail(p, path,
                    "consecutive points have no horizontal separation (their distance "
                    "underflows to 0)");
    }
    if (!isfinite(cur->z - prev->z)) {
        return fail(p, path, "altitude change is not finite (coordinates too large)");
    }
    /* Unreachable today (a leg overflows first: its squares pass the range at 1e154 m,
     * float 1e19 m, so the total would need 1e154 legs), but the core checks it. */
    *total += length;
    if (!isfinite(*total)) {
        return fail(p, path, "route length up to this point is not finite (coordinates too large)");
    }
    return true;
}

static bool parse_route(parser_t *p, const cJSON *obj, const char *obj_path, coa_vehicle_t *v)
{
    char path[PATH_SIZE];
    const cJSON *route;
    size_t n;
    coa_real_t total = 0;
    if (!get_field(p, obj, obj_path, "route", REQUIRED, &route, path) ||
        !read_array(p, route, path, 2, COAVOID_SCENARIO_MAX_ROUTE_POINTS, "point",
                    "COAVOID_SCENARIO_MAX_ROUTE_POINTS", &n)) {
        return false;
    }
    coa_vec3_t *points = scenario_alloc(p->s, n, sizeof *points);
    if (points == NULL) {
        return out_of_memory(p, path);
    }
    size_t i = 0;
    const cJSON *item;
    cJSON_ArrayForEach(item, route)
    {
        char point_path[PATH_SIZE];
        path_index(point_path, path, i);
        if (!read_vec3(p, item, point_path, &points[i])) {
            return false;
        }
        if (i > 0 && !check_route_leg(p, &points[i - 1], &points[i], &total, point_path)) {
            return false;
        }
        i++;
    }
    v->route = points;
    v->route_count = n;
    return true;
}

static bool parse_vehicle(parser_t *p, const cJSON *obj, const char *path, coa_vehicle_t *v)
{
    int64_t id = 0, priority = 0, steep = 2, initial = 0, max_offset = -1;
    bool bounded = false;
    if (!expect_object(p, obj, path) ||
        !integer_field(p, obj, path, "id", REQUIRED, RANGE_VEHICLE_ID, &id, NULL) ||
        !integer_field(p, obj, path, "priority", REQUIRED, RANGE_PRIORITY, &priority, NULL) ||
        !real_field(p, obj, path, "cruise_speed", POSITIVE, &v->cruise_speed) ||
        !real_field(p, obj, path, "climb_rate", POSITIVE, &v->climb_rate) ||
        !integer_field(p, obj, path, "steep_factor", OPTIONAL, RANGE_STEEP, &steep, NULL) ||
        !real_field(p, obj, path, "radius", POSITIVE, &v->volume.radius) ||
        !real_field(p, obj, path, "half_height", POSITIVE, &v->volume.half_height) ||
        !parse_route(p, obj, path, v) ||
        !integer_field(p, obj, path, "initial_offset", OPTIONAL, RANGE_INITIAL_OFFSET, &initial,
                       NULL) ||
        !integer_field(p, obj, path, "max_offset", OPTIONAL, RANGE_MAX_OFFSET, &max_offset,
                       &bounded)) {
        return false;
    }
    if (bounded && (initial > max_offset || -initial > max_offset)) {
        char field[PATH_SIZE];
        path_key(field, path, "initial_offset");
        return fail(p, field, "|%lld| exceeds max_offset %lld", (long long)initial,
                    (long long)max_offset);
    }
    v->id = (uint16_t)id;
    v->priority = (uint32_t)priority;
    v->steep_factor = (uint32_t)steep;
    v->initial_offset = (int32_t)initial;
    v->max_offset = bounded ? (int32_t)max_offset : -1;
    /* A backstop: every rule of the core's check is tested above with its field's path, so
     * only a rule added to the core later can reach this. */
    if (coa_vehicle_check(v) != COA_OK) {
        return fail(p, path, "rejected by the core's vehicle check");
    }
    return true;
}

/* A vehicle's deviation weight L * dh in m^2, in double as the core computes it. */
static double step_area(const coa_vehicle_t *v, coa_real_t dt)
{
    return ((double)v->cruise_speed * (double)dt) * ((double)v->climb_rate * (double)dt);
}

/* The step length L = cruise_speed * dt, the climb step dh = climb_rate * dt and their
 * product (the deviation scale) must be finite and positive, in double as the core's
 * weights are computed and as coa_real_t: each number can be fine while a product
 * overflows or underflows. */
static bool check_step_sizes(parser_t *p, const coa_vehicle_t *v, coa_real_t dt, const char *path)
{
    double l = (double)v->cruise_speed * (double)dt;
    double dh = (double)v->climb_rate * (double)dt;
    double w = l * dh;
    coa_real_t dh_real = v->climb_rate * dt;
    coa_real_t l_real = v->cruise_speed * dt;
    if (!(isfinite(w) && w > 0.0 && isfinite(dh_real) && dh_real > 0 && isfinite(l_real) &&
          l_real > 0)) {
        return fail(p, path,
                    "cruise_speed * dt (%.15g m) and climb_rate * dt (%.15g m) are out of range "
                    "(their product must be finite and > 0)",
                    l, dh);
    }
    return true;
}

/* The core weighs each vehicle's deviation by w = cruise_speed*dt * climb_rate*dt written
 * exactly as a 64-bit integer times a power of two common to the problem, and refuses
 * (COA_ERR_RANGE) vehicles whose w are too far apart in binary magnitude for that. The
 * problem check would report it as a range error of the whole problem; here the first
 * pair of vehicles that cannot be weighed together is named. The test is the core's own,
 * on two vehicles at a time: the set fails exactly when the pair of its extremes does. */
static bool check_weights(parser_t *p, const coavoid_scenario_t *s, const char *path)
{
    uint64_t weights[COA_MAX_VEHICLES];
    int exponent;
    if (coa_deviation_weights(s->vehicles, s->vehicle_count, s->dt, weights, &exponent) !=
        COA_ERR_RANGE) {
        return true; /* arguments were checked vehicle by vehicle above */
    }
    for (size_t j = 1; j < s->vehicle_count; j++) {
        for (size_t i = 0; i < j; i++) {
            const coa_vehicle_t pair[2] = {s->vehicles[i], s->vehicles[j]};
            if (coa_deviation_weights(pair, 2, s->dt, weights, &exponent) == COA_ERR_RANGE) {
                char vehicle_path[PATH_SIZE];
                path_index(vehicle_path, path, j);
                return fail(p, vehicle_path,
                            "cruise_speed * dt * climb_rate * dt (%.17g m^2) and "
                            "vehicles[%zu]'s (%.17g m^2) are too far apart for the core's exact "
                            "64-bit cost weights (make them closer in size, or use numbers with "
                            "fewer binary digits, e.g. multiples of 1/8)",
                            step_area(&s->vehicles[j], s->dt), i,
                            step_area(&s->vehicles[i], s->dt));
            }
        }
    }
    return fail(p, path,
                "cruise_speed * dt * climb_rate * dt of the vehicles are too far apart for "
                "the core's exact 64-bit cost weights (make them closer in size, or use numbers "
                "with fewer binary digits, e.g. multiples of 1/8)");
}

static bool parse_vehicles(parser_t *p, const cJSON *root)
{
    char path[PATH_SIZE];
    const cJSON *array;
    size_t n;
    if (!get_field(p, root, "", "vehicles", REQUIRED, &array, path) ||
        !read_array(p, array, path, 1, COA_MAX_VEHICLES, "vehicle", "COA_MAX_VEHICLES", &n)) {
        return false;
    }
    coavoid_scenario_t *s = p->s;
    s->vehicles = scenario_alloc(s, n, sizeof *s->vehicles);
    if (s->vehicles == NULL) {
        return out_of_memory(p, path);
    }
    size_t i = 0;
    const cJSON *item;
    cJSON_ArrayForEach(item, array)
    {
        char vehicle_path[PATH_SIZE];
        path_index(vehicle_path, path, i);
        if (!parse_vehicle(p, item, vehicle_path, &s->vehicles[i]) ||
            !check_step_sizes(p, &s->vehicles[i], s->dt, vehicle_path)) {
            return false;
        }
        for (size_t j = 0; j < i; j++) {
            if (s->vehicles[j].id == s->vehicles[i].id) {
                char id_path[PATH_SIZE];
                path_key(id_path, vehicle_path, "id");
                return fail(p, id_path, "duplicate id %u (also vehicles[%zu].id)",
                            (unsigned)s->vehicles[i].id, j);
            }
        }
        i++;
    }
    s->vehicle_count = n;
    return check_weights(p, s, path);
}

static bool parse_box(parser_t *p, const cJSON *obj, const char *path, coa_obstacle_t *o)
{
    o->kind = COA_OBSTACLE_BOX;
    coa_box_t *b = &o->box;
    if (!vec3_field(p, obj, path, "min", &b->min) || !vec3_field(p, obj, path, "max", &b->max)) {
        return false;
    }
    const coa_real_t lo[3] = {b->min.x, b->min.y, b->min.z};
    const coa_real_t hi[3] = {b->max.x, b->max.y, b->max.z};
    for (size_t axis = 0; axis < 3; axis++) {
        if (lo[axis] > hi[axis]) {
            char field[PATH_SIZE];
            path_key(field, path, "max");
            return fail(p, field, "is below min on the %c axis (%.15g < %.15g): inverted box",
                        "xyz"[axis], (double)hi[axis], (double)lo[axis]);
        }
    }
    return true;
}

static bool parse_polytope(parser_t *p, const cJSON *obj, const char *obj_path, coa_obstacle_t *o)
{
    char path[PATH_SIZE];
    const cJSON *array;
    size_t n;
    if (!get_field(p, obj, obj_path, "vertices", REQUIRED, &array, path) ||
        !read_array(p, array, path, 4, COA_POLYTOPE_MAX_VERTICES, "point",
                    "COA_POLYTOPE_MAX_VERTICES", &n)) {
        return false;
    }
    coa_vec3_t *vertices = scenario_alloc(p->s, n, sizeof *vertices);
    if (vertices == NULL) {
        return out_of_memory(p, path);
    }
    size_t i = 0;
    const cJSON *item;
    cJSON_ArrayForEach(item, array)
    {
        char vertex_path[PATH_SIZE];
        path_index(vertex_path, path, i);
        if (!read_vec3(p, item, vertex_path, &vertices[i])) {
            return false;
        }
        i++;
    }
    o->kind = COA_OBSTACLE_POLYTOPE;
    o->polytope.vertices = vertices;
    o->polytope.count = n;
    return true;
}

static bool parse_obstacle(parser_t *p, const cJSON *obj, const char *path, coa_obstacle_t *o)
{
    char type_path[PATH_SIZE];
    const cJSON *type_item;
    const char *type;
    if (!expect_object(p, obj, path) ||
        !get_field(p, obj, path, "type", REQUIRED, &type_item, type_path) ||
        !read_string(p, type_item, type_path, &type)) {
        return false;
    }
    if (strcmp(type, "box") == 0) {
        return parse_box(p, obj, path, o);
    }
    if (strcmp(type, "polytope") == 0) {
        return parse_polytope(p, obj, path, o);
    }
    return fail(p, type_path, "unknown obstacle type \"%.40s\" (expected \"box\" or \"polytope\")",
                type);
}

static bool parse_obstacles(parser_t *p, const cJSON *root)
{
    char path[PATH_SIZE];
    const cJSON *array;
    size_t n;
    if (!get_field(p, root, "", "obstacles", OPTIONAL, &array, path)) {
        return false;
    }
    if (array == NULL) {
        return true;
    }
    if (!read_array(p, array, path, 0, COAVOID_SCENARIO_MAX_OBSTACLES, "obstacle",
                    "COAVOID_SCENARIO_MAX_OBSTACLES", &n)) {
        return false;
    }
    coavoid_scenario_t *s = p->s;
    s->obstacles = scenario_alloc(s, n, sizeof *s->obstacles);
    if (s->obstacles == NULL) {
        return out_of_memory(p, path);
    }
    size_t i = 0;
    const cJSON *item;
    cJSON_ArrayForEach(item, array)
    {
        char obstacle_path[PATH_SIZE];
        path_index(obstacle_path, path, i);
        if (!parse_obstacle(p, item, obstacle_path, &s->obstacles[i])) {
            return false;
        }
        i++;
    }
    s->obstacle_count = n;
    return true;
}

/* The path leg from `prev` to `cur` (the point at `path`, whose t is already known to be
 * greater), in coa_real_t as the core takes it: its duration, its displacement and so its
 * velocity must be finite, or the core refuses the track or its samples run off to
 * infinity, and the message would then name neither the point nor the reason. */
static bool check_track_leg(parser_t *p, const coa_track_point_t *prev,
                            const coa_track_point_t *cur, const char *path)
{
    coa_real_t duration = cur->t - prev->t;
    if (!isfinite(duration)) {
        return fail(p, path, "time since the previous point is not finite (times too large)");
    }
    if (!(duration > 0)) {
        return fail(p, path, "time since the previous point underflows to 0");
    }
    const coa_real_t d[3] = {cur->p.x - prev->p.x, cur->p.y - prev->p.y, cur->p.z - prev->p.z};
    for (size_t axis = 0; axis < 3; axis++) {
        if (!isfinite(d[axis])) {
            return fail(p, path,
                        "displacement from the previous point is not finite on the %c axis "
                        "(coordinates too large)",
                        "xyz"[axis]);
        }
        if (!isfinite(d[axis] / duration)) {
            return fail(p, path,
                        "velocity from the previous point is not finite on the %c axis "
                        "(%.15g m in %.15g s)",
                        "xyz"[axis], (double)d[axis], (double)duration);
        }
    }
    return true;
}

static bool parse_track_path(parser_t *p, const cJSON *array, const char *path, coa_track_t *t)
{
    size_t n;
    if (!read_array(p, array, path, 1, COAVOID_SCENARIO_MAX_TRACK_POINTS, "point",
                    "COAVOID_SCENARIO_MAX_TRACK_POINTS", &n)) {
        return false;
    }
    coa_track_point_t *points = scenario_alloc(p->s, n, sizeof *points);
    if (points == NULL) {
        return out_of_memory(p, path);
    }
    size_t i = 0;
    const cJSON *item;
    cJSON_ArrayForEach(item, array)
    {
        char point_path[PATH_SIZE];
        coa_real_t txyz[4];
        path_index(point_path, path, i);
        if (!read_point(p, item, point_path, 4, "[t, x, y, z]", ANY_REAL, txyz)) {
            return false;
        }
        /* Strictly ascending: two points at one instant leave the velocity undefined. */
        if (i > 0 && !(txyz[0] > points[i - 1].t)) {
            return fail(p, point_path,
                        "t must be greater than the previous point's t (%.15g <= %.15g)",
                        (double)txyz[0], (double)points[i - 1].t);
        }
        points[i].t = txyz[0];
        points[i].p.x = txyz[1];
        points[i].p.y = txyz[2];
        points[i].p.z = txyz[3];
        if (i > 0 && !check_track_leg(p, &points[i - 1], &points[i], point_path)) {
            return false;
        }
        i++;
    }
    t->path = points;
    t->path_count = n;
    return true;
}

static bool parse_track(parser_t *p, const cJSON *obj, const char *path, coa_track_t *t)
{
    int64_t id = 0;
    char field[PATH_SIZE];
    const cJSON *path_item, *position_item, *velocity_item, *sigma_item;
    if (!expect_object(p, obj, path) ||
        !integer_field(p, obj, path, "id", REQUIRED, RANGE_TRACK_ID, &id, NULL) ||
        !real_field(p, obj, path, "radius", POSITIVE, &t->volume.radius) ||
        !real_field(p, obj, path, "half_height", POSITIVE, &t->volume.half_height) ||
        !get_field(p, obj, path, "position", OPTIONAL, &position_item, field) ||
        !get_field(p, obj, path, "velocity", OPTIONAL, &velocity_item, field) ||
        !get_field(p, obj, path, "path", OPTIONAL, &path_item, field)) {
        return false;
    }
    t->id = (uint32_t)id;
    if (path_item != NULL) {
        if (position_item != NULL || velocity_item != NULL) {
            return fail(p, field, "give either path or position and velocity, not both");
        }
        if (!parse_track_path(p, path_item, field, t)) {
            return false;
        }
    } else if (!vec3_field(p, obj, path, "position", &t->position) ||
               !vec3_field(p, obj, path, "velocity", &t->velocity)) {
        return false;
    }
    if (!get_field(p, obj, path, "sigma", OPTIONAL, &sigma_item, field)) {
        return false;
    }
    if (sigma_item != NULL) {
        coa_real_t sigma[2];
        if (!read_point(p, sigma_item, field, 2, "[horizontal, vertical]", NON_NEGATIVE, sigma)) {
            return false;
        }
        t->sigma_horizontal = sigma[0];
        t->sigma_vertical = sigma[1];
    }
    /* A backstop, as for vehicles: the rules are all tested above with their paths. */
    if (coa_track_check(t) != COA_OK) {
        return fail(p, path, "rejected by the core's track check");
    }
    return true;
}

static bool parse_tracks(parser_t *p, const cJSON *root)
{
    char path[PATH_SIZE];
    const cJSON *array;
    size_t n;
    if (!get_field(p, root, "", "tracks", OPTIONAL, &array, path)) {
        return false;
    }
    if (array == NULL) {
        return true;
    }
    if (!read_array(p, array, path, 0, COAVOID_SCENARIO_MAX_TRACKS, "track",
                    "COAVOID_SCENARIO_MAX_TRACKS", &n)) {
        return false;
    }
    coavoid_scenario_t *s = p->s;
    s->tracks = scenario_alloc(s, n, sizeof *s->tracks);
    if (s->tracks == NULL) {
        return out_of_memory(p, path);
    }
    size_t i = 0;
    const cJSON *item;
    cJSON_ArrayForEach(item, array)
    {
        char track_path[PATH_SIZE];
        path_index(track_path, path, i);
        if (!parse_track(p, item, track_path, &s->tracks[i])) {
            return false;
        }
        i++;
    }
    s->track_count = n;
    return true;
}

/* The optional "min_altitude": a finite number of metres within
 * +-COAVOID_SCENARIO_MAX_ALTITUDE. */
static bool parse_floor(parser_t *p, const cJSON *root)
{
    coavoid_scenario_t *s = p->s;
    char path[PATH_SIZE];
    const cJSON *item;
    if (!get_field(p, root, "", "min_altitude", OPTIONAL, &item, path)) {
        return false;
    }
    s->has_floor = item != NULL;
    if (item == NULL) {
        return true;
    }
    if (!read_real(p, item, path, ANY_REAL, &s->min_altitude)) {
        return false;
    }
    if (fabs(item->valuedouble) > COAVOID_SCENARIO_MAX_ALTITUDE) {
        return fail(p, path, "must be within +-%.0f m (COAVOID_SCENARIO_MAX_ALTITUDE), got %.15g",
                    COAVOID_SCENARIO_MAX_ALTITUDE, item->valuedouble);
    }
    return true;
}

static bool parse_root(parser_t *p, const cJSON *root)
{
    coavoid_scenario_t *s = p->s;
    char path[PATH_SIZE];
    const cJSON *item;
    const char *name;
    int64_t horizon = 0, beta = 0;
    if (!cJSON_IsObject(root)) {
        return fail(p, "(top level)", "must be an object, got %s", json_type_name(root));
    }
    if (!get_field(p, root, "", "name", REQUIRED, &item, path) ||
        !read_string(p, item, path, &name)) {
        return false;
    }
    size_t name_length = strlen(name);
    s->name = scenario_alloc(s, name_length + 1, 1);
    if (s->name == NULL) {
        return out_of_memory(p, path);
    }
    memcpy(s->name, name, name_length + 1);
    if (!real_field(p, root, "", "dt", POSITIVE, &s->dt) ||
        !integer_field(p, root, "", "horizon", REQUIRED, RANGE_HORIZON, &horizon, NULL) ||
        !integer_field(p, root, "", "beta", OPTIONAL, RANGE_BETA, &beta, &s->has_beta)) {
        return false;
    }
    s->horizon = (uint32_t)horizon;
    s->beta = s->has_beta ? (uint32_t)beta : 0u;
    return parse_floor(p, root) && parse_vehicles(p, root) && parse_obstacles(p, root) &&
           parse_tracks(p, root);
}

/* Line and column (1-based, in bytes) of position `at` in text. */
static void locate(const char *text, size_t at, size_t *line, size_t *column)
{
    *line = 1;
    *column = 1;
    for (size_t i = 0; i < at; i++) {
        if (text[i] == '\n') {
            (*line)++;
            *column = 1;
        } else {
            (*column)++;
        }
    }
}

int coavoid_scenario_parse(const char *text, size_t length, coavoid_scenario_t *s, char *err,
                           size_t err_size)
{
    memset(s, 0, sizeof *s);
    const char *nul = memchr(text, '\0', length);
    if (nul != NULL) {
        size_t line, column;
        locate(text, (size_t)(nul - text), &line, &column);
        set_error(err, err_size, "invalid JSON: NUL byte at line %zu, column %zu", line, column);
        return -1;
    }
    /* cJSON wants the terminating NUL inside the length it is given to accept the end. */
    char *copy = malloc(length + 1);
    if (copy == NULL) {
        set_error(err, err_size, "out of memory reading %zu bytes", length);
        return -1;
    }
    memcpy(copy, text, length);
    copy[length] = '\0';
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(copy, length + 1, &end, 1);
    if (root == NULL) {
        size_t at =
            end != NULL && end >= copy && end <= copy + length ? (size_t)(end - copy) : length;
        size_t line, column;
        locate(copy, at, &line, &column);
        if (at >= length) {
            set_error(err, err_size, "invalid JSON: unexpected end of file at line %zu, column %zu",
                      line, column);
        } else {
            set_error(err, err_size, "invalid JSON near line %zu, column %zu", line, column);
        }
        free(copy);
        return -1;
    }
    parser_t p = {s, err, err_size};
    bool ok = parse_root(&p, root);
    cJSON_Delete(root);
    free(copy);
    if (!ok) {
        coavoid_scenario_free(s);
        return -1;
    }
    return 0;
}

int coavoid_scenario_load(const char *path, coavoid_scenario_t *s, char *err, size_t err_size)
{
    memset(s, 0, sizeof *s);
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        set_error(err, err_size, "cannot open: %s", strerror(errno));
        return -1;
    }
    /* Read one byte past the cap so that an oversized file is recognised without
     * trusting a size reported by stat (pipes and special files have none). */
    char *text = malloc((size_t)COAVOID_SCENARIO_MAX_BYTES + 1u);
    if (text == NULL) {
        fclose(f);
        set_error(err, err_size, "out of memory");
        return -1;
    }
    errno = 0;
    size_t length = fread(text, 1, (size_t)COAVOID_SCENARIO_MAX_BYTES + 1u, f);
    int read_error = errno;
    bool failed = ferror(f) != 0;
    fclose(f);
    if (failed) {
        free(text);
        set_error(err, err_size, "cannot read: %s",
                  read_error != 0 ? strerror(read_error) : "read error");
        return -1;
    }
    if (length > COAVOID_SCENARIO_MAX_BYTES) {
        free(text);
        set_error(err, err_size, "larger than the %u MiB a scenario may have",
                  COAVOID_SCENARIO_MAX_BYTES / (1024u * 1024u));
        return -1;
    }
    int rc = coavoid_scenario_parse(text, length, s, err, err_size);
    free(text);
    return rc;
}

/* Samples into a fresh block of count rows of horizon+1 points. */
static const coa_vec3_t **alloc_rows(coavoid_scenario_t *s, size_t count, coa_vec3_t **block)
{
    size_t per_row = (size_t)s->horizon + 1u;
    if (count != 0 && per_row > SIZE_MAX / count) {
        return NULL;
    }
    const coa_vec3_t **rows = scenario_alloc(s, count, sizeof *rows);
    *block = scenario_alloc(s, count * per_row, sizeof **block);
    if (rows == NULL || *block == NULL) {
        return NULL;
    }
    for (size_t i = 0; i < count; i++) {
        rows[i] = *block + i * per_row;
    }
    return rows;
}

static bool samples_finite(const coa_vec3_t *samples, uint32_t horizon)
{
    for (uint32_t k = 0; k <= horizon; k++) {
        if (!isfinite(samples[k].x) || !isfinite(samples[k].y) || !isfinite(samples[k].z)) {
            return false;
        }
    }
    return true;
}

int coavoid_scenario_sample(coavoid_scenario_t *s, char *err, size_t err_size)
{
    size_t per_row = (size_t)s->horizon + 1u;
    coa_vec3_t *block;
    s->references = alloc_rows(s, s->vehicle_count, &block);
    if (s->references == NULL) {
        set_error(err, err_size, "vehicles: out of memory for %zu references of %zu samples",
                  s->vehicle_count, per_row);
        return -1;
    }
    /* Everything else the samplers check was validated while parsing: a refusal here means
     * a position overflowed (the core refuses non-finite samples too). */
    for (size_t i = 0; i < s->vehicle_count; i++) {
        coa_vec3_t *row = block + i * per_row;
        if (coa_reference_sample(&s->vehicles[i], s->dt, s->horizon, row) != COA_OK ||
            !samples_finite(row, s->horizon)) {
            set_error(err, err_size,
                      "vehicles[%zu]: the reference position is not finite within the horizon "
                      "(dt, cruise_speed or route too large)",
                      i);
            return -1;
        }
    }
    s->track_samples = alloc_rows(s, s->track_count, &block);
    if (s->track_samples == NULL) {
        set_error(err, err_size, "tracks: out of memory for %zu tracks of %zu samples",
                  s->track_count, per_row);
        return -1;
    }
    for (size_t j = 0; j < s->track_count; j++) {
        coa_vec3_t *row = block + j * per_row;
        if (coa_track_sample(&s->tracks[j], s->dt, s->horizon, row) != COA_OK ||
            !samples_finite(row, s->horizon)) {
            set_error(err, err_size,
                      "tracks[%zu]: the position is not finite within the horizon "
                      "(dt, velocity or path too large)",
                      j);
            return -1;
        }
    }
    return 0;
}

coa_problem_t coavoid_scenario_problem(const coavoid_scenario_t *s)
{
    coa_problem_t problem;
    memset(&problem, 0, sizeof problem);
    problem.dt = s->dt;
    problem.horizon = s->horizon;
    problem.vehicles = s->vehicles;
    problem.vehicle_count = s->vehicle_count;
    problem.references = s->references;
    problem.obstacles = s->obstacles;
    problem.obstacle_count = s->obstacle_count;
    problem.tracks = s->tracks;
    problem.track_count = s->track_count;
    problem.track_samples = s->track_samples;
    problem.has_floor = s->has_floor;
    problem.floor_z = s->min_altitude;
    return problem;
}

long coavoid_scenario_vehicle_index(const coavoid_scenario_t *s, long id)
{
    for (size_t i = 0; i < s->vehicle_count; i++) {
        if ((long)s->vehicles[i].id == id) {
            return (long)i;
        }
    }
    return -1;
}
