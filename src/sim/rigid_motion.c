/* Scripted rigid motions: x(t) = R(t) (x0 - pivot) + pivot + c(t).
 *
 * R(t) turns by theta(t) about a fixed world axis, so it is one Rodrigues rotation and the
 * angular velocity is simply theta'(t) * axis. In the VELOCITY kind c and theta are the
 * exact integrals of piecewise-linear tracks (piecewise quadratics), so a scripted motion
 * has no time-integration error whatever the time step. */
#include "sim/rigid_motion_internal.h"

#include <math.h>

piola_rigid_motion_def piola_default_rigid_motion_def(void) {
  piola_rigid_motion_def def;
  def.kind = PIOLA_MOTION_VELOCITY;
  def.pivot = vec3_make(0, 0, 0);
  def.axis = vec3_make(0, 0, 1);
  for (int k = 0; k < 3; ++k) {
    def.velocity[k] = piola_track_constant(0.0);
    def.translation[k] = piola_track_constant(0.0);
  }
  def.angular_speed = piola_track_constant(0.0);
  def.angle = piola_track_constant(0.0);
  return def;
}

void piola_rigid_motion_set_angular_velocity(piola_rigid_motion_def *motion,
                                             piola_vec3 angular_velocity) {
  double speed = vec3_norm(angular_velocity);
  if (speed > 0 && isfinite(speed)) motion->axis = vec3_scale(angular_velocity, 1.0 / speed);
  motion->angular_speed = piola_track_constant(isfinite(speed) ? speed : NAN);
}

/* Antiderivative F with F(times[0]) = 0 (F(0) = 0 for a constant track). */
static double track_antiderivative(const piola_track *track, double t) {
  int32_t n = track->key_count;
  if (n == 0) return track->value * t;
  const double *ts = track->times, *vs = track->values;
  if (t <= ts[0]) return vs[0] * (t - ts[0]);
  double sum = 0.0;
  for (int32_t i = 1; i < n; ++i) {
    if (t <= ts[i]) {
      double s = (t - ts[i - 1]) / (ts[i] - ts[i - 1]);
      double value_at_t = vs[i - 1] + s * (vs[i] - vs[i - 1]);
      return sum + 0.5 * (t - ts[i - 1]) * (vs[i - 1] + value_at_t);
    }
    sum += 0.5 * (ts[i] - ts[i - 1]) * (vs[i - 1] + vs[i]);
  }
  return sum + vs[n - 1] * (t - ts[n - 1]);
}

double piola__track_integral(const piola_track *track, double a, double b) {
  return track_antiderivative(track, b) - track_antiderivative(track, a);
}

double piola__track_slope(const piola_track *track, double t) {
  int32_t n = track->key_count;
  if (n < 2 || t < track->times[0] || t >= track->times[n - 1]) return 0.0;
  int32_t i = 1;
  while (track->times[i] <= t) ++i;
  return (track->values[i] - track->values[i - 1]) / (track->times[i] - track->times[i - 1]);
}

mat3 piola__rotation_about_axis(vec3 a, double angle) {
  double c = cos(angle), s = sin(angle), k = 1.0 - c;
  /* R = I + sin K + (1 - cos) K^2 with K the cross-product matrix of a, written out. */
  return (mat3){{{c + k * a.x * a.x, k * a.x * a.y - s * a.z, k * a.x * a.z + s * a.y},
                 {k * a.y * a.x + s * a.z, c + k * a.y * a.y, k * a.y * a.z - s * a.x},
                 {k * a.z * a.x - s * a.y, k * a.z * a.y + s * a.x, c + k * a.z * a.z}}};
}

static vec3 unit_axis(vec3 axis) {
  double n = vec3_norm(axis);
  return n > 0 && isfinite(n) ? vec3_scale(axis, 1.0 / n) : vec3_make(0, 0, 1);
}

void piola__rigid_motion_state(const piola_rigid_motion_def *motion, double t,
                               piola__rigid_state *state) {
  vec3 axis = unit_axis(motion->axis);
  double c[3], cdot[3], theta, theta_dot;
  if (motion->kind == PIOLA_MOTION_POSE) {
    for (int k = 0; k < 3; ++k) {
      c[k] = piola_track_eval(&motion->translation[k], t);
      cdot[k] = piola__track_slope(&motion->translation[k], t);
    }
    theta = piola_track_eval(&motion->angle, t);
    theta_dot = piola__track_slope(&motion->angle, t);
  } else {
    for (int k = 0; k < 3; ++k) {
      c[k] = piola__track_integral(&motion->velocity[k], 0.0, t);
      cdot[k] = piola_track_eval(&motion->velocity[k], t);
    }
    theta = piola__track_integral(&motion->angular_speed, 0.0, t);
    theta_dot = piola_track_eval(&motion->angular_speed, t);
  }
  vec3 shift = vec3_make(c[0], c[1], c[2]);
  state->rotation = piola__rotation_about_axis(axis, theta);
  state->pivot = vec3_add(motion->pivot, shift);
  /* x = R (x0 - p) + p + c  =>  translation = p + c - R p */
  state->translation = vec3_sub(state->pivot, mat3_mul_vec(state->rotation, motion->pivot));
  state->velocity = vec3_make(cdot[0], cdot[1], cdot[2]);
  state->omega = vec3_scale(axis, theta_dot);
}

void piola_rigid_motion_pose(const piola_rigid_motion_def *motion, double t, piola_mat3 *rotation,
                             piola_vec3 *translation) {
  piola__rigid_state state;
  piola__rigid_motion_state(motion, t, &state);
  if (rotation) *rotation = state.rotation;
  if (translation) *translation = state.translation;
}

piola_vec3 piola_rigid_motion_velocity(const piola_rigid_motion_def *motion, double t,
                                       piola_vec3 x) {
  piola__rigid_state state;
  piola__rigid_motion_state(motion, t, &state);
  return piola__rigid_state_velocity(&state, x);
}
