/* SPDX-License-Identifier: MIT */
/* A downstream user of the installed core: plans a head-on encounter of two UAVs in a
 * statically allocated workspace and exits 0 only when it is solved conflict-free. */
#include <coavoid/coavoid.h>
#include <stdio.h>

#define HORIZON 12u
#define BETA 2000u

static _Alignas(8) unsigned char workspace[8u * 1024u * 1024u];

int main(void)
{
    static const coa_vec3_t route_a[2] = {{0, 0, 100}, {1000, 0, 100}};
    static const coa_vec3_t route_b[2] = {{240, 0, 100}, {-760, 0, 100}};
    const coa_vehicle_t vehicles[2] = {
        {1, 1, 10.0, 2.0, 2, {15.0, 5.0}, route_a, 2, 0, -1},
        {2, 2, 10.0, 2.0, 2, {15.0, 5.0}, route_b, 2, 0, -1},
    };
    static coa_vec3_t ref_a[HORIZON + 1], ref_b[HORIZON + 1];
    const coa_vec3_t *const refs[2] = {ref_a, ref_b};
    static int32_t offsets[2 * (HORIZON + 1)];
    coa_plan_result_t result;

    if (coa_reference_sample(&vehicles[0], 1.0, HORIZON, ref_a) != COA_OK ||
        coa_reference_sample(&vehicles[1], 1.0, HORIZON, ref_b) != COA_OK) {
        return 1;
    }
    const coa_problem_t problem = {1.0, HORIZON, vehicles, 2,    refs,  NULL,
                                   0,   NULL,    0,        NULL, false, 0.0};
    coa_planner_config_t config;
    if (coa_planner_config_of(&problem, 2, BETA, &config) != COA_OK) {
        return 1;
    }
    const size_t need = coa_planner_workspace_size(&config);
    if (need == 0 || need > sizeof workspace) {
        fprintf(stderr, "workspace: need %zu bytes\n", need);
        return 1;
    }
    coa_planner_t *planner = coa_planner_init(workspace, need, &config);
    if (planner == NULL) {
        return 1;
    }
    const int rc = coa_plan_centralised(planner, &problem, offsets, &result);
    if (rc != COA_OK || result.status != COA_PLAN_SOLVED) {
        fprintf(stderr, "plan: rc %d (%s) status %d\n", rc, coa_status_name(rc),
                (int)result.status);
        return 1;
    }
    const size_t all[2] = {0, 1};
    if (coa_plan_find_conflict(&problem, offsets, all, 2, NULL, NULL) != 0) {
        return 1;
    }
    printf("consumer: solved, deviation %.3f m^2, effort %u\n", result.deviation,
           (unsigned)result.effort);
    return 0;
}
