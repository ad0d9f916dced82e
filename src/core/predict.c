/* SPDX-License-Identifier: MIT */
/*
 * predict.c: collision prediction over the horizon in a caller-provided workspace (see
 * predict.h for the contract and the probability model).
 *
 * Workspace layout (every array starts on an 8-byte boundary), with M = max_vehicles +
 * max_tracks movers, S = max_horizon + 1 samples, P = max_pairs and T the hash table's
 * slots (the power of two >= 2P):
 *
 *   coa_predictor_t header
 *   coa_vec3_t  pos[M * S]      aligned samples, mover-major: plans 0..n-1, then tracks
 *   mover_t     mover[M]        volume and sigma model of each mover, this call
 *   coa_box_t   reach[V]        each UAV's box over the whole horizon (obstacle broad phase)
 *   sap_entry_t sap[M]          this step's boxes, sorted by grid cell (wide boxes last)
 *   uint32_t    place[M]        each box's cell, then its place in sap[] (the permutation)
 *   uint32_t    cell_start[C+2] where each cell's run (and, last, the wide boxes') starts,
 *                               C = GRID_CELLS_PER_MOVER * M cells at most
 *   uint64_t    table[T]        the candidate-pair set (open addressing, EMPTY_KEY is free)
 *   uint64_t    cand[P]         distinct candidate keys, sorted before the narrow phase
 *   uint32_t    slot[P]         the table slot of each key, so a call clears what it used
 *
 * A candidate is one 64-bit key that sorts in the output order of predict.h: the kind in
 * the top two bits (vehicle 0, track 1, obstacle 2), the plan index a in the next 30 and
 * b (plan, track or obstacle index) in the low 32. Between calls the table is all empty.
 */
#include "coavoid/predict.h"

#include <math.h>

#include "internal.h"

#define PREDICT_MAGIC 0x434f5052u /* marks a buffer built by coa_predictor_init */
#define NONE UINT32_MAX
#define EMPTY_KEY UINT64_MAX /* never a key: the kind field of a key is at most 2 */
#define KIND_SHIFT 62
#define A_SHIFT 32
#define A_MASK ((UINT64_C(1) << 30) - 1u)
/* Plan indices live in 30 bits of a key; table slots (2P rounded up to a power of two)
 * and mover indices in uint32 with NONE reserved. */
#define MAX_MOVERS ((size_t)1 << 30)
#define MAX_PAIRS ((size_t)1 << 30)
/* The broad phase's grid has at most this many cells per mover. */
#define GRID_CELLS_PER_MOVER 4u

typedef struct {
    coa_volume_t volume;
    coa_real_t sigma_h; /* one sigma at look-ahead 0 */
    coa_real_t rate_h;  /* growth per second of look-ahead */
    coa_real_t sigma_v;
    coa_real_t rate_v;
} mover_t;

typedef struct {
    coa_real_t min_x;
    coa_real_t max_x;
    coa_real_t min_y;
    coa_real_t max_y;
    coa_real_t min_z;
    coa_real_t max_z;
    uint32_t id;
} sap_entry_t;

struct coa_predictor {
    uint32_t magic;
    uint32_t max_horizon;
    size_t max_vehicles;
    size_t max_tracks;
    size_t max_pairs;
    size_t bytes;
    uint32_t table_mask;

    coa_vec3_t *pos;
    mover_t *mover;
    coa_box_t *reach;
    sap_entry_t *sap;
    uint32_t *place;
    uint32_t *cell_start;
    uint64_t *table;
    uint64_t *cand;
    uint32_t *slot;

    /* Per call. */
    const coa_predict_config_t *config;
    const coa_obstacle_t *obstacles;
    size_t n;      /* plans */
    size_t movers; /* plans + tracks */
    size_t stride; /* samples per mover: horizon + 1 */
    coa_real_t slack;
    double log_threshold;
};

typedef struct {
    size_t at_pos;
    size_t at_mover;
    size_t at_reach;
    size_t at_sap;
    size_t at_place;
    size_t at_cell_start;
    size_t at_table;
    size_t at_cand;
    size_t at_slot;
    size_t table_size;
    size_t total;
} predict_layout_t;

/* ------------------------------------------------------------------------------------ */
/* Sizes                                                                                 */

static bool layout_compute(size_t max_vehicles, size_t max_tracks, uint32_t max_horizon,
                           size_t max_pairs, predict_layout_t *lo)
{
    size_t movers;
    size_t samples;
    size_t table = 1u;
    size_t cursor;
    size_t cells;

    if (max_vehicles == 0u || max_horizon == 0u || max_horizon > COA_MAX_HORIZON ||
        max_pairs == 0u || max_pairs > MAX_PAIRS || max_vehicles > MAX_MOVERS ||
        max_tracks > MAX_MOVERS - max_vehicles) {
        return false;
    }
    movers = max_vehicles + max_tracks;
    while (table < 2u * max_pairs) {
        table <<= 1;
    }
    lo->table_size = table;
    if (!size_mul(movers, (size_t)max_horizon + 1u, &samples) ||
        !size_round(sizeof(coa_predictor_t), &cursor) ||
        !reserve(&cursor, samples, sizeof(coa_vec3_t), &lo->at_pos) ||
        !reserve(&cursor, movers, sizeof(mover_t), &lo->at_mover) ||
        !reserve(&cursor, max_vehicles, sizeof(coa_box_t), &lo->at_reach) ||
        !reserve(&cursor, movers, sizeof(sap_entry_t), &lo->at_sap) ||
        !reserve(&cursor, movers, sizeof(uint32_t), &lo->at_place) ||
        !size_mul(movers, GRID_CELLS_PER_MOVER, &cells) ||
        !reserve(&cursor, cells + 2u, sizeof(uint32_t), &lo->at_cell_start) ||
        !reserve(&cursor, table, sizeof(uint64_t), &lo->at_table) ||
        !reserve(&cursor, max_pairs, sizeof(uint64_t), &lo->at_cand) ||
        !reserve(&cursor, max_pairs, sizeof(uint32_t), &lo->at_slot)) {
        return false;
    }
    lo->total = cursor;
    return true;
}

size_t coa_predictor_workspace_size(size_t max_vehicles, size_t max_tracks, uint32_t max_horizon,
                                    size_t max_pairs)
{
    predict_layout_t lo;
    return layout_compute(max_vehicles, max_tracks, max_horizon, max_pairs, &lo) ? lo.total : 0u;
}

coa_predictor_t *coa_predictor_init(void *buffer, size_t size, size_t max_vehicles,
                                    size_t max_tracks, uint32_t max_horizon, size_t max_pairs)
{
    predict_layout_t lo;
    coa_predictor_t *pr;
    unsigned char *base = (unsigned char *)buffer;
    size_t i;

    if (buffer == NULL || (uintptr_t)buffer % WS_ALIGN != 0u) {
        return NULL;
    }
    if (!layout_compute(max_vehicles, max_tracks, max_horizon, max_pairs, &lo) || size < lo.total) {
        return NULL;
    }
    pr = (coa_predictor_t *)buffer;
    *pr = (coa_predictor_t){0};
    pr->max_horizon = max_horizon;
    pr->max_vehicles = max_vehicles;
    pr->max_tracks = max_tracks;
    pr->max_pairs = max_pairs;
    pr->bytes = lo.total;
    pr->table_mask = (uint32_t)(lo.table_size - 1u);
    pr->pos = (coa_vec3_t *)(void *)(base + lo.at_pos);
    pr->mover = (mover_t *)(void *)(base + lo.at_mover);
    pr->reach = (coa_box_t *)(void *)(base + lo.at_reach);
    pr->sap = (sap_entry_t *)(void *)(base + lo.at_sap);
    pr->place = (uint32_t *)(void *)(base + lo.at_place);
    pr->cell_start = (uint32_t *)(void *)(base + lo.at_cell_start);
    pr->table = (uint64_t *)(void *)(base + lo.at_table);
    pr->cand = (uint64_t *)(void *)(base + lo.at_cand);
    pr->slot = (uint32_t *)(void *)(base + lo.at_slot);
    for (i = 0; i < lo.table_size; ++i) {
        pr->table[i] = EMPTY_KEY;
    }
    pr->magic = PREDICT_MAGIC;
    return pr;
}

/* ------------------------------------------------------------------------------------ */
/* Probability of overlap at one instant                                                 */

#define SQRT1_2 0.70710678118654752440
#define LN_SQRT_2PI 0.91893853320467274178
/* Beyond this many sigmas of the disc's edge P_h is 0 or 1 in double: the half-plane
 * bounds Q(40) and 1 - Q(40) say so (the disc lies inside one half-plane and contains the
 * disc about the Gaussian's centre of radius R - d). */
#define PROB_EDGE 40.0
/* Each Poisson window reaches this many standard deviations below its mean and
 * 9 sqrt(lambda) + 28 above it: by the Chernoff bounds P(N <= l - t) <= exp(-t^2 / 2l)
 * and P(N >= l + t) <= exp(-t^2 / (2 (l + t/3))), each tail left out is below e^-40.5. */
#define PROB_TAIL 9.0
#define PROB_TAIL_UP 28.0
/* From R / sigma = 20 the disc's edge is flat enough over the Gaussian for 32-point
 * Gauss-Hermite to be exact to about 1e-14 (test_predict checks it against the series
 * either side); below it the series needs at most about 600 terms (max(a, b) < 60). */
#define GH_MIN_RATIO 20.0

/* ln(n!) - (n + 1/2) ln n + n - ln sqrt(2 pi), the error of Stirling's formula, for
 * n = 1..15 (mpmath, 50 digits); the asymptotic series beyond. */
static const double stirling_error[16] = {0.0, /* n = 0 is never asked for */
                                          0.0810614667953272582197,
                                          0.0413406959554092940938,
                                          0.0276779256849983391488,
                                          0.0207906721037650931115,
                                          0.0166446911898211921632,
                                          0.0138761288230707479987,
                                          0.0118967099458917700951,
                                          0.0104112652619720964975,
                                          0.00925546218271273291773,
                                          0.00833056343336287125647,
                                          0.00757367548795184079497,
                                          0.00694284010720952986566,
                                          0.00640899418800420706844,
                                          0.00595137011275884773562,
                                          0.00555473355196280137104};

static double stirlerr(double n)
{
    double nn;
    if (n <= 15.0) {
        return stirling_error[(int)n];
    }
    nn = n * n;
    return (1.0 / 12.0 -
            (1.0 / 360.0 - (1.0 / 1260.0 - (1.0 / 1680.0 - (1.0 / 1188.0) / nn) / nn) / nn) / nn) /
           n;
}

/* x ln(x / l) + l - x without the cancellation near x = l (Loader's bd0): the series in
 * v = (x - l) / (x + l) converges by |v|^2 < 0.01 a term there. */
static double bd0(double x, double l)
{
    double v;
    double s;
    double ej;
    double v2;
    int j;

    if (fabs(x - l) >= 0.1 * (x + l)) {
        return x * log(x / l) + l - x;
    }
    v = (x - l) / (x + l);
    s = (x - l) * v;
    ej = 2.0 * x * v;
    v2 = v * v;
    for (j = 1; j < 100; ++j) {
        double s1;
        ej *= v2;
        s1 = s + ej / (double)(2 * j + 1);
        if (s1 == s) {
            return s1;
        }
        s = s1;
    }
    return s;
}

/* The Poisson probability of m (an integer >= 0) for mean l >= 0, to full relative
 * precision (Loader's saddle-point form), so the windows below can start anywhere. */
static double poisson_pmf(double l, double m)
{
    if (l == 0.0) {
        return m == 0.0 ? 1.0 : 0.0;
    }
    if (m == 0.0) {
        return exp(-l);
    }
    return exp(-stirlerr(m) - bd0(m, l) - LN_SQRT_2PI) / sqrt(m);
}

static double window_low(double l)
{
    double lo = l - PROB_TAIL * sqrt(l);
    return lo > 0.0 ? floor(lo) : 0.0;
}

static double window_high(double l)
{
    return ceil(l + PROB_TAIL * sqrt(l) + PROB_TAIL_UP);
}

/* sum_i p_alpha(i) F_beta(i - shift) = P(N_beta <= N_alpha - shift) for independent
 * Poisson variables, alpha <= beta, shift 0 or 1, into *out. Every term is positive and
 * F_beta is summed up from its own negligible lower tail, so a small answer keeps its
 * relative precision. Returns false, with nothing computed, when the windows need more
 * than COA_PROBABILITY_MAX_TERMS terms. */
static bool poisson_cross(double alpha, double beta, double shift, double *out)
{
    double i_hi = window_high(alpha);
    double m_lo = window_low(beta);
    double start = window_low(alpha);
    double walk;
    double span;
    double pa;
    double pb;
    double f;
    double m;
    double i;
    double sum;
    uint32_t j;
    uint32_t walk_n;
    uint32_t span_n;

    if (start < m_lo + shift) {
        start = m_lo + shift;
    }
    if (start > i_hi) {
        /* Every F_beta(i - shift) of alpha's window is in beta's dropped lower tail. */
        *out = 0.0;
        return true;
    }
    walk = start - shift - m_lo; /* F_beta's terms before the first product */
    span = i_hi - start;         /* products after the first */
    if (walk + span + 1.0 > (double)COA_PROBABILITY_MAX_TERMS) {
        return false;
    }
    walk_n = (uint32_t)walk;
    span_n = (uint32_t)span;
    pb = poisson_pmf(beta, m_lo);
    f = pb;
    m = m_lo;
    for (j = 0; j < walk_n; ++j) {
        m += 1.0;
        pb *= beta / m;
        f += pb;
    }
    pa = poisson_pmf(alpha, start);
    sum = pa * f;
    i = start;
    for (j = 0; j < span_n; ++j) {
        i += 1.0;
        pa *= alpha / i;
        m += 1.0;
        pb *= beta / m;
        f += pb;
        sum += pa * f;
    }
    *out = sum;
    return true;
}

static double normal_cdf(double x)
{
    return 0.5 * erfc(-x * SQRT1_2);
}

static double normal_sf(double x)
{
    return 0.5 * erfc(x * SQRT1_2);
}

/* Probabilists' 32-point Gauss-Hermite rule (weight the standard normal density), the
 * positive half: nodes and weights from mpmath at 50 digits; the weights sum to 1/2. */
static const double gh_node[16] = {
    0.27554641923027580801, 0.827284903779765191776, 1.38098019927214416158,
    1.9380049059257173503,  2.49984041518739524544,  3.06813516901312130536,
    3.64478124988083311123, 4.23202110999540979512,  4.83260461324448861263,
    5.45003327362342807004, 6.08896430907698681402,  6.75593083054070474481,
    7.4607557541215187579,  8.2197287653822454014,   9.06439921070240617483,
    10.0774226742294659462};
static const double gh_weight[16] = {
    0.21170556988047931757,     0.156538993757598444886,     0.0853448082720807601496,
    0.0341098477260920505106,   0.00990346170232059187677,   0.0020620510513078847176,
    0.000302557025817062492161, 0.0000305598030608963015411, 2.05962210395342887605e-6,
    8.88129071310589508938e-8,  2.31251841207424054098e-9,   3.34750123980120700489e-11,
    2.37806485577780867587e-13, 6.75529022367011874058e-16,  5.20844959196086129441e-19,
    4.12460748901826933641e-23};

/* P_h for a wide disc (b = R/sigma >= GH_MIN_RATIO). Conditioned on the error across the
 * line of centres, t sigma, the point is inside when the error along it falls within the
 * half-chord w = sqrt(R^2 - t^2 sigma^2): Phi((w - d)/sigma) - Phi((-w - d)/sigma), a
 * function of t that is nearly constant when the edge is flat over the Gaussian, which is
 * what Gauss-Hermite integrates best. (w - d)/sigma is written as c - t^2 / (b + w/sigma)
 * with c = (R - d)/sigma, free of the cancellation of w - d near the edge. */
static double horizontal_wide(double a, double b, double c)
{
    double sum = 0.0;
    int i;

    for (i = 0; i < 16; ++i) {
        double t = gh_node[i];
        double root;
        if (!(t < b)) {
            continue;
        }
        root = sqrt((b - t) * (b + t));
        sum += gh_weight[i] * (normal_cdf(c - t * t / (b + root)) - normal_cdf(-(root + a)));
    }
    return 2.0 * sum;
}

/* P(|d + e| < R), e ~ N(0, sigma^2 I_2), sigma >= 0: 1 - Q_1(d/sigma, R/sigma). */
static double horizontal_part(double d, double r, double sigma)
{
    double a;
    double b;
    double c;
    double mu;
    double y;
    double p;

    if (sigma == 0.0) {
        return d < r ? 1.0 : 0.0;
    }
    c = (r - d) / sigma;
    if (c < -PROB_EDGE) {
        return 0.0;
    }
    if (c > PROB_EDGE) {
        return 1.0;
    }
    a = d / sigma;
    b = r / sigma;
    mu = 0.5 * a * a;
    y = 0.5 * b * b;
    /* 1 - Q_1(a, b) = P(N_y > N_mu) for independent Poisson N_y, N_mu with means b^2/2
     * and a^2/2: the non-central chi-square's Poisson mixture of central chi-square
     * CDFs, each of which is a Poisson tail. Whichever of P_h and 1 - P_h is the smaller
     * is summed directly. */
    if (b < GH_MIN_RATIO) {
        bool below = y < mu;
        double t;
        if (below ? poisson_cross(y, mu, 1.0, &t) : poisson_cross(mu, y, 0.0, &t)) {
            p = below ? t : 1.0 - t;
            return p < 0.0 ? 0.0 : (p > 1.0 ? 1.0 : p);
        }
    }
    p = horizontal_wide(a, b, c);
    return p < 0.0 ? 0.0 : (p > 1.0 ? 1.0 : p);
}

/* P(|dz + e| < H), e ~ N(0, sigma^2). Both CDFs are taken from the tail they lie in, so
 * far from the slab the answer is a difference of two small numbers, not of two near 1. */
static double vertical_part(double dz, double h, double sigma)
{
    double z = fabs(dz);
    double u1;
    double u2;
    double p;

    if (sigma == 0.0) {
        return z < h ? 1.0 : 0.0;
    }
    u1 = (h - z) / sigma;
    u2 = -(h + z) / sigma;
    if (u1 <= 0.0) {
        p = normal_cdf(u1) - normal_cdf(u2);
    } else {
        p = 1.0 - normal_sf(u1) - normal_cdf(u2);
    }
    return p < 0.0 ? 0.0 : (p > 1.0 ? 1.0 : p);
}

static bool finite_nonneg(double x)
{
    return isfinite(x) != 0 && x >= 0.0;
}

double coa_conflict_probability(coa_real_t d, coa_real_t dz, coa_real_t radius_sum,
                                coa_real_t half_height_sum, coa_real_t sigma_h, coa_real_t sigma_v)
{
    double pv;

    if (!finite_nonneg((double)d) || isfinite((double)dz) == 0 ||
        !finite_nonneg((double)radius_sum) || !(radius_sum > (coa_real_t)0) ||
        !finite_nonneg((double)half_height_sum) || !(half_height_sum > (coa_real_t)0) ||
        !finite_nonneg((double)sigma_h) || !finite_nonneg((double)sigma_v)) {
        return 1.0;
    }
    pv = vertical_part((double)dz, (double)half_height_sum, (double)sigma_v);
    if (pv == 0.0) {
        return 0.0;
    }
    return horizontal_part((double)d, (double)radius_sum, (double)sigma_h) * pv;
}

/* The log of an upper bound of the overlap probability given lower bounds of the
 * horizontal and vertical gaps between the volumes (negative: they may touch) and upper
 * bounds of the sigmas. The disc lies inside a half-plane gap_h away, so P_h <=
 * Q(gap_h / sigma_h) <= exp(-x^2/2) / 2; the slab lies outside the interval of half-width
 * gap_v, so P_v <= 2 Q(gap_v / sigma_v) <= exp(-x^2/2). In logs, so that skipping a far
 * step costs no exp (and no underflow). Only ever used to skip work whose answer cannot
 * matter, so it may be loose. */
#define LN2 0.69314718055994530942
/* Skipped only below the cut by this much in log (0.1%): room for the rounding of both
 * the bound and the probability. */
#define PRUNE_MARGIN 1e-3

static double log_probability_bound(double gap_h, double sigma_h, double gap_v, double sigma_v)
{
    double e = 0.0;

    if (gap_h > 0.0) {
        if (sigma_h == 0.0) {
            return -INFINITY;
        }
        e += 0.5 * (gap_h / sigma_h) * (gap_h / sigma_h) + LN2;
    }
    if (gap_v > 0.0) {
        if (sigma_v == 0.0) {
            return -INFINITY;
        }
        e += 0.5 * (gap_v / sigma_v) * (gap_v / sigma_v);
    }
    return -e;
}

/* ------------------------------------------------------------------------------------ */
/* Input checks                                                                          */

static bool positive(coa_real_t x)
{
    return real_ok(x) && x > (coa_real_t)0;
}

static bool nonneg(coa_real_t x)
{
    return real_ok(x) && x >= (coa_real_t)0;
}

static bool config_ok(const coa_predictor_t *pr, const coa_predict_config_t *c)
{
    coa_real_t end;

    if (!real_ok(c->t0) || !positive(c->dt) || c->horizon == 0u || c->horizon > pr->max_horizon ||
        !nonneg(c->vehicle_sigma_rate_horizontal) || !nonneg(c->vehicle_sigma_rate_vertical) ||
        !nonneg(c->track_sigma_rate_horizontal) || !nonneg(c->track_sigma_rate_vertical) ||
        isfinite(c->threshold) == 0 || !(c->threshold > 0.0) || !(c->threshold <= 1.0)) {
        return false;
    }
    /* The grid's last instant and look-ahead must exist. */
    end = (coa_real_t)c->horizon * c->dt;
    return real_ok(end) && real_ok(c->t0 + end);
}

static bool plan_ok(const coa_intent_plan_t *p)
{
    size_t j;

    if (!real_ok(p->t0) || !positive(p->step) || p->samples == NULL || p->count == 0u ||
        !positive(p->volume.radius) || !positive(p->volume.half_height) ||
        !nonneg(p->sigma_horizontal) || !nonneg(p->sigma_vertical)) {
        return false;
    }
    for (j = 0; j < p->count; ++j) {
        if (!vec_ok(&p->samples[j])) {
            return false;
        }
    }
    return true;
}

/* ------------------------------------------------------------------------------------ */
/* Alignment                                                                             */

/* A plan's position at u sample steps after its first sample (u may be negative or past
 * the last sample): the track-path semantics of docs/scenario-format.md. Anchored at a sample
 * so that a whole u gives that sample exactly. */
static coa_vec3_t plan_at(const coa_intent_plan_t *p, coa_real_t u)
{
    const coa_vec3_t *s = p->samples;
    size_t last;
    size_t j;
    coa_real_t f;
    coa_vec3_t r;

    if (p->count == 1u) {
        return s[0];
    }
    last = p->count - 1u;
    if (!(u < (coa_real_t)last)) {
        f = u - (coa_real_t)last;
        r.x = s[last].x + f * (s[last].x - s[last - 1u].x);
        r.y = s[last].y + f * (s[last].y - s[last - 1u].y);
        r.z = s[last].z + f * (s[last].z - s[last - 1u].z);
        return r;
    }
    j = u < (coa_real_t)1 ? 0u : (size_t)u;
    if (j > last - 1u) {
        j = last - 1u; /* (coa_real_t)last rounded up: float and more than 2^24 samples */
    }
    f = u - (coa_real_t)j;
    r.x = s[j].x + f * (s[j + 1u].x - s[j].x);
    r.y = s[j].y + f * (s[j + 1u].y - s[j].y);
    r.z = s[j].z + f * (s[j + 1u].z - s[j].z);
    return r;
}

/* Fills the samples, the movers and the UAVs' reach. Returns COA_ERR_ARGUMENT when a
 * position or a sigma over the horizon is not finite. */
/* Plan i resampled on the predictor's grid, its volume and sigmas, and the box its samples
 * reach (widened by the volume later, once the slack is known). */
static void align_plan(coa_predictor_t *pr, size_t i, const coa_intent_plan_t *p)
{
    const coa_predict_config_t *c = pr->config;
    mover_t *mv = &pr->mover[i];
    coa_vec3_t *row = &pr->pos[i * pr->stride];
    /* u_k = off + k * ratio rather than (t_k - t0') / step: a plan on the predictor's own
     * grid then lands on its samples exactly. */
    coa_real_t off = (c->t0 - p->t0) / p->step;
    coa_real_t ratio = c->dt / p->step;
    coa_box_t *rb = &pr->reach[i];
    uint32_t k;
    mv->volume = p->volume;
    mv->sigma_h = p->sigma_horizontal;
    mv->sigma_v = p->sigma_vertical;
    mv->rate_h = c->vehicle_sigma_rate_horizontal;
    mv->rate_v = c->vehicle_sigma_rate_vertical;
    for (k = 0; k <= c->horizon; ++k) {
        row[k] = plan_at(p, off + (coa_real_t)k * ratio);
    }
    rb->min = row[0];
    rb->max = row[0];
    for (k = 1; k <= c->horizon; ++k) {
        box_include(rb, &row[k]);
    }
}

/* Track t (mover i) extrapolated on the predictor's grid, with its volume and sigmas. */
static void align_track(coa_predictor_t *pr, size_t i, const coa_track_t *t)
{
    const coa_predict_config_t *c = pr->config;
    mover_t *mv = &pr->mover[i];
    coa_vec3_t *row = &pr->pos[i * pr->stride];
    uint32_t k;
    mv->volume = t->volume;
    mv->sigma_h = t->sigma_horizontal;
    mv->sigma_v = t->sigma_vertical;
    mv->rate_h = c->track_sigma_rate_horizontal;
    mv->rate_v = c->track_sigma_rate_vertical;
    for (k = 0; k <= c->horizon; ++k) {
        row[k] = coa_track_at(t, c->t0 + (coa_real_t)k * c->dt);
    }
}

/* Mover i's samples checked finite, and the scene's scale raised to them and to the widest
 * its box gets (the volume plus the margin at the horizon's end). False: not finite. */
static bool align_scale(const coa_predictor_t *pr, size_t i, coa_real_t *scale)
{
    const coa_predict_config_t *c = pr->config;
    const mover_t *mv = &pr->mover[i];
    const coa_vec3_t *row = &pr->pos[i * pr->stride];
    const coa_real_t horizon_tau = (coa_real_t)c->horizon * c->dt;
    uint32_t k;
    for (k = 0; k <= c->horizon; ++k) {
        if (!vec_ok(&row[k])) {
            return false;
        }
        *scale = real_max_abs3(&row[k], *scale);
    }
    coa_real_t worst_h = mv->volume.radius + (coa_real_t)COA_PREDICT_SIGMA_MARGIN *
                                                 (mv->sigma_h + mv->rate_h * horizon_tau);
    coa_real_t worst_v = mv->volume.half_height + (coa_real_t)COA_PREDICT_SIGMA_MARGIN *
                                                      (mv->sigma_v + mv->rate_v * horizon_tau);
    if (!real_ok(worst_h) || !real_ok(worst_v)) {
        return false;
    }
    *scale = worst_h > *scale ? worst_h : *scale;
    *scale = worst_v > *scale ? worst_v : *scale;
    return true;
}

static int align(coa_predictor_t *pr, const coa_intent_plan_t *plans, const coa_track_t *tracks)
{
    coa_real_t scale = (coa_real_t)0;
    size_t i;
    for (i = 0; i < pr->movers; ++i) {
        if (i < pr->n) {
            align_plan(pr, i, &plans[i]);
        } else {
            align_track(pr, i, &tracks[i - pr->n]);
        }
        if (!align_scale(pr, i, &scale)) {
            return COA_ERR_ARGUMENT;
        }
    }
    pr->slack = scale * (coa_real_t)(SLACK_ULPS * REAL_EPSILON);
    for (i = 0; i < pr->n; ++i) {
        coa_box_t *rb = &pr->reach[i];
        coa_real_t r = pr->mover[i].volume.radius + pr->slack;
        coa_real_t h = pr->mover[i].volume.half_height + pr->slack;
        rb->min.x -= r;
        rb->min.y -= r;
        rb->min.z -= h;
        rb->max.x += r;
        rb->max.y += r;
        rb->max.z += h;
    }
    return COA_OK;
}

/* ------------------------------------------------------------------------------------ */
/* Broad phase                                                                           */

static coa_real_t sigma_at(coa_real_t s0, coa_real_t rate, coa_real_t tau)
{
    return s0 + rate * tau;
}

static void step_box(const coa_predictor_t *pr, uint32_t id, uint32_t k, sap_entry_t *e)
{
    const mover_t *mv = &pr->mover[id];
    const coa_vec3_t *row = &pr->pos[(size_t)id * pr->stride];
    coa_real_t tau = (coa_real_t)(k + 1u) * pr->config->dt;
    coa_real_t gh = (coa_real_t)COA_PREDICT_SIGMA_MARGIN * sigma_at(mv->sigma_h, mv->rate_h, tau) +
                    mv->volume.radius + pr->slack;
    coa_real_t gv = (coa_real_t)COA_PREDICT_SIGMA_MARGIN * sigma_at(mv->sigma_v, mv->rate_v, tau) +
                    mv->volume.half_height + pr->slack;
    const coa_vec3_t *p0 = &row[k];
    const coa_vec3_t *p1 = &row[k + 1u];

    /* coa_sweep_bounds widened by the margin, in one pass. */
    e->min_x = (p0->x < p1->x ? p0->x : p1->x) - gh;
    e->max_x = (p0->x > p1->x ? p0->x : p1->x) + gh;
    e->min_y = (p0->y < p1->y ? p0->y : p1->y) - gh;
    e->max_y = (p0->y > p1->y ? p0->y : p1->y) + gh;
    e->min_z = (p0->z < p1->z ? p0->z : p1->z) - gv;
    e->max_z = (p0->z > p1->z ? p0->z : p1->z) + gv;
    e->id = id;
}

static uint64_t make_key(uint64_t kind, uint64_t a, uint64_t b)
{
    return (kind << KIND_SHIFT) | (a << A_SHIFT) | b;
}

/* Adds a key to the set unless it is there. COA_ERR_WORKSPACE when the set is full. */
static int set_insert(coa_predictor_t *pr, uint64_t key, size_t *count)
{
    uint32_t h = (uint32_t)((key * UINT64_C(0x9e3779b97f4a7c15)) >> 32) & pr->table_mask;

    /* At most half the slots are ever used, so an empty one is always reached. */
    while (pr->table[h] != EMPTY_KEY) {
        if (pr->table[h] == key) {
            return COA_OK;
        }
        h = (h + 1u) & pr->table_mask;
    }
    if (*count == pr->max_pairs) {
        return COA_ERR_WORKSPACE;
    }
    pr->table[h] = key;
    pr->slot[*count] = h;
    pr->cand[*count] = key;
    *count += 1u;
    return COA_OK;
}

static void set_clear(coa_predictor_t *pr, size_t count)
{
    size_t i;
    for (i = 0; i < count; ++i) {
        pr->table[pr->slot[i]] = EMPTY_KEY;
    }
}

/* A pair of this step's boxes: a candidate when they overlap in x, y and z and are not
 * both tracks. */
static int sap_pair(coa_predictor_t *pr, const sap_entry_t *e, const sap_entry_t *f, size_t *count)
{
    size_t n = pr->n;
    uint32_t lo;
    uint32_t hi;

    if (f->min_x > e->max_x || e->min_x > f->max_x || f->min_y > e->max_y || e->min_y > f->max_y ||
        (e->id >= n && f->id >= n) || f->min_z > e->max_z || e->min_z > f->max_z) {
        return COA_OK;
    }
    lo = e->id < f->id ? e->id : f->id;
    hi = e->id < f->id ? f->id : e->id;
    return set_insert(pr, hi < n ? make_key(0u, lo, hi) : make_key(1u, lo, hi - n), count);
}

/* Every pair within sap[a, b). */
static int pairs_within(coa_predictor_t *pr, size_t a, size_t b, size_t *count)
{
    size_t i;
    size_t j;
    int rc = COA_OK;

    for (i = a; i < b && rc == COA_OK; ++i) {
        for (j = i + 1u; j < b && rc == COA_OK; ++j) {
            rc = sap_pair(pr, &pr->sap[i], &pr->sap[j], count);
        }
    }
    return rc;
}

/* Every pair of sap[i] with a box of sap[a, b). */
static int pairs_across(coa_predictor_t *pr, size_t i, size_t a, size_t b, size_t *count)
{
    size_t j;
    int rc = COA_OK;

    for (j = a; j < b && rc == COA_OK; ++j) {
        rc = sap_pair(pr, &pr->sap[i], &pr->sap[j], count);
    }
    return rc;
}

/* Heap sort by min_x (the wide boxes: few, and in id order). */
static void sap_sift(sap_entry_t *a, size_t root, size_t n)
{
    sap_entry_t v = a[root];
    size_t child;

    while ((child = 2u * root + 1u) < n) {
        if (child + 1u < n && a[child + 1u].min_x > a[child].min_x) {
            ++child;
        }
        if (!(a[child].min_x > v.min_x)) {
            break;
        }
        a[root] = a[child];
        root = child;
    }
    a[root] = v;
}

static void sap_heap_sort(sap_entry_t *a, size_t n)
{
    size_t i;
    if (n < 2u) {
        return;
    }
    for (i = n / 2u; i > 0u; --i) {
        sap_sift(a, i - 1u, n);
    }
    for (i = n - 1u; i > 0u; --i) {
        sap_entry_t t = a[0];
        a[0] = a[i];
        a[i] = t;
        sap_sift(a, 0u, i);
    }
}

/* The grid column (or row) of a coordinate: monotone in it (a subtraction, a product by
 * a non-negative number, a clamp and a truncation each are), which is all correctness
 * needs. */
static uint32_t cell_of(coa_real_t v, coa_real_t v0, coa_real_t inv_w, uint32_t cells)
{
    coa_real_t t = (v - v0) * inv_w;
    if (!(t < (coa_real_t)(cells - 1u))) {
        return cells - 1u;
    }
    return (uint32_t)t;
}

#define GRID_SAMPLES 31u /* boxes whose median extent sets the cell width */
#define GRID_EXTENTS 2   /* cell width in median box extents */
#define GRID_GROWTH 64   /* steps of 1/8 of the cell width, at most (a few suffice) */

typedef struct {
    coa_real_t x0;
    coa_real_t y0;
    coa_real_t inv_w; /* 0 on an axis of one cell */
    coa_real_t inv_h;
    uint32_t nx;
    uint32_t ny;
} grid_t;

static void box_cells(const grid_t *g, const sap_entry_t *e, uint32_t *lx, uint32_t *hx,
                      uint32_t *ly, uint32_t *hy)
{
    *lx = cell_of(e->min_x, g->x0, g->inv_w, g->nx);
    *hx = cell_of(e->max_x, g->x0, g->inv_w, g->nx);
    *ly = cell_of(e->min_y, g->y0, g->inv_h, g->ny);
    *hy = cell_of(e->max_y, g->y0, g->inv_h, g->ny);
}

/* The cell of a box that reaches at most into the next column and row: the one of its
 * min corner; a larger box ("wide") goes to the last run, index nx * ny. */
static uint32_t box_slot(const grid_t *g, const sap_entry_t *e)
{
    uint32_t lx;
    uint32_t hx;
    uint32_t ly;
    uint32_t hy;
    box_cells(g, e, &lx, &hx, &ly, &hy);
    if (hx - lx > 1u || hy - ly > 1u) {
        return g->nx * g->ny;
    }
    return ly * g->nx + lx;
}

/* Lays a uniform square grid over this step's boxes, at most GRID_CELLS_PER_MOVER cells
 * per mover, cells GRID_EXTENTS median box extents wide where that fits (a robust width:
 * a few large boxes, such as tracks with a large sigma, do not coarsen every cell), and
 * counting-sorts the boxes into it (one cell when the scene is degenerate). */
/* The grid's shape over the movers' boxes: origin at their least corner; square cells a few
 * times the median box's extent (GRID_EXTENTS, from up to GRID_SAMPLES boxes), at least
 * wide enough that rx ry / w^2 and (rx + ry) / w are within the room, so that
 * (rx / w + 1) (ry / w + 1) is within about twice it; then grown in steps of 1/8 until it
 * fits (a few steps). Fewer than 4 movers, or a degenerate scene: one cell. */
static void grid_shape(const coa_predictor_t *pr, grid_t *g)
{
    const sap_entry_t *sap = pr->sap;
    const size_t m = pr->movers;
    const size_t s = m < GRID_SAMPLES ? m : GRID_SAMPLES;
    coa_real_t sample[GRID_SAMPLES];
    coa_real_t x1 = sap[0].max_x;
    coa_real_t y1 = sap[0].max_y;
    size_t p;
    size_t i;
    g->x0 = sap[0].min_x;
    g->y0 = sap[0].min_y;
    for (p = 1; p < m; ++p) {
        g->x0 = sap[p].min_x < g->x0 ? sap[p].min_x : g->x0;
        g->y0 = sap[p].min_y < g->y0 ? sap[p].min_y : g->y0;
        x1 = sap[p].max_x > x1 ? sap[p].max_x : x1;
        y1 = sap[p].max_y > y1 ? sap[p].max_y : y1;
    }
    for (i = 0; i < s; ++i) {
        const sap_entry_t *e = &sap[i * m / s];
        coa_real_t ex = e->max_x - e->min_x;
        coa_real_t ey = e->max_y - e->min_y;
        coa_real_t h = ex > ey ? ex : ey;
        size_t j = i;
        while (j > 0u && sample[j - 1u] > h) {
            sample[j] = sample[j - 1u];
            --j;
        }
        sample[j] = h;
    }
    /* No mover, no sample: the scene is one cell (below). */
    const coa_real_t w = s > 0u ? sample[s / 2u] * (coa_real_t)GRID_EXTENTS : (coa_real_t)0;
    const coa_real_t rx = x1 - g->x0;
    const coa_real_t ry = y1 - g->y0;
    g->nx = 1u;
    g->ny = 1u;
    g->inv_w = (coa_real_t)0;
    g->inv_h = (coa_real_t)0;
    if (!(m >= 4u && w > (coa_real_t)0 && real_ok(w) && real_ok(rx) && real_ok(ry))) {
        return;
    }
    double room = (double)m * (double)GRID_CELLS_PER_MOVER;
    double fit = sqrt((double)rx * (double)ry / room);
    double line = ((double)rx + (double)ry) / room; /* a long thin scene */
    double wd = (double)w > fit ? (double)w : fit;
    wd = wd > line ? wd : line;
    for (int grow = 0; grow < GRID_GROWTH; ++grow) {
        double cx = (double)rx > wd ? (double)rx / wd : 0.0;
        double cy = (double)ry > wd ? (double)ry / wd : 0.0;
        if ((cx + 1.0) * (cy + 1.0) <= room) {
            /* floor(c) + 1 <= c + 1, so nx ny <= the cells' room. */
            g->nx = (uint32_t)cx + 1u;
            g->ny = (uint32_t)cy + 1u;
            g->inv_w = g->nx > 1u ? (coa_real_t)(1.0 / wd) : (coa_real_t)0;
            g->inv_h = g->ny > 1u ? (coa_real_t)(1.0 / wd) : (coa_real_t)0;
            return;
        }
        wd *= 1.125;
    }
}

static void grid_fill(coa_predictor_t *pr, grid_t *g)
{
    const size_t m = pr->movers;
    uint32_t *start = pr->cell_start;
    size_t cells;
    size_t p;
    size_t i;
    grid_shape(pr, g);
    cells = (size_t)g->nx * g->ny;
    for (i = 0; i <= cells + 1u; ++i) {
        start[i] = 0u;
    }
    for (p = 0; p < m; ++p) {
        uint32_t slot = box_slot(g, &pr->sap[p]);
        pr->place[p] = slot;
        start[slot] += 1u;
    }
    uint32_t sum = 0u;
    for (i = 0; i <= cells; ++i) {
        uint32_t c = start[i];
        start[i] = sum;
        sum += c;
    }
    start[cells + 1u] = sum;
    for (p = 0; p < m; ++p) {
        pr->place[p] = start[pr->place[p]]++;
    }
    /* Moves each box to its place in cell order, in place: every swap puts one box where it
     * belongs, so at most m swaps. */
    for (p = 0; p < m; ++p) {
        while (pr->place[p] != (uint32_t)p) {
            uint32_t d = pr->place[p];
            sap_entry_t t = pr->sap[d];
            pr->sap[d] = pr->sap[p];
            pr->sap[p] = t;
            pr->place[p] = pr->place[d];
            pr->place[d] = d;
        }
    }
    /* Placing advanced each start to the next run's; shift back. */
    for (i = cells; i > 0u; --i) {
        start[i] = start[i - 1u];
    }
    start[0] = 0u;
}

/* This step's pairs. Two boxes that overlap in x and y have columns (rows) at most one
 * apart: if e starts no later than f in x, f starts within e, so f's column is at most
 * e's last, which is at most one past e's first (cell_of is monotone). So a small box's
 * partners are in its own cell and the 8 around it: each cell is paired with itself and
 * 4 of its neighbours, which finds each pair once. A wide box is checked against the
 * small boxes of every cell from one before its own first to its last on each axis, and
 * against every other wide box. */
static int grid_pairs(coa_predictor_t *pr, const grid_t *g, size_t *count)
{
    const uint32_t *start = pr->cell_start;
    uint32_t wide = g->nx * g->ny;
    uint32_t cx;
    uint32_t cy;
    size_t i;
    int rc = COA_OK;

    for (cy = 0; cy < g->ny && rc == COA_OK; ++cy) {
        for (cx = 0; cx < g->nx && rc == COA_OK; ++cx) {
            uint32_t c = cy * g->nx + cx;
            uint32_t right = cx + 1u < g->nx ? c + 2u : c + 1u;
            if (start[c + 1u] == start[c]) {
                continue;
            }
            rc = pairs_within(pr, start[c], start[c + 1u], count);
            for (i = start[c]; i < start[c + 1u] && rc == COA_OK; ++i) {
                /* The cell to the right; then above-left, above and above-right, one
                 * run. */
                rc = pairs_across(pr, i, start[c + 1u], start[right], count);
                if (rc == COA_OK && cy + 1u < g->ny) {
                    uint32_t u = c + g->nx;
                    uint32_t lo = cx > 0u ? u - 1u : u;
                    uint32_t hi = cx + 1u < g->nx ? u + 1u : u;
                    rc = pairs_across(pr, i, start[lo], start[hi + 1u], count);
                }
            }
        }
    }
    /* The wide boxes: by x among themselves (sweep and prune), each against the small
     * boxes of the cells it reaches. */
    sap_heap_sort(&pr->sap[start[wide]], start[wide + 1u] - start[wide]);
    for (i = start[wide]; i < start[wide + 1u] && rc == COA_OK; ++i) {
        const sap_entry_t *e = &pr->sap[i];
        uint32_t lx;
        uint32_t hx;
        uint32_t ly;
        uint32_t hy;
        size_t j;
        box_cells(g, e, &lx, &hx, &ly, &hy);
        for (cy = ly > 0u ? ly - 1u : 0u; cy <= hy && rc == COA_OK; ++cy) {
            uint32_t first = cy * g->nx + (lx > 0u ? lx - 1u : 0u);
            uint32_t last = cy * g->nx + hx;
            rc = pairs_across(pr, i, start[first], start[last + 1u], count);
        }
        for (j = i + 1u; j < start[wide + 1u] && pr->sap[j].min_x <= e->max_x && rc == COA_OK;
             ++j) {
            rc = sap_pair(pr, e, &pr->sap[j], count);
        }
    }
    return rc;
}

/* Pairs on a uniform grid over every step, then the obstacles against each UAV's
 * reach. */
static int broad_phase(coa_predictor_t *pr, size_t obstacle_count, size_t *count)
{
    size_t m = pr->movers;
    size_t n = pr->n;
    uint32_t k;
    size_t p;
    size_t o;
    int rc = COA_OK;

    *count = 0u;
    for (k = 0; k < pr->config->horizon && rc == COA_OK && m > 0u; ++k) {
        grid_t g;
        for (p = 0; p < m; ++p) {
            step_box(pr, (uint32_t)p, k, &pr->sap[p]);
        }
        grid_fill(pr, &g);
        rc = grid_pairs(pr, &g, count);
    }
    /* The set has done its work (the keys are distinct); leave the table empty. */
    set_clear(pr, *count);
    if (rc != COA_OK) {
        return rc;
    }
    for (o = 0; o < obstacle_count; ++o) {
        coa_box_t ob = coa_obstacle_bounds(&pr->obstacles[o]);
        for (p = 0; p < n; ++p) {
            if (coa_boxes_touch(&pr->reach[p], &ob)) {
                if (*count == pr->max_pairs) {
                    return COA_ERR_WORKSPACE;
                }
                pr->cand[*count] = make_key(2u, p, o);
                *count += 1u;
            }
        }
    }
    return COA_OK;
}

static void key_sift(uint64_t *a, size_t root, size_t n)
{
    uint64_t v = a[root];
    size_t child;

    while ((child = 2u * root + 1u) < n) {
        if (child + 1u < n && a[child + 1u] > a[child]) {
            ++child;
        }
        if (a[child] <= v) {
            break;
        }
        a[root] = a[child];
        root = child;
    }
    a[root] = v;
}

/* Heap sort: O(P log P) whatever the order the sweep found the pairs in, in place. */
static void key_sort(uint64_t *a, size_t n)
{
    size_t i;
    if (n < 2u) {
        return;
    }
    for (i = n / 2u; i > 0u; --i) {
        key_sift(a, i - 1u, n);
    }
    for (i = n - 1u; i > 0u; --i) {
        uint64_t t = a[0];
        a[0] = a[i];
        a[i] = t;
        key_sift(a, 0u, i);
    }
}

/* ------------------------------------------------------------------------------------ */
/* Narrow phase                                                                          */

typedef struct {
    coa_real_t d0x;
    coa_real_t d0y;
    coa_real_t d0z;
    coa_real_t wx;
    coa_real_t wy;
    coa_real_t wz;
} relative_t;

/* Combined one-sigma of a pair at look-ahead tau, in double. */
static double pair_sigma(coa_real_t s0a, coa_real_t ra, coa_real_t s0b, coa_real_t rb, double tau)
{
    double x = (double)s0a + (double)ra * tau;
    double y = (double)s0b + (double)rb * tau;
    return sqrt(x * x + y * y);
}

/* Evaluates a UAV against another moving thing over the whole horizon. Returns whether
 * the pair is a conflict (file comment of predict.h) and fills *out when it is. */
/* Where the evaluation of one pair of movers stands, step by step. */
typedef struct {
    const coa_predictor_t *pr;
    const mover_t *ma;
    const mover_t *mb;
    const coa_vec3_t *pa; /* their positions, rows of N + 1 */
    const coa_vec3_t *pb;
    coa_real_t rsum;
    coa_real_t hsum;
    coa_real_t near_h; /* rsum and hsum widened by the slack */
    coa_real_t near_v;
    uint32_t first; /* the first conflicting step, NONE so far */
    double pmax;    /* the largest probability seen (uncertain pairs) */
    double log_cut; /* log of what an instant must reach to matter */
} pair_eval_t;

/* One step's relative motion and its least separations, exactly: the closest point of a
 * segment (at uh) and a sign change of a linear function (at uv). */
typedef struct {
    relative_t r;
    coa_real_t d1z;
    coa_real_t uh;
    coa_real_t uv;
    coa_real_t h2;   /* least horizontal separation, squared */
    coa_real_t vmin; /* least vertical separation */
} step_sep_t;

static void step_separations(const pair_eval_t *e, uint32_t k, step_sep_t *st)
{
    const coa_vec3_t *pa = e->pa;
    const coa_vec3_t *pb = e->pb;
    relative_t *r = &st->r;
    coa_real_t len2;
    coa_real_t hx;
    coa_real_t hy;
    r->d0x = pa[k].x - pb[k].x;
    r->d0y = pa[k].y - pb[k].y;
    r->d0z = pa[k].z - pb[k].z;
    r->wx = (pa[k + 1u].x - pb[k + 1u].x) - r->d0x;
    r->wy = (pa[k + 1u].y - pb[k + 1u].y) - r->d0y;
    st->d1z = pa[k + 1u].z - pb[k + 1u].z;
    r->wz = st->d1z - r->d0z;
    st->uh = (coa_real_t)0;
    len2 = r->wx * r->wx + r->wy * r->wy;
    if (len2 > (coa_real_t)0) {
        st->uh = -(r->d0x * r->wx + r->d0y * r->wy) / len2;
        st->uh = st->uh < (coa_real_t)0 ? (coa_real_t)0
                                        : (st->uh > (coa_real_t)1 ? (coa_real_t)1 : st->uh);
    }
    hx = r->d0x + st->uh * r->wx;
    hy = r->d0y + st->uh * r->wy;
    st->h2 = hx * hx + hy * hy;
    if ((r->d0z <= (coa_real_t)0 && st->d1z >= (coa_real_t)0) ||
        (r->d0z >= (coa_real_t)0 && st->d1z <= (coa_real_t)0)) {
        st->vmin = (coa_real_t)0;
        st->uv = r->d0z == st->d1z ? (coa_real_t)0 : r->d0z / (r->d0z - st->d1z);
    } else if (real_fabs(r->d0z) <= real_fabs(st->d1z)) {
        st->vmin = real_fabs(r->d0z);
        st->uv = (coa_real_t)0;
    } else {
        st->vmin = real_fabs(st->d1z);
        st->uv = (coa_real_t)1;
    }
}

/* A certain pair: the exact test only where the separations (widened by the slack) allow
 * a conflict: both are necessary conditions of it. */
static void step_certain(pair_eval_t *e, uint32_t k, const step_sep_t *st)
{
    coa_sweep_t sa;
    coa_sweep_t sb;
    if (e->first != NONE || !(st->h2 < e->near_h * e->near_h && st->vmin < e->near_v)) {
        return;
    }
    sa.volume = e->ma->volume;
    sa.p0 = e->pa[k];
    sa.p1 = e->pa[k + 1u];
    sb.volume = e->mb->volume;
    sb.p0 = e->pb[k];
    sb.p1 = e->pb[k + 1u];
    if (coa_conflict_volumes(&sa, &sb)) {
        e->first = k;
    }
}

/* The instants of the file comment: the endpoints (the start only at k = 0: later it is
 * the previous step's end), the least separations, quarters. Returns how many. */
static size_t step_instants(uint32_t k, const step_sep_t *st, coa_real_t *instants)
{
    size_t count = 0u;
    if (k == 0u) {
        instants[count++] = (coa_real_t)0;
    }
    instants[count++] = (coa_real_t)1;
    if (st->uh > (coa_real_t)0 && st->uh < (coa_real_t)1) {
        instants[count++] = st->uh;
    }
    if (st->uv > (coa_real_t)0 && st->uv < (coa_real_t)1 && st->uv != st->uh) {
        instants[count++] = st->uv;
    }
    instants[count++] = (coa_real_t)0.25;
    instants[count++] = (coa_real_t)0.5;
    instants[count++] = (coa_real_t)0.75;
    return count;
}

/* An uncertain pair. Sigmas only grow with look-ahead, so the step's end bounds them.
 * Below the cut (the threshold, or the maximum once it is above) an instant cannot change
 * the answer: before the threshold is met it cannot meet it, after, it cannot raise the
 * maximum. */
static void step_uncertain(pair_eval_t *e, uint32_t k, const step_sep_t *st)
{
    const coa_predict_config_t *c = e->pr->config;
    const mover_t *ma = e->ma;
    const mover_t *mb = e->mb;
    const relative_t *r = &st->r;
    double tau1 = (double)((coa_real_t)(k + 1u) * c->dt);
    double sh1 = pair_sigma(ma->sigma_h, ma->rate_h, mb->sigma_h, mb->rate_h, tau1);
    double sv1 = pair_sigma(ma->sigma_v, ma->rate_v, mb->sigma_v, mb->rate_v, tau1);
    double gap_h = (double)real_sqrt(st->h2) - (double)e->near_h;
    double gap_v = (double)st->vmin - (double)e->near_v;
    coa_real_t instants[7];
    size_t count;
    size_t i;
    if (log_probability_bound(gap_h, sh1, gap_v, sv1) + PRUNE_MARGIN < e->log_cut) {
        return;
    }
    count = step_instants(k, st, instants);
    for (i = 0; i < count; ++i) {
        coa_real_t u = instants[i];
        coa_real_t x = r->d0x + u * r->wx;
        coa_real_t y = r->d0y + u * r->wy;
        coa_real_t d = real_norm2(x, y);
        coa_real_t dz = r->d0z + u * r->wz;
        double tau = (double)(((coa_real_t)k + u) * c->dt);
        double sh = pair_sigma(ma->sigma_h, ma->rate_h, mb->sigma_h, mb->rate_h, tau);
        double sv = pair_sigma(ma->sigma_v, ma->rate_v, mb->sigma_v, mb->rate_v, tau);
        double p;
        if (!real_ok(d) || !real_ok(dz) ||
            log_probability_bound((double)d - (double)e->rsum, sh,
                                  (double)real_fabs(dz) - (double)e->hsum, sv) +
                    PRUNE_MARGIN <
                e->log_cut) {
            continue;
        }
        p = coa_conflict_probability(d, dz, e->rsum, e->hsum, (coa_real_t)sh, (coa_real_t)sv);
        if (p > e->pmax) {
            e->pmax = p;
        }
        if (e->first == NONE && p >= c->threshold) {
            e->first = k;
        }
        if (p > c->threshold && p == e->pmax) {
            e->log_cut = log(e->pmax);
        }
    }
}

static bool evaluate_movers(const coa_predictor_t *pr, uint32_t a, uint32_t b, coa_conflict_t *out)
{
    const coa_predict_config_t *c = pr->config;
    const mover_t *ma = &pr->mover[a];
    const mover_t *mb = &pr->mover[b];
    pair_eval_t e;
    coa_real_t best_h2 = (coa_real_t)INFINITY;
    coa_real_t best_v = (coa_real_t)INFINITY;
    bool uncertain = ma->sigma_h != (coa_real_t)0 || ma->rate_h != (coa_real_t)0 ||
                     ma->sigma_v != (coa_real_t)0 || ma->rate_v != (coa_real_t)0 ||
                     mb->sigma_h != (coa_real_t)0 || mb->rate_h != (coa_real_t)0 ||
                     mb->sigma_v != (coa_real_t)0 || mb->rate_v != (coa_real_t)0;
    uint32_t k;

    e.pr = pr;
    e.ma = ma;
    e.mb = mb;
    e.pa = &pr->pos[(size_t)a * pr->stride];
    e.pb = &pr->pos[(size_t)b * pr->stride];
    e.rsum = ma->volume.radius + mb->volume.radius;
    e.hsum = ma->volume.half_height + mb->volume.half_height;
    e.near_h = e.rsum + pr->slack;
    e.near_v = e.hsum + pr->slack;
    e.first = NONE;
    e.pmax = 0.0;
    e.log_cut = pr->log_threshold;
    for (k = 0; k < c->horizon; ++k) {
        step_sep_t st;
        step_separations(&e, k, &st);
        best_h2 = st.h2 < best_h2 ? st.h2 : best_h2;
        best_v = st.vmin < best_v ? st.vmin : best_v;
        if (!uncertain) {
            step_certain(&e, k, &st);
        } else {
            step_uncertain(&e, k, &st);
        }
    }
    if (e.first == NONE) {
        return false;
    }
    out->first_step = e.first;
    out->first_time = c->t0 + (coa_real_t)e.first * c->dt;
    out->min_horizontal = real_sqrt(best_h2);
    out->min_vertical = best_v;
    out->probability = uncertain ? e.pmax : 1.0;
    return true;
}

/* The part of a coordinate beyond [lo, hi] as alpha + beta u on the piece of the step
 * around u = mid (zero inside). */
static void outside_linear(coa_real_t p, coa_real_t v, coa_real_t lo, coa_real_t hi, coa_real_t mid,
                           coa_real_t *alpha, coa_real_t *beta)
{
    coa_real_t x = p + mid * v;
    if (x < lo) {
        *alpha = lo - p;
        *beta = -v;
    } else if (x > hi) {
        *alpha = p - hi;
        *beta = v;
    } else {
        *alpha = (coa_real_t)0;
        *beta = (coa_real_t)0;
    }
}

/* The least squared horizontal distance from the segment p0-p1 to the box's rectangle:
 * the distance is piecewise quadratic in u, with pieces split where a coordinate crosses
 * an edge's line, each minimised in closed form. */
static coa_real_t rectangle_distance2(const coa_vec3_t *p0, const coa_vec3_t *p1,
                                      const coa_box_t *box)
{
    coa_real_t vx = p1->x - p0->x;
    coa_real_t vy = p1->y - p0->y;
    coa_real_t cut[6];
    coa_real_t best = (coa_real_t)INFINITY;
    size_t n = 0u;
    size_t i;

    cut[n++] = (coa_real_t)0;
    if (vx != (coa_real_t)0) {
        coa_real_t u1 = (box->min.x - p0->x) / vx;
        coa_real_t u2 = (box->max.x - p0->x) / vx;
        if (u1 > (coa_real_t)0 && u1 < (coa_real_t)1) {
            cut[n++] = u1;
        }
        if (u2 > (coa_real_t)0 && u2 < (coa_real_t)1) {
            cut[n++] = u2;
        }
    }
    if (vy != (coa_real_t)0) {
        coa_real_t u1 = (box->min.y - p0->y) / vy;
        coa_real_t u2 = (box->max.y - p0->y) / vy;
        if (u1 > (coa_real_t)0 && u1 < (coa_real_t)1) {
            cut[n++] = u1;
        }
        if (u2 > (coa_real_t)0 && u2 < (coa_real_t)1) {
            cut[n++] = u2;
        }
    }
    cut[n++] = (coa_real_t)1;
    for (i = 2; i + 1u < n; ++i) { /* sort the inner cuts (at most four) */
        size_t j = i;
        coa_real_t v = cut[i];
        while (j > 1u && cut[j - 1u] > v) {
            cut[j] = cut[j - 1u];
            --j;
        }
        cut[j] = v;
    }
    for (i = 0; i + 1u < n; ++i) {
        coa_real_t lo = cut[i];
        coa_real_t hi = cut[i + 1u];
        coa_real_t ax;
        coa_real_t bx;
        coa_real_t ay;
        coa_real_t by;
        coa_real_t den;
        coa_real_t u = lo;
        coa_real_t ex;
        coa_real_t ey;
        coa_real_t q;

        outside_linear(p0->x, vx, box->min.x, box->max.x, (lo + hi) / (coa_real_t)2, &ax, &bx);
        outside_linear(p0->y, vy, box->min.y, box->max.y, (lo + hi) / (coa_real_t)2, &ay, &by);
        den = bx * bx + by * by;
        if (den > (coa_real_t)0) {
            u = -(ax * bx + ay * by) / den;
            u = u < lo ? lo : (u > hi ? hi : u);
        }
        ex = ax + u * bx;
        ey = ay + u * by;
        q = ex * ex + ey * ey;
        best = q < best ? q : best;
    }
    return best;
}

/* The least vertical distance from z0 -> z1 to [lo, hi]. */
static coa_real_t slab_distance(coa_real_t z0, coa_real_t z1, coa_real_t lo, coa_real_t hi)
{
    coa_real_t zmin = z0 < z1 ? z0 : z1;
    coa_real_t zmax = z0 < z1 ? z1 : z0;
    if (zmax < lo) {
        return lo - zmax;
    }
    if (zmin > hi) {
        return zmin - hi;
    }
    return (coa_real_t)0;
}

static bool evaluate_obstacle(const coa_predictor_t *pr, uint32_t a, uint32_t o,
                              coa_conflict_t *out)
{
    const coa_predict_config_t *c = pr->config;
    const coa_obstacle_t *obs = &pr->obstacles[o];
    const mover_t *ma = &pr->mover[a];
    const coa_vec3_t *pa = &pr->pos[(size_t)a * pr->stride];
    coa_box_t ob = coa_obstacle_bounds(obs);
    uint32_t first = NONE;
    uint32_t k;

    for (k = 0; k < c->horizon && first == NONE; ++k) {
        coa_sweep_t s;
        coa_box_t sb;
        s.volume = ma->volume;
        s.p0 = pa[k];
        s.p1 = pa[k + 1u];
        sb = box_widened(coa_sweep_bounds(&s), pr->slack);
        /* An error of the polytope test (a scene no floating-point frame holds) counts
         * as a conflict, as in the planner: the safe side. */
        if (coa_boxes_touch(&sb, &ob) && coa_conflict_obstacle(&s, obs) != 0) {
            first = k;
        }
    }
    if (first == NONE) {
        return false;
    }
    out->first_step = first;
    out->first_time = c->t0 + (coa_real_t)first * c->dt;
    out->probability = 1.0;
    out->min_horizontal = (coa_real_t)0;
    out->min_vertical = (coa_real_t)0;
    if (obs->kind == COA_OBSTACLE_BOX) {
        coa_real_t best_h2 = (coa_real_t)INFINITY;
        coa_real_t best_v = (coa_real_t)INFINITY;
        for (k = 0; k < c->horizon; ++k) {
            coa_real_t h2 = rectangle_distance2(&pa[k], &pa[k + 1u], &obs->box);
            coa_real_t v = slab_distance(pa[k].z, pa[k + 1u].z, obs->box.min.z, obs->box.max.z);
            best_h2 = h2 < best_h2 ? h2 : best_h2;
            best_v = v < best_v ? v : best_v;
        }
        out->min_horizontal = real_sqrt(best_h2);
        out->min_vertical = best_v;
    }
    return true;
}

/* Evaluates one candidate and, when it is a conflict, counts it and writes it if there is
 * room: candidates arrive in the output order, so the array holds the first ones. */
static void emit(const coa_predictor_t *pr, uint64_t key, coa_conflict_t *conflicts,
                 size_t capacity, coa_predict_result_t *result)
{
    coa_conflict_t c;
    uint32_t kind = (uint32_t)(key >> KIND_SHIFT);
    uint32_t a = (uint32_t)((key >> A_SHIFT) & A_MASK);
    uint32_t b = (uint32_t)(key & UINT32_MAX);
    bool hit;

    c.a = a;
    c.b = b;
    if (kind == 0u) {
        c.kind = COA_CONFLICT_VEHICLE;
        hit = evaluate_movers(pr, a, b, &c);
    } else if (kind == 1u) {
        c.kind = COA_CONFLICT_TRACK;
        hit = evaluate_movers(pr, a, (uint32_t)(pr->n + b), &c);
    } else {
        c.kind = COA_CONFLICT_OBSTACLE;
        hit = evaluate_obstacle(pr, a, b, &c);
    }
    result->pair_tests += 1u;
    if (!hit) {
        return;
    }
    if (result->conflict_count < capacity) {
        conflicts[result->conflict_count] = c;
        result->conflict_count += 1u;
    }
    result->conflicts_found += 1u;
}

/* ------------------------------------------------------------------------------------ */
/* The cycle                                                                             */

static int check_inputs(const coa_predictor_t *pr, const coa_predict_config_t *config,
                        const coa_intent_plan_t *plans, size_t plan_count,
                        const coa_obstacle_t *obstacles, size_t obstacle_count,
                        const coa_track_t *tracks, size_t track_count,
                        const coa_conflict_t *conflicts, size_t capacity)
{
    size_t i;

    if (plan_count > pr->max_vehicles || track_count > pr->max_tracks ||
        (plan_count > 0u && plans == NULL) || (track_count > 0u && tracks == NULL) ||
        (obstacle_count > 0u && obstacles == NULL) || obstacle_count > (size_t)UINT32_MAX ||
        (capacity > 0u && conflicts == NULL) || !config_ok(pr, config)) {
        return COA_ERR_ARGUMENT;
    }
    for (i = 0; i < plan_count; ++i) {
        if (!plan_ok(&plans[i])) {
            return COA_ERR_ARGUMENT;
        }
    }
    for (i = 0; i < track_count; ++i) {
        if (coa_track_check(&tracks[i]) != COA_OK) {
            return COA_ERR_ARGUMENT;
        }
    }
    for (i = 0; i < obstacle_count; ++i) {
        if (coa_obstacle_check(&obstacles[i]) != COA_OK) {
            return COA_ERR_ARGUMENT;
        }
    }
    return COA_OK;
}

int coa_predict(coa_predictor_t *predictor, const coa_predict_config_t *config,
                const coa_intent_plan_t *plans, size_t plan_count, const coa_obstacle_t *obstacles,
                size_t obstacle_count, const coa_track_t *tracks, size_t track_count,
                coa_conflict_t *conflicts, size_t capacity, coa_predict_result_t *result)
{
    coa_predictor_t *pr = predictor;
    int rc;

    if (result != NULL) {
        *result = (coa_predict_result_t){0};
    }
    if (pr == NULL || config == NULL || result == NULL) {
        return COA_ERR_ARGUMENT;
    }
    if (pr->magic != PREDICT_MAGIC) {
        return COA_ERR_WORKSPACE;
    }
    rc = check_inputs(pr, config, plans, plan_count, obstacles, obstacle_count, tracks, track_count,
                      conflicts, capacity);
    if (rc != COA_OK) {
        return rc;
    }
    pr->config = config;
    pr->obstacles = obstacles;
    pr->n = plan_count;
    pr->movers = plan_count + track_count;
    pr->stride = (size_t)config->horizon + 1u;
    pr->log_threshold = log(config->threshold);
    rc = align(pr, plans, tracks);
    if (rc != COA_OK) {
        return rc;
    }
    if (config->all_pairs) {
        size_t a;
        size_t b;
        for (a = 0; a < plan_count; ++a) {
            for (b = a + 1u; b < plan_count; ++b) {
                emit(pr, make_key(0u, a, b), conflicts, capacity, result);
            }
        }
        for (a = 0; a < plan_count; ++a) {
            for (b = 0; b < track_count; ++b) {
                emit(pr, make_key(1u, a, b), conflicts, capacity, result);
            }
        }
        for (a = 0; a < plan_count; ++a) {
            for (b = 0; b < obstacle_count; ++b) {
                emit(pr, make_key(2u, a, b), conflicts, capacity, result);
            }
        }
    } else {
        size_t count;
        size_t i;
        rc = broad_phase(pr, obstacle_count, &count);
        if (rc != COA_OK) {
            *result = (coa_predict_result_t){0};
            return rc;
        }
        key_sort(pr->cand, count);
        result->candidate_pairs = count;
        for (i = 0; i < count; ++i) {
            emit(pr, pr->cand[i], conflicts, capacity, result);
        }
    }
    result->overflow = result->conflicts_found > capacity;
    return COA_OK;
}

/* ------------------------------------------------------------------------------------ */
/* Clusters                                                                              */

/* The root of i's set, halving the path on the way. Every parent is at most its child's
 * index (unions link the larger root under the smaller), so roots are each set's
 * smallest index and the labelling pass below can follow parents it has already
 * labelled. */
static uint32_t find_root(uint32_t *parent, uint32_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

int coa_predict_clusters(const coa_conflict_t *conflicts, size_t count, size_t plan_count,
                         uint32_t *cluster, size_t *cluster_count)
{
    size_t i;
    uint32_t labels = 0u;

    if ((count > 0u && conflicts == NULL) || (plan_count > 0u && cluster == NULL) ||
        cluster_count == NULL || plan_count >= (size_t)COA_NO_CLUSTER) {
        return COA_ERR_ARGUMENT;
    }
    for (i = 0; i < count; ++i) {
        const coa_conflict_t *c = &conflicts[i];
        if (c->a >= plan_count || (c->kind == COA_CONFLICT_VEHICLE && c->b >= plan_count) ||
            (c->kind != COA_CONFLICT_VEHICLE && c->kind != COA_CONFLICT_TRACK &&
             c->kind != COA_CONFLICT_OBSTACLE)) {
            return COA_ERR_ARGUMENT;
        }
    }
    for (i = 0; i < plan_count; ++i) {
        cluster[i] = COA_NO_CLUSTER;
    }
    for (i = 0; i < count; ++i) {
        const coa_conflict_t *c = &conflicts[i];
        uint32_t ra;
        uint32_t rb;
        if (cluster[c->a] == COA_NO_CLUSTER) {
            cluster[c->a] = c->a;
        }
        if (c->kind != COA_CONFLICT_VEHICLE) {
            continue;
        }
        if (cluster[c->b] == COA_NO_CLUSTER) {
            cluster[c->b] = c->b;
        }
        ra = find_root(cluster, c->a);
        rb = find_root(cluster, c->b);
        if (ra < rb) {
            cluster[rb] = ra;
        } else {
            cluster[ra] = rb;
        }
    }
    /* Ascending: a root opens the next label; anyone else takes its parent's, which is
     * smaller and so already a label. */
    for (i = 0; i < plan_count; ++i) {
        if (cluster[i] == COA_NO_CLUSTER) {
            continue;
        }
        if (cluster[i] == (uint32_t)i) {
            cluster[i] = labels++;
        } else {
            cluster[i] = cluster[cluster[i]];
        }
    }
    *cluster_count = labels;
    return COA_OK;
}
