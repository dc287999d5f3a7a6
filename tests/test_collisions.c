/* Section 9 collision processing: projection, normal velocity, separation, Coulomb friction
 * with the dxN / dt term, moving obstacles, several obstacles, determinism. */
#include <math.h>
#include <omp.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "test_support.h"

#include "math/mat3.h"
#include "piola/obstacle.h"
#include "piola/threads.h"

static piola_obstacle *make(const piola_obstacle_def *def) {
  piola_obstacle *o = NULL;
  if (piola_obstacle_create(def, &o) != PIOLA_OK) fail_msg("%s", piola_last_error());
  return o;
}

static piola_obstacle *floor_plane(double mu) {
  piola_obstacle_def d = piola_default_obstacle_def();
  d.friction = mu;
  return make(&d);
}

static void node_below_plane_is_projected_and_stops_approaching(void **state) {
  (void)state;
  piola_obstacle *floor = floor_plane(0);
  double x[3] = {0.3, -0.2, -0.05}, v[3] = {1.0, 0.5, -3.0}, normals[3] = {0};
  uint8_t colliding = 0;
  int32_t n = piola_obstacles_collide(&floor, 1, 0.0, 0.01, 1, x, v, &colliding, normals);
  assert_int_equal(n, 1);
  assert_int_equal(colliding, 1);
  assert_close(x[0], 0.3, 0);
  assert_close(x[1], -0.2, 0);
  assert_close(x[2], 0.0, 0);
  /* The normal velocity becomes the (resting) obstacle's; without friction the tangential
   * velocity is untouched. */
  assert_close(v[2], 0.0, 0);
  assert_close(v[0], 1.0, 0);
  assert_close(v[1], 0.5, 0);
  assert_close(normals[2], 1.0, 0);
  piola_obstacle_destroy(floor);
}

static void separating_node_keeps_its_normal_velocity(void **state) {
  (void)state;
  piola_obstacle *floor = floor_plane(0.5);
  double x[3] = {0, 0, -0.01}, v[3] = {2.0, 0, 1.5};
  uint8_t colliding = 0;
  assert_int_equal(piola_obstacles_collide(&floor, 1, 0.0, 0.1, 1, x, v, &colliding, NULL), 1);
  assert_close(x[2], 0, 0);
  assert_close(v[2], 1.5, 0);
  /* dvN = 0, dxN = 0.01 m: friction from the position change only, 0.5 * 0.01 / 0.1. */
  assert_close(v[0], 2.0 - 0.05, 1e-15);
  piola_obstacle_destroy(floor);
}

static void nodes_outside_are_untouched(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_SPHERE;
  d.radius = 1;
  d.friction = 1;
  piola_obstacle *ball = make(&d);
  double x[6] = {2, 0, 0, 0, 0, 1.0 + 1e-12}, v[6] = {-1, 2, 3, 4, 5, -6};
  double x0[6], v0[6];
  memcpy(x0, x, sizeof x);
  memcpy(v0, v, sizeof v);
  uint8_t colliding[2] = {7, 7};
  double normals[6] = {9, 9, 9, 9, 9, 9};
  assert_int_equal(piola_obstacles_collide(&ball, 1, 0.0, 0.01, 2, x, v, colliding, normals), 0);
  assert_memory_equal(x, x0, sizeof x);
  assert_memory_equal(v, v0, sizeof v);
  assert_int_equal(colliding[0], 0);
  assert_int_equal(colliding[1], 0);
  assert_close(normals[0], 9, 0); /* normals of non-colliding nodes are left alone */
  piola_obstacle_destroy(ball);
}

/* vT <- max(0, 1 - mu (dvN + dxN / dt) / |vT|) vT, checked number by number. */
static void friction_slides_by_exactly_mu_times_the_normal_change(void **state) {
  (void)state;
  const double mus[] = {0.05, 0.1, 0.3};
  for (int k = 0; k < 3; ++k) {
    piola_obstacle *floor = floor_plane(mus[k]);
    double depth = 0.001, dt = 0.01;
    double x[3] = {0, 0, -depth}, v[3] = {3.0, 4.0, -1.0}; /* |vT| = 5 */
    piola_obstacles_collide(&floor, 1, 0.0, dt, 1, x, v, NULL, NULL);
    double dvn = 1.0, dxn = depth;
    double scale = 1 - mus[k] * (dvn + dxn / dt) / 5.0;
    assert_true(scale > 0); /* sliding */
    assert_close(v[0], 3.0 * scale, 1e-14);
    assert_close(v[1], 4.0 * scale, 1e-14);
    assert_close(v[2], 0.0, 0);
    /* The speed dropped by exactly mu (dvN + dxN / dt). */
    assert_close(5.0 - hypot(v[0], v[1]), mus[k] * (dvn + dxn / dt), 1e-14);
    piola_obstacle_destroy(floor);
  }
}

static void large_friction_sticks(void **state) {
  (void)state;
  piola_obstacle *floor = floor_plane(10.0);
  double x[3] = {0, 0, -0.001}, v[3] = {3.0, 4.0, -1.0};
  piola_obstacles_collide(&floor, 1, 0.0, 0.01, 1, x, v, NULL, NULL);
  assert_close(v[0], 0, 0);
  assert_close(v[1], 0, 0);
  assert_close(v[2], 0, 0);
  piola_obstacle_destroy(floor);
}

/* A floor moving up at 2 m/s and sideways at 1 m/s: a node it overtook is put on it, moves
 * up with it, and with sticking friction is carried sideways too (relative velocity 0). */
static void moving_plane_pushes_nodes_with_its_velocity(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  d.motion.velocity[0] = piola_track_constant(1.0);
  d.motion.velocity[2] = piola_track_constant(2.0);
  d.friction = 100;
  piola_obstacle *floor = make(&d);
  double t = 0.5; /* the floor is at z = 1 */
  double x[6] = {0.2, 0.1, 0.97, 5, 5, 1.5}, v[6] = {0, 0, 0, 0, 0, 0};
  uint8_t colliding[2];
  assert_int_equal(piola_obstacles_collide(&floor, 1, t, 0.01, 2, x, v, colliding, NULL), 1);
  assert_close(x[2], 1.0, 1e-15);
  assert_close(v[0], 1.0, 1e-15);
  assert_close(v[1], 0.0, 1e-15);
  assert_close(v[2], 2.0, 1e-15);
  assert_int_equal(colliding[0], 1);
  assert_int_equal(colliding[1], 0);
  assert_close(x[5], 1.5, 0);
  /* Without friction only the normal velocity is taken. */
  d.friction = 0;
  piola_obstacle *slippery = make(&d);
  double y[3] = {0.2, 0.1, 0.97}, w[3] = {0.3, 0, -1};
  piola_obstacles_collide(&slippery, 1, t, 0.01, 1, y, w, NULL, NULL);
  assert_close(w[0], 0.3, 1e-15);
  assert_close(w[2], 2.0, 1e-15);
  piola_obstacle_destroy(floor);
  piola_obstacle_destroy(slippery);
}

/* A spinning cylinder with sticking friction drags a node at its surface velocity w x r. */
static void spinning_cylinder_drags_with_surface_velocity(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_CYLINDER;
  d.radius = 0.5;
  d.half_length = 1;
  d.friction = 50;
  d.motion.angular_speed = piola_track_constant(4.0);
  piola_obstacle *roller = make(&d);
  double x[3] = {0.49, 0, 0.2}, v[3] = {0, 0, 0};
  double normal[3];
  assert_int_equal(piola_obstacles_collide(&roller, 1, 0.3, 0.01, 1, x, v, NULL, normal), 1);
  assert_close(hypot(x[0], x[1]), 0.5, 1e-14);
  assert_close(v[0], -4.0 * x[1], 1e-13);
  assert_close(v[1], 4.0 * x[0], 1e-13);
  assert_close(v[2], 0, 1e-13);
  assert_close(normal[0] * x[0] + normal[1] * x[1], 0.5, 1e-13);
  piola_obstacle_destroy(roller);
}

/* Interior nodes deep inside are projected too (section 9: small obstacles must not slip
 * between surface nodes). */
static void deep_interior_nodes_are_projected(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_SPHERE;
  d.radius = 0.2;
  piola_obstacle *ball = make(&d);
  double x[3] = {0.01, 0.02, -0.03}, v[3] = {0, 0, 0};
  assert_int_equal(piola_obstacles_collide(&ball, 1, 0, 0.01, 1, x, v, NULL, NULL), 1);
  assert_close(sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), 0.2, 1e-15);
  assert_close(x[1] / x[0], 2, 1e-12); /* along the ray from the centre */
  piola_obstacle_destroy(ball);
}

/* A node in the corner of a floor and a wall leaves both, and both normal velocities go. */
static void node_in_two_obstacles_leaves_both(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  piola_obstacle *obstacles[2];
  obstacles[0] = make(&d);
  d.axis = vec3_make(-1, 0, 0);
  d.center = vec3_make(1, 0, 0);
  obstacles[1] = make(&d);
  double x[3] = {1.02, 0.3, -0.01}, v[3] = {1, 1, -1};
  uint8_t c;
  assert_int_equal(piola_obstacles_collide(obstacles, 2, 0, 0.01, 1, x, v, &c, NULL), 1);
  assert_true(piola_obstacle_signed_distance(obstacles[0], 0, vec3_load(x), NULL, NULL) >= 0);
  assert_true(piola_obstacle_signed_distance(obstacles[1], 0, vec3_load(x), NULL, NULL) >= 0);
  assert_close(x[0], 1.0, 1e-15);
  assert_close(x[2], 0.0, 1e-15);
  assert_close(v[0], 0, 0);
  assert_close(v[1], 1, 0);
  assert_close(v[2], 0, 0);
  piola_obstacle_destroy(obstacles[0]);
  piola_obstacle_destroy(obstacles[1]);
}

/* Many random nodes against a turning gear and a box: afterwards none is inside, and the
 * result is bit-identical with 1 thread and with several. */
static void many_nodes_end_outside_and_results_do_not_depend_on_threads(void **state) {
  (void)state;
  piola_obstacle_def g = piola_default_obstacle_def();
  g.type = PIOLA_OBSTACLE_GEAR;
  g.radius = 0.3;
  g.tooth_depth = 0.05;
  g.tooth_count = 10;
  g.half_length = 0.1;
  g.friction = 0.3;
  g.motion.angular_speed = piola_track_constant(2.0);
  piola_obstacle_def b = piola_default_obstacle_def();
  b.type = PIOLA_OBSTACLE_BOX;
  b.center = vec3_make(0.6, 0, 0);
  b.half_extents = vec3_make(0.1, 0.2, 0.3);
  b.friction = 0.1;
  piola_obstacle *obstacles[2] = {make(&g), make(&b)};
  int32_t n = (int32_t)test_samples(20000, 500);
  double *x = malloc(sizeof(double) * 3 * (size_t)n), *v = malloc(sizeof(double) * 3 * (size_t)n);
  double *x2 = malloc(sizeof(double) * 3 * (size_t)n), *v2 = malloc(sizeof(double) * 3 * (size_t)n);
  uint8_t *c = malloc((size_t)n), *c2 = malloc((size_t)n);
  double *normals = malloc(sizeof(double) * 3 * (size_t)n);
  test_rng rng = test_rng_seeded(77);
  for (int32_t i = 0; i < 3 * n; ++i) {
    x[i] = test_rng_uniform(&rng, -0.4, 0.8);
    v[i] = test_rng_normal(&rng);
  }
  memcpy(x2, x, sizeof(double) * 3 * (size_t)n);
  memcpy(v2, v, sizeof(double) * 3 * (size_t)n);
  int threads = omp_get_max_threads();
  piola_set_thread_count(1);
  int32_t hits = piola_obstacles_collide(obstacles, 2, 0.7, 0.005, n, x, v, c, normals);
  piola_set_thread_count(threads > 1 ? threads : 2);
  int32_t hits2 = piola_obstacles_collide(obstacles, 2, 0.7, 0.005, n, x2, v2, c2, NULL);
  piola_set_thread_count(0);
  assert_int_equal(hits, hits2);
  assert_true(hits > n / 50); /* the obstacles fill about 6 % of the sampled cube */
  assert_memory_equal(x, x2, sizeof(double) * 3 * (size_t)n);
  assert_memory_equal(v, v2, sizeof(double) * 3 * (size_t)n);
  assert_memory_equal(c, c2, (size_t)n);
  int32_t flagged = 0;
  for (int32_t i = 0; i < n; ++i) {
    flagged += c[i];
    bool separates = false;
    for (int k = 0; k < 2; ++k) {
      vec3 vel;
      double phi =
          piola_obstacle_signed_distance(obstacles[k], 0.7, vec3_load(x + 3 * i), NULL, &vel);
      assert_true(phi >= -1e-12);
      /* A node left on an obstacle does not move into it along the normal it was given. */
      if (c[i] && phi < 1e-12 &&
          vec3_dot(vec3_sub(vec3_load(v + 3 * i), vel), vec3_load(normals + 3 * i)) >= -1e-12)
        separates = true;
    }
    if (c[i]) assert_true(separates);
  }
  assert_int_equal(flagged, hits);
  piola_obstacle_destroy(obstacles[0]);
  piola_obstacle_destroy(obstacles[1]);
  free(x);
  free(v);
  free(x2);
  free(v2);
  free(c);
  free(c2);
  free(normals);
}

/* Every shape, turning: random nodes in and around it all end outside or on it, and exactly
 * the nodes that were inside are flagged (the bounding-sphere early out misses none). */
static void every_shape_leaves_no_node_inside(void **state) {
  (void)state;
  static const int32_t cube_tris[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                        2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};
  double cube_positions[24];
  for (int i = 0; i < 8; ++i) {
    int xb = (i == 1 || i == 2 || i == 5 || i == 6), yb = (i == 2 || i == 3 || i == 6 || i == 7);
    cube_positions[3 * i] = xb ? 0.4 : -0.3;
    cube_positions[3 * i + 1] = yb ? 0.2 : -0.5;
    cube_positions[3 * i + 2] = i >= 4 ? 0.35 : -0.25;
  }
  piola_tri_mesh cube = {8, cube_positions, 12, (int32_t *)cube_tris};
  int32_t n = (int32_t)test_samples(4000, 400);
  double *x = malloc(sizeof(double) * 3 * (size_t)n), *v = malloc(sizeof(double) * 3 * (size_t)n);
  double *before = malloc(sizeof(double) * 3 * (size_t)n);
  uint8_t *c = malloc((size_t)n);
  for (int type = 0; type < PIOLA_OBSTACLE_TYPE_COUNT; ++type) {
    piola_obstacle_def d = piola_default_obstacle_def();
    d.type = (piola_obstacle_type)type;
    d.center = vec3_make(0.05, 0, -0.02);
    d.axis = vec3_make(0, 0.6, 0.8);
    d.radius = 0.4;
    d.minor_radius = 0.1;
    d.half_length = 0.2;
    d.half_extents = vec3_make(0.3, 0.2, 0.4);
    d.tooth_count = 11;
    d.tooth_depth = 0.08;
    d.mesh = &cube;
    d.friction = 0.2;
    d.motion.axis = vec3_make(1, 0, 0);
    d.motion.angular_speed = piola_track_constant(1.3);
    d.motion.velocity[1] = piola_track_constant(0.2);
    piola_obstacle *o = make(&d);
    test_rng rng = test_rng_seeded(500 + (uint64_t)type);
    int32_t inside = 0;
    for (int32_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) {
        before[3 * i + k] = x[3 * i + k] = test_rng_uniform(&rng, -0.7, 0.7);
        v[3 * i + k] = test_rng_normal(&rng);
      }
      inside += piola_obstacle_signed_distance(o, 0.4, vec3_load(x + 3 * i), NULL, NULL) < 0;
    }
    int32_t hits = piola_obstacles_collide(&o, 1, 0.4, 0.01, n, x, v, c, NULL);
    assert_int_equal(hits, inside);
    assert_true(type == PIOLA_OBSTACLE_PLANE || hits < n);
    assert_true(hits > 0);
    for (int32_t i = 0; i < n; ++i) {
      double phi = piola_obstacle_signed_distance(o, 0.4, vec3_load(x + 3 * i), NULL, NULL);
      if (!(phi >= -1e-12)) fail_msg("type %d node %d left inside at %g", type, (int)i, phi);
      if (!c[i]) assert_memory_equal(x + 3 * i, before + 3 * i, 3 * sizeof(double));
    }
    piola_obstacle_destroy(o);
  }
  free(x);
  free(v);
  free(before);
  free(c);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(node_below_plane_is_projected_and_stops_approaching),
      cmocka_unit_test(separating_node_keeps_its_normal_velocity),
      cmocka_unit_test(nodes_outside_are_untouched),
      cmocka_unit_test(friction_slides_by_exactly_mu_times_the_normal_change),
      cmocka_unit_test(large_friction_sticks),
      cmocka_unit_test(moving_plane_pushes_nodes_with_its_velocity),
      cmocka_unit_test(spinning_cylinder_drags_with_surface_velocity),
      cmocka_unit_test(deep_interior_nodes_are_projected),
      cmocka_unit_test(node_in_two_obstacles_leaves_both),
      cmocka_unit_test(every_shape_leaves_no_node_inside),
      cmocka_unit_test(many_nodes_end_outside_and_results_do_not_depend_on_threads),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
