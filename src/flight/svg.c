/* SPDX-License-Identifier: MIT */
/*
 * svg.c: the figure of a flight record (flight.h), after the paper's figures: a top view
 * of the run, then one altitude-against-time panel per UAV with its reference dashed and
 * its flown path solid, the terrain under it and the traffic near it.
 *
 * The document is self-contained: no scripts, no fonts or images from elsewhere; the only
 * references are to its own clip paths. Text that came from input (the scenario's name)
 * is escaped and invalid UTF-8 is replaced, so the file is always well-formed XML.
 *
 * Conflict markers come from coavoid_flight_conflicts, the same geometry tests as the
 * evaluation: hollow red circles where the references (offsets held at their initial
 * value) would have conflicted, filled red crosses where the flown paths lost separation.
 */
#define _POSIX_C_SOURCE 200809L

#include "flight.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SVG_WIDTH 960.0
#define SVG_LEFT 76.0 /* room for the z and y tick labels */
#define SVG_RIGHT 24.0
#define SVG_PLOT_WIDTH (SVG_WIDTH - SVG_LEFT - SVG_RIGHT)
#define SVG_TOP_MIN_HEIGHT 220.0
#define SVG_TOP_MAX_HEIGHT 560.0
#define SVG_PANEL_HEIGHT 210.0
#define SVG_PANEL_GAP 74.0    /* between panels: the t axis labels and the next title */
#define SVG_SUBSTEPS 8u       /* samples per step when finding the terrain under a path */
#define SVG_NEAR_RADII 3.0    /* traffic within this many summed radii is drawn in a panel */
#define SVG_MAX_MARKERS 4000u /* markers of one kind beyond this are counted, not drawn */

static const char *const palette[] = {"#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd",
                                      "#8c564b", "#e377c2", "#17becf", "#bcbd22"};
#define PALETTE_SIZE (sizeof palette / sizeof palette[0])
#define TRACK_COLOUR "#333333"
#define TERRAIN_FILL "#a0a0a0"
#define CONFLICT_COLOUR "#e00000"
#define UNKNOWN_COLOUR "#ff9800"

static const char *colour_of(size_t i)
{
    return palette[i % PALETTE_SIZE];
}

/* A world rectangle drawn into a pixel rectangle. */
typedef struct {
    double left, top, width, height; /* px */
    double x0, x1, y0, y1;           /* world: x0 at the left, y0 at the bottom */
} frame_t;

static double px(const frame_t *fr, double x)
{
    return fr->left + (x - fr->x0) / (fr->x1 - fr->x0) * fr->width;
}

static double py(const frame_t *fr, double y)
{
    return fr->top + fr->height - (y - fr->y0) / (fr->y1 - fr->y0) * fr->height;
}

typedef struct {
    const coavoid_flight_t *f;
    FILE *out;
    size_t row;         /* steps + 1 */
    coa_vec3_t *flown;  /* n rows: flown positions */
    coa_vec3_t *refpos; /* n rows: positions at the initial offset (no manoeuvre) */
    coa_vec3_t *tracks; /* track_count rows */
    coavoid_flight_conflict_t *ref_conflicts;
    size_t ref_count;
    coavoid_flight_conflict_t *losses;
    size_t loss_count;
    bool *ref_mark;  /* n * steps: UAV i's step k conflicts (references) */
    bool *loss_mark; /* n * steps: UAV i's step k conflicts (flown) */
    bool any_unknown;
} svg_t;

/* ---- text ---- */

/* Writes s as XML character data: markup characters escaped, control characters and
 * invalid UTF-8 (which would make the document ill-formed) replaced by '?'. */
static void put_text(FILE *out, const char *s)
{
    const unsigned char *c = (const unsigned char *)(s != NULL ? s : "");
    while (*c != 0u) {
        unsigned char b = *c;
        size_t len = 0;
        if (b < 0x80u) {
            if (b == '&') {
                fputs("&amp;", out);
            } else if (b == '<') {
                fputs("&lt;", out);
            } else if (b == '>') {
                fputs("&gt;", out);
            } else if (b == '"') {
                fputs("&quot;", out);
            } else if (b < 0x20u || b == 0x7fu) {
                fputc('?', out);
            } else {
                fputc((int)b, out);
            }
            c++;
            continue;
        }
        /* Lead byte and the allowed range of the second byte (no overlongs, no surrogates,
         * nothing past U+10FFFF). */
        unsigned char lo = 0x80u, hi = 0xbfu;
        if (b >= 0xc2u && b <= 0xdfu) {
            len = 2;
        } else if (b >= 0xe0u && b <= 0xefu) {
            len = 3;
            lo = b == 0xe0u ? 0xa0u : 0x80u;
            hi = b == 0xedu ? 0x9fu : 0xbfu;
        } else if (b >= 0xf0u && b <= 0xf4u) {
            len = 4;
            lo = b == 0xf0u ? 0x90u : 0x80u;
            hi = b == 0xf4u ? 0x8fu : 0xbfu;
        }
        bool ok = len > 0;
        for (size_t j = 1; ok && j < len; j++) {
            unsigned char x = c[j];
            ok = (j == 1) ? (x >= lo && x <= hi) : (x >= 0x80u && x <= 0xbfu);
        }
        /* U+FFFE and U+FFFF are not XML characters either. */
        if (ok && len == 3 && b == 0xefu && c[1] == 0xbfu && (c[2] == 0xbeu || c[2] == 0xbfu)) {
            ok = false;
        }
        if (!ok) {
            fputc('?', out);
            c++;
            continue;
        }
        fwrite(c, 1, len, out);
        c += len;
    }
}

static void text_at(FILE *out, double x, double y, const char *attrs, const char *s)
{
    fprintf(out, "<text x=\"%.1f\" y=\"%.1f\" %s>", x, y, attrs);
    put_text(out, s);
    fputs("</text>\n", out);
}

/* ---- scales ---- */

/* A round step (1, 2 or 5 times a power of ten) giving about `target` ticks over span. */
static double tick_step(double span, double target)
{
    double raw = span / target;
    double mag = pow(10.0, floor(log10(raw)));
    double r = raw / mag;
    double m = r < 1.5 ? 1.0 : (r < 3.0 ? 2.0 : (r < 7.0 ? 5.0 : 10.0));
    return m * mag;
}

/* A tick label with as many decimals as the step needs (no 0.30000000000000004). */
static void tick_label(char *buf, size_t size, double value, double step)
{
    int decimals = step >= 1.0 ? 0 : (int)ceil(-log10(step) - 1e-9);
    if (decimals > 6) {
        decimals = 6;
    }
    if (fabs(value) < step * 1e-6) {
        value = 0.0; /* no "-0" */
    }
    snprintf(buf, size, "%.*f", decimals, value);
}

/* Grid, frame, ticks and axis titles of a frame. */
static void axes(FILE *out, const frame_t *fr, const char *xtitle, const char *ytitle)
{
    double xs = tick_step(fr->x1 - fr->x0, fr->width / 90.0);
    double ys = tick_step(fr->y1 - fr->y0, fr->height / 45.0);
    char label[64];
    fputs("<g class=\"axes\">\n", out);
    for (double v = ceil(fr->x0 / xs) * xs; v <= fr->x1 + xs * 1e-9; v += xs) {
        double x = px(fr, v);
        fprintf(out,
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#e4e4e4\"/>\n"
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#444\"/>\n",
                x, fr->top, x, fr->top + fr->height, x, fr->top + fr->height, x,
                fr->top + fr->height + 5.0);
        tick_label(label, sizeof label, v, xs);
        text_at(out, x, fr->top + fr->height + 17.0, "text-anchor=\"middle\" class=\"tick\"",
                label);
    }
    for (double v = ceil(fr->y0 / ys) * ys; v <= fr->y1 + ys * 1e-9; v += ys) {
        double y = py(fr, v);
        fprintf(out,
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#e4e4e4\"/>\n"
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#444\"/>\n",
                fr->left, y, fr->left + fr->width, y, fr->left - 5.0, y, fr->left, y);
        tick_label(label, sizeof label, v, ys);
        text_at(out, fr->left - 8.0, y + 4.0, "text-anchor=\"end\" class=\"tick\"", label);
    }
    fputs("</g>\n", out);
    text_at(out, fr->left + fr->width / 2.0, fr->top + fr->height + 34.0,
            "text-anchor=\"middle\" class=\"axis\"", xtitle);
    fprintf(out,
            "<text transform=\"translate(%.1f %.1f) rotate(-90)\" "
            "text-anchor=\"middle\" class=\"axis\">",
            fr->left - 56.0, fr->top + fr->height / 2.0);
    put_text(out, ytitle);
    fputs("</text>\n", out);
}

static void frame_border(FILE *out, const frame_t *fr)
{
    fprintf(out,
            "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" "
            "stroke=\"#444\"/>\n",
            fr->left, fr->top, fr->width, fr->height);
}

static void clip_path(FILE *out, const char *id, const frame_t *fr)
{
    fprintf(out,
            "<clipPath id=\"%s\"><rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" "
            "height=\"%.1f\"/></clipPath>\n",
            id, fr->left, fr->top, fr->width, fr->height);
}

/* Widens [*lo, *hi] to at least `min_span`, around its middle. */
static void ensure_span(double *lo, double *hi, double min_span)
{
    if (*hi - *lo < min_span) {
        double mid = (*lo + *hi) / 2.0;
        *lo = mid - min_span / 2.0;
        *hi = mid + min_span / 2.0;
    }
}

/* ---- markers ---- */

static void cross(FILE *out, double x, double y)
{
    fprintf(out,
            "<path d=\"M%.1f %.1fl10 10m0 -10l-10 10\" stroke=\"#000\" stroke-width=\"5\"/>"
            "<path d=\"M%.1f %.1fl10 10m0 -10l-10 10\" stroke=\"" CONFLICT_COLOUR
            "\" stroke-width=\"3\"/>\n",
            x - 5.0, y - 5.0, x - 5.0, y - 5.0);
}

static void ring(FILE *out, double x, double y)
{
    fprintf(out,
            "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"6\" fill=\"none\" stroke=\"" CONFLICT_COLOUR
            "\" stroke-width=\"2\"/>\n",
            x, y);
}

/* Marks which (UAV, step) pairs are in a conflict of the list. */
static void mark_steps(const svg_t *s, const coavoid_flight_conflict_t *list, size_t count,
                       bool *mark)
{
    const size_t steps = s->f->steps;
    for (size_t c = 0; c < count; c++) {
        mark[list[c].vehicle * steps + list[c].step] = true;
        if (list[c].kind == COA_CONFLICT_VEHICLE) {
            mark[list[c].other * steps + list[c].step] = true;
        }
    }
}

static coa_vec3_t mid(coa_vec3_t a, coa_vec3_t b)
{
    coa_vec3_t m;
    m.x = (coa_real_t)(((double)a.x + (double)b.x) / 2.0);
    m.y = (coa_real_t)(((double)a.y + (double)b.y) / 2.0);
    m.z = (coa_real_t)(((double)a.z + (double)b.z) / 2.0);
    return m;
}

/* ---- polylines ---- */

/* Points k = from..to of a row as an SVG points list: x and y picked by the callers'
 * frames (top view: x, y; altitude: t, z). */
static void polyline_xy(FILE *out, const frame_t *fr, const coa_vec3_t *row, size_t from, size_t to,
                        const char *attrs)
{
    fputs("<polyline fill=\"none\" points=\"", out);
    for (size_t k = from; k <= to; k++) {
        fprintf(out, "%s%.2f,%.2f", k == from ? "" : " ", px(fr, (double)row[k].x),
                py(fr, (double)row[k].y));
    }
    fprintf(out, "\" %s/>\n", attrs);
}

static void polyline_tz(FILE *out, const frame_t *fr, const coa_vec3_t *row, double dt, size_t from,
                        size_t to, double dz, const char *attrs)
{
    fputs("<polyline fill=\"none\" points=\"", out);
    for (size_t k = from; k <= to; k++) {
        fprintf(out, "%s%.2f,%.2f", k == from ? "" : " ", px(fr, (double)k * dt),
                py(fr, (double)row[k].z + dz));
    }
    fprintf(out, "\" %s/>\n", attrs);
}

/* The band z +- h along a row, k = from..to. */
static void band_tz(FILE *out, const frame_t *fr, const coa_vec3_t *row, double dt, size_t from,
                    size_t to, double h, const char *attrs)
{
    fputs("<polygon points=\"", out);
    for (size_t k = from; k <= to; k++) {
        fprintf(out, "%s%.2f,%.2f", k == from ? "" : " ", px(fr, (double)k * dt),
                py(fr, (double)row[k].z + h));
    }
    for (size_t k = to + 1u; k-- > from;) {
        fprintf(out, " %.2f,%.2f", px(fr, (double)k * dt), py(fr, (double)row[k].z - h));
    }
    fprintf(out, "\" %s/>\n", attrs);
}

/* ---- obstacles ---- */

/* Horizontal bounding rectangle of an obstacle (a polytope's vertices' extent). */
static void obstacle_bounds(const coa_obstacle_t *o, double *x0, double *y0, double *z0, double *x1,
                            double *y1, double *z1)
{
    if (o->kind == COA_OBSTACLE_BOX) {
        *x0 = (double)o->box.min.x;
        *y0 = (double)o->box.min.y;
        *z0 = (double)o->box.min.z;
        *x1 = (double)o->box.max.x;
        *y1 = (double)o->box.max.y;
        *z1 = (double)o->box.max.z;
        return;
    }
    const coa_vec3_t *v = o->polytope.vertices;
    *x0 = *x1 = (double)v[0].x;
    *y0 = *y1 = (double)v[0].y;
    *z0 = *z1 = (double)v[0].z;
    for (size_t j = 1; j < o->polytope.count; j++) {
        *x0 = fmin(*x0, (double)v[j].x);
        *x1 = fmax(*x1, (double)v[j].x);
        *y0 = fmin(*y0, (double)v[j].y);
        *y1 = fmax(*y1, (double)v[j].y);
        *z0 = fmin(*z0, (double)v[j].z);
        *z1 = fmax(*z1, (double)v[j].z);
    }
}

typedef struct {
    double x, y;
} pt_t;

static int pt_compare(const void *a, const void *b)
{
    const pt_t *p = a;
    const pt_t *q = b;
    if (p->x != q->x) {
        return p->x < q->x ? -1 : 1;
    }
    if (p->y != q->y) {
        return p->y < q->y ? -1 : 1;
    }
    return 0;
}

static double turn(pt_t o, pt_t a, pt_t b)
{
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

/* The convex hull of a polytope's xy projection (monotone chain), counter-clockwise into
 * hull (room for 2 * count points); returns its size. */
static size_t footprint_hull(const coa_polytope_t *poly, pt_t *pts, pt_t *hull)
{
    size_t n = poly->count;
    size_t h = 0;
    for (size_t j = 0; j < n; j++) {
        pts[j].x = (double)poly->vertices[j].x;
        pts[j].y = (double)poly->vertices[j].y;
    }
    qsort(pts, n, sizeof *pts, pt_compare);
    for (size_t j = 0; j < n; j++) {
        while (h >= 2u && turn(hull[h - 2u], hull[h - 1u], pts[j]) <= 0.0) {
            h--;
        }
        hull[h++] = pts[j];
    }
    for (size_t j = n - 1u, lower = h + 1u; j-- > 0;) {
        while (h >= lower && turn(hull[h - 2u], hull[h - 1u], pts[j]) <= 0.0) {
            h--;
        }
        hull[h++] = pts[j];
    }
    return h > 1u ? h - 1u : h; /* the last point repeats the first */
}

/* ---- the document ---- */

static void legend_item(FILE *out, double *x, double *y, const char *glyph, const char *label)
{
    double width = 34.0 + 6.6 * (double)strlen(label) + 18.0;
    if (*x + width > SVG_WIDTH - SVG_RIGHT) {
        *x = SVG_LEFT;
        *y += 20.0;
    }
    fprintf(out, "<g transform=\"translate(%.1f %.1f)\">%s", *x, *y, glyph);
    text_at(out, 34.0, 4.0, "class=\"legend\"", label);
    fputs("</g>\n", out);
    *x += width;
}

/* Legend rows from y; returns the y below them. */
static double legend(const svg_t *s, double y)
{
    FILE *out = s->out;
    double x = SVG_LEFT;
    char glyph[512];
    char label[64];
    for (size_t i = 0; i < s->f->vehicle_count; i++) {
        snprintf(glyph, sizeof glyph,
                 "<line x1=\"0\" y1=\"0\" x2=\"28\" y2=\"0\" stroke=\"%s\" stroke-width=\"2.2\"/>",
                 colour_of(i));
        snprintf(label, sizeof label, "UAV %u", (unsigned)s->f->vehicles[i].vehicle.id);
        legend_item(out, &x, &y, glyph, label);
    }
    legend_item(out, &x, &y,
                "<line x1=\"0\" y1=\"0\" x2=\"28\" y2=\"0\" stroke=\"#555\" stroke-width=\"2\" "
                "stroke-dasharray=\"7 4\"/>",
                "reference (no manoeuvre), dashed");
    legend_item(out, &x, &y,
                "<line x1=\"0\" y1=\"0\" x2=\"28\" y2=\"0\" stroke=\"#555\" stroke-width=\"2.2\"/>",
                "flown, solid");
    legend_item(out, &x, &y,
                "<rect x=\"0\" y=\"-6\" width=\"28\" height=\"12\" fill=\"#555\" "
                "fill-opacity=\"0.15\"/>",
                "protected half-height");
    if (s->f->track_count > 0u) {
        legend_item(out, &x, &y,
                    "<line x1=\"0\" y1=\"0\" x2=\"28\" y2=\"0\" stroke=\"" TRACK_COLOUR
                    "\" stroke-width=\"1.6\" stroke-dasharray=\"2 3\"/>",
                    "non-cooperative track");
    }
    if (s->f->obstacle_count > 0u) {
        legend_item(out, &x, &y,
                    "<rect x=\"0\" y=\"-6\" width=\"28\" height=\"12\" fill=\"" TERRAIN_FILL
                    "\" stroke=\"#777\"/>",
                    "terrain / obstacle");
    }
    legend_item(out, &x, &y,
                "<circle cx=\"14\" cy=\"0\" r=\"6\" fill=\"none\" stroke=\"" CONFLICT_COLOUR
                "\" stroke-width=\"2\"/>",
                "references would conflict");
    legend_item(out, &x, &y,
                "<path d=\"M9 -5l10 10m0 -10l-10 10\" stroke=\"#000\" stroke-width=\"5\"/>"
                "<path d=\"M9 -5l10 10m0 -10l-10 10\" stroke=\"" CONFLICT_COLOUR
                "\" stroke-width=\"3\"/>",
                "loss of separation (flown)");
    if (s->any_unknown) {
        legend_item(out, &x, &y,
                    "<rect x=\"0\" y=\"-3\" width=\"28\" height=\"6\" fill=\"" UNKNOWN_COLOUR
                    "\"/>",
                    "no intent in the log");
    }
    return y + 16.0;
}

static void header(const svg_t *s, const coavoid_flight_eval_t *eval, double *y)
{
    FILE *out = s->out;
    const coavoid_flight_t *f = s->f;
    char line[512];
    fprintf(out, "<text x=\"%.1f\" y=\"%.1f\" class=\"title\">", SVG_LEFT, *y);
    put_text(out, f->scenario);
    fputs(" \xe2\x80\x94 ", out); /* an em dash */
    put_text(out, f->mode);
    fputs("</text>\n", out);
    *y += 22.0;
    if (eval != NULL) {
        if (eval->loss_of_separation && s->loss_count > 0u) {
            /* The list's first entry is the core's first: the earliest step, and there the
             * lowest-indexed UAV in conflict, which is the one the evaluation names. */
            const coavoid_flight_conflict_t *c = &s->losses[0];
            char other[64];
            if (c->kind == COA_CONFLICT_VEHICLE) {
                snprintf(other, sizeof other, "UAV %u", (unsigned)f->vehicles[c->other].vehicle.id);
            } else if (c->kind == COA_CONFLICT_TRACK) {
                snprintf(other, sizeof other, "track %lu", (unsigned long)f->tracks[c->other].id);
            } else {
                snprintf(other, sizeof other, "obstacle %zu", c->other);
            }
            snprintf(line, sizeof line,
                     "LOSS OF SEPARATION: first UAV %u and %s over step %lu (t = %g to %g s)",
                     (unsigned)f->vehicles[c->vehicle].vehicle.id, other, (unsigned long)c->step,
                     (double)c->step * (double)f->dt, (double)(c->step + 1u) * (double)f->dt);
            text_at(out, SVG_LEFT, *y, "class=\"result\" fill=\"" CONFLICT_COLOUR "\"", line);
        } else {
            text_at(out, SVG_LEFT, *y, "class=\"result\" fill=\"#2e7d32\"",
                    eval->loss_of_separation ? "LOSS OF SEPARATION" : "No loss of separation");
        }
        *y += 18.0;
        snprintf(line, sizeof line,
                 "deviation %.6g m\xc2\xb2 \xc2\xb7 effort %lu \xc2\xb7 replans %lu \xc2\xb7 "
                 "%lu steps of %g s \xc2\xb7 the references alone %s",
                 eval->deviation, (unsigned long)eval->effort, (unsigned long)f->replans,
                 (unsigned long)f->steps, (double)f->dt,
                 s->ref_count > 0u ? "would have conflicted (circles)" : "were conflict-free");
        text_at(out, SVG_LEFT, *y, "class=\"info\"", line);
        *y += 20.0;
    }
}

/* The top view: x east to the right, y north up, one metre the same on both axes. */
/* The top view's world box: every sample flown and every track's, grown by the largest
 * protected radius, with the terrain near the traffic (a box the size of a continent would
 * otherwise shrink the run to a dot; anything beyond is clipped), then padded. */
static void top_extent(const svg_t *s, double *x0, double *x1, double *y0, double *y1)
{
    const coavoid_flight_t *f = s->f;
    double reach = 0.0;
    *x0 = INFINITY, *x1 = -INFINITY, *y0 = INFINITY, *y1 = -INFINITY;
    for (size_t m = 0; m < f->vehicle_count + f->track_count; m++) {
        const bool uav = m < f->vehicle_count;
        const size_t j = uav ? m : m - f->vehicle_count;
        const coa_vec3_t *row = uav ? &s->flown[j * s->row] : &s->tracks[j * s->row];
        reach = fmax(reach, (double)(uav ? f->vehicles[j].vehicle.volume.radius
                                         : f->tracks[j].volume.radius));
        for (size_t k = 0; k < s->row; k++) {
            *x0 = fmin(*x0, (double)row[k].x);
            *x1 = fmax(*x1, (double)row[k].x);
            *y0 = fmin(*y0, (double)row[k].y);
            *y1 = fmax(*y1, (double)row[k].y);
        }
    }
    *x0 -= reach;
    *x1 += reach;
    *y0 -= reach;
    *y1 += reach;
    double grow = 0.5 * fmax(*x1 - *x0, *y1 - *y0);
    double lx0 = *x0 - grow, lx1 = *x1 + grow, ly0 = *y0 - grow, ly1 = *y1 + grow;
    for (size_t j = 0; j < f->obstacle_count; j++) {
        double ox0, oy0, oz0, ox1, oy1, oz1;
        obstacle_bounds(&f->obstacles[j], &ox0, &oy0, &oz0, &ox1, &oy1, &oz1);
        *x0 = fmin(*x0, fmax(ox0, lx0));
        *x1 = fmax(*x1, fmin(ox1, lx1));
        *y0 = fmin(*y0, fmax(oy0, ly0));
        *y1 = fmax(*y1, fmin(oy1, ly1));
    }
    ensure_span(x0, x1, 10.0);
    ensure_span(y0, y1, 10.0);
    double pad = 0.05 * fmax(*x1 - *x0, *y1 - *y0);
    *x0 -= pad;
    *x1 += pad;
    *y0 -= pad;
    *y1 += pad;
}

/* The top view's frame at `top`: equal scale, the panel's height following the run's shape
 * within limits, and the shorter side of the world box grown to fill the panel. */
static frame_t top_frame(const svg_t *s, double top, double *scale)
{
    double x0, x1, y0, y1;
    top_extent(s, &x0, &x1, &y0, &y1);
    double height = SVG_PLOT_WIDTH * (y1 - y0) / (x1 - x0);
    height = fmin(fmax(height, SVG_TOP_MIN_HEIGHT), SVG_TOP_MAX_HEIGHT);
    *scale = fmin(SVG_PLOT_WIDTH / (x1 - x0), height / (y1 - y0));
    double wx = SVG_PLOT_WIDTH / *scale, wy = height / *scale;
    double cx = (x0 + x1) / 2.0, cy = (y0 + y1) / 2.0;
    frame_t fr = {SVG_LEFT,      top,           SVG_PLOT_WIDTH, height,
                  cx - wx / 2.0, cx + wx / 2.0, cy - wy / 2.0,  cy + wy / 2.0};
    return fr;
}

/* Terrain footprints, each labelled with its altitudes. */
static void top_terrain(const svg_t *s, const frame_t *fr, double scale)
{
    FILE *out = s->out;
    const coavoid_flight_t *f = s->f;
    pt_t pts[COA_POLYTOPE_MAX_VERTICES];
    pt_t hull[2u * COA_POLYTOPE_MAX_VERTICES + 1u];
    for (size_t j = 0; j < f->obstacle_count; j++) {
        const coa_obstacle_t *o = &f->obstacles[j];
        double ox0, oy0, oz0, ox1, oy1, oz1;
        char label[96];
        obstacle_bounds(o, &ox0, &oy0, &oz0, &ox1, &oy1, &oz1);
        if (o->kind == COA_OBSTACLE_BOX) {
            fprintf(
                out,
                "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\" fill=\"" TERRAIN_FILL
                "\" fill-opacity=\"0.75\" stroke=\"#777\"/>\n",
                px(fr, ox0), py(fr, oy1), (ox1 - ox0) * scale, (oy1 - oy0) * scale);
        } else {
            size_t h = footprint_hull(&o->polytope, pts, hull);
            fputs("<polygon points=\"", out);
            for (size_t q = 0; q < h; q++) {
                fprintf(out, "%s%.2f,%.2f", q == 0 ? "" : " ", px(fr, hull[q].x),
                        py(fr, hull[q].y));
            }
            fputs("\" fill=\"" TERRAIN_FILL "\" fill-opacity=\"0.75\" stroke=\"#777\"/>\n", out);
        }
        snprintf(label, sizeof label, "obstacle %zu, z %g to %g m", j, oz0, oz1);
        text_at(out, px(fr, fmax(ox0, fr->x0)) + 3.0, py(fr, fmin(oy1, fr->y1)) + 12.0,
                "class=\"small\"", label);
    }
}

/* Tracks over the run, with their ids at the start. */
static void top_tracks(const svg_t *s, const frame_t *fr)
{
    FILE *out = s->out;
    const coavoid_flight_t *f = s->f;
    for (size_t j = 0; j < f->track_count; j++) {
        const coa_vec3_t *row = &s->tracks[j * s->row];
        char label[48];
        polyline_xy(out, fr, row, 0, s->row - 1u,
                    "stroke=\"" TRACK_COLOUR "\" stroke-width=\"1.6\" stroke-dasharray=\"2 3\"");
        fprintf(out,
                "<rect x=\"%.2f\" y=\"%.2f\" width=\"7\" height=\"7\" fill=\"" TRACK_COLOUR
                "\"/>\n",
                px(fr, (double)row[0].x) - 3.5, py(fr, (double)row[0].y) - 3.5);
        snprintf(label, sizeof label, "track %lu", (unsigned long)f->tracks[j].id);
        text_at(out, px(fr, (double)row[0].x) + 7.0, py(fr, (double)row[0].y) + 14.0,
                "class=\"label\"", label);
    }
}

/* Routes: the reference dashed and wide beneath, the flown solid on top (the same
 * horizontally: only altitude changes). */
static void top_routes(const svg_t *s, const frame_t *fr)
{
    const size_t n = s->f->vehicle_count;
    for (size_t i = 0; i < n; i++) {
        char attrs[160];
        snprintf(attrs, sizeof attrs,
                 "stroke=\"%s\" stroke-width=\"5\" stroke-opacity=\"0.35\" "
                 "stroke-dasharray=\"10 6\"",
                 colour_of(i));
        polyline_xy(s->out, fr, &s->refpos[i * s->row], 0, s->row - 1u, attrs);
    }
    for (size_t i = 0; i < n; i++) {
        char attrs[96];
        snprintf(attrs, sizeof attrs, "stroke=\"%s\" stroke-width=\"2.2\"", colour_of(i));
        polyline_xy(s->out, fr, &s->flown[i * s->row], 0, s->row - 1u, attrs);
    }
}

/* Start markers: the protected radius to scale, a dot, and the id; labels of UAVs that
 * start at the same place are stacked. */
static void top_starts(const svg_t *s, const frame_t *fr, double scale)
{
    FILE *out = s->out;
    const coavoid_flight_t *f = s->f;
    for (size_t i = 0; i < f->vehicle_count; i++) {
        const coa_vec3_t *p = &s->flown[i * s->row];
        const coa_vec3_t *e = &s->flown[i * s->row + s->row - 1u];
        size_t same = 0;
        char label[32];
        for (size_t q = 0; q < i; q++) {
            const coa_vec3_t *o = &s->flown[q * s->row];
            if (fabs(px(fr, (double)o->x) - px(fr, (double)p->x)) < 40.0 &&
                fabs(py(fr, (double)o->y) - py(fr, (double)p->y)) < 14.0) {
                same++;
            }
        }
        fprintf(out,
                "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%.2f\" fill=\"%s\" fill-opacity=\"0.12\" "
                "stroke=\"%s\" stroke-width=\"0.8\"/>\n"
                "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"3.5\" fill=\"%s\"/>\n"
                "<path d=\"M%.2f %.2fl-4 -4m4 4l-4 4\" stroke=\"%s\" stroke-width=\"2\" "
                "fill=\"none\"/>\n",
                px(fr, (double)p->x), py(fr, (double)p->y),
                (double)f->vehicles[i].vehicle.volume.radius * scale, colour_of(i), colour_of(i),
                px(fr, (double)p->x), py(fr, (double)p->y), colour_of(i), px(fr, (double)e->x),
                py(fr, (double)e->y), colour_of(i));
        snprintf(label, sizeof label, "UAV %u", (unsigned)f->vehicles[i].vehicle.id);
        fprintf(out, "<text x=\"%.1f\" y=\"%.1f\" class=\"label\" fill=\"%s\">",
                px(fr, (double)p->x) + 6.0, py(fr, (double)p->y) - 7.0 - 14.0 * (double)same,
                colour_of(i));
        put_text(out, label);
        fputs("</text>\n", out);
    }
}

/* Conflict markers at the middle of each conflicting step: rings on the references' predicted
 * conflicts, crosses where the flight lost separation (at most SVG_MAX_MARKERS each). */
static void top_markers(const svg_t *s, const frame_t *fr)
{
    const coavoid_flight_t *f = s->f;
    for (int kind = 0; kind < 2; kind++) {
        const bool *marks = kind == 0 ? s->ref_mark : s->loss_mark;
        const coa_vec3_t *rows = kind == 0 ? s->refpos : s->flown;
        size_t drawn = 0;
        for (size_t i = 0; i < f->vehicle_count; i++) {
            for (uint32_t k = 0; k < f->steps && drawn < SVG_MAX_MARKERS; k++) {
                if (marks[i * f->steps + k]) {
                    coa_vec3_t m = mid(rows[i * s->row + k], rows[i * s->row + k + 1u]);
                    (kind == 0 ? ring : cross)(s->out, px(fr, (double)m.x), py(fr, (double)m.y));
                    drawn++;
                }
            }
        }
    }
}

static void top_view(const svg_t *s, double *y)
{
    FILE *out = s->out;
    double scale;
    text_at(out, SVG_LEFT, *y + 14.0, "class=\"panel\"",
            "Top view (x east, y north, equal scale): routes over the run, traffic, terrain");
    frame_t fr = top_frame(s, *y + 24.0, &scale);
    clip_path(out, "clip-top", &fr);
    axes(out, &fr, "x (m, east)", "y (m, north)");
    fputs("<g clip-path=\"url(#clip-top)\">\n", out);
    top_terrain(s, &fr, scale);
    top_tracks(s, &fr);
    top_routes(s, &fr);
    top_starts(s, &fr, scale);
    top_markers(s, &fr);
    fputs("</g>\n", out);
    frame_border(out, &fr);
    *y = fr.top + fr.height + SVG_PANEL_GAP;
}

/* Whether (x, y) lies over obstacle o's footprint grown by r. Polytopes are taken by the
 * bounding box of their vertices: the panel shows the terrain's height range under the
 * path, and for a hill that is its full height wherever the path crosses its extent. */
static bool over_footprint(const coa_obstacle_t *o, double x, double y, double r)
{
    double x0, y0, z0, x1, y1, z1;
    obstacle_bounds(o, &x0, &y0, &z0, &x1, &y1, &z1);
    return x >= x0 - r && x <= x1 + r && y >= y0 - r && y <= y1 + r;
}

static double horizontal_distance(coa_vec3_t a, coa_vec3_t b)
{
    return hypot((double)a.x - (double)b.x, (double)a.y - (double)b.y);
}

/* Traffic q as UAV i's panel sees it: UAV q when q < vehicle_count, else track
 * q - vehicle_count. */
typedef struct {
    bool is_track;
    size_t j;              /* its index among the UAVs or among the tracks */
    const coa_vec3_t *row; /* its samples 0..K */
    const coa_volume_t *vol;
    double near; /* horizontal distance to UAV i within which it is drawn */
} svg_other_t;

static svg_other_t other_traffic(const svg_t *s, size_t i, size_t q)
{
    const coavoid_flight_t *f = s->f;
    svg_other_t o;
    o.is_track = q >= f->vehicle_count;
    o.j = o.is_track ? q - f->vehicle_count : q;
    o.row = o.is_track ? &s->tracks[o.j * s->row] : &s->flown[o.j * s->row];
    o.vol = o.is_track ? &f->tracks[o.j].volume : &f->vehicles[o.j].vehicle.volume;
    o.near =
        SVG_NEAR_RADII * ((double)f->vehicles[i].vehicle.volume.radius + (double)o.vol->radius);
    return o;
}

/* Traffic near UAV i: other UAVs' and tracks' altitudes over the runs of samples where they
 * are within SVG_NEAR_RADII summed radii horizontally. */
static void near_traffic(const svg_t *s, size_t i, const frame_t *fr, bool draw_labels)
{
    FILE *out = s->out;
    const coavoid_flight_t *f = s->f;
    const coa_vec3_t *me = &s->flown[i * s->row];
    const size_t others = f->vehicle_count + f->track_count;
    for (size_t q = 0; q < others; q++) {
        if (q == i) {
            continue;
        }
        const svg_other_t o = other_traffic(s, i, q);
        const char *colour = o.is_track ? TRACK_COLOUR : colour_of(o.j);
        size_t k = 0;
        bool labelled = false;
        while (k < s->row) {
            if (horizontal_distance(me[k], o.row[k]) >= o.near) {
                k++;
                continue;
            }
            size_t from = k;
            while (k + 1u < s->row && horizontal_distance(me[k + 1u], o.row[k + 1u]) < o.near) {
                k++;
            }
            size_t to = k;
            char attrs[160];
            snprintf(attrs, sizeof attrs, "fill=\"%s\" fill-opacity=\"0.10\" stroke=\"none\"",
                     colour);
            band_tz(out, fr, o.row, (double)f->dt, from, to, (double)o.vol->half_height, attrs);
            if (to > from) {
                snprintf(attrs, sizeof attrs, "stroke=\"%s\" stroke-width=\"1.4\"%s", colour,
                         o.is_track ? " stroke-dasharray=\"2 3\"" : "");
                polyline_tz(out, fr, o.row, (double)f->dt, from, to, 0.0, attrs);
            } else {
                fprintf(out, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"2.5\" fill=\"%s\"/>\n",
                        px(fr, (double)from * (double)f->dt), py(fr, (double)o.row[from].z),
                        colour);
            }
            if (draw_labels && !labelled) {
                char label[48];
                if (o.is_track) {
                    snprintf(label, sizeof label, "track %lu (near)",
                             (unsigned long)f->tracks[o.j].id);
                } else {
                    snprintf(label, sizeof label, "UAV %u (near)",
                             (unsigned)f->vehicles[o.j].vehicle.id);
                }
                /* Beside the run's start, outside it: conflict markers sit inside runs. */
                double x = px(fr, (double)from * (double)f->dt);
                bool left = x - fr->left > 90.0;
                fprintf(out, "<text x=\"%.1f\" y=\"%.1f\" class=\"near\" fill=\"%s\"%s>",
                        left ? x - 5.0 : x + 5.0, py(fr, (double)o.row[from].z) + 4.0, colour,
                        left ? " text-anchor=\"end\"" : "");
                put_text(out, label);
                fputs("</text>\n", out);
                labelled = true;
            }
            k++;
        }
    }
}

/* The z extent of traffic near UAV i, when it is close enough in altitude to belong in
 * the panel: within a few protected heights of the UAV's own range. */
static void near_extent(const svg_t *s, size_t i, double lo_own, double hi_own, double *lo,
                        double *hi)
{
    const coavoid_flight_t *f = s->f;
    const coa_vec3_t *me = &s->flown[i * s->row];
    const double hi_vol = (double)f->vehicles[i].vehicle.volume.half_height;
    for (size_t q = 0; q < f->vehicle_count + f->track_count; q++) {
        if (q == i) {
            continue;
        }
        const svg_other_t o = other_traffic(s, i, q);
        const double h = (double)o.vol->half_height;
        const double reach = 6.0 * (hi_vol + h);
        for (size_t k = 0; k < s->row; k++) {
            double z = (double)o.row[k].z;
            if (horizontal_distance(me[k], o.row[k]) < o.near && z > lo_own - reach &&
                z < hi_own + reach) {
                *lo = fmin(*lo, z - h);
                *hi = fmax(*hi, z + h);
            }
        }
    }
}

/* UAV i's altitude range for its panel: flown and reference, its half-height, the traffic
 * near it, padded. */
static void altitude_range(const svg_t *s, size_t i, double *lo, double *hi)
{
    const coa_vec3_t *flown = &s->flown[i * s->row];
    const coa_vec3_t *ref = &s->refpos[i * s->row];
    const double h = (double)s->f->vehicles[i].vehicle.volume.half_height;
    *lo = INFINITY, *hi = -INFINITY;
    for (size_t k = 0; k < s->row; k++) {
        *lo = fmin(*lo, fmin((double)flown[k].z, (double)ref[k].z));
        *hi = fmax(*hi, fmax((double)flown[k].z, (double)ref[k].z));
    }
    double own_lo = *lo, own_hi = *hi;
    *lo -= h;
    *hi += h;
    near_extent(s, i, own_lo, own_hi, lo, hi);
    ensure_span(lo, hi, 4.0 * h);
    double pad = 0.15 * (*hi - *lo);
    *lo -= pad;
    *hi += pad;
}

/* The panel's title (the UAV, its volume and priority) and its costs when judged. */
static void altitude_title(const svg_t *s, const coavoid_flight_eval_t *eval, size_t i, double y)
{
    FILE *out = s->out;
    const coavoid_flight_vehicle_t *v = &s->f->vehicles[i];
    char text[256];
    snprintf(text, sizeof text,
             "UAV %u: altitude along its path (radius %g m, half-height %g m, "
             "priority %lu)",
             (unsigned)v->vehicle.id, (double)v->vehicle.volume.radius,
             (double)v->vehicle.volume.half_height, (unsigned long)v->vehicle.priority);
    fprintf(out, "<text x=\"%.1f\" y=\"%.1f\" class=\"panel\" fill=\"%s\">", SVG_LEFT, y + 14.0,
            colour_of(i));
    put_text(out, text);
    fputs("</text>\n", out);
    if (eval != NULL && eval->vehicle_deviation != NULL && eval->vehicle_effort != NULL) {
        snprintf(text, sizeof text, "deviation %.6g m\xc2\xb2, effort %lu",
                 eval->vehicle_deviation[i], (unsigned long)eval->vehicle_effort[i]);
        text_at(out, SVG_LEFT + SVG_PLOT_WIDTH, y + 14.0, "text-anchor=\"end\" class=\"info\"",
                text);
    }
}

/* Obstacle o under UAV i's flown path, found on sub-samples of each step and merged into
 * runs, each drawn as its altitude band and labelled. */
static void altitude_terrain(const svg_t *s, size_t i, size_t j, const frame_t *fr)
{
    const coavoid_flight_t *f = s->f;
    const coa_obstacle_t *o = &f->obstacles[j];
    const coa_vec3_t *flown = &s->flown[i * s->row];
    const double dt = (double)f->dt;
    const double t_end = (double)f->steps * dt;
    const double r = (double)f->vehicles[i].vehicle.volume.radius;
    double ox0, oy0, oz0, ox1, oy1, oz1;
    obstacle_bounds(o, &ox0, &oy0, &oz0, &ox1, &oy1, &oz1);
    const size_t total = (size_t)f->steps * SVG_SUBSTEPS;
    const double sub = dt / (double)SVG_SUBSTEPS;
    bool in_run = false;
    double run_start = 0.0;
    for (size_t q = 0; q <= total; q++) {
        size_t k = q / SVG_SUBSTEPS;
        double u = (double)(q % SVG_SUBSTEPS) / (double)SVG_SUBSTEPS;
        coa_vec3_t a = flown[k];
        coa_vec3_t b = flown[k < f->steps ? k + 1u : k];
        double x = (double)a.x + u * ((double)b.x - (double)a.x);
        double yy = (double)a.y + u * ((double)b.y - (double)a.y);
        bool over = over_footprint(o, x, yy, r);
        double t = (double)q * sub;
        if (over && !in_run) {
            in_run = true;
            run_start = fmax(0.0, t - sub / 2.0);
        }
        if (in_run && (!over || q == total)) {
            char text[256];
            double run_end = over ? t_end : fmin(t_end, t - sub / 2.0);
            fprintf(s->out,
                    "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\" "
                    "fill=\"" TERRAIN_FILL "\" fill-opacity=\"0.8\" stroke=\"#777\"/>\n",
                    px(fr, run_start), py(fr, oz1), px(fr, run_end) - px(fr, run_start),
                    py(fr, oz0) - py(fr, oz1));
            snprintf(text, sizeof text, "obstacle %zu%s", j,
                     o->kind == COA_OBSTACLE_BOX ? "" : " (bounding box)");
            text_at(s->out, px(fr, run_start) + 3.0, fmax(py(fr, oz1), fr->top) + 12.0,
                    "class=\"small\"", text);
            in_run = false;
        }
    }
}

/* Its own protected half-height around the flown path, the reference, the flown; then the
 * samples no intent covered (a log that missed them). */
static void altitude_paths(const svg_t *s, size_t i, const frame_t *fr)
{
    FILE *out = s->out;
    const coavoid_flight_vehicle_t *v = &s->f->vehicles[i];
    const coa_vec3_t *flown = &s->flown[i * s->row];
    const double dt = (double)s->f->dt;
    const double t_end = (double)s->f->steps * dt;
    char attrs[128];
    snprintf(attrs, sizeof attrs, "fill=\"%s\" fill-opacity=\"0.15\" stroke=\"none\"",
             colour_of(i));
    band_tz(out, fr, flown, dt, 0, s->row - 1u, (double)v->vehicle.volume.half_height, attrs);
    snprintf(attrs, sizeof attrs, "stroke=\"%s\" stroke-width=\"2\" stroke-dasharray=\"7 4\"",
             colour_of(i));
    polyline_tz(out, fr, &s->refpos[i * s->row], dt, 0, s->row - 1u, 0.0, attrs);
    snprintf(attrs, sizeof attrs, "stroke=\"%s\" stroke-width=\"2.2\"", colour_of(i));
    polyline_tz(out, fr, flown, dt, 0, s->row - 1u, 0.0, attrs);
    if (v->known == NULL) {
        return;
    }
    for (size_t k = 0; k < s->row; k++) {
        if (!v->known[k]) {
            double t0 = fmax(0.0, ((double)k - 0.5) * dt);
            double t1 = fmin(t_end, ((double)k + 0.5) * dt);
            fprintf(out,
                    "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"6\" fill=\"" UNKNOWN_COLOUR
                    "\"/>\n",
                    px(fr, t0), fr->top + fr->height - 6.0, px(fr, t1) - px(fr, t0));
        }
    }
}

/* Conflict markers mid-step: rings on the reference's predicted conflicts, crosses where the
 * flight lost separation (at most SVG_MAX_MARKERS each). */
static void altitude_markers(const svg_t *s, size_t i, const frame_t *fr)
{
    const coavoid_flight_t *f = s->f;
    const double dt = (double)f->dt;
    for (int kind = 0; kind < 2; kind++) {
        const bool *marks = kind == 0 ? s->ref_mark : s->loss_mark;
        const coa_vec3_t *row = kind == 0 ? &s->refpos[i * s->row] : &s->flown[i * s->row];
        size_t drawn = 0;
        for (uint32_t k = 0; k < f->steps && drawn < SVG_MAX_MARKERS; k++) {
            if (marks[i * f->steps + k]) {
                (kind == 0 ? ring
                           : cross)(s->out, px(fr, ((double)k + 0.5) * dt),
                                    py(fr, ((double)row[k].z + (double)row[k + 1u].z) / 2.0));
                drawn++;
            }
        }
    }
}

static void altitude_panel(const svg_t *s, const coavoid_flight_eval_t *eval, size_t i, double *y)
{
    FILE *out = s->out;
    const coavoid_flight_t *f = s->f;
    double lo, hi;
    altitude_range(s, i, &lo, &hi);
    altitude_title(s, eval, i, *y);
    frame_t fr = {SVG_LEFT,
                  *y + 24.0,
                  SVG_PLOT_WIDTH,
                  SVG_PANEL_HEIGHT,
                  0.0,
                  (double)f->steps * (double)f->dt,
                  lo,
                  hi};
    char clip[32];
    snprintf(clip, sizeof clip, "clip-alt-%zu", i);
    clip_path(out, clip, &fr);
    axes(out, &fr, "t (s)", "z (m, up)");
    fprintf(out, "<g clip-path=\"url(#%s)\">\n", clip);
    for (size_t j = 0; j < f->obstacle_count; j++) {
        altitude_terrain(s, i, j, &fr);
    }
    near_traffic(s, i, &fr, true);
    altitude_paths(s, i, &fr);
    altitude_markers(s, i, &fr);
    fputs("</g>\n", out);
    frame_border(out, &fr);
    *y = fr.top + fr.height + SVG_PANEL_GAP;
}

static void svg_free(svg_t *s)
{
    free(s->flown);
    free(s->refpos);
    free(s->tracks);
    free(s->ref_conflicts);
    free(s->losses);
    free(s->ref_mark);
    free(s->loss_mark);
}

/* The list of conflicts of one kind of trajectory, allocated. */
static int list_conflicts(const coavoid_flight_t *f, coavoid_flight_trajectory_t which,
                          coavoid_flight_conflict_t **list, size_t *count)
{
    size_t found = 0;
    int rc = coavoid_flight_conflicts(f, which, NULL, 0u, &found);
    if (rc != COA_OK) {
        return rc;
    }
    *list = malloc((found > 0u ? found : 1u) * sizeof **list);
    if (*list == NULL) {
        return COA_ERR_WORKSPACE;
    }
    rc = coavoid_flight_conflicts(f, which, *list, found, count);
    if (rc == COA_OK && *count != found) {
        rc = COA_ERR_WORKSPACE; /* cannot happen: the same record twice */
    }
    return rc;
}

static int prepare(svg_t *s, const coavoid_flight_t *f, FILE *out)
{
    const size_t n = f->vehicle_count;
    memset(s, 0, sizeof *s);
    s->f = f;
    s->out = out;
    s->row = (size_t)f->steps + 1u;
    /* The lists first: they run the core's checks on the whole record. */
    int rc = list_conflicts(f, COAVOID_FLIGHT_REFERENCE, &s->ref_conflicts, &s->ref_count);
    if (rc == COA_OK) {
        rc = list_conflicts(f, COAVOID_FLIGHT_FLOWN, &s->losses, &s->loss_count);
    }
    if (rc != COA_OK) {
        return rc;
    }
    s->flown = malloc(n * s->row * sizeof *s->flown);
    s->refpos = malloc(n * s->row * sizeof *s->refpos);
    s->tracks = malloc((f->track_count > 0u ? f->track_count : 1u) * s->row * sizeof *s->tracks);
    s->ref_mark = calloc(n * f->steps, sizeof *s->ref_mark);
    s->loss_mark = calloc(n * f->steps, sizeof *s->loss_mark);
    if (s->flown == NULL || s->refpos == NULL || s->tracks == NULL || s->ref_mark == NULL ||
        s->loss_mark == NULL) {
        return COA_ERR_WORKSPACE;
    }
    for (size_t i = 0; i < n; i++) {
        const coavoid_flight_vehicle_t *v = &f->vehicles[i];
        for (uint32_t k = 0; k <= f->steps; k++) {
            s->flown[i * s->row + k] = coavoid_flight_position(f, i, k, v->offsets[k]);
            s->refpos[i * s->row + k] = coavoid_flight_position(f, i, k, v->offsets[0]);
            s->any_unknown = s->any_unknown || (v->known != NULL && !v->known[k]);
        }
    }
    for (size_t j = 0; j < f->track_count; j++) {
        /* Checked by the conflict listing above. */
        if (coa_track_sample(&f->tracks[j], f->dt, f->steps, &s->tracks[j * s->row]) != COA_OK) {
            return COA_ERR_ARGUMENT;
        }
    }
    mark_steps(s, s->ref_conflicts, s->ref_count, s->ref_mark);
    mark_steps(s, s->losses, s->loss_count, s->loss_mark);
    return COA_OK;
}

int coavoid_flight_svg(const coavoid_flight_t *flight, const coavoid_flight_eval_t *eval, FILE *out)
{
    if (flight == NULL || out == NULL) {
        return COA_ERR_ARGUMENT;
    }
    svg_t s;
    int rc = prepare(&s, flight, out);
    if (rc != COA_OK) {
        svg_free(&s);
        return rc;
    }
    const coavoid_flight_t *f = flight;

    /* Write the body to a memory stream first: the document's height is only known once
     * the panels are laid out. */
    char *body = NULL;
    size_t body_size = 0;
    FILE *mem = open_memstream(&body, &body_size);
    if (mem == NULL) {
        svg_free(&s);
        return COA_ERR_WORKSPACE;
    }
    s.out = mem;
    double y = 28.0;
    header(&s, eval, &y);
    y = legend(&s, y + 4.0);
    top_view(&s, &y);
    for (size_t i = 0; i < f->vehicle_count; i++) {
        altitude_panel(&s, eval, i, &y);
    }
    bool mem_ok = !ferror(mem);
    if (fclose(mem) != 0) {
        mem_ok = false;
    }
    s.out = out;
    if (!mem_ok || body == NULL) {
        free(body);
        svg_free(&s);
        return COA_ERR_WORKSPACE;
    }
    double height = y - SVG_PANEL_GAP + 50.0;
    fprintf(out,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
            "viewBox=\"0 0 %.0f %.0f\" font-family=\"DejaVu Sans, Arial, sans-serif\">\n",
            SVG_WIDTH, height, SVG_WIDTH, height);
    fputs("<title>", out);
    put_text(out, f->scenario);
    fputs(" \xe2\x80\x94 ", out);
    put_text(out, f->mode);
    fputs("</title>\n"
          "<style>\n"
          ".title{font-size:17px;font-weight:bold}\n"
          ".result{font-size:14px;font-weight:bold}\n"
          ".info{font-size:12.5px;fill:#333}\n"
          ".panel{font-size:13px;font-weight:bold}\n"
          ".legend{font-size:12px}\n"
          ".label{font-size:12px;font-weight:bold}\n"
          ".small{font-size:10.5px;fill:#333}\n"
          ".near{font-size:10.5px;font-weight:bold}\n"
          ".tick{font-size:11px;fill:#333}\n"
          ".axis{font-size:12px}\n"
          "</style>\n"
          "<rect width=\"100%\" height=\"100%\" fill=\"#fff\"/>\n",
          out);
    fwrite(body, 1, body_size, out);
    fputs("</svg>\n", out);
    free(body);
    svg_free(&s);
    return (fflush(out) == 0 && !ferror(out)) ? COA_OK : COA_ERR_WORKSPACE;
}
