/* Scripted rigid motions: exact integrals of keyframed velocities, Rodrigues rotations,
 * and velocities that are the time derivative of tracked material points. */
#include <math.h>

#include "test_support.h"

#include "math/mat3.h"
#include "piola/rigid_motion.h"

static piola_track keys(const double *times, const double *values, int n) {
  piola_track track;
  assert_int_equal(piola_track_from_keys(times, values, n, &track), PIOLA_OK);
  return track;
}

static vec3 move(const piola_rigid_motion_def *m, double t, vec3 x0) {
  mat3 r;
  vec3 c;
  piola_rigid_motion_pose(m, t, &r, &c);
  return vec3_add(mat3_mul_vec(r, x0), c);
}

static void default_motion_is_rest(void **state) {
  (void)state;
  piola_rigid_motion_def m = piola_default_rigid_motion_def();
  assert_int_equal(m.kind, PIOLA_MOTION_VELOCITY);
  assert_true(m.axis.x == 0 && m.axis.y == 0 && m.axis.z == 1);
  mat3 r;
  vec3 c;
  piola_rigid_motion_pose(&m, 3.7, &r, &c);
  assert_close(mat3_max_abs(mat3_sub(r, mat3_identity())), 0, 0);
  assert_close(vec3_norm(c), 0, 0);
  vec3 v = piola_rigid_motion_velocity(&m, 3.7, vec3_make(1, 2, 3));
  assert_close(vec3_norm(v), 0, 0);
}

/* c(t) for velocity keys (0, 0), (1, 2), (3, -2), by hand:
 *   t <= 0: 0;  0..1: t^2;  1..3: 1 + 2 (t-1) - (t-1)^2;  t >= 3: 1 - 2 (t-3). */
static double hand_integral(double t) {
  if (t <= 0) return 0;
  if (t <= 1) return t * t;
  if (t <= 3) return 1 + 2 * (t - 1) - (t - 1) * (t - 1);
  return 1 - 2 * (t - 3);
}

static void keyframed_velocity_integrates_exactly(void **state) {
  (void)state;
  const double times[] = {0, 1, 3}, values[] = {0, 2, -2};
  piola_rigid_motion_def m = piola_default_rigid_motion_def();
  m.velocity[0] = keys(times, values, 3);
  m.velocity[2] = piola_track_constant(-0.5);
  const double samples[] = {-1.0, 0.0, 0.3, 0.5, 1.0, 1.7, 2.0, 3.0, 4.0, 6.25};
  for (size_t i = 0; i < sizeof samples / sizeof *samples; ++i) {
    double t = samples[i];
    vec3 p = move(&m, t, vec3_make(0, 0, 0));
    assert_close(p.x, hand_integral(t), 1e-14);
    assert_close(p.y, 0, 0);
    assert_close(p.z, -0.5 * t, 1e-15);
  }
  /* Keys that start after 0: before the first key the velocity is the first value. */
  const double late_times[] = {0.5, 1.5}, late_values[] = {1, 3};
  m.velocity[1] = keys(late_times, late_values, 2);
  assert_close(move(&m, 0.25, vec3_make(0, 0, 0)).y, 0.25, 1e-15);
  assert_close(move(&m, -1.0, vec3_make(0, 0, 0)).y, -1.0, 1e-15);
  assert_close(move(&m, 1.0, vec3_make(0, 0, 0)).y, 0.5 + 0.5 + 0.25, 1e-15);
  assert_close(move(&m, 2.0, vec3_make(0, 0, 0)).y, 0.5 + 2.0 + 1.5, 1e-14);
}

static void keyframed_angular_speed_integrates_exactly(void **state) {
  (void)state;
  const double times[] = {0, 1, 3}, values[] = {0, 2, -2};
  piola_rigid_motion_def m = piola_default_rigid_motion_def();
  m.angular_speed = keys(times, values, 3);
  m.pivot = vec3_make(1, 1, 0);
  const double samples[] = {0.5, 1.0, 2.0, 2.9, 4.5};
  for (size_t i = 0; i < sizeof samples / sizeof *samples; ++i) {
    double t = samples[i], theta = hand_integral(t);
    /* A point one metre from the pivot along x turns to angle theta about z. */
    vec3 p = move(&m, t, vec3_make(2, 1, 0.3));
    assert_close(p.x, 1 + cos(theta), 1e-14);
    assert_close(p.y, 1 + sin(theta), 1e-14);
    assert_close(p.z, 0.3, 1e-15);
  }
}

static void rotation_is_rodrigues_about_the_axis(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(11);
  for (long s = 0; s < test_samples(200, 20); ++s) {
    piola_rigid_motion_def m = piola_default_rigid_motion_def();
    vec3 a = vec3_make(test_rng_normal(&rng), test_rng_normal(&rng), test_rng_normal(&rng));
    m.axis = vec3_scale(a, 1.0 / vec3_norm(a));
    m.kind = PIOLA_MOTION_POSE;
    double angle = test_rng_uniform(&rng, -7, 7);
    m.angle = piola_track_constant(angle);
    mat3 r;
    piola_rigid_motion_pose(&m, 0.0, &r, NULL);
    /* Orthonormal, proper, fixes the axis, turns a perpendicular vector by angle. */
    assert_close(mat3_max_abs(mat3_sub(mat3_mul_transpose_a(r, r), mat3_identity())), 0, 1e-14);
    assert_close(mat3_det(r), 1, 1e-14);
    assert_close(vec3_norm(vec3_sub(mat3_mul_vec(r, m.axis), m.axis)), 0, 1e-14);
    vec3 u = vec3_cross(m.axis, vec3_make(1, 0, 0));
    u = vec3_scale(u, 1.0 / vec3_norm(u));
    vec3 w = mat3_mul_vec(r, u);
    assert_close(vec3_dot(w, u), cos(angle), 1e-14);
    assert_close(vec3_dot(w, vec3_cross(m.axis, u)), sin(angle), 1e-14);
  }
}

static void pose_keys_are_the_pose(void **state) {
  (void)state;
  piola_rigid_motion_def m = piola_default_rigid_motion_def();
  m.kind = PIOLA_MOTION_POSE;
  m.pivot = vec3_make(0, 0, 1);
  m.axis = vec3_make(1, 0, 0);
  const double times[] = {0, 2}, tx[] = {0, 4}, angles[] = {0, M_PI};
  m.translation[0] = keys(times, tx, 2);
  m.angle = keys(times, angles, 2);
  /* At t = 1: half way, moved 2 in x and turned a quarter about x through (0, 0, 1). */
  vec3 p = move(&m, 1.0, vec3_make(0, 1, 1));
  assert_close(p.x, 2, 1e-14);
  assert_close(p.y, 0, 1e-14);
  assert_close(p.z, 2, 1e-14);
  /* The velocity: linear 2 m/s in x plus (pi/2 rad/s) x about the moved pivot. */
  vec3 v = piola_rigid_motion_velocity(&m, 1.0, p);
  assert_close(v.x, 2, 1e-14);
  assert_close(v.y, -M_PI / 2, 1e-14);
  assert_close(v.z, 0, 1e-14);
  /* After the last key the pose holds and nothing moves. */
  vec3 late = move(&m, 5.0, vec3_make(0, 1, 1));
  assert_close(late.x, 4, 1e-14);
  assert_close(late.z, 1, 1e-14);
  assert_close(late.y, -1, 1e-14);
  assert_close(vec3_norm(piola_rigid_motion_velocity(&m, 5.0, late)), 0, 0);
}

/* The velocity of the material point at x(t) equals dx/dt of that point, for random motions
 * of both kinds (times kept off the keys, where the velocity jumps). */
static void velocity_is_the_time_derivative_of_material_points(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(5);
  const double times[] = {0.0, 0.4, 1.0, 2.0};
  for (long s = 0; s < test_samples(100, 10); ++s) {
    piola_rigid_motion_def m = piola_default_rigid_motion_def();
    m.kind = s % 2 ? PIOLA_MOTION_POSE : PIOLA_MOTION_VELOCITY;
    vec3 a = vec3_make(test_rng_normal(&rng), test_rng_normal(&rng), test_rng_normal(&rng));
    m.axis = vec3_scale(a, 1.0 / vec3_norm(a));
    m.pivot = vec3_make(test_rng_normal(&rng), test_rng_normal(&rng), test_rng_normal(&rng));
    double v[4];
    for (int k = 0; k < 3; ++k) {
      for (int j = 0; j < 4; ++j) v[j] = test_rng_uniform(&rng, -2, 2);
      m.velocity[k] = keys(times, v, 4);
      m.translation[k] = keys(times, v, 4);
    }
    for (int j = 0; j < 4; ++j) v[j] = test_rng_uniform(&rng, -3, 3);
    m.angular_speed = keys(times, v, 4);
    m.angle = keys(times, v, 4);
    vec3 x0 = vec3_make(test_rng_normal(&rng), test_rng_normal(&rng), test_rng_normal(&rng));
    const double t_samples[] = {-0.5, 0.2, 0.7, 1.5, 2.6};
    for (int i = 0; i < 5; ++i) {
      double t = t_samples[i], h = 1e-6;
      vec3 fd = vec3_scale(vec3_sub(move(&m, t + h, x0), move(&m, t - h, x0)), 0.5 / h);
      vec3 vel = piola_rigid_motion_velocity(&m, t, move(&m, t, x0));
      assert_close(vec3_norm(vec3_sub(fd, vel)), 0, 1e-7 * (1 + vec3_norm(vel)));
    }
  }
}

static void angular_velocity_vector_sets_axis_and_speed(void **state) {
  (void)state;
  piola_rigid_motion_def m = piola_default_rigid_motion_def();
  piola_rigid_motion_set_angular_velocity(&m, vec3_make(0, 3, -4));
  assert_close(m.axis.y, 0.6, 1e-15);
  assert_close(m.axis.z, -0.8, 1e-15);
  assert_close(piola_track_eval(&m.angular_speed, 1.0), 5, 1e-15);
  /* The velocity of a point is omega x (x - pivot). */
  vec3 v = piola_rigid_motion_velocity(&m, 0.0, vec3_make(1, 0, 0));
  vec3 expected = vec3_cross(vec3_make(0, 3, -4), vec3_make(1, 0, 0));
  assert_close(vec3_norm(vec3_sub(v, expected)), 0, 1e-14);
  piola_rigid_motion_set_angular_velocity(&m, vec3_make(0, 0, 0));
  assert_close(piola_track_eval(&m.angular_speed, 1.0), 0, 0);
  assert_close(vec3_norm(m.axis), 1, 1e-15);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(default_motion_is_rest),
      cmocka_unit_test(keyframed_velocity_integrates_exactly),
      cmocka_unit_test(keyframed_angular_speed_integrates_exactly),
      cmocka_unit_test(rotation_is_rodrigues_about_the_axis),
      cmocka_unit_test(pose_keys_are_the_pose),
      cmocka_unit_test(angular_velocity_vector_sets_axis_and_speed),
      cmocka_unit_test(velocity_is_the_time_derivative_of_material_points),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
