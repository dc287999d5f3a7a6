/* Internal view of a scripted rigid motion: its full state at one instant.
 *
 * Collision processing evaluates the same motion at the same time for every node, so the
 * pose (rotation, translation) and the twist (linear velocity of the moving pivot, angular
 * velocity vector) are computed once per obstacle per call and reused; the public functions
 * in piola/rigid_motion.h are thin wrappers over this. */
#ifndef PIOLA_SIM_RIGID_MOTION_INTERNAL_H
#define PIOLA_SIM_RIGID_MOTION_INTERNAL_H

#include "math/mat3.h"
#include "piola/rigid_motion.h"

typedef struct piola__rigid_state {
  mat3 rotation;    /* R(t) */
  vec3 translation; /* x(t) = R x0 + translation, m */
  vec3 pivot;       /* where the t = 0 pivot is at time t, m */
  vec3 velocity;    /* velocity of the pivot, m/s */
  vec3 omega;       /* angular velocity vector (axis * angular speed), rad/s */
} piola__rigid_state;

void piola__rigid_motion_state(const piola_rigid_motion_def *motion, double t,
                               piola__rigid_state *state);

/* Velocity of the material point at world position x, for a state from the function above. */
static inline vec3 piola__rigid_state_velocity(const piola__rigid_state *state, vec3 x) {
  return vec3_add(state->velocity, vec3_cross(state->omega, vec3_sub(x, state->pivot)));
}

/* Rotation by angle (rad) about unit axis (Rodrigues' formula). */
mat3 piola__rotation_about_axis(vec3 unit_axis, double angle);

/* Integral of a piecewise-linear track over [a, b] (exact: a piecewise quadratic in b). */
double piola__track_integral(const piola_track *track, double a, double b);

/* Derivative of a track at t: the slope of the segment t lies in (right-sided at keys),
 * 0 before the first and from the last key on, 0 for a constant. */
double piola__track_slope(const piola_track *track, double t);

#endif
