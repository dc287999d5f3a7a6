/* Exact intersection test of two closed triangles, independent of collision processing.
 *
 * This is the referee for collision processing: tests use it to check that no two triangles
 * of a surface intersect after a step, so it must not share code or tolerances with the code
 * it judges. The world asks it too, outside collision processing, whether a solid that
 * started tangled has untangled (surface_intersection.h). It uses only the signs of orientation
 * determinants (orient3d, and orient2d in a coordinate plane for coplanar pieces), evaluated
 * exactly: a floating-point filter first, and when the value is too close to zero to trust, an
 * exact sum of products in expansion arithmetic (error-free transformations: two_sum and an
 * fma-based two_product). Touching counts as intersecting. */
#ifndef PIOLA_CONTACT_TRIANGLE_INTERSECTION_H
#define PIOLA_CONTACT_TRIANGLE_INTERSECTION_H

/* Sign (-1, 0, 1) of det [b - a, c - a, d - a]: positive when d is on the side of the plane
 * (a, b, c) that the normal (b - a) x (c - a) points to. Exact. */
int piola__orient3d_sign(const double a[3], const double b[3], const double c[3],
                         const double d[3]);

/* 1 when the closed triangles (p0, p1, p2) and (q0, q1, q2) share a point, else 0. When both
 * triangles are degenerate (collinear vertices) the answer is -1: not decided. */
int piola__triangles_intersect(const double *const p[3], const double *const q[3]);

#endif
