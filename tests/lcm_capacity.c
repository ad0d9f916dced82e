/* SPDX-License-Identifier: MIT */
/*
 * lcm_capacity.c: a receiver that keeps fewer samples than a message carries (built with
 * the Cortex-M4F vehicle's COAVOID_LCM_MAX_SAMPLES, 25: tests/CMakeLists.txt). A longer
 * intent or plan is refused as beyond its capacity, never written past its arrays, and
 * before the sequence rule takes its number; what fits converts as on the host.
 */
#include <check.h>
#include <stdlib.h>

#include "lcm_examples.h"

_Static_assert(COAVOID_LCM_MAX_SAMPLES == 25, "built as the part's receiver");

/* The good intent cut to `samples`: what lies past them is not part of the message. */
static coavoid_intent_t intent_of(int32_t samples)
{
    coavoid_intent_t m = good_intent();
    m.sample_count = samples;
    return m;
}

START_TEST(test_intent_beyond_capacity)
{
    const coavoid_lcm_context_t ctx = ctx_now();
    coavoid_lcm_sender_t entries[4];
    coavoid_lcm_sequence_table_t seq;
    coavoid_lcm_intent_info_t info;
    coa_vehicle_t vehicle;
    coa_intent_plan_t plan;
    coavoid_lcm_intent_arrays_t arrays;
    const char *why = NULL;
    coavoid_lcm_sequence_init(&seq, entries, 4);

    coavoid_intent_t m = intent_of(26);
    ck_assert_int_eq(coavoid_lcm_intent_check(&m, &ctx, &why), COA_OK); /* a valid message */
    ck_assert_int_eq(
        coavoid_lcm_intent_to_core(&m, &ctx, &seq, &info, &vehicle, &plan, &arrays, &why),
        COAVOID_LCM_ERR_CAPACITY);
    ck_assert_str_eq(why, "intent: more samples than this receiver keeps");
    /* Its sequence number was not taken: the same number, cut to 25 samples, converts. */
    m = intent_of(25);
    ck_assert_int_eq(
        coavoid_lcm_intent_to_core(&m, &ctx, &seq, &info, &vehicle, &plan, &arrays, &why), COA_OK);
    ck_assert_uint_eq(plan.count, 25u);
    ck_assert_int_eq(arrays.offsets[24], m.offsets[24]);
    ck_assert(arrays.reference[24].x == (coa_real_t)m.reference[24][0]);
}
END_TEST

/* Row `row` of the good plan over `horizon` steps (offsets past it zero). */
static coavoid_plan_t row_of(int32_t row, int32_t horizon)
{
    coavoid_plan_t m = good_plan_row(row);
    m.horizon = horizon;
    for (int32_t k = horizon + 1; k < COAVOID_PLAN_T_MAX_SAMPLES; k++) {
        m.offsets[k] = 0;
    }
    return m;
}

START_TEST(test_plan_beyond_capacity)
{
    const coavoid_lcm_context_t ctx = ctx_now();
    static coavoid_lcm_plan_slot_t slots[1];
    static int32_t offsets[3 * COAVOID_PLAN_T_MAX_SAMPLES]; /* the caller's room is not the limit */
    coavoid_lcm_plan_rows_t rows;
    coavoid_lcm_plan_info_t info;
    coa_plan_result_t result;
    const coavoid_plan_t *whole = NULL;
    const char *why = NULL;
    coavoid_lcm_plan_rows_init(&rows, slots, 1);

    coavoid_plan_t m = row_of(0, 25);
    ck_assert_int_eq(coavoid_lcm_plan_check(&m, &ctx, &why), COA_OK);
    ck_assert_int_eq(coavoid_lcm_plan_collect(&rows, &m, &ctx, &whole, &info, &result, offsets,
                                              3 * COAVOID_PLAN_T_MAX_SAMPLES, &why),
                     COAVOID_LCM_ERR_CAPACITY);
    ck_assert_str_eq(why, "plan: a longer horizon than this receiver keeps");
    ck_assert(!slots[0].used);
    /* Over 24 steps every row fits, and the plan is whole with each row's offsets. */
    for (int32_t r = 0; r < 3; r++) {
        m = row_of(r, 24);
        ck_assert_int_eq(coavoid_lcm_plan_collect(&rows, &m, &ctx, &whole, &info, &result, offsets,
                                                  3 * COAVOID_PLAN_T_MAX_SAMPLES, &why),
                         COA_OK);
    }
    ck_assert_ptr_nonnull(whole);
    ck_assert_uint_eq(info.horizon, 24u);
    for (int32_t r = 0; r < 3; r++) {
        ck_assert_int_eq(offsets[(size_t)r * 25u + 24u], row_of(r, 24).offsets[24]);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("lcm_capacity");
    TCase *tc = tcase_create("samples");
    tcase_add_test(tc, test_intent_beyond_capacity);
    tcase_add_test(tc, test_plan_beyond_capacity);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
