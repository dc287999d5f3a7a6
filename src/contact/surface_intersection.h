/* Whether a triangle surface intersects itself, or surfaces intersect each other, with the
 * exact triangle test (triangle_intersection.h) on the pairs a bounding-volume hierarchy
 * finds. The world asks before it lets self-collision act on a solid that started tangled,
 * and warns of bodies that start through each other (world_contact.c): collision processing
 * keeps an intersection-free surface free, and cannot untangle one. */
#ifndef PIOLA_CONTACT_SURFACE_INTERSECTION_H
#define PIOLA_CONTACT_SURFACE_INTERSECTION_H

#include <stdint.h>

/* 1 when two of the COUNT triangles TRIS (3 vertex indices each into X, 3 numbers per vertex)
 * that share no vertex intersect or touch, or when the exact test cannot decide a pair (both
 * degenerate: a collapsed surface counts as tangled); 0 when none does; -1 out of memory. */
int piola__surface_intersects(const double *x, const int32_t *tris, int32_t count);

/* The same test, only on pairs whose GROUP (one per triangle: the body it belongs to) differs:
 * 1 with the first such pair (triangle indices, the lower first) in PAIR, 0 when none
 * intersects, -1 out of memory. */
int piola__surfaces_cross(const double *x, const int32_t *tris, const int32_t *group, int32_t count,
                          int32_t pair[2]);

#endif
