/* Continuous collision detection for one point-triangle or edge-edge pair over a step.
 *
 * Every vertex moves on a straight line, x(s) = x + s d for s in [0, 1] (s is time divided by
 * the step length). A point can only hit a triangle, and an edge another edge, at an s where
 * the four points are coplanar: where the cubic f(s) = (e1 x e2) . e3 of the three edge
 * vectors vanishes. Solving that cubic in closed form is fragile (cancellation near double
 * roots, leading coefficients that vanish), so instead the interval is cut at the cubic's
 * critical points into pieces on which it is monotone, and each piece with a sign change is
 * bisected. The candidate times are these roots together with the interval ends and the
 * critical points themselves: at a grazing contact f touches zero at a critical point without
 * changing sign. When the four points stay coplanar for the whole step (f vanishes
 * identically, e.g. a point sliding in the plane of a triangle) the contact can happen at any
 * time, so the candidates add the times at which a vertex crosses the line of an edge in that
 * plane. At each candidate time, in order, the pair's true distance is measured; the first
 * one closer than the tolerance is the collision. The tolerance turns "exactly coplanar and
 * inside" into "within eps", so rounding in the root cannot let a crossing slip through. */
#ifndef PIOLA_CONTACT_CCD_H
#define PIOLA_CONTACT_CCD_H

#include "math/mat3.h"

/* A collision found at normalized time s. The relative position of the pair is
 * sum_k w[k] x_k: for a point-triangle pair w = (1, -b0, -b1, -b2) with b the barycentric
 * weights of the closest point; for edges (x0, x1) and (x2, x3), w = (1 - a, a, -(1 - b), -b).
 * normal is a unit vector oriented so that the pair's relative position at the start of the
 * step has a non-negative component along it (or, when that is zero, so that the pair
 * approaches along it: sum_k w[k] d_k . normal <= 0). */
typedef struct piola__ccd_hit {
  double s;
  double w[4];
  piola_vec3 normal;
  double distance; /* m, at s */
} piola__ccd_hit;

/* Candidate times in [0, 1], sorted ascending, for the coplanarity cubic of the edge vectors
 * e_i(s) = u[i] + s du[i]; returns how many (at most 8). */
int piola__coplanarity_times(const vec3 u[3], const vec3 du[3], double times[8]);

/* Point x[0] against triangle (x[1], x[2], x[3]), moving by d[k] over the step. Returns 1 and
 * fills hit when they come closer than eps (m) at some time, else 0. */
int piola__ccd_point_triangle(const vec3 x[4], const vec3 d[4], double eps, piola__ccd_hit *hit);

/* Edge (x[0], x[1]) against edge (x[2], x[3]); as above. */
int piola__ccd_edge_edge(const vec3 x[4], const vec3 d[4], double eps, piola__ccd_hit *hit);

#endif
