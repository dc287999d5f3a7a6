/* piola: scripted rigid motions, for obstacles, bones and driven constraints.
 *
 * A motion maps points given at t = 0 to time t: x(t) = R(t) (x0 - pivot) + pivot + c(t),
 * with R(t) a rotation about the fixed world axis by angle theta(t) and c(t) a translation.
 *   PIOLA_MOTION_VELOCITY: c' = velocity(t) and theta' = angular_speed(t), each a keyframed
 *     track (a constant gives constant linear and angular velocity); c and theta are their
 *     exact integrals from 0 (piecewise-linear tracks integrate to piecewise quadratics).
 *   PIOLA_MOTION_POSE: c(t) = translation(t) and theta(t) = angle(t) are keyframed directly;
 *     velocities are their derivatives. */
#ifndef PIOLA_RIGID_MOTION_H
#define PIOLA_RIGID_MOTION_H

#include "piola/export.h"
#include "piola/keyframes.h"
#include "piola/math_types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum piola_motion_kind {
  PIOLA_MOTION_VELOCITY = 0,
  PIOLA_MOTION_POSE,
} piola_motion_kind;

typedef struct piola_rigid_motion_def {
  piola_motion_kind kind;     /* default PIOLA_MOTION_VELOCITY */
  piola_vec3 pivot;           /* m, the point the rotation turns about, at t = 0 */
  piola_vec3 axis;            /* unit rotation axis in world space, default (0, 0, 1) */
  piola_track velocity[3];    /* VELOCITY: m/s, default 0 */
  piola_track angular_speed;  /* VELOCITY: rad/s about axis, default 0 */
  piola_track translation[3]; /* POSE: m, default 0 */
  piola_track angle;          /* POSE: rad, default 0 */
} piola_rigid_motion_def;

/* No motion: everything 0, axis (0, 0, 1). */
PIOLA_API piola_rigid_motion_def piola_default_rigid_motion_def(void);

/* Constant angular velocity (rad/s) given as a vector, axis * speed: sets axis to its
 * direction and angular_speed to its length (a zero vector sets the speed to 0 and keeps the
 * axis). How the scene key `angular_velocity` maps onto the definition. */
PIOLA_API void piola_rigid_motion_set_angular_velocity(piola_rigid_motion_def *motion,
                                                       piola_vec3 angular_velocity);

/* The pose at time t (s): rotation R and translation so that x(t) = R x0 + translation. */
PIOLA_API void piola_rigid_motion_pose(const piola_rigid_motion_def *motion, double t,
                                       piola_mat3 *rotation, piola_vec3 *translation);

/* Velocity (m/s) at time t of the material point that is at world position x at time t. */
PIOLA_API piola_vec3 piola_rigid_motion_velocity(const piola_rigid_motion_def *motion, double t,
                                                 piola_vec3 x);

#ifdef __cplusplus
}
#endif

#endif
