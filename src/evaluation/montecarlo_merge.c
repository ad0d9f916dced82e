/* SPDX-License-Identifier: MIT */
/*
 * montecarlo_merge.c: a run rebuilt from the CSVs of its parts (montecarlo.h,
 * coavoid_montecarlo_merge). Each row names its run (seed, planners' limits, --first,
 * --count, the network) and its encounter, so the parts' rows are checked against each
 * other and placed where the whole run would hold them; the report is then the whole
 * run's. The files are untrusted: every line is bounded, every field checked, and the
 * first problem is one error naming the file and line.
 */
#define _POSIX_C_SOURCE 200809L

#include "montecarlo.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "coavoid/coavoid.h"
#include "encounter.h"
#include "evaluation_internal.h"
#include "montecarlo_internal.h"
#include "output.h"
#include "run.h"

#define MERGE_LINE_MAX 1024u      /* a row is about 200 characters */
#define MERGE_LINES_MAX 50000000u /* per file, as --figure-from reads */

/* The columns, numbered as in a --fly CSV (montecarlo_internal.h); a plan run's CSV has
 * no NETWORK and FLOWN columns (NULL when its row is read). */
enum {
    COL_SEED,
    COL_VEHICLES,
    COL_INDEX,
    COL_REDRAWS,
    COL_HILLS,
    COL_TRACKS,
    COL_FIRST_CONFLICT,
    COL_METHOD,
    COL_STATUS,
    COL_DEVIATION,
    COL_UNITS,
    COL_EFFORT,
    COL_EXPANDED,
    COL_GENERATED,
    COL_ORDERS,
    COL_TIME,
    COL_LOSS,
    COL_DELAY,
    COL_JITTER,
    COL_NET_SEED,
    COL_STOP_STEP,
    COL_STOP_MESSAGES,
    COL_OPTIMAL,
    COL_BOUND,
    COL_BETA,
    COL_MAX_ORDERS,
    COL_WORK,
    COL_FIRST,
    COL_COUNT,
    COL_FALLBACKS,
    COL_SENT,
    COL_DELIVERED,
    COL_DROPPED,
    COL_SWEEP,
    COL_NET_SEED_OPTION,
    COLS
};

/* The rows of an encounter before its stop rows: its methods', then the flown modes'. */
enum { ROW_FLOWN = COAVOID_MC_METHODS, ROWS_FLY = COAVOID_MC_METHODS + COAVOID_MC_FLY_MODES };

/* What has been read of an encounter. */
typedef struct {
    uint8_t rows;      /* its rows seen, in order (up to ROWS_FLY) */
    uint8_t stop_step; /* the last stop row's cycle and cut point */
    uint16_t stop_messages;
} merge_slot_t;

/* A file's encounters: its rows' first and count. */
typedef struct {
    uint32_t first, count;
    size_t file; /* its place in the list */
} merge_part_t;

typedef struct {
    const char *const *paths;
    size_t files;
    merge_part_t by_file[COAVOID_MC_MERGE_MAX_FILES]; /* in the list's order */
    merge_part_t sorted[COAVOID_MC_MERGE_MAX_FILES];  /* by first */
    bool fly;
    coavoid_montecarlo_t *mc; /* config.first and count: the parts'; sizes as read */
    merge_slot_t *slots;      /* one per result */
    bool has_size[COAVOID_MONTECARLO_MAX_SIZES]; /* mc->sizes[k] holds its limits */
    bool has_run;                                /* the seed and the network seen */
    uint32_t sweep;                              /* 0 none, 1 all, 2 ends */
} merge_t;

/* The file being read. */
typedef struct {
    const char *path;
    unsigned long line;
    const merge_part_t *part;
    uint32_t size_pos; /* the place in mc->sizes of the last row's UAV count */
} merge_file_t;

static int merge_fail(coavoid_run_error_t *e, const merge_file_t *f, const char *fmt, ...)
    COAVOID_EVALUATION_PRINTF_LIKE(3, 4);

static int merge_fail(coavoid_run_error_t *e, const merge_file_t *f, const char *fmt, ...)
{
    char why[512];
    va_list args;
    va_start(args, fmt);
    vsnprintf(why, sizeof why, fmt, args);
    va_end(args);
    return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--merge: %.200s:%lu: %s", f->path, f->line,
                            why);
}

/* ---- fields ---- */

/* Splits line at commas into at most max fields; the count, or max + 1 when more. */
static uint32_t split(char *line, char **fields, uint32_t max)
{
    uint32_t n = 0;
    for (char *p = line;;) {
        if (n == max) {
            return max + 1u;
        }
        fields[n++] = p;
        char *comma = strchr(p, ',');
        if (comma == NULL) {
            return n;
        }
        *comma = '\0';
        p = comma + 1;
    }
}

/* A decimal integer of at most max, digits only. */
static bool whole(const char *t, uint64_t max, uint64_t *out)
{
    size_t n = t != NULL ? strlen(t) : 0u;
    if (n == 0u || n > 20u || strspn(t, "0123456789") != n || (n > 1u && t[0] == '0')) {
        return false;
    }
    uint64_t v = 0;
    for (size_t k = 0; k < n; k++) {
        const uint64_t d = (uint64_t)(t[k] - '0');
        if (v > (UINT64_MAX - d) / 10u) {
            return false;
        }
        v = v * 10u + d;
    }
    *out = v;
    return v <= max;
}

static bool whole32(const char *t, uint32_t *out)
{
    uint64_t v = 0;
    bool ok = whole(t, UINT32_MAX, &v);
    *out = (uint32_t)v;
    return ok;
}

/* A plain decimal number (the CSV's %.6f, %.1f and settings), finite and >= 0. */
static bool real(const char *t, double *out)
{
    size_t n = t != NULL ? strlen(t) : 0u;
    if (n == 0u || n > 32u || strspn(t, "0123456789.e+-") != n) {
        return false;
    }
    char *end = NULL;
    errno = 0;
    *out = strtod(t, &end);
    return errno == 0 && *end == '\0' && isfinite(*out) && *out >= 0.0;
}

/* A 128-bit cost in decimal (deviation_units). */
static bool cost(const char *t, coa_cost_t *out)
{
    size_t n = t != NULL ? strlen(t) : 0u;
    if (n == 0u || n > 39u || strspn(t, "0123456789") != n) {
        return false;
    }
    uint64_t hi = 0, lo = 0;
    for (size_t k = 0; k < n; k++) {
        /* (hi, lo) * 10 + d, in 32-bit limbs so that the carries are exact. */
        uint64_t limb[4] = {lo & 0xffffffffu, lo >> 32, hi & 0xffffffffu, hi >> 32};
        uint64_t carry = (uint64_t)(t[k] - '0');
        for (int j = 0; j < 4; j++) {
            uint64_t v = limb[j] * 10u + carry;
            limb[j] = v & 0xffffffffu;
            carry = v >> 32;
        }
        if (carry != 0u) {
            return false;
        }
        lo = limb[0] | (limb[1] << 32);
        hi = limb[2] | (limb[3] << 32);
    }
    out->hi = hi;
    out->lo = lo;
    return true;
}

/* Every listed column empty (absent ones, of a plan run's CSV, too). */
static bool empty(char *const *f, int from, int to)
{
    for (int c = from; c <= to; c++) {
        if (f[c] != NULL && f[c][0] != '\0') {
            return false;
        }
    }
    return true;
}

/* ---- lines ---- */

/* The next line of in, its newline removed: 1, 0 at the end, or an error. */
static int next_line(FILE *in, merge_file_t *f, char *line, size_t size, coavoid_run_error_t *e)
{
    if (fgets(line, (int)size, in) == NULL) {
        return ferror(in) ? merge_fail(e, f, "read error") : 0;
    }
    f->line++;
    size_t n = strlen(line);
    if (f->line > MERGE_LINES_MAX) {
        return merge_fail(e, f, "more lines than a run writes");
    }
    if (n == 0u || line[n - 1u] != '\n') {
        return merge_fail(e, f, "a line too long, or no newline at the end");
    }
    line[n - 1u] = '\0';
    return 1;
}

/* The header's kind: 1 a plan run's, 2 a --fly run's; or an error. */
static int header_kind(const char *line, const merge_file_t *f, coavoid_run_error_t *e)
{
    if (strcmp(line, COAVOID_MC_CSV_HEADER_LINE) == 0) {
        return 1;
    }
    if (strcmp(line, COAVOID_MC_CSV_HEADER_FLY_LINE) == 0) {
        return 2;
    }
    if (strcmp(line, COAVOID_MC_CSV_OLD_HEADER_LINE) == 0 ||
        strcmp(line, COAVOID_MC_CSV_OLD_HEADER_FLY_LINE) == 0) {
        return merge_fail(e, f,
                          "no columns optimal to count (a CSV from before --merge): run the "
                          "part again");
    }
    return merge_fail(e, f, "not the header of a montecarlo CSV");
}

/* Splits a row into the columns of a --fly CSV (NULL: a column a plan run's CSV has not). */
static int row_fields(const merge_t *m, const merge_file_t *f, char *line, char **col,
                      coavoid_run_error_t *e)
{
    _Static_assert((int)COLS == (int)COAVOID_MC_CSV_FLY_FIELDS, "the columns of a --fly CSV");
    char *raw[COLS + 1];
    const uint32_t want = m->fly ? (uint32_t)COAVOID_MC_CSV_FLY_FIELDS : COAVOID_MC_CSV_FIELDS;
    if (split(line, raw, COLS) != want) {
        return merge_fail(e, f, "not %u fields", (unsigned)want);
    }
    if (m->fly) {
        memcpy(col, raw, COLS * sizeof *col);
        return COAVOID_RUN_DONE;
    }
    for (int c = 0; c < COLS; c++) {
        col[c] = NULL;
    }
    memcpy(col, raw, COAVOID_MC_CSV_PLAN_FIELDS * sizeof *col);
    memcpy(col + COL_OPTIMAL, raw + COAVOID_MC_CSV_PLAN_FIELDS,
           COAVOID_MC_CSV_MORE_FIELDS * sizeof *col);
    return COAVOID_RUN_DONE;
}

/* ---- the parts' encounters ---- */

/* Opens f and reads its header: its kind (header_kind), or an error. *in is the open file
 * (NULL when it could not be opened), for the caller to close. */
static int open_part(merge_file_t *f, FILE **in, char *line, size_t size, coavoid_run_error_t *e)
{
    *in = fopen(f->path, "r");
    if (*in == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--merge: cannot read '%.200s'", f->path);
    }
    int rc = next_line(*in, f, line, size, e);
    if (rc == 0) {
        rc = coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--merge: %.200s: an empty file", f->path);
    }
    return rc == 1 ? header_kind(line, f, e) : rc;
}

/* File j's header and first row: its kind (every file the first's) and encounters. */
static int scan_part(merge_t *m, size_t j, coavoid_run_error_t *e)
{
    merge_file_t f = {m->paths[j], 0ul, NULL, 0u};
    FILE *in = NULL;
    char line[MERGE_LINE_MAX];
    int rc = open_part(&f, &in, line, sizeof line, e);
    if (in == NULL) {
        return rc;
    }
    if (rc > 0 && j > 0u && (rc == 2) != m->fly) {
        rc = merge_fail(e, &f, "%s --fly, and '%.200s' %s (the parts of a run have its options)",
                        rc == 2 ? "with" : "without", m->paths[0], m->fly ? "with" : "without");
    }
    if (rc > 0) {
        m->fly = rc == 2;
        rc = next_line(in, &f, line, sizeof line, e);
        rc = rc == 0 ? merge_fail(e, &f, "no rows after the header") : rc;
    }
    char *col[COLS];
    if (rc == 1) {
        rc = row_fields(m, &f, line, col, e);
    }
    merge_part_t *p = &m->by_file[j];
    p->file = j;
    if (rc == COAVOID_RUN_DONE &&
        (!whole32(col[COL_FIRST], &p->first) || !whole32(col[COL_COUNT], &p->count) ||
         p->count == 0u || p->first > UINT32_MAX - p->count)) {
        rc = merge_fail(e, &f, "first and count are not a run's");
    }
    fclose(in);
    return rc;
}

static int by_first(const void *pa, const void *pb)
{
    const merge_part_t *a = pa, *b = pb;
    return a->first < b->first ? -1 : (a->first > b->first ? 1 : 0);
}

/* The parts' encounters, end to end: none twice, none left out, as many as a run has. */
static int merge_ranges(merge_t *m, coavoid_run_error_t *e)
{
    merge_part_t *p = m->sorted;
    memcpy(p, m->by_file, m->files * sizeof *p);
    qsort(p, m->files, sizeof *p, by_first);
    uint64_t next = p[0].first;
    for (size_t k = 0; k < m->files; k++) {
        if (p[k].first < next) {
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                    "--merge: '%.200s' and '%.200s' both hold encounter %lu "
                                    "(each part of a run has its own --first)",
                                    m->paths[p[k - 1u].file], m->paths[p[k].file],
                                    (unsigned long)p[k].first);
        }
        if (p[k].first > next) {
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                    "--merge: no part holds encounters %llu to %lu (the next, "
                                    "'%.200s', starts after them)",
                                    (unsigned long long)next, (unsigned long)(p[k].first - 1u),
                                    m->paths[p[k].file]);
        }
        next = (uint64_t)p[k].first + p[k].count;
    }
    const uint64_t count = next - p[0].first;
    if (count > COAVOID_MONTECARLO_MAX_COUNT || next > UINT32_MAX) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "--merge: encounters %lu to %llu, more than a run's %u",
                                (unsigned long)p[0].first, (unsigned long long)(next - 1u),
                                COAVOID_MONTECARLO_MAX_COUNT);
    }
    m->mc->config.first = p[0].first;
    m->mc->config.count = (uint32_t)count;
    return COAVOID_RUN_DONE;
}

/* The part that holds encounter index. */
static const char *owner(const merge_t *m, uint32_t index)
{
    size_t k = 0;
    while (k + 1u < m->files && m->sorted[k + 1u].first <= index) {
        k++;
    }
    return m->paths[m->sorted[k].file];
}

/* ---- a row ---- */

/* A new UAV count (the first file's rows give them, in order): room for its encounters. */
static int add_size(merge_t *m, uint32_t n, coavoid_run_error_t *e)
{
    coavoid_montecarlo_t *mc = m->mc;
    const uint32_t k = mc->config.size_count, count = mc->config.count;
    const size_t total = (size_t)(k + 1u) * count;
    coavoid_mc_result_t *results = realloc(mc->results, total * sizeof *results);
    if (results != NULL) {
        mc->results = results;
    }
    merge_slot_t *slots = realloc(m->slots, total * sizeof *slots);
    if (slots != NULL) {
        m->slots = slots;
    }
    if (results == NULL || slots == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "--merge: out of memory for %lu encounters of %lu UAVs",
                                (unsigned long)count, (unsigned long)n);
    }
    memset(&results[(size_t)k * count], 0, count * sizeof *results);
    memset(&slots[(size_t)k * count], 0, count * sizeof *slots);
    mc->config.vehicles[k] = n;
    mc->sizes[k].n = n;
    mc->config.size_count = k + 1u;
    mc->total = (uint32_t)total;
    return COAVOID_RUN_DONE;
}

/* The row's UAV count, in *k its place in the sizes (the first file's order, which every
 * file's rows follow), and its planners' limits, the same in every row. */
static int row_size(merge_t *m, merge_file_t *f, char *const *col, uint32_t n, uint32_t *k,
                    coavoid_run_error_t *e)
{
    coavoid_montecarlo_t *mc = m->mc;
    *k = 0;
    while (*k < mc->config.size_count && mc->sizes[*k].n != n) {
        (*k)++;
    }
    if (*k == mc->config.size_count) {
        if (f->part != &m->by_file[0]) {
            return merge_fail(e, f,
                              "%lu UAVs, of which '%.200s' has no rows (the parts of a "
                              "run have its --vehicles)",
                              (unsigned long)n, m->paths[0]);
        }
        int rc = add_size(m, n, e);
        if (rc != COAVOID_RUN_DONE) {
            return rc;
        }
    }
    if (*k < f->size_pos) {
        return merge_fail(e, f, "%lu UAVs after %lu (a run's rows follow its --vehicles)",
                          (unsigned long)n, (unsigned long)mc->sizes[f->size_pos].n);
    }
    f->size_pos = *k;
    coavoid_mc_size_t *size = &mc->sizes[*k], limits = {n, 0u, 0u, 0u};
    if (!whole32(col[COL_BETA], &limits.beta) || limits.beta == 0u ||
        !whole32(col[COL_MAX_ORDERS], &limits.max_orders) || limits.max_orders == 0u ||
        !whole(col[COL_WORK], UINT64_MAX, &limits.work)) {
        return merge_fail(e, f, "beta, max_orders or work is not a planner's");
    }
    if (!m->has_size[*k]) {
        *size = limits;
        m->has_size[*k] = true;
    } else if (size->beta != limits.beta || size->max_orders != limits.max_orders ||
               size->work != limits.work) {
        return merge_fail(e, f,
                          "beta %lu, max_orders %lu, work %llu for %lu UAVs, where '%.200s' has "
                          "%lu, %lu, %llu (the parts of a run have its options)",
                          (unsigned long)limits.beta, (unsigned long)limits.max_orders,
                          (unsigned long long)limits.work, (unsigned long)n, m->paths[0],
                          (unsigned long)size->beta, (unsigned long)size->max_orders,
                          (unsigned long long)size->work);
    }
    return COAVOID_RUN_DONE;
}

/* The run's seed and, with fly, its network, the sweep and --net-seed: the same in every
 * row. */
static int row_run(merge_t *m, const merge_file_t *f, char *const *col, coavoid_run_error_t *e)
{
    coavoid_montecarlo_config_t *c = &m->mc->config, run;
    memset(&run, 0, sizeof run);
    const char *sweep = m->fly ? col[COL_SWEEP] : "";
    const char *net_seed = m->fly ? col[COL_NET_SEED_OPTION] : "";
    run.has_net_seed = net_seed[0] != '\0';
    if (!whole(col[COL_SEED], UINT64_MAX, &run.seed) ||
        (m->fly &&
         (!real(col[COL_LOSS], &run.loss) || !(run.loss < 1.0) ||
          !real(col[COL_DELAY], &run.delay) || !real(col[COL_JITTER], &run.jitter) ||
          !(run.delay + run.jitter < coavoid_encounter_montecarlo.dt) ||
          (run.has_net_seed && !whole(net_seed, UINT64_MAX, &run.net_seed)) ||
          (sweep[0] != '\0' && strcmp(sweep, "all") != 0 && strcmp(sweep, "ends") != 0)))) {
        return merge_fail(e, f,
                          "seed, loss, delay, jitter, coordinator_stops_sweep or "
                          "net_seed_option is not a run's");
    }
    const uint32_t kind = sweep[0] == '\0' ? 0u : (strcmp(sweep, "all") == 0 ? 1u : 2u);
    if (!m->has_run) {
        c->seed = run.seed;
        c->loss = run.loss;
        c->delay = run.delay;
        c->jitter = run.jitter;
        c->has_net_seed = run.has_net_seed;
        c->net_seed = run.net_seed;
        m->sweep = kind;
        m->has_run = true;
    } else if (run.seed != c->seed || run.loss != c->loss || run.delay != c->delay ||
               run.jitter != c->jitter || run.has_net_seed != c->has_net_seed ||
               run.net_seed != c->net_seed || kind != m->sweep) {
        return merge_fail(e, f,
                          "seed, loss, delay, jitter, coordinator_stops_sweep or net_seed_option "
                          "differ from '%.200s''s (the parts of a run have its options)",
                          m->paths[0]);
    }
    return COAVOID_RUN_DONE;
}

/* What a row's method names: 0-2 a method's plan, ROW_FLOWN + mode a closed-loop run,
 * ROWS_FLY a stopped run; -1 none of the run's. */
static int row_kind(const merge_t *m, const char *method)
{
    for (int k = 0; k < COAVOID_MC_METHODS; k++) {
        if (strcmp(method, coavoid_mc_method_names[k]) == 0) {
            return k;
        }
    }
    if (!m->fly || strncmp(method, "flown_", 6) != 0) {
        return -1;
    }
    for (int k = 0; k < COAVOID_MC_FLY_MODES; k++) {
        if (strcmp(method + 6, coavoid_mc_fly_mode_names[k]) == 0) {
            return ROW_FLOWN + k;
        }
    }
    return m->sweep != 0u && strcmp(method, "flown_centralised_stop") == 0 ? ROWS_FLY : -1;
}

/* The name of the row due after `rows` rows of an encounter. */
static const char *due_name(const merge_t *m, uint32_t rows)
{
    if (rows < COAVOID_MC_METHODS) {
        return coavoid_mc_method_names[rows];
    }
    if (m->fly && rows < ROWS_FLY) {
        return rows == ROW_FLOWN ? "flown_centralised" : "flown_decoupled";
    }
    return m->sweep != 0u ? "flown_centralised_stop or the next encounter's"
                          : "the next encounter's";
}

/* The row in its encounter: due there (the rows of each encounter in the order a run
 * writes them), and its encounter's columns the same as its first row's. */
static int row_place(const merge_t *m, const merge_file_t *f, char *const *col, int row,
                     coavoid_mc_result_t *r, merge_slot_t *s, coavoid_run_error_t *e)
{
    const uint32_t rows = m->fly ? ROWS_FLY : COAVOID_MC_METHODS;
    const int due = s->rows < rows ? (int)s->rows : ROWS_FLY;
    coavoid_mc_result_t got;
    memset(&got, 0, sizeof got);
    if (!whole32(col[COL_VEHICLES], &got.vehicles) || !whole32(col[COL_INDEX], &got.index) ||
        !whole32(col[COL_REDRAWS], &got.redraws) || !whole32(col[COL_HILLS], &got.info.hills) ||
        !whole32(col[COL_TRACKS], &got.info.tracks) ||
        !whole32(col[COL_FIRST_CONFLICT], &got.first_conflict_step) ||
        (m->fly && !whole(col[COL_NET_SEED], UINT64_MAX, &got.net_seed))) {
        return merge_fail(e, f,
                          "redraws, hills, tracks, first_conflict_step or net_seed is not "
                          "an integer");
    }
    if (row != due || (row == ROWS_FLY && m->sweep == 0u)) {
        return merge_fail(e, f,
                          "encounter %lu of %lu UAVs: a %.40s row where %s was due (a row "
                          "repeated, left out or out of order)",
                          (unsigned long)got.index, (unsigned long)got.vehicles, col[COL_METHOD],
                          due_name(m, s->rows));
    }
    if (s->rows == 0u) {
        r->vehicles = got.vehicles;
        r->index = got.index;
        r->redraws = got.redraws;
        r->info = got.info;
        r->first_conflict_step = got.first_conflict_step;
        r->net_seed = got.net_seed;
    } else if (got.redraws != r->redraws || got.info.hills != r->info.hills ||
               got.info.tracks != r->info.tracks ||
               got.first_conflict_step != r->first_conflict_step || got.net_seed != r->net_seed) {
        return merge_fail(e, f,
                          "encounter %lu of %lu UAVs: redraws, hills, tracks, "
                          "first_conflict_step or net_seed differ from its first row's",
                          (unsigned long)got.index, (unsigned long)got.vehicles);
    }
    if (s->rows < rows) {
        s->rows++;
    }
    return COAVOID_RUN_DONE;
}

/* A method's row: its status, costs only of a plan, the search's counts and time, and
 * centralised, whether proven optimal and the lower bound; no stop point nor traffic. */
static int plan_row(const merge_file_t *f, char *const *col, int method, coavoid_mc_outcome_t *o,
                    coavoid_run_error_t *e)
{
    static const coa_plan_status_t statuses[] = {COA_PLAN_SOLVED, COA_PLAN_INFEASIBLE,
                                                 COA_PLAN_BUDGET_EXHAUSTED};
    size_t k = 0;
    while (k < 3u && strcmp(col[COL_STATUS], coavoid_output_status_name(statuses[k])) != 0) {
        k++;
    }
    if (k == 3u) {
        return merge_fail(e, f, "status '%.40s' is not a plan's", col[COL_STATUS]);
    }
    o->status = statuses[k];
    const bool solved = o->status == COA_PLAN_SOLVED;
    if (solved ? !real(col[COL_DEVIATION], &o->deviation) || !cost(col[COL_UNITS], &o->units) ||
                     !whole32(col[COL_EFFORT], &o->effort)
               : !empty(col, COL_DEVIATION, COL_EFFORT)) {
        return merge_fail(e, f, "deviation, deviation_units and effort are not a %s plan's",
                          solved ? "solved" : "failed");
    }
    if (!whole(col[COL_EXPANDED], UINT64_MAX, &o->expanded) ||
        !whole(col[COL_GENERATED], UINT64_MAX, &o->generated) ||
        !whole32(col[COL_ORDERS], &o->orders_tried) || !real(col[COL_TIME], &o->time_us)) {
        return merge_fail(e, f, "expanded, generated, orders_tried or time_us is not a number");
    }
    const char *optimal = col[COL_OPTIMAL];
    if (method == COAVOID_MC_CENTRALISED
            ? (strcmp(optimal, "0") != 0 && strcmp(optimal, "1") != 0) ||
                  !real(col[COL_BOUND], &o->bound_deviation)
            : !empty(col, COL_OPTIMAL, COL_BOUND)) {
        return merge_fail(e, f, "optimal and bound_deviation are not a %s row's",
                          coavoid_mc_method_names[method]);
    }
    o->optimal = optimal[0] == '1';
    if (!empty(col, COL_STOP_STEP, COL_STOP_MESSAGES) || !empty(col, COL_FALLBACKS, COL_DROPPED)) {
        return merge_fail(e, f, "a plan's row with a stop point or a closed loop's traffic");
    }
    return COAVOID_RUN_DONE;
}

/* A stopped run's row: the next stop point of the sweep (every cycle from 0 in order,
 * each from cut point 0 up, every cut point with all), no traffic. */
static int stop_row(const merge_t *m, const merge_file_t *f, char *const *col, bool lost,
                    coavoid_mc_result_t *r, merge_slot_t *s, coavoid_run_error_t *e)
{
    uint64_t step = 0, cut = 0;
    if (!whole(col[COL_STOP_STEP], 2u * coavoid_encounter_montecarlo.horizon, &step) ||
        !whole(col[COL_STOP_MESSAGES], UINT16_MAX - 1u, &cut) ||
        !empty(col, COL_FALLBACKS, COL_DROPPED)) {
        return merge_fail(e, f,
                          "stop_step and stop_messages are not a stop point of a "
                          "cycle, or the stopped run has traffic");
    }
    coavoid_mc_sweep_t *w = &r->sweep;
    const bool next = w->runs == 0u          ? step == 0u && cut == 0u
                      : step == s->stop_step ? cut > s->stop_messages &&
                                                   (m->sweep == 2u || cut == s->stop_messages + 1u)
                      : step == s->stop_step + 1u ? cut == 0u
                                                  : false;
    if (!next || w->runs == COAVOID_MC_MAX_STOPS) {
        return merge_fail(e, f,
                          "encounter %lu of %lu UAVs: stop %lu:%lu out of order (a sweep "
                          "stops in every cycle from 0, each from cut point 0 up)",
                          (unsigned long)r->index, (unsigned long)r->vehicles, (unsigned long)step,
                          (unsigned long)cut);
    }
    if (lost) {
        w->lost[w->runs / 8u] |= (uint8_t)(1u << (w->runs % 8u));
        if (w->losses++ == 0u) {
            w->loss_step = (uint32_t)step;
            w->loss_messages = (uint32_t)cut;
        }
    }
    w->runs++;
    w->cycles = (uint32_t)step + 1u;
    s->stop_step = (uint8_t)step;
    s->stop_messages = (uint16_t)cut;
    return COAVOID_RUN_DONE;
}

/* A closed-loop row: its verdict, no plan's columns, and its traffic (flown_centralised,
 * flown_decoupled) or its stop point (flown_centralised_stop). */
static int flown_row(const merge_t *m, const merge_file_t *f, char *const *col, int row,
                     coavoid_mc_result_t *r, merge_slot_t *s, coavoid_run_error_t *e)
{
    const char *status = col[COL_STATUS];
    const bool lost = strcmp(status, "loss_of_separation") == 0;
    if (!lost && strcmp(status, "separated") != 0) {
        return merge_fail(e, f,
                          "a flown row's status is neither separated nor "
                          "loss_of_separation");
    }
    if (!empty(col, COL_DEVIATION, COL_TIME) || !empty(col, COL_OPTIMAL, COL_BOUND)) {
        return merge_fail(e, f, "a flown row with a plan's columns");
    }
    if (row == ROWS_FLY) {
        return stop_row(m, f, col, lost, r, s, e);
    }
    coavoid_mc_flown_t *flown = &r->flown[row - ROW_FLOWN];
    flown->loss_of_separation = lost;
    if (!empty(col, COL_STOP_STEP, COL_STOP_MESSAGES) ||
        !whole32(col[COL_FALLBACKS], &flown->fallbacks) ||
        !whole(col[COL_SENT], UINT64_MAX, &flown->sent) ||
        !whole(col[COL_DELIVERED], UINT64_MAX, &flown->delivered) ||
        !whole(col[COL_DROPPED], UINT64_MAX, &flown->dropped)) {
        return merge_fail(e, f,
                          "a flown row's fallbacks, sent, delivered and dropped are not "
                          "integers, or it has a stop point");
    }
    return COAVOID_RUN_DONE;
}

/* One data row of file f into its encounter. */
static int merge_row(merge_t *m, merge_file_t *f, char *line, coavoid_run_error_t *e)
{
    char *col[COLS];
    uint32_t first = 0, count = 0, index = 0, n = 0, k = 0;
    int rc = row_fields(m, f, line, col, e);
    if (rc != COAVOID_RUN_DONE) {
        return rc;
    }
    if (!whole32(col[COL_FIRST], &first) || !whole32(col[COL_COUNT], &count) ||
        first != f->part->first || count != f->part->count) {
        return merge_fail(e, f,
                          "first and count differ from the file's first row's (a file "
                          "holds one run)");
    }
    if (!whole32(col[COL_VEHICLES], &n) || n < COAVOID_ENCOUNTER_MIN_VEHICLES ||
        n > COAVOID_ENCOUNTER_MAX_VEHICLES || !whole32(col[COL_INDEX], &index) || index < first ||
        index - first >= count) {
        return merge_fail(e, f,
                          "vehicles is not a UAV count, or index not one of the run's "
                          "encounters %lu to %lu",
                          (unsigned long)first, (unsigned long)(first + count - 1u));
    }
    rc = row_run(m, f, col, e);
    rc = rc == COAVOID_RUN_DONE ? row_size(m, f, col, n, &k, e) : rc;
    if (rc != COAVOID_RUN_DONE) {
        return rc;
    }
    const int row = row_kind(m, col[COL_METHOD]);
    if (row < 0) {
        return merge_fail(e, f, "method '%.40s' is not one of the run's", col[COL_METHOD]);
    }
    const coavoid_montecarlo_config_t *c = &m->mc->config;
    const size_t item = (size_t)k * c->count + (index - c->first);
    coavoid_mc_result_t *r = &m->mc->results[item];
    merge_slot_t *s = &m->slots[item];
    rc = row_place(m, f, col, row, r, s, e);
    if (rc != COAVOID_RUN_DONE) {
        return rc;
    }
    return row < ROW_FLOWN ? plan_row(f, col, row, &r->m[row], e)
                           : flown_row(m, f, col, row, r, s, e);
}

/* File j's rows into their encounters. */
static int read_part(merge_t *m, size_t j, coavoid_run_error_t *e)
{
    merge_file_t f = {m->paths[j], 0ul, &m->by_file[j], 0u};
    FILE *in = NULL;
    char line[MERGE_LINE_MAX];
    int rc = open_part(&f, &in, line, sizeof line, e);
    if (in == NULL) {
        return rc;
    }
    rc = rc > 0 && (rc == 2) != m->fly ? merge_fail(e, &f, "another header than before") : rc;
    while (rc > 0 && (rc = next_line(in, &f, line, sizeof line, e)) == 1) {
        rc = merge_row(m, &f, line, e);
        rc = rc == COAVOID_RUN_DONE ? 1 : rc;
    }
    fclose(in);
    return rc;
}

/* ---- the run ---- */

/* Every encounter of every UAV count whole: its rows and, with the sweep, every cycle's
 * stop rows (a part stopped early ends in the middle of one). */
static int merge_complete(const merge_t *m, coavoid_run_error_t *e)
{
    const coavoid_montecarlo_config_t *c = &m->mc->config;
    const uint32_t rows = m->fly ? ROWS_FLY : COAVOID_MC_METHODS;
    const uint32_t cycles = 2u * coavoid_encounter_montecarlo.horizon + 1u;
    for (uint32_t k = 0; k < c->size_count; k++) {
        for (uint32_t j = 0; j < c->count; j++) {
            const size_t item = (size_t)k * c->count + j;
            const merge_slot_t *s = &m->slots[item];
            if (s->rows == rows &&
                (m->sweep == 0u || m->mc->results[item].sweep.cycles == cycles)) {
                continue;
            }
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                    "--merge: %.200s: encounter %lu of %lu UAVs: %s (a run cut "
                                    "short?)",
                                    owner(m, c->first + j), (unsigned long)(c->first + j),
                                    (unsigned long)c->vehicles[k],
                                    s->rows == 0u    ? "no rows"
                                    : s->rows < rows ? "some of its rows only"
                                                     : "stop rows of some cycles only");
        }
    }
    return COAVOID_RUN_DONE;
}

/* The figure's file: not one of the parts, and one we can write. */
static int merge_svg(const char *const *paths, size_t count, const char *svg,
                     coavoid_run_error_t *e)
{
    struct stat out, in;
    if (svg == NULL) {
        return COAVOID_RUN_DONE;
    }
    for (size_t j = 0; j < count && stat(svg, &out) == 0; j++) {
        if (stat(paths[j], &in) == 0 && in.st_dev == out.st_dev && in.st_ino == out.st_ino) {
            return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--svg: '%.200s' is a part to merge",
                                    svg);
        }
    }
    FILE *probe = fopen(svg, "w");
    if (probe == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--svg: cannot write '%.200s'", svg);
    }
    fclose(probe);
    return COAVOID_RUN_DONE;
}

/* Reads the parts into m->mc: their encounters, then every file's rows. */
static int merge_read(merge_t *m, coavoid_run_error_t *e)
{
    int rc = COAVOID_RUN_DONE;
    for (size_t j = 0; j < m->files && rc == COAVOID_RUN_DONE; j++) {
        rc = scan_part(m, j, e);
    }
    rc = rc == COAVOID_RUN_DONE ? merge_ranges(m, e) : rc;
    if (rc != COAVOID_RUN_DONE) {
        return rc;
    }
    m->mc->x = calloc(m->mc->config.count, sizeof *m->mc->x);
    if (m->mc->x == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--merge: out of memory");
    }
    for (size_t j = 0; j < m->files && rc == COAVOID_RUN_DONE; j++) {
        rc = read_part(m, j, e);
    }
    return rc == COAVOID_RUN_DONE ? merge_complete(m, e) : rc;
}

int coavoid_montecarlo_merge(const char *const *csv_paths, size_t count, const char *svg_path,
                             void (*defect)(void *context, const char *line), void *context,
                             coavoid_montecarlo_t **out, coavoid_run_error_t *e)
{
    *out = NULL;
    if (count == 0u || count > COAVOID_MC_MERGE_MAX_FILES) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--merge: 1 to %u CSV files",
                                COAVOID_MC_MERGE_MAX_FILES);
    }
    merge_t *m = calloc(1u, sizeof *m);
    coavoid_montecarlo_t *mc = calloc(1u, sizeof *mc);
    int rc = m == NULL || mc == NULL
                 ? coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "--merge: out of memory")
                 : merge_svg(csv_paths, count, svg_path, e);
    if (rc == COAVOID_RUN_DONE) {
        m->paths = csv_paths;
        m->files = count;
        m->mc = mc;
        rc = merge_read(m, e);
    }
    if (rc == COAVOID_RUN_DONE) {
        coavoid_montecarlo_config_t *c = &mc->config;
        c->jobs = 1u;
        c->svg = svg_path;
        c->defect = defect;
        c->context = context;
        c->fly = m->fly;
        c->stops_sweep = m->sweep != 0u;
        c->stops_ends = m->sweep == 2u;
        /* What the run checked of its plans, checked again on theirs as the CSVs give them
         * (but for the conflicts, which need the plans). */
        for (uint32_t j = 0; j < mc->total; j++) {
            coavoid_mc_cross_check(&mc->results[j]);
            coavoid_mc_report_defect(c, &mc->results[j]);
        }
    }
    if (m != NULL) {
        free(m->slots);
    }
    free(m);
    if (rc != COAVOID_RUN_DONE) {
        coavoid_montecarlo_free(mc);
        return rc;
    }
    *out = mc;
    return COAVOID_RUN_DONE;
}
