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
  const double frames = 36; /* fixed simulated time: the end state is checked */
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

/* One-way coupling: a cloth dropped on a soft block (a simulated solid, fixed at its base)
 * never ends a step inside the block's boundary, and drapes over it. */
static void cloth_stays_outside_a_simulated_solid(void **state) {
  (void)state;
  piola_world *world = make_world(2e-3);
  /* a 0.4 x 0.4 x 0.2 block of 2 x 2 x 1 cubes, 6 tets each */
  piola_tet_mesh block;
  memset(&block, 0, sizeof block);
  block.vertex_count = 18;
  block.tet_count = 24;
  block.positions = malloc(sizeof(double) * 54);
  block.tets = malloc(sizeof(int32_t) * 96);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        double *p = block.positions + 3 * ((k * 3 + j) * 3 + i);
        p[0] = -0.2 + 0.2 * i, p[1] = -0.2 + 0.2 * j, p[2] = 0.2 * k;
      }
  static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  int t = 0;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i)
      for (int q = 0; q < 6; ++q) {
        int c[3] = {i, j, 0};
        block.tets[4 * t] = (c[2] * 3 + c[1]) * 3 + c[0];
        for (int s = 0; s < 3; ++s) {
          c[perms[q][s]]++;
          block.tets[4 * t + 1 + s] = (c[2] * 3 + c[1]) * 3 + c[0];
        }
        ++t;
      }
  piola_solid_def sdef = piola_default_solid_def();
  sdef.mesh = &block;
  sdef.material.youngs_modulus = 2e5;
  sdef.shear_viscosity.value = 10;
  piola_constraint_def base;
  memset(&base, 0, sizeof base);
  base.selector.type = PIOLA_SELECT_BOX;
  base.selector.box_min = (piola_vec3){-1, -1, -0.01};
  base.selector.box_max = (piola_vec3){1, 1, 0.01};
  sdef.constraints = &base;
  sdef.constraint_count = 1;
  assert_int_equal(piola_world_add_solid(world, &sdef, NULL), PIOLA_OK);
  piola_tri_mesh cloth = shell_sheet(0.8, 0.8, 12, 12);
  for (int i = 0; i < cloth.vertex_count; ++i) cloth.positions[3 * i + 2] = 0.3;
  piola_shell_def def = piola_default_shell_def();
  def.mesh = &cloth;
  def.material.youngs_modulus = 1e5;
  def.density = 200;
  def.bending.stiffness = 1e-5;
  def.shear_viscosity.value = 0.5;
  def.collide_with_solids = true;
  assert_int_equal(piola_world_add_shell(world, &def, NULL), PIOLA_OK);
  int steps = 0;
  while (piola_world_time(world) < 0.3) {
    assert_int_equal(piola_world_step(world, 0, NULL), PIOLA_OK);
    ++steps;
    const double *x = piola_world_shell_positions(world, 0);
    const double *b = piola_world_solid_positions(world, 0);
    double top = 0; /* the block's current top (its top nodes) */
    for (int i = 9; i < 18; ++i) top += b[3 * i + 2] / 9;
    for (int i = 0; i < cloth.vertex_count; ++i) {
      const double *p = x + 3 * i;
      assert_true(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]));
      int inside = fabs(p[0]) < 0.19 && fabs(p[1]) < 0.19 && p[2] < top - 0.01 && p[2] > 0.01;
      if (inside) fail_msg("step %d: cloth node %d at (%g, %g, %g) is inside the block (top %g)", steps,
                           i, p[0], p[1], p[2], top);
    }
  }
  const double *x = piola_world_shell_positions(world, 0);
  assert_true(x[3 * (6 * 13 + 6) + 2] > 0.15); /* the centre rests on the block */
  assert_true(x[2] < x[3 * (6 * 13 + 6) + 2] - 0.02); /* a corner already hangs lower */
  piola_world_destroy(world);
  free(block.positions);
  free(block.tets);
  piola_tri_mesh_free(&cloth);
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
      cmocka_unit_test(cloth_stays_outside_a_simulated_solid),
      cmocka_unit_test(bad_shells_are_rejected),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
