/* SPDX-License-Identifier: MIT */
/*
 * montecarlo_figure.c: the closed loop's figure across runs (montecarlo.h,
 * coavoid_montecarlo_figure): a montecarlo --fly run has one network loss, so the rate of
 * loss of separation against loss is drawn from several runs' CSV files. The files are
 * untrusted: every line is bounded, every field it uses is checked, and the first problem
 * is one error naming the file and line.
 */
#define _POSIX_C_SOURCE 200809L

#include "montecarlo.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "encounter.h"
#include "montecarlo_internal.h"
#include "run.h"

#define FIG_LINE_MAX 1024u      /* a row is about 120 characters */
#define FIG_LINES_MAX 50000000u /* per file: 100,000 encounters x 5 sizes x ~60 rows, and more */
#define FIG_FIELDS ((uint32_t)COAVOID_MC_CSV_FLY_FIELDS) /* the most a --fly header has */
#define FIG_COL_VEHICLES 1u
#define FIG_COL_METHOD 7u
#define FIG_COL_STATUS 8u
#define FIG_COL_LOSS 16u
#define FIG_COL_DELAY 17u
#define FIG_COL_JITTER 18u

/* One point: encounters and losses of a (loss level, UAV count, mode). */
typedef struct {
    uint32_t encounters, losses;
} fig_count_t;

typedef struct {
    double loss[COAVOID_MC_FIGURE_MAX_FILES]; /* the levels, ascending */
    uint32_t levels;
    fig_count_t count[COAVOID_MC_FIGURE_MAX_FILES][COAVOID_MONTECARLO_MAX_SIZES]
                     [COAVOID_MC_FLY_MODES];
    bool has_network; /* delay and jitter of the first file, which every file must share */
    double delay, jitter;
} fig_data_t;

/* The file's reading state, for its errors. */
typedef struct {
    const char *path;
    unsigned long line;
    uint32_t fields; /* its header's: 22, or 35 with the columns --merge reads */
    bool has_loss;
    double loss;
} fig_file_t;

/* Splits line (its newline removed) at commas into at most FIG_FIELDS fields; the count,
 * or FIG_FIELDS + 1 when there are more. */
static uint32_t split(char *line, char **fields)
{
    uint32_t n = 0;
    for (char *p = line;;) {
        if (n == FIG_FIELDS) {
            return FIG_FIELDS + 1u;
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

/* A plain decimal number (the CSV's %.15g), or false. */
static bool real(const char *text, double *out)
{
    if (*text == '\0' || strlen(text) > 32u || strspn(text, "0123456789.e+-") != strlen(text)) {
        return false;
    }
    char *end = NULL;
    errno = 0;
    *out = strtod(text, &end);
    return errno == 0 && *end == '\0' && isfinite(*out);
}

static int fig_fail(coavoid_run_error_t *e, const fig_file_t *f, const char *why)
{
    return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--figure-from: %.200s:%lu: %s", f->path,
                            f->line, why);
}

/* The file's network (loss, delay, jitter of a flown row): one loss per file, and the
 * delay and jitter of every file the first's (the figure is against loss alone). */
static int fig_network(fig_data_t *d, fig_file_t *f, char **fields, coavoid_run_error_t *e)
{
    double loss = 0, delay = 0, jitter = 0;
    if (!real(fields[FIG_COL_LOSS], &loss) || !(loss >= 0.0 && loss < 1.0) ||
        !real(fields[FIG_COL_DELAY], &delay) || !(delay >= 0.0) ||
        !real(fields[FIG_COL_JITTER], &jitter) || !(jitter >= 0.0)) {
        return fig_fail(e, f, "loss, delay or jitter is not a number in range");
    }
    if (f->has_loss && loss != f->loss) {
        return fig_fail(e, f, "a second loss in one file (one run has one loss)");
    }
    if (d->has_network && (delay != d->delay || jitter != d->jitter)) {
        return fig_fail(e, f,
                        "delay or jitter differs from the first file's (the figure is "
                        "against loss alone)");
    }
    f->has_loss = true;
    f->loss = loss;
    d->has_network = true;
    d->delay = delay;
    d->jitter = jitter;
    return COAVOID_RUN_DONE;
}

/* The level of loss in d, added in order when new; -1 when there are too many. */
static int fig_level(fig_data_t *d, double loss)
{
    uint32_t k = 0;
    while (k < d->levels && d->loss[k] < loss) {
        k++;
    }
    if (k < d->levels && d->loss[k] == loss) {
        return (int)k;
    }
    if (d->levels == COAVOID_MC_FIGURE_MAX_FILES) {
        return -1;
    }
    memmove(&d->loss[k + 1u], &d->loss[k], (d->levels - k) * sizeof d->loss[0]);
    memmove(&d->count[k + 1u], &d->count[k], (d->levels - k) * sizeof d->count[0]);
    memset(&d->count[k], 0, sizeof d->count[0]);
    d->loss[k] = loss;
    d->levels++;
    return (int)k;
}

/* One data row: counted when it is a flown_centralised or flown_decoupled row. */
static int fig_row(fig_data_t *d, fig_file_t *f, char *line, coavoid_run_error_t *e)
{
    char *fields[FIG_FIELDS + 1u];
    if (split(line, fields) != f->fields) {
        return fig_fail(e, f, f->fields == FIG_FIELDS ? "not 35 fields" : "not 22 fields");
    }
    int mode = strcmp(fields[FIG_COL_METHOD], "flown_centralised") == 0 ? COAVOID_MC_FLY_CENTRALISED
               : strcmp(fields[FIG_COL_METHOD], "flown_decoupled") == 0 ? COAVOID_MC_FLY_DECOUPLED
                                                                        : -1;
    if (mode < 0) {
        return COAVOID_RUN_DONE;
    }
    const char *v = fields[FIG_COL_VEHICLES], *status = fields[FIG_COL_STATUS];
    const bool lost = strcmp(status, "loss_of_separation") == 0;
    char *v_end = NULL;
    const unsigned long vehicles = strtoul(v, &v_end, 10);
    if (v[0] < '0' || v[0] > '9' || *v_end != '\0' || vehicles < COAVOID_ENCOUNTER_MIN_VEHICLES ||
        vehicles > COAVOID_ENCOUNTER_MAX_VEHICLES) {
        return fig_fail(e, f, "vehicles is not a UAV count montecarlo draws");
    }
    if (!lost && strcmp(status, "separated") != 0) {
        return fig_fail(e, f, "a flown row's status is neither separated nor loss_of_separation");
    }
    int rc = fig_network(d, f, fields, e);
    if (rc != COAVOID_RUN_DONE) {
        return rc;
    }
    int level = fig_level(d, f->loss);
    if (level < 0) {
        return fig_fail(e, f, "more distinct losses than the figure draws");
    }
    const uint32_t n = (uint32_t)vehicles - COAVOID_ENCOUNTER_MIN_VEHICLES;
    fig_count_t *c = &d->count[level][n][mode];
    if (c->encounters == UINT32_MAX) {
        return fig_fail(e, f, "too many rows");
    }
    c->encounters++;
    c->losses += lost;
    return COAVOID_RUN_DONE;
}

/* Reads one file's lines into d. */
static int fig_read(fig_data_t *d, const char *path, coavoid_run_error_t *e)
{
    fig_file_t f = {path, 0ul, 0u, false, 0.0};
    FILE *in = fopen(path, "r");
    if (in == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--figure-from: cannot read '%.200s'",
                                path);
    }
    char line[FIG_LINE_MAX];
    int rc = COAVOID_RUN_DONE;
    while (rc == COAVOID_RUN_DONE && fgets(line, sizeof line, in) != NULL) {
        f.line++;
        size_t n = strlen(line);
        if (n == 0u || line[n - 1u] != '\n' || f.line > FIG_LINES_MAX) {
            rc = fig_fail(e, &f,
                          f.line > FIG_LINES_MAX ? "more lines than a run writes"
                                                 : "a line too long, or no newline at "
                                                   "the end");
            break;
        }
        line[n - 1u] = '\0';
        if (f.line == 1u) {
            f.fields = strcmp(line, COAVOID_MC_CSV_HEADER_FLY_LINE) == 0 ? FIG_FIELDS
                       : strcmp(line, COAVOID_MC_CSV_OLD_HEADER_FLY_LINE) == 0
                           ? (uint32_t)(COAVOID_MC_CSV_PLAN_FIELDS + COAVOID_MC_CSV_NETWORK_FIELDS)
                           : 0u;
            rc = f.fields != 0u ? COAVOID_RUN_DONE
                                : fig_fail(e, &f, "not the header of a montecarlo --fly CSV");
        } else {
            rc = fig_row(d, &f, line, e);
        }
    }
    if (rc == COAVOID_RUN_DONE && ferror(in)) {
        rc = fig_fail(e, &f, "read error");
    }
    if (rc == COAVOID_RUN_DONE && !f.has_loss) {
        rc = fig_fail(e, &f, "no flown rows (a montecarlo --fly CSV has them)");
    }
    fclose(in);
    return rc;
}

/* ---- the table and the figure ---- */

#define FIG_W 760.0
#define FIG_H 470.0
#define FIG_LEFT 80.0
#define FIG_TOP 60.0
#define FIG_PW 440.0 /* the plot's width and height */
#define FIG_PH 320.0

/* As the report's figure: one colour per UAV count. */
static const char *const fig_colours[COAVOID_MONTECARLO_MAX_SIZES] = {
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#8c564b"};

static void fig_table(FILE *out, const fig_data_t *d, size_t files)
{
    fprintf(out,
            "closed loop: loss of separation against network loss, from %zu files (delay %g s, "
            "jitter %g s)\n  %4s %-12s %6s %10s %7s %7s %16s\n",
            files, d->delay, d->jitter, "UAVs", "mode", "loss", "encounters", "losses", "rate",
            "95% Wilson");
    for (uint32_t n = 0; n < COAVOID_MONTECARLO_MAX_SIZES; n++) {
        for (int mode = 0; mode < COAVOID_MC_FLY_MODES; mode++) {
            for (uint32_t k = 0; k < d->levels; k++) {
                const fig_count_t *c = &d->count[k][n][mode];
                if (c->encounters == 0u) {
                    continue;
                }
                double rate = 0, low = 0, high = 0;
                coavoid_mc_wilson(c->losses, c->encounters, &rate, &low, &high);
                fprintf(out, "  %4u %-12s %5.1f%% %10lu %7lu %6.1f%% %7.1f-%5.1f%%\n",
                        n + COAVOID_ENCOUNTER_MIN_VEHICLES, coavoid_mc_fly_mode_names[mode],
                        100.0 * d->loss[k], (unsigned long)c->encounters, (unsigned long)c->losses,
                        100 * rate, 100 * low, 100 * high);
            }
        }
    }
}

/* The axes: loss 0..right (at least 50 %) across, the rate 0..100 % up. */
static void fig_axes(FILE *f, double right)
{
    const double y0 = FIG_TOP + FIG_PH;
    for (int t = 0; t <= 10; t += 2) {
        double py = y0 - t / 10.0 * FIG_PH;
        fprintf(f,
                "<line x1=\"%.0f\" y1=\"%.1f\" x2=\"%.0f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n"
                "<text x=\"%.0f\" y=\"%.1f\" text-anchor=\"end\">%d%%</text>\n",
                FIG_LEFT, py, FIG_LEFT + FIG_PW, py, FIG_LEFT - 6, py + 4, t * 10);
    }
    for (int t = 0; t <= 10; t++) {
        double v = right * t / 10.0, px = FIG_LEFT + v / right * FIG_PW;
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.0f\" x2=\"%.1f\" y2=\"%.0f\" stroke=\"#eee\"/>\n"
                "<text x=\"%.1f\" y=\"%.0f\" text-anchor=\"middle\">%.0f%%</text>\n",
                px, FIG_TOP, px, y0, px, y0 + 18, 100 * v);
    }
    fprintf(f,
            "<rect x=\"%.0f\" y=\"%.0f\" width=\"%.0f\" height=\"%.0f\" fill=\"none\" "
            "stroke=\"black\"/>\n<text x=\"%.0f\" y=\"%.0f\" text-anchor=\"middle\">network loss "
            "(each copy to each node)</text>\n<text transform=\"translate(%.0f %.0f) "
            "rotate(-90)\" text-anchor=\"middle\">encounters that lose separation</text>\n",
            FIG_LEFT, FIG_TOP, FIG_PW, FIG_PH, FIG_LEFT + FIG_PW / 2, y0 + 38, FIG_LEFT - 50,
            FIG_TOP + FIG_PH / 2);
}

/* The x of loss level k for a mode: the modes side by side, so their intervals show. */
static double fig_x(const fig_data_t *d, uint32_t k, int mode, double right)
{
    return FIG_LEFT + d->loss[k] / right * FIG_PW +
           (mode == COAVOID_MC_FLY_CENTRALISED ? -3.0 : 3.0);
}

/* One UAV count and mode: the rate at each loss joined (centralised solid, decoupled
 * dashed), each point with its 95 % Wilson interval. */
static void fig_series(FILE *f, const fig_data_t *d, uint32_t n, int mode, double right)
{
    const double y0 = FIG_TOP + FIG_PH;
    const char *colour = fig_colours[n];
    bool any = false;
    for (uint32_t k = 0; k < d->levels; k++) {
        any = any || d->count[k][n][mode].encounters > 0u;
    }
    if (!any) {
        return;
    }
    fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.8\"%s points=\"", colour,
            mode == COAVOID_MC_FLY_DECOUPLED ? " stroke-dasharray=\"6 4\"" : "");
    for (uint32_t k = 0, first = 1; k < d->levels; k++) {
        const fig_count_t *c = &d->count[k][n][mode];
        if (c->encounters > 0u) {
            fprintf(f, "%s%.1f,%.1f", first ? "" : " ", fig_x(d, k, mode, right),
                    y0 - (double)c->losses / c->encounters * FIG_PH);
            first = 0;
        }
    }
    fprintf(f, "\"/>\n");
    for (uint32_t k = 0; k < d->levels; k++) {
        const fig_count_t *c = &d->count[k][n][mode];
        if (c->encounters == 0u) {
            continue;
        }
        double rate = 0, low = 0, high = 0, px = fig_x(d, k, mode, right);
        coavoid_mc_wilson(c->losses, c->encounters, &rate, &low, &high);
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\"/>"
                "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"%s\" stroke=\"%s\"/>\n",
                px, y0 - low * FIG_PH, px, y0 - high * FIG_PH, colour, px, y0 - rate * FIG_PH,
                mode == COAVOID_MC_FLY_CENTRALISED ? colour : "white", colour);
    }
}

/* The legend: a line per UAV count drawn, and the modes. */
static void fig_legend(FILE *f, const fig_data_t *d)
{
    const double x = FIG_LEFT + FIG_PW + 30;
    double y = FIG_TOP + 10;
    for (uint32_t n = 0; n < COAVOID_MONTECARLO_MAX_SIZES; n++) {
        bool any = false;
        for (uint32_t k = 0; k < d->levels; k++) {
            any = any || d->count[k][n][0].encounters > 0u || d->count[k][n][1].encounters > 0u;
        }
        if (any) {
            fprintf(f,
                    "<line x1=\"%.0f\" y1=\"%.0f\" x2=\"%.0f\" y2=\"%.0f\" stroke=\"%s\" "
                    "stroke-width=\"2\"/><text x=\"%.0f\" y=\"%.0f\">%u UAVs</text>\n",
                    x, y - 4, x + 24, y - 4, fig_colours[n], x + 30, y,
                    n + COAVOID_ENCOUNTER_MIN_VEHICLES);
            y += 18;
        }
    }
    fprintf(f,
            "<text x=\"%.0f\" y=\"%.0f\">solid, filled: centralised</text>\n"
            "<text x=\"%.0f\" y=\"%.0f\">dashed, open: decoupled</text>\n"
            "<text x=\"%.0f\" y=\"%.0f\">bars: 95%% Wilson</text>\n",
            x, y + 12, x, y + 30, x, y + 48);
}

static int fig_svg(const char *path, const fig_data_t *d, size_t files)
{
    FILE *f = fopen(path, "w");
    if (f == NULL) {
        return -1;
    }
    const double right = d->loss[d->levels - 1u] > 0.5 ? 1.0 : 0.5;
    fprintf(f,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
            "viewBox=\"0 0 %.0f %.0f\" font-family=\"sans-serif\" font-size=\"13\">\n"
            "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n"
            "<text x=\"%.0f\" y=\"28\" font-size=\"15\" font-weight=\"bold\">coavoid montecarlo "
            "--fly: closed-loop loss of separation against network loss</text>\n"
            "<text x=\"%.0f\" y=\"46\">%zu runs; delay %g s, jitter %g s</text>\n",
            FIG_W, FIG_H, FIG_W, FIG_H, FIG_LEFT, FIG_LEFT, files, d->delay, d->jitter);
    fig_axes(f, right);
    for (uint32_t n = 0; n < COAVOID_MONTECARLO_MAX_SIZES; n++) {
        for (int mode = 0; mode < COAVOID_MC_FLY_MODES; mode++) {
            fig_series(f, d, n, mode, right);
        }
    }
    fig_legend(f, d);
    fprintf(f, "</svg>\n");
    bool ok = !ferror(f);
    return fclose(f) == 0 && ok ? 0 : -1;
}

int coavoid_montecarlo_figure(const char *const *csv_paths, size_t count, const char *svg_path,
                              FILE *out, coavoid_run_error_t *e)
{
    if (count == 0u || count > COAVOID_MC_FIGURE_MAX_FILES || svg_path == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT,
                                "--figure-from: 1 to %u CSV files, and --svg",
                                COAVOID_MC_FIGURE_MAX_FILES);
    }
    fig_data_t *d = calloc(1u, sizeof *d);
    if (d == NULL) {
        return coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "out of memory");
    }
    int rc = COAVOID_RUN_DONE;
    for (size_t j = 0; j < count && rc == COAVOID_RUN_DONE; j++) {
        rc = fig_read(d, csv_paths[j], e);
    }
    if (rc == COAVOID_RUN_DONE && fig_svg(svg_path, d, count) != 0) {
        rc = coavoid_run_fail(e, COAVOID_RUN_ERR_INPUT, "--svg: cannot write '%.200s'", svg_path);
    }
    if (rc == COAVOID_RUN_DONE) {
        fig_table(out, d, count);
        if (fflush(out) != 0 || ferror(out)) {
            rc = coavoid_run_fail(e, COAVOID_RUN_ERR_INTERNAL, "cannot write the table");
        }
    }
    free(d);
    return rc;
}
