/* SPDX-License-Identifier: MIT */
#include "coavoid/common.h"

const char *coa_status_name(int status)
{
    switch (status) {
    case COA_OK:
        return "ok";
    case COA_ERR_ARGUMENT:
        return "invalid argument";
    case COA_ERR_WORKSPACE:
        return "workspace too small or not built for this problem";
    case COA_ERR_RANGE:
        return "problem too large for the integer cost or offset range";
    default:
        return "unknown status";
    }
}
