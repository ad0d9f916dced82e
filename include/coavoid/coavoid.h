/* SPDX-License-Identifier: MIT */
/*
 * coavoid.h: the whole core API in one include. See each module header for its contract:
 *   common.h     types, limits, status codes
 *   geometry.h   protected volumes, obstacles, exact conflict tests over one step
 *   trajectory.h vehicles, reference sampling, tracks, actions and exact integer costs
 *   plan.h       the allocation-free A* planner: centralised and decoupled
 *   predict.h    collision prediction over the horizon: conflicts, probability, clusters
 *   version.h    COAVOID_VERSION
 */
#ifndef COAVOID_COAVOID_H
#define COAVOID_COAVOID_H

#include "coavoid/common.h"
#include "coavoid/geometry.h"
#include "coavoid/trajectory.h"
#include "coavoid/plan.h"
#include "coavoid/predict.h"
#include "coavoid/version.h"

#endif /* COAVOID_COAVOID_H */
