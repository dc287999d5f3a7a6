/* Internal layout of an obstacle and the posed distance query used by collision processing.
 *
 * An obstacle is a shape fixed in its t = 0 frame plus a rigid motion. A query at time t
 * maps the world point back into the t = 0 frame with the inverse pose, evaluates the shape
 * there and rotates the normal forward. Collision processing asks thousands of nodes at the
 * same t, so the pose is computed once (piola__rigid_state) and passed in. */
#ifndef PIOLA_SIM_OBSTACLE_INTERNAL_H
#define PIOLA_SIM_OBSTACLE_INTERNAL_H

#include "piola/obstacle.h"
#include "sim/obstacles/obstacle_shapes.h"
#include "sim/rigid_motion_internal.h"

struct piola_obstacle {
  piola_obstacle_type type;
  double friction;
  piola_rigid_motion_def motion;
  /* A sphere holding the shape in its t = 0 frame (radius INFINITY for the plane): nodes
   * outside it are not inside, which collision processing checks before the distance. */
  vec3 bound_center;
  double bound_radius;
  union {
    piola__plane_shape plane;
    piola__sphere_shape sphere;
    piola__box_shape box;
    piola__axial_shape cylinder;
    piola__axial_shape capsule;
    piola__torus_shape torus;
    piola__gear_shape gear;
    piola__mesh_shape mesh;
  } shape;
};

/* Signed distance (m) at world point p for the obstacle posed by state; normal and velocity
 * (may be NULL) as in piola_obstacle_signed_distance. */
double piola__obstacle_distance_posed(const piola_obstacle *obstacle,
                                      const piola__rigid_state *state, vec3 p, vec3 *normal,
                                      vec3 *velocity);

/* False when p (world, at the pose of state) is further than margin (m) outside the
 * obstacle's bounding sphere; *p0 (may be NULL) receives p in the t = 0 frame. */
static inline bool piola__obstacle_within_bound(const piola_obstacle *obstacle,
                                                const piola__rigid_state *state, vec3 p,
                                                double margin, vec3 *p0) {
  const vec3 q = mat3_transpose_mul_vec(state->rotation, vec3_sub(p, state->translation));
  if (p0) *p0 = q;
  const double reach = obstacle->bound_radius + margin;
  return vec3_norm2(vec3_sub(q, obstacle->bound_center)) < reach * reach;
}

/* False when p (world, at the pose of state) is certainly outside the obstacle. */
static inline bool piola__obstacle_may_contain(const piola_obstacle *obstacle,
                                               const piola__rigid_state *state, vec3 p) {
  vec3 p0;
  if (!piola__obstacle_within_bound(obstacle, state, p, 0.0, &p0)) return false;
  /* A mesh answers inside/outside by its winding number far more cheaply than its distance. */
  if (obstacle->type == PIOLA_OBSTACLE_MESH)
    return piola__mesh_obstacle_contains(&obstacle->shape.mesh, p0);
  return true;
}

#endif
