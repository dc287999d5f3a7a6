/* piola: rigid obstacles as implicit surfaces, and collision processing (paper section 9).
 *
 * An obstacle is a signed distance function (negative inside) with an outward normal and a
 * velocity at any point, moving by a scripted rigid motion. Collision processing projects
 * every node that is inside an obstacle to its surface, takes the normal velocity from the
 * obstacle unless the node already separates, and applies friction:
 *   vT <- max(0, 1 - mu (dvN + dxN / dt) / |vT|) vT
 * with dvN and dxN the changes of normal velocity and position the projection caused. */
#ifndef PIOLA_OBSTACLE_H
#define PIOLA_OBSTACLE_H

#include <stdbool.h>
#include <stdint.h>

#include "piola/export.h"
#include "piola/keyframes.h"
#include "piola/math_types.h"
#include "piola/mesh.h"
#include "piola/rigid_motion.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum piola_obstacle_type {
  PIOLA_OBSTACLE_PLANE = 0, /* point, normal */
  PIOLA_OBSTACLE_SPHERE,    /* center, radius */
  PIOLA_OBSTACLE_BOX,       /* center, half_extents (rotated by the motion's orientation) */
  PIOLA_OBSTACLE_CYLINDER,  /* center, axis, radius, half_length (capped) */
  PIOLA_OBSTACLE_CAPSULE,   /* center, axis, radius, half_length (segment half length) */
  PIOLA_OBSTACLE_TORUS,     /* center, axis, major radius, minor radius */
  PIOLA_OBSTACLE_GEAR,      /* center, axis, radius (tips), tooth count/depth, half_length */
  PIOLA_OBSTACLE_MESH,      /* closed triangle mesh */
  PIOLA_OBSTACLE_TYPE_COUNT
} piola_obstacle_type;

typedef struct piola_obstacle piola_obstacle;

/* Shapes are given at t = 0 in world space and then move by `motion`. */
typedef struct piola_obstacle_def {
  piola_obstacle_type type;
  piola_vec3 center;        /* m: plane: a point on it; others: the centre */
  piola_vec3 axis;          /* unit: plane: its normal; cylinder, capsule, torus, gear: axis.
                               Default (0, 0, 1) */
  double radius;            /* m: sphere, cylinder, capsule; torus: major radius; gear: radius
                               at the tooth tips */
  double minor_radius;      /* m: torus tube radius */
  double half_length;       /* m: cylinder and gear half height, capsule segment half length */
  piola_vec3 half_extents;  /* m: box */
  int tooth_count;          /* gear: number of teeth, 3 to 100000 */
  double tooth_depth;       /* m: gear: radial depth of the teeth, < radius */
  const piola_tri_mesh *mesh; /* mesh obstacle: a closed triangle surface, copied */
  double friction;          /* Coulomb coefficient mu, >= 0. Default 0 */
  piola_rigid_motion_def motion; /* default: at rest */
} piola_obstacle_def;

PIOLA_API piola_obstacle_def piola_default_obstacle_def(void);

/* Validates def (positive sizes, unit axis, closed mesh) and builds the obstacle. */
PIOLA_API piola_status piola_obstacle_create(const piola_obstacle_def *def, piola_obstacle **out);

/* Signed distance (m, negative inside) at world point p and time t (s); the outward unit
 * normal and the obstacle's velocity (m/s) there are written when not NULL. A non-finite p
 * or t gives NaN, and NaN normal and velocity. */
PIOLA_API double piola_obstacle_signed_distance(const piola_obstacle *obstacle, double t,
                                                piola_vec3 p, piola_vec3 *normal,
                                                piola_vec3 *velocity);

PIOLA_API double piola_obstacle_friction(const piola_obstacle *obstacle);
PIOLA_API piola_obstacle_type piola_obstacle_shape_type(const piola_obstacle *obstacle);

/* Where an obstacle is at one time: the point x0 of its shape at t = 0 is at
 * rotation x0 + translation. */
typedef struct piola_obstacle_pose {
  piola_mat3 rotation;
  piola_vec3 translation; /* m */
} piola_obstacle_pose;

/* The pose at time t (s). Many queries at one time (a renderer tracing rays) compute it once
 * and pass it to piola_obstacle_posed_distance. */
PIOLA_API piola_obstacle_pose piola_obstacle_pose_at(const piola_obstacle *obstacle, double t);

/* piola_obstacle_signed_distance (m, negative inside) for the obstacle at pose: the same
 * value and outward unit normal (written when not NULL) as at the pose's time; NaN for a
 * non-finite p. */
PIOLA_API double piola_obstacle_posed_distance(const piola_obstacle *obstacle,
                                               const piola_obstacle_pose *pose, piola_vec3 p,
                                               piola_vec3 *normal);

/* A sphere holding the shape at t = 0: centre (m) and radius (m; INFINITY for a plane).
 * Points outside it at the matching pose are outside the obstacle. */
PIOLA_API void piola_obstacle_bounding_sphere(const piola_obstacle *obstacle, piola_vec3 *center,
                                              double *radius);

PIOLA_API void piola_obstacle_destroy(piola_obstacle *obstacle);

/* Section 9 collision processing for node_count nodes at time t (s) after a position
 * update of length dt (s; with dt <= 0 the dxN / dt friction term is dropped). x (m) and
 * v (m/s) are 3 * node_count and are modified in place. colliding (node_count, may be NULL)
 * is set to 1 for nodes that were projected, else 0; normals (3 * node_count, may be NULL)
 * receives their obstacle normals, for holding the normal velocity fixed in the final
 * solve (entries of other nodes are left alone). Returns the number of colliding nodes, or
 * -1 (with piola_last_error set) when memory for more than 8 obstacle poses cannot be had.
 * A node inside several obstacles is projected out of each in order, sweeping the list up
 * to 4 times; the normal stored is that of its last projection. NULL entries are skipped. */
PIOLA_API int32_t piola_obstacles_collide(piola_obstacle *const *obstacles, int32_t obstacle_count,
                                          double t, double dt, int32_t node_count, double *x,
                                          double *v, uint8_t *colliding, double *normals);

#ifdef __cplusplus
}
#endif

#endif
