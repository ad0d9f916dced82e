/* SPDX-License-Identifier: MIT */
/* The programs' shared sizing policy for planners (scenario.h, "sizing"). */
#include "scenario.h"

coa_planner_config_t coavoid_scenario_planner_config(const coavoid_scenario_t *s, size_t searched,
                                                     uint32_t beta)
{
    coa_planner_config_t config;
    coa_problem_t problem = coavoid_scenario_problem(s);
    /* It fills config whatever beta is. One beyond the planner's limits (a beta from the
     * command line or the scenario, up to 2^32 - 1) is refused by config_ok, and has no
     * workspace size: the callers report that as too large, a usage error. */
    (void)coa_planner_config_of(&problem, searched, beta, &config);
    return config;
}

void coavoid_planner_config_widen(coa_planner_config_t *into, const coa_planner_config_t *with)
{
    if (with->horizon > into->horizon) {
        into->horizon = with->horizon;
    }
    if (with->steep_factor > into->steep_factor) {
        into->steep_factor = with->steep_factor;
    }
    if (into->max_offset >= 0 && (with->max_offset < 0 || with->max_offset > into->max_offset)) {
        into->max_offset = with->max_offset;
    }
}

bool coavoid_workspace_fits(const coa_planner_config_t *config)
{
    size_t size = coa_planner_workspace_size(config);
    return size != 0u && size <= COAVOID_DEFAULT_WORKSPACE_MAX;
}

uint32_t coavoid_default_beta(const coa_planner_config_t *config)
{
    uint32_t fits = coa_planner_max_beta(config, COAVOID_DEFAULT_WORKSPACE_MAX);
    return fits < COAVOID_DEFAULT_BETA ? fits : COAVOID_DEFAULT_BETA;
}
