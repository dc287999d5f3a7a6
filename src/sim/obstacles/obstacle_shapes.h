/* The shapes of rigid obstacles, each in its own file, evaluated in the obstacle's t = 0
 * frame (world space before the rigid motion moves it).
 *
 * Why a tagged union and a switch rather than function pointers: the set of shapes is
 * closed, every shape is small, and the dispatch in src/sim/obstacle.c reads as one table
 * a reader can take in at a glance (the same choice Box2D makes for its joints). Each
 * shape file provides an init that validates the definition and fills its member of the
 * union, a signed distance with outward normal, and (for shapes that own memory) a free.
 *
 * All distances here are exact Euclidean signed distances to the shape as defined (the gear
 * is defined by its polygon outline, the mesh by its triangles), so collision processing
 * needs one projection x - phi n. */
#ifndef PIOLA_SIM_OBSTACLES_OBSTACLE_SHAPES_H
#define PIOLA_SIM_OBSTACLES_OBSTACLE_SHAPES_H

#include <stdbool.h>
#include <stdint.h>

#include "math/mat3.h"
#include "piola/obstacle.h"

typedef struct piola__plane_shape {
  vec3 point, normal;
} piola__plane_shape;

typedef struct piola__sphere_shape {
  vec3 center;
  double radius;
} piola__sphere_shape;

typedef struct piola__box_shape {
  vec3 center, half_extents;
} piola__box_shape;

/* Cylinder and capsule share the parameters. */
typedef struct piola__axial_shape {
  vec3 center, axis;
  double radius, half_length;
} piola__axial_shape;

typedef struct piola__torus_shape {
  vec3 center, axis;
  double major_radius, minor_radius;
} piola__torus_shape;

/* A polygon outline in the plane (e1, e2) through center, extruded +- half_length along
 * axis. outline holds 2 * vertex_count coordinates, counter-clockwise about axis. */
typedef struct piola__gear_shape {
  vec3 center, axis, e1, e2;
  double half_length, tip_radius, root_radius;
  double inner_radius; /* distance from the centre to the nearest outline edge, m */
  int32_t tooth_count;
  int32_t vertex_count;
  double *outline;
} piola__gear_shape;

struct piola__surface_distance;

/* A closed triangle surface (copied into the distance structure, wound outward). */
typedef struct piola__mesh_shape {
  int32_t vertex_count, triangle_count;
  vec3 box_min, box_max;
  struct piola__surface_distance *accel; /* geometry/surface_distance: BVH + winding number */
} piola__mesh_shape;

/* Vertices per tooth of the gear outline (see gear.c for the profile). */
#define PIOLA_GEAR_VERTICES_PER_TOOTH 16

piola_status piola__plane_init(const piola_obstacle_def *def, piola__plane_shape *shape);
double piola__plane_distance(const piola__plane_shape *shape, vec3 p, vec3 *normal);

piola_status piola__sphere_init(const piola_obstacle_def *def, piola__sphere_shape *shape);
double piola__sphere_distance(const piola__sphere_shape *shape, vec3 p, vec3 *normal);

piola_status piola__box_init(const piola_obstacle_def *def, piola__box_shape *shape);
double piola__box_distance(const piola__box_shape *shape, vec3 p, vec3 *normal);

piola_status piola__cylinder_init(const piola_obstacle_def *def, piola__axial_shape *shape);
double piola__cylinder_distance(const piola__axial_shape *shape, vec3 p, vec3 *normal);

piola_status piola__capsule_init(const piola_obstacle_def *def, piola__axial_shape *shape);
double piola__capsule_distance(const piola__axial_shape *shape, vec3 p, vec3 *normal);

piola_status piola__torus_init(const piola_obstacle_def *def, piola__torus_shape *shape);
double piola__torus_distance(const piola__torus_shape *shape, vec3 p, vec3 *normal);

piola_status piola__gear_init(const piola_obstacle_def *def, piola__gear_shape *shape);
double piola__gear_distance(const piola__gear_shape *shape, vec3 p, vec3 *normal);
void piola__gear_free(piola__gear_shape *shape);
/* Radius of the gear profile at polar angle phi (rad) in its own plane, m (for tests and
 * documentation; the outline polygon samples this function). */
double piola__gear_profile_radius(const piola__gear_shape *shape, double phi);

piola_status piola__mesh_obstacle_init(const piola_obstacle_def *def, piola__mesh_shape *shape);
double piola__mesh_obstacle_distance(const piola__mesh_shape *shape, vec3 p, vec3 *normal);
void piola__mesh_obstacle_free(piola__mesh_shape *shape);
/* Whether p is inside by the winding number alone: much cheaper than the distance far from
 * the surface, where the nearest-triangle search cannot prune. */
bool piola__mesh_obstacle_contains(const piola__mesh_shape *shape, vec3 p);

/* Shared validation: the axis normalized if its length is within 1e-3 of 1, else an error
 * naming `what`. */
piola_status piola__obstacle_unit_axis(vec3 axis, const char *what, vec3 *out);
/* A finite, strictly positive length, else an error naming `what`. */
piola_status piola__obstacle_positive(double value, const char *what);

#endif
