/* SPDX-License-Identifier: MIT */
/*
 * test_noheap.c: the planner, the predictor and the vehicle protocol never touch the heap.
 *
 * The link wraps malloc, calloc, realloc and free (-Wl,--wrap=..., see CMakeLists.txt):
 * every call from a statically linked object (the core archive, this file, Check) goes
 * through the __wrap_ functions below. While `armed` is set they record the call and fail
 * it; otherwise they forward to the real allocator, so Check and the setup work normally.
 * The __wrap_/__real_ names are the linker's convention and cannot be avoided.
 */
#include <check.h>
#include <stdlib.h>
#include <string.h>

#include "coavoid/coavoid.h"
#include "coavoid/predict.h"
#ifdef COAVOID_HAVE_PROTOCOL
#include "protocol.h"
#endif

void *__real_malloc(size_t size);
void *__real_calloc(size_t count, size_t size);
void *__real_realloc(void *ptr, size_t size);
void __real_free(void *ptr);
void *__wrap_malloc(size_t size);
void *__wrap_calloc(size_t count, size_t size);
void *__wrap_realloc(void *ptr, size_t size);
void __wrap_free(void *ptr);

static volatile bool armed = false;
static volatile unsigned heap_calls = 0u;

void *__wrap_malloc(size_t size)
{
    if (armed) {
        ++heap_calls;
        return NULL;
    }
    return __real_malloc(size);
}

void *__wrap_calloc(size_t count, size_t size)
{
    if (armed) {
        ++heap_calls;
        return NULL;
    }
    return __real_calloc(count, size);
}

void *__wrap_realloc(void *ptr, size_t size)
{
    if (armed) {
        ++heap_calls;
        return NULL;
    }
    return __real_realloc(ptr, size);
}

void __wrap_free(void *ptr)
{
    if (armed) {
        if (ptr != NULL) {
            ++heap_calls;
        }
        return;
    }
    __real_free(ptr);
}

#define N 16u

static coa_vec3_t V(double x, double y, double z)
{
    coa_vec3_t v;
    v.x = (coa_real_t)x;
    v.y = (coa_real_t)y;
    v.z = (coa_real_t)z;
    return v;
}

/* A crosses B's path while B flies between a thin roof and floor that leave it no room
 * (so the priority order fails and reordering must run); a polytope sits where A's way
 * around would take it and a track passes above. */
START_TEST(planner_makes_no_heap_call)
{
    static coa_vec3_t route_a[2];
    static coa_vec3_t route_b[2];
    static coa_vec3_t hull[8];
    static coa_vec3_t ref[2][N + 1u];
    static coa_vec3_t track_ref[1][N + 1u];
    static const coa_vec3_t *refp[2];
    static const coa_vec3_t *trackp[1];
    static coa_vehicle_t veh[2];
    static coa_obstacle_t obs[3];
    static coa_track_t track;
    static int32_t rows[2 * (N + 1u)];
    static int32_t rows_at_start[2 * (N + 1u)];
    coa_vec3_t b_start;
    coa_problem_t p;
    coa_plan_result_t central;
    coa_plan_result_t decoupled;
    coa_plan_result_t at_start;
    coa_planner_config_t cfg;
    coa_planner_t *pl;
    void *mem;
    size_t bytes;
    size_t i;
    int rc_central;
    int rc_decoupled;
    int rc_at_start;
    int rc_weights;
    uint64_t weights[2];
    int exponent;

    route_a[0] = V(-200, 0, 100);
    route_a[1] = V(200, 0, 100);
    route_b[0] = V(0, -100, 100);
    route_b[1] = V(0, 100, 100);
    for (i = 0; i < 2u; ++i) {
        memset(&veh[i], 0, sizeof veh[i]);
        veh[i].id = (uint16_t)(i + 1u);
        veh[i].priority = (uint32_t)(i + 1u);
        veh[i].cruise_speed = (coa_real_t)(i == 0u ? 20.0 : 10.0);
        veh[i].climb_rate = (coa_real_t)4.0;
        veh[i].steep_factor = 2u;
        veh[i].volume.radius = (coa_real_t)10.0;
        veh[i].volume.half_height = (coa_real_t)5.0;
        veh[i].route = i == 0u ? route_a : route_b;
        veh[i].route_count = 2u;
        veh[i].max_offset = -1;
    }
    obs[0].kind = COA_OBSTACLE_BOX;
    obs[0].box.min = V(-11, -160, 105.5);
    obs[0].box.max = V(11, 160, 106.5);
    obs[1].kind = COA_OBSTACLE_BOX;
    obs[1].box.min = V(-11, -160, 93.5);
    obs[1].box.max = V(11, 160, 94.5);
    for (i = 0; i < 8u; ++i) {
        hull[i] = V(60.0 + 20.0 * (double)(i & 1u), -5.0 + 10.0 * (double)((i >> 1) & 1u),
                    115.0 + 10.0 * (double)((i >> 2) & 1u));
    }
    obs[2].kind = COA_OBSTACLE_POLYTOPE;
    obs[2].polytope.vertices = hull;
    obs[2].polytope.count = 8u;
    memset(&track, 0, sizeof track);
    track.id = 7u;
    track.volume.radius = (coa_real_t)5.0;
    track.volume.half_height = (coa_real_t)3.0;
    track.position = V(-150, 40, 140);
    track.velocity = V(25, 0, -1);

    for (i = 0; i < 2u; ++i) {
        ck_assert_int_eq(coa_reference_sample(&veh[i], (coa_real_t)1.0, N, ref[i]), COA_OK);
        refp[i] = ref[i];
    }
    ck_assert_int_eq(coa_track_sample(&track, (coa_real_t)1.0, N, track_ref[0]), COA_OK);
    trackp[0] = track_ref[0];
    memset(&p, 0, sizeof p);
    p.dt = (coa_real_t)1.0;
    p.horizon = N;
    p.vehicles = veh;
    p.vehicle_count = 2u;
    p.references = refp;
    p.obstacles = obs;
    p.obstacle_count = 3u;
    p.tracks = &track;
    p.track_count = 1u;
    p.track_samples = trackp;

    ck_assert_int_eq(coa_planner_config_of(&p, 2u, 2000u, &cfg), COA_OK);
    bytes = coa_planner_workspace_size(&cfg);
    ck_assert_uint_gt(bytes, 0u);
    mem = malloc(bytes);
    ck_assert_ptr_nonnull(mem);

    heap_calls = 0u;
    armed = true;
    pl = coa_planner_init(mem, bytes, &cfg);
    rc_central = coa_plan_centralised(pl, &p, rows, &central);
    rc_decoupled = coa_plan_decoupled(pl, &p, NULL, 2u, rows, &decoupled);
    rc_weights = coa_deviation_weights(veh, 2u, p.dt, weights, &exponent);
    /* B moved onto A's start: the t = 0 check that ends reordering runs here too. */
    b_start = ref[1][0];
    ref[1][0] = ref[0][0];
    rc_at_start = coa_plan_decoupled(pl, &p, NULL, 100u, rows_at_start, &at_start);
    armed = false;
    ref[1][0] = b_start;

    ck_assert_uint_eq(heap_calls, 0u);
    ck_assert_ptr_nonnull(pl);
    ck_assert_int_eq(rc_central, COA_OK);
    ck_assert_int_eq(central.status, COA_PLAN_SOLVED);
    /* A and B could not go around each other at their own costs: they were merged and
     * searched jointly, so the joint search and its pair tables ran under the wrappers too. */
    ck_assert_uint_eq(central.largest_group, 2u);
    ck_assert_uint_gt(central.nodes_generated, 0u);
    ck_assert_int_eq(rc_decoupled, COA_OK);
    ck_assert_int_eq(decoupled.status, COA_PLAN_SOLVED);
    ck_assert_uint_eq(decoupled.orders_tried, 2u);
    ck_assert_int_eq(rc_weights, COA_OK);
    ck_assert_uint_eq(weights[0], 10u); /* L*dh = 80 = 10 * 2^3 and 40 = 5 * 2^3 */
    ck_assert_uint_eq(weights[1], 5u);
    ck_assert_int_eq(exponent, 3);
    ck_assert_int_eq(rc_at_start, COA_OK);
    ck_assert_int_eq(at_start.status, COA_PLAN_INFEASIBLE);
    ck_assert(at_start.all_orders_covered);
    ck_assert_uint_eq(at_start.orders_tried, 1u);
    ck_assert_int_eq(coa_plan_find_conflict(&p, rows, (const size_t[]){0u, 1u}, 2u, NULL, NULL), 0);
    free(mem);

    /* The wrappers do catch a heap call from the planner's side of the link. */
    armed = true;
    mem = malloc(16u);
    armed = false;
    ck_assert_ptr_null(mem);
    ck_assert_uint_eq(heap_calls, 1u);
}
END_TEST

/* One prediction cycle over everything it can meet: unaligned plans (one a single sample),
 * UAVs and a track with growing sigma, a box and a polytope, a capacity too small for
 * every conflict; then the clusters and the probability alone. Broad phase and all-pairs. */
START_TEST(predictor_makes_no_heap_call)
{
    static coa_vec3_t samples[4][12];
    static coa_vec3_t hull[8];
    static coa_intent_plan_t plans[4];
    static coa_obstacle_t obs[2];
    static coa_track_t track;
    static coa_conflict_t conflicts[2][3];
    static uint32_t cluster[4];
    coa_predict_config_t cfg;
    coa_predict_result_t res[2];
    coa_predictor_t *pr;
    void *mem;
    size_t bytes;
    size_t cluster_count = 0u;
    size_t i;
    size_t j;
    int rc[2];
    int rc_clusters;
    double p;

    for (i = 0; i < 4u; ++i) {
        memset(&plans[i], 0, sizeof plans[i]);
        plans[i].id = (uint16_t)(i + 1u);
        plans[i].volume.radius = (coa_real_t)10.0;
        plans[i].volume.half_height = (coa_real_t)5.0;
        plans[i].t0 = (coa_real_t)(-0.25 * (double)i);
        plans[i].step = (coa_real_t)(i == 2u ? 2.0 : 1.0);
        plans[i].count = i == 3u ? 1u : 12u;
        plans[i].samples = samples[i];
        plans[i].sigma_horizontal = (coa_real_t)(i == 1u ? 2.0 : 0.0);
        for (j = 0; j < 12u; ++j) {
            double t = (double)plans[i].t0 + (double)j * (double)plans[i].step;
            /* 0 and 1 meet head-on; 2 crosses them; 3 hovers where 0 passes. */
            samples[i][j] = i == 0u   ? V(-60.0 + 10.0 * t, 0, 100)
                            : i == 1u ? V(60.0 - 10.0 * t, 5, 100)
                            : i == 2u ? V(0, -40.0 + 8.0 * t, 102)
                                      : V(30, 3, 98);
        }
    }
    obs[0].kind = COA_OBSTACLE_BOX;
    obs[0].box.min = V(-5, -5, 80);
    obs[0].box.max = V(5, 5, 96);
    for (i = 0; i < 8u; ++i) {
        hull[i] = V(40.0 + 10.0 * (double)(i & 1u), -5.0 + 10.0 * (double)((i >> 1) & 1u),
                    90.0 + 20.0 * (double)((i >> 2) & 1u));
    }
    obs[1].kind = COA_OBSTACLE_POLYTOPE;
    obs[1].polytope.vertices = hull;
    obs[1].polytope.count = 8u;
    memset(&track, 0, sizeof track);
    track.id = 7u;
    track.volume.radius = (coa_real_t)15.0;
    track.volume.half_height = (coa_real_t)5.0;
    track.position = V(-20, 40, 100);
    track.velocity = V(2, -6, 0);
    track.sigma_horizontal = (coa_real_t)5.0;
    track.sigma_vertical = (coa_real_t)2.0;
    memset(&cfg, 0, sizeof cfg);
    cfg.dt = (coa_real_t)1.0;
    cfg.horizon = 10u;
    cfg.vehicle_sigma_rate_horizontal = (coa_real_t)0.2;
    cfg.track_sigma_rate_horizontal = (coa_real_t)0.5;
    cfg.threshold = 0.01;

    bytes = coa_predictor_workspace_size(4u, 1u, 10u, 64u);
    ck_assert_uint_gt(bytes, 0u);
    mem = malloc(bytes);
    ck_assert_ptr_nonnull(mem);

    heap_calls = 0u;
    armed = true;
    pr = coa_predictor_init(mem, bytes, 4u, 1u, 10u, 64u);
    for (i = 0; i < 2u; ++i) {
        cfg.all_pairs = i == 1u;
        rc[i] = coa_predict(pr, &cfg, plans, 4u, obs, 2u, &track, 1u, conflicts[i], 3u, &res[i]);
    }
    rc_clusters =
        coa_predict_clusters(conflicts[0], res[0].conflict_count, 4u, cluster, &cluster_count);
    p = coa_conflict_probability((coa_real_t)25.0, (coa_real_t)2.0, (coa_real_t)20.0,
                                 (coa_real_t)10.0, (coa_real_t)5.0, (coa_real_t)1.0);
    armed = false;

    ck_assert_uint_eq(heap_calls, 0u);
    ck_assert_ptr_nonnull(pr);
    for (i = 0; i < 2u; ++i) {
        ck_assert_int_eq(rc[i], COA_OK);
        ck_assert_uint_eq(res[i].conflict_count, 3u);
        ck_assert(res[i].overflow);
        ck_assert_uint_gt(res[i].conflicts_found, 3u);
    }
    ck_assert_uint_eq(res[0].conflicts_found, res[1].conflicts_found);
    ck_assert_int_eq(rc_clusters, COA_OK);
    ck_assert_uint_ge(cluster_count, 1u);
    ck_assert(p > 0.0 && p < 1.0);
    free(mem);
}
END_TEST

#ifdef COAVOID_HAVE_PROTOCOL
/* ---- the vehicle protocol: two signed UAVs head-on, each in memory of its own, their
 * datagrams carried by a queue; the heap is armed from the first init to the last poll. */

#define FLIGHT_UAVS 2u
#define FLIGHT_QUEUE 256u
#define FLIGHT_EPOCH INT64_C(1000000000000000)

typedef struct {
    size_t channel; /* index into flight_channels */
    size_t size;
    uint8_t data[COAVOID_LCM_MAX_DATAGRAM_BYTES];
} flight_datagram_t;

static const char *const flight_channels[] = {COAVOID_CHANNEL_INTENT,    COAVOID_CHANNEL_STATUS,
                                              COAVOID_CHANNEL_PLAN,      COAVOID_CHANNEL_TRACK,
                                              COAVOID_CHANNEL_OBSTACLES, COAVOID_CHANNEL_AGREEMENT,
                                              COAVOID_CHANNEL_CONFLICTS};
static flight_datagram_t flight_queue[FLIGHT_QUEUE];
static size_t flight_head, flight_tail;
static unsigned flight_sent, flight_lost, flight_errors; /* no ck_assert while armed */
static int64_t flight_now;
static coavoid_vehicle_node_t *flight_uav[FLIGHT_UAVS];

/* The link: a copy of each datagram, for every node (the sender's own echo included). */
static int flight_send(void *user, const char *channel, const uint8_t *data, size_t size)
{
    (void)user;
    size_t c = 0;
    while (c < sizeof flight_channels / sizeof flight_channels[0] &&
           strcmp(flight_channels[c], channel) != 0) {
        c++;
    }
    if (c == sizeof flight_channels / sizeof flight_channels[0] ||
        size > sizeof flight_queue[0].data || flight_tail - flight_head == FLIGHT_QUEUE) {
        flight_lost++;
        return COA_ERR_ARGUMENT;
    }
    flight_datagram_t *d = &flight_queue[flight_tail++ % FLIGHT_QUEUE];
    d->channel = c;
    d->size = size;
    memcpy(d->data, data, size);
    flight_sent++;
    return COA_OK;
}

static void flight_deliver(void)
{
    while (flight_head != flight_tail) {
        const flight_datagram_t d = flight_queue[flight_head++ % FLIGHT_QUEUE];
        for (size_t i = 0; i < FLIGHT_UAVS; i++) {
            (void)coavoid_vehicle_node_receive(flight_uav[i], flight_channels[d.channel], d.data,
                                               d.size);
        }
    }
}

/* Cycle k: each starts it, then every poll due before the next cycle, in time order. */
static void flight_cycle(int64_t k)
{
    const int64_t start = FLIGHT_EPOCH + k * INT64_C(1000000);
    flight_now = start;
    for (size_t i = 0; i < FLIGHT_UAVS; i++) {
        flight_errors += coavoid_vehicle_node_cycle(flight_uav[i], start) != COA_OK ? 1u : 0u;
        flight_deliver();
    }
    for (;;) {
        int64_t next = INT64_MAX;
        for (size_t i = 0; i < FLIGHT_UAVS; i++) {
            const int64_t d = coavoid_vehicle_node_deadline(flight_uav[i]);
            next = d < next ? d : next;
        }
        if (next >= start + INT64_C(1000000)) {
            return;
        }
        flight_now = next > flight_now ? next : flight_now;
        for (size_t i = 0; i < FLIGHT_UAVS; i++) {
            flight_errors += coavoid_vehicle_node_poll(flight_uav[i], flight_now) < 0 ? 1u : 0u;
            flight_deliver();
        }
    }
}

static void flight_keys(coavoid_auth_trust_t *trust, coavoid_auth_signer_t signer[FLIGHT_UAVS])
{
    const unsigned char fleet[COAVOID_AUTH_FLEET_KEY_BYTES] = "noheap fleet";
    coavoid_auth_trust_init(trust);
    ck_assert_int_eq(coavoid_auth_trust_set_fleet_key(trust, fleet), COA_OK);
    for (uint16_t i = 0; i < FLIGHT_UAVS; i++) {
        unsigned char seed[COAVOID_AUTH_SEED_BYTES] = {(unsigned char)(i + 1u), 9};
        coavoid_auth_key_t key = {101u + i, COAVOID_AUTH_VEHICLE, (uint16_t)(i + 1u), {0}};
        memset(&signer[i], 0, sizeof signer[i]);
        signer[i].key_id = key.key_id;
        coavoid_auth_signer_use_fleet(&signer[i], trust);
        ck_assert_int_eq(coavoid_auth_keypair_seed(seed, key.public_key, signer[i].secret_key),
                         COA_OK);
        ck_assert_int_eq(coavoid_auth_trust_add(trust, &key), COA_OK);
    }
}

static coavoid_vehicle_node_config_t flight_config(uint16_t id, coa_vec3_t route[2],
                                                   const coavoid_auth_trust_t *trust,
                                                   const coavoid_auth_signer_t *signer)
{
    coavoid_vehicle_node_config_t c;
    memset(&c, 0, sizeof c);
    ck_assert_int_eq(
        coavoid_node_common_defaults(&c.common, FLIGHT_EPOCH, (coa_real_t)1, 12u, &flight_now),
        COA_OK);
    c.common.trust = trust;
    c.common.signer = signer;
    const coa_real_t x0 = id == 1u ? (coa_real_t)0 : (coa_real_t)400;
    route[0].x = x0;
    route[1].x = (coa_real_t)400 - x0;
    route[0].y = route[1].y = (coa_real_t)0;
    route[0].z = route[1].z = (coa_real_t)100;
    c.vehicle.id = id;
    c.vehicle.priority = id;
    c.vehicle.cruise_speed = (coa_real_t)10;
    c.vehicle.climb_rate = (coa_real_t)2;
    c.vehicle.steep_factor = 2u;
    c.vehicle.volume.radius = (coa_real_t)15;
    c.vehicle.volume.half_height = (coa_real_t)5;
    c.vehicle.route = route;
    c.vehicle.route_count = 2u;
    c.vehicle.max_offset = -1;
    c.mode = COAVOID_NODE_DECOUPLED;
    c.intent_copies = COAVOID_NODE_DEFAULT_COPIES;
    return c;
}

START_TEST(vehicle_protocol_makes_no_heap_call)
{
    static coavoid_auth_trust_t trust;
    static coavoid_auth_signer_t signer[FLIGHT_UAVS];
    static coa_vec3_t route[FLIGHT_UAVS][2];
    coavoid_vehicle_node_config_t config[FLIGHT_UAVS];
    void *memory[FLIGHT_UAVS];
    size_t size[FLIGHT_UAVS];
    ck_assert_int_eq(coavoid_auth_init(), COA_OK);
    flight_keys(&trust, signer);
    for (uint16_t i = 0; i < FLIGHT_UAVS; i++) {
        config[i] = flight_config((uint16_t)(i + 1u), route[i], &trust, &signer[i]);
        size[i] = coavoid_vehicle_node_size(&config[i]);
        ck_assert_uint_gt(size[i], 0u);
        memory[i] = malloc(size[i]); /* the caller's memory, before the heap is armed */
        ck_assert_ptr_nonnull(memory[i]);
    }
    const coavoid_node_link_t link = {flight_send, NULL};
    int error[FLIGHT_UAVS] = {-99, -99};
    heap_calls = 0u;
    armed = true;
    for (size_t i = 0; i < FLIGHT_UAVS; i++) {
        flight_uav[i] = coavoid_vehicle_node_init(memory[i], size[i], &config[i], &link, &error[i]);
    }
    for (int64_t k = 0; k < 30 && flight_uav[0] != NULL && flight_uav[1] != NULL; k++) {
        flight_cycle(k);
    }
    armed = false;

    ck_assert_uint_eq(heap_calls, 0u);
    ck_assert_int_eq(error[0], COA_OK);
    ck_assert_int_eq(error[1], COA_OK);
    ck_assert_uint_eq(flight_lost, 0u);
    ck_assert_uint_eq(flight_errors, 0u);
    const coavoid_vehicle_node_state_t *a = coavoid_vehicle_node_state(flight_uav[0]);
    const coavoid_vehicle_node_state_t *b = coavoid_vehicle_node_state(flight_uav[1]);
    /* They heard each other (signed, checked) and one of them climbed out of the way. */
    ck_assert_int_gt(a->rx.received, 0);
    ck_assert_int_eq(a->rx.rejected, 0);
    ck_assert_int_gt(b->rx.received, 0);
    ck_assert_int_eq(b->rx.rejected, 0);
    ck_assert_uint_gt(a->plans_adopted + b->plans_adopted, 0u);
    ck_assert_uint_gt(flight_sent, 60u);
    /* Too small a block is a distinct error, not a node. */
    int small = -99;
    ck_assert_ptr_null(
        coavoid_vehicle_node_init(memory[0], size[0] - 1u, &config[0], &link, &small));
    ck_assert_int_eq(small, COA_ERR_WORKSPACE);
    for (size_t i = 0; i < FLIGHT_UAVS; i++) {
        coavoid_vehicle_node_fini(flight_uav[i]);
        free(memory[i]);
    }
}
END_TEST
#endif /* COAVOID_HAVE_PROTOCOL */

int main(void)
{
    Suite *s = suite_create("noheap");
    TCase *tc = tcase_create("noheap");
    SRunner *sr;
    int failed;

    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, planner_makes_no_heap_call);
    tcase_add_test(tc, predictor_makes_no_heap_call);
#ifdef COAVOID_HAVE_PROTOCOL
    tcase_add_test(tc, vehicle_protocol_makes_no_heap_call);
#endif
    suite_add_tcase(s, tc);
    sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
