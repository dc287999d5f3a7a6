/* The implicit damping solves of the step loop (src/sim/integrator.c) as the rest of the
 * step sees them:
 *  - a free, damped body falling under gravity gains exactly the momentum gravity gives it,
 *    even with a loose CG tolerance (the guess carries gravity's uniform velocity change,
 *    which the damping cannot alter, so the residual CG stops at has no net force);
 *  - at the default cg_tolerance the solves' error in the trajectory stays well below the
 *    time discretization error (the change a halved step makes) on a smooth motion, where
 *    that error is small. Measured after 100 steps (velocity error / step error, CG
 *    iterations per step): 1e-8: 1e-5, 6.1; 1e-6: 0.7%, 4.6; 1e-4 (default): 1.1%, 4.0;
 *    1e-3: 17 times, 2.1 (docs/time-stepping.md);
 *  - the solves take as many iterations for the block moving at 3 m/s as at rest: the
 *    stopping test is relative to the residual of the guess (the velocity change still to
 *    be made), not to the momentum-dominated right-hand side;
 *  - results do not depend on the thread count, for small bodies and for bodies large
 *    enough that the solver's passes run in parallel. */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "force/elastic_body_internal.h"
#include "sim/world_internal.h"
#include "piola/mesh.h"
#include "piola/threads.h"
#include "piola/world.h"
#include "test_elastic_body_fixtures.h"

/* A 4x3x3-cube block (0.4 x 0.3 x 0.3 m), stretched and sheared, moving and spinning:
 * elastic forces and damping are busy. */
static piola_world *busy_block_moving(double cg_tolerance, double max_dt, double moving,
                                     piola_tet_mesh *mesh) {
  piola_world_def wd = piola_default_world_def();
  wd.gravity[0] = piola_track_constant(1.0);
  wd.gravity[2] = piola_track_constant(-9.81);
  wd.max_dt = max_dt;
  wd.cfl = 2; /* every step max_dt long */
  wd.cg_tolerance = cg_tolerance;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  assert_int_equal(piola_tet_mesh_box_grid(4, 3, 3, (piola_vec3){0.1, 0.1, 0.1}, mesh), PIOLA_OK);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material.youngs_modulus = 5e4;
  sd.material.poisson_ratio = 0.3;
  sd.shear_viscosity = piola_track_constant(20);
  sd.bulk_viscosity = piola_track_constant(10);
  sd.initial_matrix = (piola_mat3){{{1.3, 0.2, 0}, {0, 0.8, 0.1}, {0.1, 0, 1.1}}};
  sd.velocity = (piola_vec3){0.5 * moving, -0.2 * moving, 3.0 * moving};
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  int32_t n = piola_elastic_body_vertex_count(piola_world_solid_body(w, 0));
  double *v = malloc(3 * (size_t)n * sizeof(double));
  const double *x = piola_world_solid_positions(w, 0);
  for (int32_t i = 0; i < n; ++i) {
    const double *xi = x + 3 * i;
    v[3 * i] = 0.5 * moving - 4.0 * (xi[1] - 0.15) + 0.3 * sin(20 * xi[2]);
    v[3 * i + 1] = -0.2 * moving + 4.0 * (xi[0] - 0.2);
    v[3 * i + 2] = 3.0 * moving + 1.0 * (xi[1] - 0.15) + 0.2 * cos(15 * xi[0]);
  }
  assert_int_equal(piola_world_solid_set_state(w, 0, NULL, v), PIOLA_OK);
  free(v);
  return w;
}

/* The block with its mean velocity of 3 m/s. */
static piola_world *busy_block(double cg_tolerance, double max_dt, piola_tet_mesh *mesh) {
  return busy_block_moving(cg_tolerance, max_dt, 1, mesh);
}

static void momentum(const piola_world *w, double p[3], double *mass) {
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const double *m = piola_elastic_body_masses(b);
  const double *v = piola_world_solid_velocities(w, 0);
  p[0] = p[1] = p[2] = *mass = 0;
  for (int32_t i = 0; i < piola_elastic_body_vertex_count(b); ++i) {
    *mass += m[i];
    for (int k = 0; k < 3; ++k) p[k] += m[i] * v[3 * i + k];
  }
}

static void free_fall_gains_exactly_gravity_momentum(void **state) {
  (void)state;
  const double tolerances[] = {1e-3, 1e-8};
  for (int k = 0; k < 2; ++k) {
    piola_tet_mesh mesh;
    piola_world *w = busy_block(tolerances[k], 2e-4, &mesh);
    double p0[3], p1[3], mass;
    momentum(w, p0, &mass);
    piola_step_stats st = {0};
    assert_int_equal(piola_world_advance_to(w, 0.02, &st), PIOLA_OK);
    assert_true(st.cg_iterations > 0);
    momentum(w, p1, &mass);
    const double g[3] = {1.0, 0, -9.81};
    double scale = mass * (3.0 + 9.81 * 0.02);
    for (int c = 0; c < 3; ++c) assert_close(p1[c], p0[c] + mass * g[c] * 0.02, 1e-12 * scale);
    piola_world_destroy(w);
    free(mesh.positions);
    free(mesh.tets);
  }
}

/* Max |a - b| over 3n entries. */
static double max_difference(const double *a, const double *b, int32_t n3) {
  double d = 0;
  for (int32_t i = 0; i < n3; ++i) d = fmax(d, fabs(a[i] - b[i]));
  return d;
}

/* Runs the block to t_end; returns the CG iterations it took. */
static int64_t run_moving_to(double tolerance, double dt, double moving, double t_end, double *x,
                             double *v, int32_t *n3) {
  piola_tet_mesh mesh;
  piola_world *w = busy_block_moving(tolerance, dt, moving, &mesh);
  piola_step_stats st = {0};
  assert_int_equal(piola_world_advance_to(w, t_end, &st), PIOLA_OK);
  *n3 = 3 * piola_elastic_body_vertex_count(piola_world_solid_body(w, 0));
  memcpy(x, piola_world_solid_positions(w, 0), (size_t)*n3 * sizeof(double));
  memcpy(v, piola_world_solid_velocities(w, 0), (size_t)*n3 * sizeof(double));
  piola_world_destroy(w);
  free(mesh.positions);
  free(mesh.tets);
  return st.cg_iterations;
}

static void run_to(double tolerance, double dt, double t_end, double *x, double *v, int32_t *n3) {
  (void)run_moving_to(tolerance, dt, 1, t_end, x, v, n3);
}

static void default_tolerance_error_is_well_below_the_step_error(void **state) {
  (void)state;
  enum { MAX3 = 3 * 5 * 4 * 4 };
  double xt[MAX3], vt[MAX3], xd[MAX3], vd[MAX3], xh[MAX3], vh[MAX3];
  int32_t n3;
  const double dt = 2e-4, t_end = 0.02;
  run_to(1e-13, dt, t_end, xt, vt, &n3);
  assert_true(n3 <= MAX3);
  run_to(1e-13, dt / 2, t_end, xh, vh, &n3);
  run_to(piola_default_world_def().cg_tolerance, dt, t_end, xd, vd, &n3);
  double solve_x = max_difference(xd, xt, n3), solve_v = max_difference(vd, vt, n3);
  double step_x = max_difference(xh, xt, n3), step_v = max_difference(vh, vt, n3);
  print_message("default tolerance vs tight: dx %.3g m, dv %.3g m/s; dt/2 vs dt: dx %.3g m, dv %.3g m/s\n",
                solve_x, solve_v, step_x, step_v);
  assert_true(step_v > 0 && step_x > 0);
  assert_true(solve_x < 0.05 * step_x);
  assert_true(solve_v < 0.05 * step_v);
}

static void iterations_do_not_depend_on_the_body_speed(void **state) {
  (void)state;
  enum { MAX3 = 3 * 5 * 4 * 4 };
  double x[MAX3], v[MAX3];
  int32_t n3;
  const double tolerance = piola_default_world_def().cg_tolerance;
  int64_t moving = run_moving_to(tolerance, 2e-4, 1, 0.02, x, v, &n3);
  int64_t resting = run_moving_to(tolerance, 2e-4, 0, 0.02, x, v, &n3);
  print_message("CG iterations in 100 steps: %lld moving at 3 m/s, %lld at rest\n", (long long)moving,
                (long long)resting);
  assert_true(resting >= 100); /* it iterates at all */
  /* the residuals differ only by rounding, which may tip a borderline solve */
  assert_true(llabs(moving - resting) <= resting / 50);
}

static void solves_do_not_depend_on_the_thread_count(void **state) {
  (void)state;
  enum { MAX3 = 3 * 5 * 4 * 4 };
  double x1[MAX3], v1[MAX3], x2[MAX3], v2[MAX3];
  int32_t n3;
  piola_set_thread_count(1);
  run_to(1e-6, 2e-4, 0.01, x1, v1, &n3);
  piola_set_thread_count(2);
  run_to(1e-6, 2e-4, 0.01, x2, v2, &n3);
  piola_set_thread_count(0);
  assert_memory_equal(x1, x2, (size_t)n3 * sizeof(double));
  assert_memory_equal(v1, v2, (size_t)n3 * sizeof(double));
}

/* A body large enough that the solver's passes and the damping apply run in parallel
 * (>= 4096 nodes): a few steps on 1 and 2 threads give the same bits. */
static void large_body_does_not_depend_on_the_thread_count(void **state) {
  (void)state;
  double *result[2] = {NULL, NULL};
  int32_t n3 = 0;
  for (int threads = 1; threads <= 2; ++threads) {
    piola_set_thread_count(threads);
    piola_world_def wd = piola_default_world_def();
    wd.max_dt = 1e-3;
    piola_world *w = NULL;
    assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
    piola_tet_mesh mesh;
    assert_int_equal(piola_tet_mesh_box_grid(16, 16, 16, (piola_vec3){0.02, 0.02, 0.02}, &mesh), PIOLA_OK);
    piola_solid_def sd = piola_default_solid_def();
    sd.mesh = &mesh;
    sd.material.youngs_modulus = 1e5;
    sd.shear_viscosity = piola_track_constant(50);
    sd.bulk_viscosity = piola_track_constant(20);
    sd.scramble_radius = 2e-3;
    assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
    piola_obstacle_def ground = piola_default_obstacle_def();
    ground.type = PIOLA_OBSTACLE_PLANE;
    ground.center = (piola_vec3){0, 0, 0.001};
    ground.axis = (piola_vec3){0, 0, 1};
    ground.friction = 0.5;
    assert_int_equal(piola_world_add_obstacle(w, &ground, NULL), PIOLA_OK);
    n3 = 3 * piola_elastic_body_vertex_count(piola_world_solid_body(w, 0));
    assert_true(n3 >= 3 * 4096);
    piola_step_stats st = {0};
    for (int k = 0; k < 3; ++k) assert_int_equal(piola_world_step(w, 1e-4, &st), PIOLA_OK);
    assert_true(st.cg_iterations > 0 && st.colliding > 0);
    result[threads - 1] = malloc(2 * (size_t)n3 * sizeof(double));
    memcpy(result[threads - 1], piola_world_solid_positions(w, 0), (size_t)n3 * sizeof(double));
    memcpy(result[threads - 1] + n3, piola_world_solid_velocities(w, 0), (size_t)n3 * sizeof(double));
    piola_world_destroy(w);
    free(mesh.positions);
    free(mesh.tets);
  }
  piola_set_thread_count(0);
  assert_memory_equal(result[0], result[1], 2 * (size_t)n3 * sizeof(double));
  free(result[0]);
  free(result[1]);
}

/* The second right-hand side's D_n v', taken from the first solve's initial product and
 * corrected on the nodes that collisions and constraints moved, is the full damping pass
 * to rounding: a block pressed onto a rough ground, one end driven sideways, run with each. */
static void reused_first_product_matches_a_full_pass(void **state) {
  (void)state;
  enum { STEPS = 40 };
  double *result[2] = {NULL, NULL};
  int32_t n3 = 0;
  double vmax = 0;
  for (int reuse = 0; reuse <= 1; ++reuse) {
    piola__step_reuse_first_product = reuse;
    piola_world_def wd = piola_default_world_def();
    wd.gravity[2] = piola_track_constant(-9.81);
    wd.max_dt = 2e-4;
    wd.cfl = 2;
    piola_world *w = NULL;
    assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
    piola_tet_mesh mesh;
    assert_int_equal(piola_tet_mesh_box_grid(5, 3, 3, (piola_vec3){0.05, 0.05, 0.05}, &mesh), PIOLA_OK);
    piola_constraint_def c = {0};
    c.selector.type = PIOLA_SELECT_BOX;
    c.selector.box_min = (piola_vec3){-1, -1, -1};
    c.selector.box_max = (piola_vec3){0.01, 1, 1};
    c.driven = true;
    c.motion = piola_default_rigid_motion_def();
    c.motion.velocity[1] = piola_track_constant(0.3);
    c.motion.velocity[2] = piola_track_constant(-0.2);
    c.motion.angular_speed = piola_track_constant(2.0);
    piola_solid_def sd = piola_default_solid_def();
    sd.mesh = &mesh;
    sd.material.youngs_modulus = 5e4;
    sd.shear_viscosity = piola_track_constant(30);
    sd.bulk_viscosity = piola_track_constant(10);
    sd.velocity = (piola_vec3){0.5, 0, -1.0};
    sd.constraints = &c;
    sd.constraint_count = 1;
    assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
    piola_obstacle_def ground = piola_default_obstacle_def();
    ground.type = PIOLA_OBSTACLE_PLANE;
    ground.center = (piola_vec3){0, 0, 0.002};
    ground.axis = (piola_vec3){0, 0, 1};
    ground.friction = 0.5;
    assert_int_equal(piola_world_add_obstacle(w, &ground, NULL), PIOLA_OK);
    piola_step_stats st = {0};
    int32_t colliding = 0;
    for (int k = 0; k < STEPS; ++k) {
      assert_int_equal(piola_world_step(w, 2e-4, &st), PIOLA_OK);
      colliding += st.colliding;
    }
    assert_true(colliding > 0);
    n3 = 3 * piola_elastic_body_vertex_count(piola_world_solid_body(w, 0));
    result[reuse] = malloc((size_t)n3 * sizeof(double));
    memcpy(result[reuse], piola_world_solid_velocities(w, 0), (size_t)n3 * sizeof(double));
    for (int32_t i = 0; i < n3; ++i) vmax = fmax(vmax, fabs(result[reuse][i]));
    piola_world_destroy(w);
    free(mesh.positions);
    free(mesh.tets);
  }
  piola__step_reuse_first_product = 1;
  double d = max_difference(result[0], result[1], n3);
  print_message("reused vs full pass: max |dv| %.3g m/s (max |v| %.3g)\n", d, vmax);
  assert_true(d <= 1e-9 * vmax);
  free(result[0]);
  free(result[1]);
}

/* The fused operator the solves apply, M v - h D v, gives the same numbers as forming it
 * from piola_elastic_body_damping_forces, on a small body (serial path) and a large one (chunked,
 * parallel path), at a deformed state. */
static void fused_operator_matches_damping_forces(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(77);
  const int sizes[] = {3, 12}; /* 162 and 10,368 tets */
  for (int k = 0; k < 2; ++k) {
    piola_tet_mesh mesh = fixture_grid(sizes[k], 1.0 / sizes[k]);
    piola_material material = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
    piola_elastic_body *body = fixture_body(&mesh, &material);
    int32_t n = mesh.vertex_count;
    double *x = malloc(3 * (size_t)n * sizeof(double)), *v = malloc(3 * (size_t)n * sizeof(double));
    double *f = malloc(3 * (size_t)n * sizeof(double)), *out = malloc(3 * (size_t)n * sizeof(double));
    for (int32_t i = 0; i < 3 * n; ++i) {
      x[i] = mesh.positions[i] + 0.2 / sizes[k] * test_rng_uniform(&rng, -1, 1);
      v[i] = test_rng_uniform(&rng, -1, 1);
    }
    assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
    const double *mass = piola_elastic_body_masses(body);
    const double h = 3e-4;
    piola_elastic_body_damping_forces(body, v, 2.0, 0.7, f);
    piola__elastic_body_damping_operator(body, v, 2.0, 0.7, mass, h, out);
    for (int32_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        /* the same expression; a tolerance only for a compiler that contracts it into a
         * fused multiply-add in one place and not the other */
        double expect = mass[i] * v[3 * i + c] - h * f[3 * i + c];
        assert_close(out[3 * i + c], expect, 1e-15 * (fabs(mass[i] * v[3 * i + c]) + fabs(h * f[3 * i + c])));
      }
    free(x), free(v), free(f), free(out);
    piola_elastic_body_destroy(body);
    fixture_mesh_free(&mesh);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(free_fall_gains_exactly_gravity_momentum),
      cmocka_unit_test(default_tolerance_error_is_well_below_the_step_error),
      cmocka_unit_test(iterations_do_not_depend_on_the_body_speed),
      cmocka_unit_test(solves_do_not_depend_on_the_thread_count),
      cmocka_unit_test(large_body_does_not_depend_on_the_thread_count),
      cmocka_unit_test(fused_operator_matches_damping_forces),
      cmocka_unit_test(reused_first_product_matches_a_full_pass),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
