/* SPDX-License-Identifier: MIT */
/*
 * test_net.c: the simulation's network (src/sim/net.h) with stand-in receivers that log
 * what reaches them and when: without loss or delay every message reaches every node at
 * once in the order sent; a node hears its own at once even when it hears nobody else;
 * one seed gives one run and another seed other deliveries; a delay holds a copy until
 * its time; the counts add up; a full queue is an error, not a loss; and a node cut after
 * M messages gets exactly those M out, whatever is in flight.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <lcm/lcm.h>

#include "coavoid/coavoid.h"
#include "net.h"
#include "test_support.h"

#define NODES 4u
#define LOG_MAX 4096u

typedef struct {
    uint32_t receiver, sender, id;
    int64_t at;
} arrival_t;

typedef struct {
    coavoid_sim_net_t *net;
    int64_t now;
    arrival_t log[LOG_MAX];
    size_t count;
} world_t;

typedef struct {
    world_t *w;
    uint32_t index;
} ear_t;

static void on_message(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    (void)channel;
    const ear_t *ear = user;
    world_t *w = ear->w;
    REQUIRE(rbuf->data_size == 8u && w->count < LOG_MAX);
    uint32_t v[2];
    memcpy(v, rbuf->data, sizeof v);
    w->log[w->count++] = (arrival_t){ear->index, v[0], v[1], w->now};
}

/* A network of NODES receiving nodes, each listening on its rx, with c's settings. */
static void open_world(world_t *w, ear_t *ears, const coavoid_sim_net_config_t *c)
{
    memset(w, 0, sizeof *w);
    bool receives[NODES] = {true, true, true, true};
    int error = COA_OK;
    w->net = coavoid_sim_net_create(c, NODES, receives, &error);
    ck_assert_ptr_nonnull(w->net);
    for (uint32_t i = 0; i < NODES; i++) {
        ears[i] = (ear_t){w, i};
        ck_assert_ptr_nonnull(
            lcm_subscribe(coavoid_sim_net_rx(w->net, i), "TEST", on_message, &ears[i]));
    }
}

static int send_at(world_t *w, uint32_t sender, uint32_t id, int64_t now)
{
    uint32_t v[2] = {sender, id};
    ck_assert_int_eq(lcm_publish(coavoid_sim_net_tx(w->net, sender), "TEST", v, sizeof v), 0);
    w->now = now;
    return coavoid_sim_net_pump(w->net, now);
}

/* Runs every copy still in flight to its time. */
static void finish(world_t *w)
{
    while (coavoid_sim_net_next(w->net) != INT64_MAX) {
        w->now = coavoid_sim_net_next(w->net);
        ck_assert_int_eq(coavoid_sim_net_pump(w->net, w->now), COA_OK);
    }
}

static coavoid_sim_net_config_t settings(double loss, int64_t delay, int64_t jitter, uint64_t seed)
{
    coavoid_sim_net_config_t c;
    memset(&c, 0, sizeof c);
    c.loss = loss;
    c.delay_us = delay;
    c.jitter_us = jitter;
    c.seed = seed;
    c.message_capacity = delay > 0 || jitter > 0 ? 64u : 0u;
    c.copy_capacity = delay > 0 || jitter > 0 ? 256u : 0u;
    return c;
}

START_TEST(test_quiet_network_is_one_bus)
{
    world_t *w = malloc(sizeof *w);
    ear_t ears[NODES];
    coavoid_sim_net_config_t c = settings(0.0, 0, 0, 7u);
    open_world(w, ears, &c);
    for (uint32_t id = 0; id < 10u; id++) {
        ck_assert_int_eq(send_at(w, id % NODES, id, 100 * (int64_t)id), COA_OK);
        /* At once, to every node, the sender too. */
        ck_assert_uint_eq(w->count, (size_t)(id + 1u) * NODES);
    }
    for (size_t k = 0; k < w->count; k++) {
        ck_assert_uint_eq(w->log[k].id, k / NODES);
        ck_assert_int_eq(w->log[k].at, 100 * (int64_t)(k / NODES));
    }
    coavoid_sim_net_stats_t st = coavoid_sim_net_stats(w->net);
    ck_assert_uint_eq(st.sent, 10u);
    ck_assert_uint_eq(st.delivered, 10u * (NODES - 1u));
    ck_assert_uint_eq(st.dropped + st.in_flight, 0u);
    coavoid_sim_net_destroy(w->net);
    free(w);
}
END_TEST

START_TEST(test_deaf_receiver_hears_only_itself)
{
    world_t *w = malloc(sizeof *w);
    ear_t ears[NODES];
    coavoid_sim_net_config_t c = settings(0.0, 0, 0, 7u);
    open_world(w, ears, &c);
    coavoid_sim_net_set_loss(w->net, 2u, 1.0);
    for (uint32_t id = 0; id < 40u; id++) {
        ck_assert_int_eq(send_at(w, id % NODES, id, id), COA_OK);
    }
    size_t own = 0, heard[NODES] = {0};
    for (size_t k = 0; k < w->count; k++) {
        heard[w->log[k].receiver]++;
        if (w->log[k].receiver == 2u) {
            ck_assert_uint_eq(w->log[k].sender, 2u);
            own++;
        }
    }
    ck_assert_uint_eq(own, 10u);
    ck_assert_uint_eq(heard[0], 40u);
    ck_assert_uint_eq(heard[1], 40u);
    ck_assert_uint_eq(heard[3], 40u);
    coavoid_sim_net_stats_t st = coavoid_sim_net_stats(w->net);
    ck_assert_uint_eq(st.dropped, 30u);
    coavoid_sim_net_destroy(w->net);
    free(w);
}
END_TEST

/* 200 messages through a lossy, jittery network with seed; the log into *w. */
static void lossy_run(world_t *w, ear_t *ears, uint64_t seed)
{
    coavoid_sim_net_config_t c = settings(0.3, 50, 400, seed);
    open_world(w, ears, &c);
    for (uint32_t id = 0; id < 200u; id++) {
        int64_t t = 100 * (int64_t)id;
        while (coavoid_sim_net_next(w->net) <= t) {
            w->now = coavoid_sim_net_next(w->net);
            ck_assert_int_eq(coavoid_sim_net_pump(w->net, w->now), COA_OK);
        }
        ck_assert_int_eq(send_at(w, id % NODES, id, t), COA_OK);
    }
    finish(w);
    coavoid_sim_net_stats_t st = coavoid_sim_net_stats(w->net);
    ck_assert_uint_eq(st.sent, 200u);
    ck_assert_uint_eq(st.delivered + st.dropped, 200u * (NODES - 1u));
    ck_assert_uint_eq(st.in_flight, 0u);
    ck_assert_uint_eq(w->count, st.delivered + 200u);
    /* About 30 % lost (600 copies: 3 sigma is about 34). */
    ck_assert(st.dropped > 140u && st.dropped < 220u);
    coavoid_sim_net_destroy(w->net);
}

START_TEST(test_one_seed_one_run)
{
    world_t *a = malloc(sizeof *a), *b = malloc(sizeof *b);
    ear_t ears_a[NODES], ears_b[NODES];
    lossy_run(a, ears_a, 42u);
    lossy_run(b, ears_b, 42u);
    ck_assert_uint_eq(a->count, b->count);
    ck_assert(memcmp(a->log, b->log, a->count * sizeof a->log[0]) == 0);
    lossy_run(b, ears_b, 43u);
    ck_assert(a->count != b->count || memcmp(a->log, b->log, a->count * sizeof a->log[0]) != 0);
    /* Every copy within [delay, delay + jitter] of its sending, and in time order. */
    for (size_t k = 0; k < a->count; k++) {
        int64_t late = a->log[k].at - 100 * (int64_t)a->log[k].id;
        if (a->log[k].receiver == a->log[k].sender) {
            ck_assert_int_eq(late, 0);
        } else {
            ck_assert(late >= 50 && late <= 450);
        }
        ck_assert(k == 0 || a->log[k].at >= a->log[k - 1u].at);
    }
    free(a);
    free(b);
}
END_TEST

START_TEST(test_delay_holds_a_copy_until_its_time)
{
    world_t *w = malloc(sizeof *w);
    ear_t ears[NODES];
    coavoid_sim_net_config_t c = settings(0.0, 1000, 0, 1u);
    open_world(w, ears, &c);
    ck_assert_int_eq(send_at(w, 1u, 5u, 10000), COA_OK);
    ck_assert_uint_eq(w->count, 1u); /* its own, at once */
    ck_assert_uint_eq(w->log[0].receiver, 1u);
    ck_assert_int_eq(coavoid_sim_net_next(w->net), 11000);
    w->now = 10999;
    ck_assert_int_eq(coavoid_sim_net_pump(w->net, w->now), COA_OK);
    ck_assert_uint_eq(w->count, 1u);
    ck_assert_uint_eq(coavoid_sim_net_stats(w->net).in_flight, NODES - 1u);
    w->now = 11000;
    ck_assert_int_eq(coavoid_sim_net_pump(w->net, w->now), COA_OK);
    ck_assert_uint_eq(w->count, NODES);
    for (size_t k = 1; k < w->count; k++) {
        ck_assert_int_eq(w->log[k].at, 11000);
        ck_assert_uint_ne(w->log[k].receiver, 1u);
    }
    ck_assert_int_eq(coavoid_sim_net_next(w->net), INT64_MAX);
    coavoid_sim_net_destroy(w->net);
    free(w);
}
END_TEST

START_TEST(test_full_queue_is_an_error)
{
    world_t *w = malloc(sizeof *w);
    ear_t ears[NODES];
    coavoid_sim_net_config_t c = settings(0.0, 1000, 0, 1u);
    c.copy_capacity = NODES - 2u; /* one copy too few for a message */
    open_world(w, ears, &c);
    ck_assert_int_eq(send_at(w, 0u, 1u, 0), COA_ERR_WORKSPACE);
    coavoid_sim_net_destroy(w->net);
    /* A delay without a queue is refused at create. */
    c.copy_capacity = 0u;
    bool receives[NODES] = {true, true, true, true};
    int error = COA_OK;
    ck_assert_ptr_null(coavoid_sim_net_create(&c, NODES, receives, &error));
    ck_assert_int_eq(error, COA_ERR_ARGUMENT);
    free(w);
}
END_TEST

/* Node 1 cut after 2 messages amid others' traffic: its first 2 reach every node (itself
 * too), the rest none; the others go on; copies already in flight still arrive. */
static void cut_run(int64_t delay)
{
    world_t *w = malloc(sizeof *w);
    ear_t ears[NODES];
    coavoid_sim_net_config_t c = settings(0.0, delay, 0, 3u);
    open_world(w, ears, &c);
    ck_assert_int_eq(send_at(w, 1u, 100u, 0), COA_OK); /* before the count starts */
    coavoid_sim_net_stop_after(w->net, 1u, 2u);
    ck_assert(!coavoid_sim_net_cut(w->net, 1u));
    for (uint32_t id = 0; id < 10u; id++) {
        ck_assert_int_eq(send_at(w, id % 2u == 0u ? 1u : 2u, id, 10 * (int64_t)id), COA_OK);
        ck_assert(coavoid_sim_net_cut(w->net, 1u) == (id >= 2u));
    }
    finish(w);
    size_t from1[NODES] = {0}, from2 = 0;
    for (size_t k = 0; k < w->count; k++) {
        if (w->log[k].sender == 1u) {
            ck_assert(w->log[k].id == 100u || w->log[k].id == 0u || w->log[k].id == 2u);
            from1[w->log[k].receiver]++;
        } else {
            from2++;
        }
    }
    for (uint32_t i = 0; i < NODES; i++) {
        ck_assert_uint_eq(from1[i], 3u);
    }
    ck_assert_uint_eq(from2, 5u * NODES);
    coavoid_sim_net_stats_t st = coavoid_sim_net_stats(w->net);
    ck_assert_uint_eq(st.sent, 3u + 5u);
    ck_assert_uint_eq(st.cut, 3u);
    ck_assert_uint_eq(coavoid_sim_net_sent_by(w->net, 1u), 3u);
    ck_assert_uint_eq(coavoid_sim_net_sent_by(w->net, 2u), 5u);
    ck_assert_uint_eq(st.delivered, 8u * (NODES - 1u));
    coavoid_sim_net_destroy(w->net);
    free(w);
}

START_TEST(test_cut_after_m_messages)
{
    cut_run(0);
    cut_run(25); /* 2.5 messages' time: the last ones out are in flight at the cut */
}
END_TEST

START_TEST(test_cut_at_zero_sends_nothing)
{
    world_t *w = malloc(sizeof *w);
    ear_t ears[NODES];
    coavoid_sim_net_config_t c = settings(0.5, 0, 0, 9u);
    open_world(w, ears, &c);
    coavoid_sim_net_stop_after(w->net, 3u, 0u);
    ck_assert(coavoid_sim_net_cut(w->net, 3u));
    for (uint32_t id = 0; id < 20u; id++) {
        ck_assert_int_eq(send_at(w, 3u, id, id), COA_OK);
    }
    ck_assert_uint_eq(w->count, 0u);
    coavoid_sim_net_stats_t st = coavoid_sim_net_stats(w->net);
    ck_assert_uint_eq(st.sent + st.dropped + st.delivered, 0u);
    ck_assert_uint_eq(st.cut, 20u);
    coavoid_sim_net_destroy(w->net);
    free(w);
}
END_TEST

static Suite *net_suite(void)
{
    Suite *s = suite_create("net");
    TCase *tc = tcase_create("net");
    tcase_add_test(tc, test_quiet_network_is_one_bus);
    tcase_add_test(tc, test_deaf_receiver_hears_only_itself);
    tcase_add_test(tc, test_one_seed_one_run);
    tcase_add_test(tc, test_delay_holds_a_copy_until_its_time);
    tcase_add_test(tc, test_full_queue_is_an_error);
    tcase_add_test(tc, test_cut_after_m_messages);
    tcase_add_test(tc, test_cut_at_zero_sends_nothing);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(net_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
