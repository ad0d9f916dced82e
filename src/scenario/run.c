/* SPDX-License-Identifier: MIT */
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

#include "coavoid/common.h"
#include "run.h"

/* Both runs hand malloc's blocks to the core as workspaces (planner, predictor). */
_Static_assert(_Alignof(max_align_t) >= COA_WORKSPACE_ALIGNMENT,
               "malloc does not align enough for the core's workspaces");

int coavoid_run_fail(coavoid_run_error_t *e, int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(e->text, sizeof e->text, fmt, ap);
    va_end(ap);
    return status;
}
