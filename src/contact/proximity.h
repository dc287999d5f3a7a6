/* Closest points between a point and a triangle and between two segments.
 *
 * Both the repulsion stage (distances at the start of the step) and continuous collision
 * detection (distances at the candidate times) ask the same two questions, and both must get
 * an answer for every input: zero-area triangles and zero-length edges occur when cloth is
 * crushed, so each routine falls back to lower-dimensional pieces instead of dividing by an
 * area or a length that may be zero. The weights returned sum to one and are in [0, 1]. */
#ifndef PIOLA_CONTACT_PROXIMITY_H
#define PIOLA_CONTACT_PROXIMITY_H

#include "math/mat3.h"

/* Squared distance from p to the closed triangle (a, b, c); bary receives the barycentric
 * weights of the closest point. */
double piola__point_triangle_closest(vec3 p, vec3 a, vec3 b, vec3 c, double bary[3]);

/* Squared distance between the closed segments (p0, p1) and (q0, q1); the closest points are
 * p0 + s (p1 - p0) and q0 + t (q1 - q0). */
double piola__segment_segment_closest(vec3 p0, vec3 p1, vec3 q0, vec3 q1, double *s, double *t);

#endif
