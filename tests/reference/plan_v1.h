/* SPDX-License-Identifier: MIT */
/*
 * plan_v1.h: a composite A* over every UAV's joint state, kept as a test-only reference
 * (plan_v1.c). The entry points of plan.h (coa_planner_workspace_size, coa_planner_init,
 * coa_plan_centralised, coa_plan_decoupled) for an exact search without tables or a work
 * budget: the workspace holds 1 + beta * 5^max_vehicles nodes, beta bounds the states
 * each search closes.
 */
#ifndef COAVOID_TESTS_PLAN_V1_H
#define COAVOID_TESTS_PLAN_V1_H

#include "coavoid/plan.h"

typedef struct ref_planner ref_planner_t;

size_t ref_planner_workspace_size(size_t max_vehicles, uint32_t beta);
ref_planner_t *ref_planner_init(void *buffer, size_t size, size_t max_vehicles, uint32_t beta);
int ref_plan_centralised(ref_planner_t *planner, const coa_problem_t *problem, int32_t *offsets,
                         coa_plan_result_t *result);
int ref_plan_decoupled(ref_planner_t *planner, const coa_problem_t *problem, const size_t *order,
                       uint32_t max_orders, int32_t *offsets, coa_plan_result_t *result);

#endif /* COAVOID_TESTS_PLAN_V1_H */
