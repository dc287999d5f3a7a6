/* Why. An unconverged iterate satisfies M (x - x^n - dt v^n) = dt^2 f + r with a residual r
 * that can be far larger than the forces (measured: 1e13 and up on scrambled armadillos), so
 * (x - x^n) / dt can carry r / (m dt) into the next step's prediction, which then starts
 * further from a solution; on a scrambled armadillo one such step raised the energy from
 * 5e9 J to 7e15 J, and the failures that followed overflowed. The rigid motion takes kinetic
 * energy away (at the start's shape; the caller checks it at the kept one, where a body that
 * contracted spins faster), while keeping what a free body must keep: its linear and angular
 * momentum. */
#include "sim/failed_step_velocity.h"

#include <math.h>

#include "math/inertia.h"
#include "piola/diagonalize.h"

/* Principal moments below this fraction of the start's or the kept shape's inertia (its
 * trace) count as zero: the spin about such an axis (a body collapsed onto a line, or to a
 * point) moves nothing, and dividing by the moment would only amplify rounding. */
#define NULL_MOMENT 1e-9

/* The mass-weighted sums of n points at x moving at v: total mass (kg), centre (m), momentum
 * (kg m/s), angular momentum about the centre (kg m^2/s), inertia tensor about it (kg m^2) */
typedef struct body_motion {
  double mass;
  vec3 centre, momentum, angular;
  mat3 inertia;
} body_motion;

static body_motion motion_of(int32_t n, const double *mass, const double *x, const double *v) {
  body_motion b = {0, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, mat3_zero()};
  for (int32_t i = 0; i < n; ++i) {
    b.mass += mass[i];
    b.centre = vec3_add(b.centre, vec3_scale(vec3_load(x + 3 * i), mass[i]));
    b.momentum = vec3_add(b.momentum, vec3_scale(vec3_load(v + 3 * i), mass[i]));
  }
  if (!(b.mass > 0)) return b;
  b.centre = vec3_scale(b.centre, 1.0 / b.mass);
  for (int32_t i = 0; i < n; ++i) {
    const vec3 r = vec3_sub(vec3_load(x + 3 * i), b.centre);
    b.angular = vec3_add(b.angular, vec3_scale(vec3_cross(r, vec3_load(v + 3 * i)), mass[i]));
    b.inertia = mat3_add(b.inertia, point_inertia(r, mass[i]));
  }
  return b;
}

/* The spin w with I w = L on the principal axes whose moment is not zero against `scale`
 * (kg m^2; the pseudo-inverse: the inertia tensor is symmetric, so its singular vectors are
 * its principal axes). */
static vec3 spin_of(mat3 inertia, vec3 angular, double scale) {
  piola_mat3 u, v;
  piola_vec3 moments;
  if (piola_diagonalize3(&inertia, &u, &moments, &v) != PIOLA_OK) return vec3_make(0, 0, 0);
  vec3 spin = vec3_make(0, 0, 0);
  for (int k = 0; k < 3; ++k) {
    const double moment = vec3_get(moments, k);
    if (!(fabs(moment) > NULL_MOMENT * scale)) continue;
    const double along = vec3_dot(mat3_column(u, k), angular) / moment;
    spin = vec3_add(spin, vec3_scale(mat3_column(v, k), along));
  }
  return spin;
}

static double moment_scale(const body_motion *start, const body_motion *kept) {
  return fmax(mat3_trace(start->inertia), mat3_trace(kept->inertia));
}

void piola__failed_step_velocity(int32_t n, const double *mass, const double *x_old,
                                 const double *v_old, const double *x, const double g[3], double dt,
                                 double *v) {
  const body_motion start = motion_of(n, mass, x_old, v_old);
  if (!(start.mass > 0)) return;
  const body_motion kept = motion_of(n, mass, x, v_old); /* for its centre and inertia */
  const vec3 velocity =
      vec3_add(vec3_scale(start.momentum, 1.0 / start.mass), vec3_scale(vec3_load(g), dt));
  /* gravity exerts no torque about the centre of mass */
  const vec3 spin = spin_of(kept.inertia, start.angular, moment_scale(&start, &kept));
  for (int32_t i = 0; i < n; ++i) {
    const vec3 r = vec3_sub(vec3_load(x + 3 * i), kept.centre);
    vec3_store(v + 3 * i, vec3_add(velocity, vec3_cross(spin, r)));
  }
}

void piola__failed_step_keep_angular_momentum(int32_t n, const double *mass, const double *x_old,
                                              const double *v_old, const double *x, double *v) {
  const body_motion start = motion_of(n, mass, x_old, v_old);
  const body_motion kept = motion_of(n, mass, x, v);
  if (!(kept.mass > 0)) return;
  const vec3 spin =
      spin_of(kept.inertia, vec3_sub(start.angular, kept.angular), moment_scale(&start, &kept));
  for (int32_t i = 0; i < n; ++i) {
    const vec3 r = vec3_sub(vec3_load(x + 3 * i), kept.centre);
    vec3_store(v + 3 * i, vec3_add(vec3_load(v + 3 * i), vec3_cross(spin, r)));
  }
}
