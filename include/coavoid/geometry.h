/* SPDX-License-Identifier: MIT */
/*
 * geometry.h: protected volumes, obstacles and exact continuous-time conflict tests.
 *
 * The big picture. Every moving thing (a UAV or a non-cooperative track) is known at the
 * samples t_k = k*dt and moves in a straight line between consecutive samples. A UAV is
 * protected by a vertical cylinder (radius r, half-height h) centred on it. Over one step
 * [t_k, t_k+1] a moving volume is therefore described by a coa_sweep_t: its volume and
 * its centre at the start (p0) and at the end (p1) of the step.
 *
 * A conflict is an instant in the closed step where:
 *   - two volumes overlap: horizontal distance < r_a + r_b while vertical distance
 *     < h_a + h_b (strict: touching is not a conflict), or
 *   - a volume overlaps an obstacle: a closed axis-aligned box or the convex hull of a
 *     set of points (again strict for boxes).
 *
 * Volume against volume and volume against box are solved in closed form: each condition
 * is an open interval of the step parameter u in [0, 1] and a conflict is a non-empty
 * intersection. Volume against polytope uses libccd's allocation-free MPR test on the
 * swept volume (the Minkowski sum of the cylinder and the segment p0-p1, which is convex);
 * this is exact up to MPR's tolerance (1e-9 relative to the scene), so touching contact
 * with a polytope may be reported either way.
 *
 * Preconditions shared by every test: every coordinate finite; radius and half_height
 * finite and > 0; box min <= max on every axis. The volume tests cannot fail and return
 * bool; the polytope test checks its input and returns a status.
 */
#ifndef COAVOID_GEOMETRY_H
#define COAVOID_GEOMETRY_H

#include "coavoid/common.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A protected volume: a vertical cylinder centred on the vehicle. */
typedef struct {
    coa_real_t radius;      /* m, > 0 */
    coa_real_t half_height; /* m, > 0 */
} coa_volume_t;

/* A volume moving linearly over one step: centre p0 at the step's start, p1 at its end. */
typedef struct {
    coa_volume_t volume;
    coa_vec3_t p0;
    coa_vec3_t p1;
} coa_sweep_t;

/* A closed axis-aligned box, min <= max on every axis (a zero thickness is allowed). */
typedef struct {
    coa_vec3_t min;
    coa_vec3_t max;
} coa_box_t;

/* The convex hull of `count` >= 4 points; the points are the caller's and must outlive
 * every call that uses the polytope. */
typedef struct {
    const coa_vec3_t *vertices;
    size_t count;
} coa_polytope_t;

#define COA_POLYTOPE_MAX_VERTICES 256u /* bounds the cost of one support evaluation */

typedef enum { COA_OBSTACLE_BOX = 0, COA_OBSTACLE_POLYTOPE = 1 } coa_obstacle_kind_t;

/* A static obstacle: `box` is used when kind is COA_OBSTACLE_BOX, `polytope` otherwise. */
typedef struct {
    coa_obstacle_kind_t kind;
    coa_box_t box;
    coa_polytope_t polytope;
} coa_obstacle_t;

/* Conflict between two moving volumes over one step (closed form).
 * Returns true when some u in [0,1] has both volumes overlapping (strictly).
 * Cost O(1), no memory. Preconditions as in the file comment. */
bool coa_conflict_volumes(const coa_sweep_t *a, const coa_sweep_t *b);

/* Whether two moving volumes' horizontal discs come within r_a + r_b of each other
 * (strictly) at some instant of the step, whatever their altitudes: the horizontal half of
 * coa_conflict_volumes, by the same arithmetic, so that coa_conflict_volumes(a, b) implies
 * it. A planner uses it to know where two vehicles can meet at all. Cost O(1), no memory. */
bool coa_conflict_horizontal(const coa_sweep_t *a, const coa_sweep_t *b);

/* Conflict between a moving volume and a static box over one step (closed form).
 * Returns true when some u in [0,1] has the volume overlapping the box (strictly).
 * Cost O(1), no memory. */
bool coa_conflict_box(const coa_sweep_t *a, const coa_box_t *box);

/* Conflict between a moving volume and a static convex polytope over one step, by
 * libccd's MPR on the swept volume. Returns 1 (conflict), 0 (none), or
 * COA_ERR_ARGUMENT when a pointer is NULL, count < 4 or > COA_POLYTOPE_MAX_VERTICES,
 * or any number is not finite (MPR can spin on non-finite input, so it is never called
 * with one), radius or half_height is not > 0, or the scene's size is below about 1e-300
 * of its largest coordinate (no floating-point frame holds both; MPR runs on the scene
 * moved to the sweep's midpoint and scaled to unit size). MPR's refinement is bounded:
 * after COA_MPR_MAX_SUPPORT_CALLS support evaluations the test stops and answers 1
 * (conflict), the safe side.
 * Cost O(COA_MPR_MAX_SUPPORT_CALLS * count), no heap, O(1) stack. */
#define COA_MPR_MAX_SUPPORT_CALLS 128u
int coa_conflict_polytope(const coa_sweep_t *a, const coa_polytope_t *poly);

/* Checks an obstacle: a known kind; a box with finite corners and min <= max on every
 * axis; a polytope with non-NULL vertices, 4..COA_POLYTOPE_MAX_VERTICES of them, all
 * finite. Returns COA_OK or COA_ERR_ARGUMENT. Cost O(count), no memory. */
int coa_obstacle_check(const coa_obstacle_t *obstacle);

/* Dispatch on the obstacle kind. Returns 1, 0, or COA_ERR_ARGUMENT (NULL, unknown kind,
 * or the polytope test's errors). Cost as the test it dispatches to. */
int coa_conflict_obstacle(const coa_sweep_t *a, const coa_obstacle_t *obstacle);

/* The axis-aligned bounding box of everything a sweep covers over its step (for broad
 * phases and cheap rejection). Cost O(1); cannot fail. */
coa_box_t coa_sweep_bounds(const coa_sweep_t *a);

/* The axis-aligned box of an obstacle: the box itself, or the box of a polytope's
 * vertices. Precondition: coa_obstacle_check(o) == COA_OK. Cost O(1) for a box,
 * O(vertices) for a polytope; cannot fail. */
coa_box_t coa_obstacle_bounds(const coa_obstacle_t *o);

/* Whether two closed boxes share any point (touching counts: a broad phase must never
 * reject a pair the exact test would accept). Cost O(1). */
bool coa_boxes_touch(const coa_box_t *a, const coa_box_t *b);

#ifdef __cplusplus
}
#endif

#endif /* COAVOID_GEOMETRY_H */
