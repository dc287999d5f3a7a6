/* Signed distance functions of the analytic primitives shared by the mesher and the
 * obstacles: sphere, box, cylinder, capsule, torus, each in world space given its centre
 * and unit axis. Negative inside. Each also returns the outward unit normal (the gradient
 * of the distance; on the medial set, where it is not defined, any valid unit direction).
 *
 * They are exact Euclidean distances (not bounds), so the mesher can snap boundary nodes
 * with one projection x - d n and collisions can project nodes the same way. */
#ifndef PIOLA_GEOMETRY_ANALYTIC_SHAPES_H
#define PIOLA_GEOMETRY_ANALYTIC_SHAPES_H

#include "math/mat3.h"

/* An orthonormal frame (e1, e2, axis) around a unit axis. */
void piola__shape_frame(vec3 axis, vec3 *e1, vec3 *e2);

double piola__shape_sphere_distance(vec3 p, vec3 center, double radius, vec3 *normal);
double piola__shape_plane_distance(vec3 p, vec3 point, vec3 unit_normal, vec3 *normal);
/* Box aligned with the world axes (rotate p into the box frame first for a rotated box). */
double piola__shape_box_distance(vec3 p, vec3 center, vec3 half_extents, vec3 *normal);
/* Capped cylinder: radius around the axis, |height| <= half_length along it. */
double piola__shape_cylinder_distance(vec3 p, vec3 center, vec3 axis, double radius, double half_length,
                               vec3 *normal);
/* Capsule: points within radius of the segment center +- half_length axis. */
double piola__shape_capsule_distance(vec3 p, vec3 center, vec3 axis, double radius, double half_length,
                              vec3 *normal);
/* Torus: tube of minor_radius around the circle of major_radius in the plane normal to axis. */
double piola__shape_torus_distance(vec3 p, vec3 center, vec3 axis, double major_radius,
                            double minor_radius, vec3 *normal);

#endif
