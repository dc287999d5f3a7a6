/* Shells in motion, with a plain explicit integrator written here (the world's integrator
 * has its own tests): a hanging cloth comes to rest without NaN, a cloth dropped on a sphere
 * never ends a step inside it, and in-plane plasticity keeps a stretch. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/obstacle.h"
#include "test_shell_fixtures.h"

typedef struct cloth_run {
  piola_shell_body *body;
  int n;
  double *x, *v, *f, *fd;
  const double *mass;
  uint8_t *pinned;
} cloth_run;

static cloth_run cloth_start(const piola_tri_mesh *mesh, double bending, double bending_damping) {
  piola_material material = shell_material(PIOLA_MODEL_NEOHOOKEAN, 1e5);
  piola_shell_body_def def = piola_default_shell_body_def();
  def.rest_mesh = mesh;
  def.materials = &material;
  def.material_count = 1;
  def.thickness = 1e-3;
  def.density = 200;
  def.bending.stiffness = bending;
  def.bending.damping = bending_damping;
  cloth_run run;
  memset(&run, 0, sizeof run);
  assert_int_equal(piola_shell_body_create(&def, &run.body), PIOLA_OK);
  run.n = mesh->vertex_count;
  run.x = malloc(sizeof(double) * 3 * run.n);
  run.v = calloc(3 * (size_t)run.n, sizeof(double));
  run.f = malloc(sizeof(double) * 3 * run.n);
  run.fd = malloc(sizeof(double) * 3 * run.n);
  run.pinned = calloc((size_t)run.n, 1);
  run.mass = piola_shell_body_masses(run.body);
  memcpy(run.x, mesh->positions, sizeof(double) * 3 * run.n);
  return run;
}

static void cloth_free(cloth_run *run) {
  piola_shell_body_destroy(run->body);
  free(run->x);
  free(run->v);
  free(run->f);
  free(run->fd);
  free(run->pinned);
}

/* Symplectic Euler: elastic + damping + gravity (-z) + air drag (drag / s times m v). */
static void cloth_step(cloth_run *run, double dt, double drag) {
  assert_int_equal(piola_shell_body_update(run->body, run->x, 1.0, run->f, NULL), PIOLA_OK);
  piola_shell_body_damping_forces(run->body, run->v, 0.5, 0.5, run->fd);
  for (int i = 0; i < run->n; ++i) {
    if (run->pinned[i]) continue;
    for (int k = 0; k < 3; ++k) {
      double force = run->f[3 * i + k] + run->fd[3 * i + k] - drag * run->mass[i] * run->v[3 * i + k];
      if (k == 2) force -= 9.81 * run->mass[i];
      run->v[3 * i + k] += dt * force / run->mass[i];
      run->x[3 * i + k] += dt * run->v[3 * i + k];
    }
  }
}

static void hanging_cloth_comes_to_rest(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_sheet(0.5, 0.5, 10, 10);
  cloth_run run = cloth_start(&mesh, 1e-5, 1e-6);
  /* pin the two corners of the edge y = +0.25 */
  run.pinned[10 * 11] = run.pinned[10 * 11 + 10] = 1;
  const double dt = 4e-4;
  /* a fixed simulated time: the end state is what the test checks, so it does not scale */
  const int steps = (int)(6.0 / dt);
  double max_speed = 0;
  for (int s = 0; s < steps; ++s) cloth_step(&run, dt, s * dt < 0.5 * steps * dt ? 1.0 : 4.0);
  for (int i = 0; i < 3 * run.n; ++i) {
    assert_true(isfinite(run.x[i]) && isfinite(run.v[i]));
    max_speed = fmax(max_speed, fabs(run.v[i]));
  }
  printf("hanging cloth after %d steps: max speed %.3g m/s\n", steps, max_speed);
  assert_true(max_speed < 5e-3);
  /* it hangs: every free node below the pins, the far edge about a sheet length below */
  for (int i = 0; i < run.n; ++i)
    if (!run.pinned[i]) assert_true(run.x[3 * i + 2] < 1e-3);
  assert_true(run.x[3 * 5 + 2] < -0.4);
  /* at rest the forces balance gravity: the pins carry the weight */
  assert_int_equal(piola_shell_body_update(run.body, run.x, 1.0, run.f, NULL), PIOLA_OK);
  double weight = 0, worst = 0;
  for (int i = 0; i < run.n; ++i) weight += 9.81 * run.mass[i];
  for (int i = 0; i < run.n; ++i)
    if (!run.pinned[i])
      worst = fmax(worst, fabs(run.f[3 * i + 2] - 9.81 * run.mass[i]) / weight);
  assert_true(worst < 0.01);
  cloth_free(&run);
  piola_tri_mesh_free(&mesh);
}

static void cloth_nodes_stay_outside_obstacles(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_sheet(0.6, 0.6, 12, 12);
  for (int i = 0; i < mesh.vertex_count; ++i) mesh.positions[3 * i + 2] = 0.25;
  cloth_run run = cloth_start(&mesh, 1e-5, 1e-6);
  piola_obstacle_def sphere_def = piola_default_obstacle_def();
  sphere_def.type = PIOLA_OBSTACLE_SPHERE;
  sphere_def.center = (piola_vec3){0.05, 0, 0};
  sphere_def.radius = 0.15;
  sphere_def.friction = 0.3;
  piola_obstacle_def ground_def = piola_default_obstacle_def();
  ground_def.type = PIOLA_OBSTACLE_PLANE;
  ground_def.center = (piola_vec3){0, 0, -0.12};
  ground_def.axis = (piola_vec3){0, 0, 1};
  piola_obstacle *obstacles[2];
  assert_int_equal(piola_obstacle_create(&sphere_def, &obstacles[0]), PIOLA_OK);
  assert_int_equal(piola_obstacle_create(&ground_def, &obstacles[1]), PIOLA_OK);
  const double dt = 4e-4;
  const int steps = (int)(1.0 / dt); /* fixed simulated time, as above */
  int touched = 0;
  for (int s = 0; s < steps; ++s) {
    cloth_step(&run, dt, 0.5);
    int32_t hits = piola_obstacles_collide(obstacles, 2, (s + 1) * dt, dt, run.n, run.x, run.v,
                                           NULL, NULL);
    assert_true(hits >= 0);
    touched += hits > 0;
    for (int i = 0; i < run.n; ++i) {
      piola_vec3 p = {run.x[3 * i], run.x[3 * i + 1], run.x[3 * i + 2]};
      for (int o = 0; o < 2; ++o)
        assert_true(piola_obstacle_signed_distance(obstacles[o], (s + 1) * dt, p, NULL, NULL) >= -1e-9);
      assert_true(isfinite(run.v[3 * i]) && isfinite(run.v[3 * i + 1]) && isfinite(run.v[3 * i + 2]));
    }
  }
  assert_true(touched > 0);
  /* the cloth drapes: its centre rests on top of the sphere, its corners hang lower */
  assert_close(run.x[3 * (6 * 13 + 6) + 2], 0.15, 0.02);
  assert_true(run.x[2] < 0.0);
  piola_obstacle_destroy(obstacles[0]);
  piola_obstacle_destroy(obstacles[1]);
  cloth_free(&run);
  piola_tri_mesh_free(&mesh);
}

/* In-plane plasticity: a triangle stretched past the yield strain flows so that its elastic
 * stretch is back at the yield surface (rate infinite); the plastic stretch is capped; a
 * stretch within yield, and a collapsed triangle, do not flow. */
static void inplane_plasticity_keeps_a_stretch(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_single_triangle(1.0);
  piola_material material = shell_material(PIOLA_MODEL_COROTATED, 1e5);
  piola_shell_body_def def = shell_def_of(&mesh, &material);
  def.plasticity.yield_strain = 0.1;
  def.plasticity.max_plastic_stretch = 2.0;
  piola_shell_body *body;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_OK);
  double x[9], f[9];
  /* within yield */
  memcpy(x, mesh.positions, sizeof x);
  for (int i = 0; i < 3; ++i) x[3 * i] *= 1.05;
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  assert_int_equal(piola_shell_body_plastic_flow(body, 0.01), 0);
  /* past yield: 1.5 x along x */
  for (int i = 0; i < 3; ++i) x[3 * i] = 1.5 * mesh.positions[3 * i];
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  assert_int_equal(piola_shell_body_plastic_flow(body, 0.01), 1);
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  assert_close(piola_shell_body_fhat(body)[0], exp(0.1), 1e-12);
  assert_close(piola_shell_body_fhat(body)[1], 1.0, 1e-12);
  /* the rest shape is now longer: released at 1.5/exp(0.1) x, it feels no force */
  for (int i = 0; i < 3; ++i) x[3 * i] = 1.5 / exp(0.1) * mesh.positions[3 * i];
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  assert_true(shell_max_abs(f, 9) < 1e-6);
  /* a huge stretch is capped by max_plastic_stretch = 2 */
  for (int s = 0; s < 5; ++s) {
    for (int i = 0; i < 3; ++i) x[3 * i] = 10 * mesh.positions[3 * i];
    assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
    piola_shell_body_plastic_flow(body, 0.01);
  }
  const double *fpi = piola_shell_body_fp_inverse(body);
  double a = fpi[0] * fpi[0] + fpi[2] * fpi[2], b = fpi[0] * fpi[1] + fpi[2] * fpi[3],
         c = fpi[1] * fpi[1] + fpi[3] * fpi[3];
  double smallest = sqrt(0.5 * (a + c) - sqrt(0.25 * (a - c) * (a - c) + b * b));
  assert_true(smallest >= 0.5 - 1e-12); /* Fp's largest stretch <= 2 */
  /* a collapsed triangle does not flow */
  double line[9] = {0, 0, 0, 3, 0, 0, 1, 0, 0};
  assert_int_equal(piola_shell_body_update(body, line, 1.0, f, NULL), PIOLA_OK);
  assert_int_equal(piola_shell_body_plastic_flow(body, 0.01), 0);
  piola_shell_body_destroy(body);
  piola_tri_mesh_free(&mesh);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(hanging_cloth_comes_to_rest),
      cmocka_unit_test(cloth_nodes_stay_outside_obstacles),
      cmocka_unit_test(inplane_plasticity_keeps_a_stretch),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
