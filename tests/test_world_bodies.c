/* The world's body table (piola/world_bodies.h): one id per body whatever its kind, ids
 * that survive insertions and refuse what names no body, accessors and stats that agree with
 * the kind-specific ones and with sums over the nodes, and a result that does not depend on
 * the order in which solids and shells were added. A NULL world is refused, never read. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "piola/checkpoint.h"
#include "piola/world_bodies.h"
#include "piola/world_shells.h"
#include "test_shell_fixtures.h"

static piola_tet_mesh block(int n, double size, double z0) {
  piola_tet_mesh m;
  assert_int_equal(piola_tet_mesh_box_grid(n, n, n, (piola_vec3){size / n, size / n, size / n}, &m),
                   PIOLA_OK);
  for (int32_t i = 0; i < m.vertex_count; ++i) {
    m.positions[3 * i] -= 0.5 * size, m.positions[3 * i + 1] -= 0.5 * size;
    m.positions[3 * i + 2] += z0;
  }
  return m;
}

static void free_tets(piola_tet_mesh *m) { free(m->positions), free(m->tets); }

static piola_world *make_world(void) {
  piola_world_def wdef = piola_default_world_def();
  wdef.max_dt = 1e-3;
  piola_world *w;
  assert_int_equal(piola_world_create(&wdef, &w), PIOLA_OK);
  piola_obstacle_def ground = piola_default_obstacle_def();
  assert_int_equal(piola_world_add_obstacle(w, &ground, NULL), PIOLA_OK);
  return w;
}

static piola_solid_def solid_def(const piola_tet_mesh *mesh, const char *name) {
  piola_solid_def d = piola_default_solid_def();
  d.mesh = mesh;
  d.name = name;
  d.material.youngs_modulus = 2e4;
  d.shear_viscosity.value = 5;
  d.self_collision.enabled = true;
  d.self_collision.thickness = 2e-3;
  return d;
}

static piola_shell_def shell_def(const piola_tri_mesh *mesh, const char *name) {
  piola_shell_def d = piola_default_shell_def();
  d.mesh = mesh;
  d.name = name;
  d.material.youngs_modulus = 1e5;
  d.density = 200;
  d.bending.stiffness = 1e-5;
  d.shear_viscosity.value = 0.5;
  d.collide_with_solids = true;
  d.self_collision.enabled = true;
  d.self_collision.thickness = 2e-3;
  return d;
}

/* A sheet 0.4 m wide (8 x 8 cells) at height z, m. */
static piola_tri_mesh sheet_above(double z) {
  piola_tri_mesh m = shell_sheet(0.4, 0.4, 8, 8);
  for (int32_t i = 0; i < m.vertex_count; ++i) m.positions[3 * i + 2] = z;
  return m;
}

/* Ids name the body they were given for, through the move of the shells when a solid is
 * added after them; positions in the table follow the step order (solids, then shells). */
static void ids_survive_insertions(void **state) {
  (void)state;
  piola_tet_mesh cube = block(2, 0.2, 0.0);
  piola_tri_mesh sheet = sheet_above(0.3);
  piola_world *w = make_world();
  piola_shell_def sd = shell_def(&sheet, "cloth");
  piola_solid_def bd = solid_def(&cube, "cube");
  int32_t index = -1;
  assert_int_equal(piola_world_add_shell(w, &sd, &index), PIOLA_OK);
  assert_int_equal(index, 0);
  piola_body_id cloth = piola_world_body_of(w, PIOLA_BODY_SHELL, 0);
  assert_true(cloth != PIOLA_NO_BODY);
  assert_int_equal(piola_world_body_at(w, 0), cloth);
  assert_int_equal(piola_world_add_solid(w, &bd, &index), PIOLA_OK);
  assert_int_equal(index, 0);
  bd.name = "cube2";
  assert_int_equal(piola_world_add_solid(w, &bd, &index), PIOLA_OK);
  assert_int_equal(index, 1);
  assert_int_equal(piola_world_body_count(w), 3);
  /* the cloth moved to the end of the table; its id did not change */
  assert_int_equal(piola_world_body_at(w, 2), cloth);
  assert_int_equal(piola_world_body_of(w, PIOLA_BODY_SHELL, 0), cloth);
  assert_int_equal(piola_world_body_kind(w, cloth), PIOLA_BODY_SHELL);
  assert_int_equal(piola_world_body_index(w, cloth), 0);
  assert_string_equal(piola_world_body_name(w, cloth), "cloth");
  const char *names[3] = {"cube", "cube2", "cloth"};
  for (int32_t p = 0; p < 3; ++p) {
    piola_body_id id = piola_world_body_at(w, p);
    assert_string_equal(piola_world_body_name(w, id), names[p]);
    assert_int_equal(piola_world_body_kind(w, id), p < 2 ? PIOLA_BODY_SOLID : PIOLA_BODY_SHELL);
    for (int32_t q = 0; q < p; ++q) assert_true(piola_world_body_at(w, q) != id);
  }
  /* the body accessors and the kind-specific ones show the same data */
  for (int32_t s = 0; s < 2; ++s) {
    piola_body_id id = piola_world_body_of(w, PIOLA_BODY_SOLID, s);
    assert_int_equal(piola_world_body_index(w, id), s);
    assert_ptr_equal(piola_world_body_positions(w, id), piola_world_solid_positions(w, s));
    assert_ptr_equal(piola_world_body_velocities(w, id), piola_world_solid_velocities(w, s));
    assert_ptr_equal(piola_world_body_constraint_flags(w, id), piola_world_solid_constraint_flags(w, s));
    const piola_elastic_body *b = piola_world_solid_body(w, s);
    assert_int_equal(piola_world_body_node_count(w, id), piola_elastic_body_vertex_count(b));
    assert_int_equal(piola_world_body_element_count(w, id), piola_elastic_body_tet_count(b));
    assert_memory_equal(piola_world_body_masses(w, id), piola_elastic_body_masses(b),
                        sizeof(double) * (size_t)piola_elastic_body_vertex_count(b));
  }
  assert_ptr_equal(piola_world_body_positions(w, cloth), piola_world_shell_positions(w, 0));
  assert_int_equal(piola_world_body_node_count(w, cloth), sheet.vertex_count);
  assert_int_equal(piola_world_body_element_count(w, cloth), sheet.triangle_count);
  piola_world_destroy(w);
  free_tets(&cube);
  piola_tri_mesh_free(&sheet);
}

/* What names no body is refused, never read as another body: no id, a made-up slot, a real
 * slot with another generation; a failed add leaves the table and every id as they were. */
static void ids_that_name_no_body_are_refused(void **state) {
  (void)state;
  piola_tet_mesh cube = block(2, 0.2, 0.0);
  piola_world *w = make_world();
  piola_solid_def bd = solid_def(&cube, "cube");
  assert_int_equal(piola_world_add_solid(w, &bd, NULL), PIOLA_OK);
  piola_body_id id = piola_world_body_at(w, 0);
  const piola_body_id bad[] = {PIOLA_NO_BODY, id + 1, id + ((piola_body_id)1 << 32),
                               id - ((piola_body_id)1 << 32), ~(piola_body_id)0};
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
    assert_int_equal(piola_world_body_kind(w, bad[k]), PIOLA_BODY_NONE);
    assert_int_equal(piola_world_body_index(w, bad[k]), -1);
    assert_null(piola_world_body_name(w, bad[k]));
    assert_int_equal(piola_world_body_node_count(w, bad[k]), -1);
    assert_int_equal(piola_world_body_element_count(w, bad[k]), -1);
    assert_null(piola_world_body_positions(w, bad[k]));
    assert_null(piola_world_body_velocities(w, bad[k]));
    assert_null(piola_world_body_masses(w, bad[k]));
    assert_null(piola_world_body_constraint_flags(w, bad[k]));
    assert_int_equal(piola_world_body_set_state(w, bad[k], NULL, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
    piola_body_stats st = piola_world_body_stats(w, bad[k]);
    assert_true(st.kinetic_energy == 0 && st.elastic_energy == 0 && st.inverted_count == 0);
  }
  assert_int_equal(piola_world_body_at(w, -1), PIOLA_NO_BODY);
  assert_int_equal(piola_world_body_at(w, 1), PIOLA_NO_BODY);
  assert_int_equal(piola_world_body_of(w, PIOLA_BODY_SHELL, 0), PIOLA_NO_BODY);
  assert_int_equal(piola_world_body_of(w, PIOLA_BODY_NONE, 0), PIOLA_NO_BODY);
  /* a failed add (a degenerate tet) */
  piola_tet_mesh flat = block(1, 0.2, 0.0);
  for (int32_t i = 0; i < flat.vertex_count; ++i) flat.positions[3 * i + 2] = 0;
  piola_solid_def fd = solid_def(&flat, "flat");
  assert_int_not_equal(piola_world_add_solid(w, &fd, NULL), PIOLA_OK);
  assert_int_equal(piola_world_body_count(w), 1);
  assert_int_equal(piola_world_solid_count(w), 1);
  assert_int_equal(piola_world_body_at(w, 0), id);
  assert_string_equal(piola_world_body_name(w, id), "cube");
  /* the next body gets an id of its own that no earlier one had */
  bd.name = "second";
  assert_int_equal(piola_world_add_solid(w, &bd, NULL), PIOLA_OK);
  piola_body_id second = piola_world_body_at(w, 1);
  assert_true(second != id && second != PIOLA_NO_BODY);
  assert_string_equal(piola_world_body_name(w, second), "second");
  assert_string_equal(piola_world_body_name(w, id), "cube");
  piola_world_destroy(w);
  free_tets(&cube);
  free_tets(&flat);
}

/* A NULL world: the status functions say so, the getters give their neutral values; and the
 * checkpoint calls take a NULL why and refuse a negative frame before writing anything. */
static void a_null_world_is_refused(void **state) {
  (void)state;
  piola_step_stats stats;
  assert_int_equal(piola_world_step(NULL, 0, &stats), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "NULL world"));
  assert_int_equal(piola_world_advance_to(NULL, 1, &stats), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "NULL world"));
  assert_int_equal(piola_world_solid_set_state(NULL, 0, NULL, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  piola_tet_mesh cube = block(1, 0.2, 0.0);
  piola_solid_def bd = solid_def(&cube, "cube");
  assert_int_equal(piola_world_add_solid(NULL, &bd, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  piola_obstacle_def ground = piola_default_obstacle_def();
  assert_int_equal(piola_world_add_obstacle(NULL, &ground, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_true(isnan(piola_world_time(NULL)));
  assert_true(isnan(piola_world_stable_dt(NULL)));
  assert_int_equal(piola_world_integrator(NULL), PIOLA_INTEGRATOR_COUNT);
  assert_int_equal(piola_world_solid_count(NULL), 0);
  assert_int_equal(piola_world_obstacle_count(NULL), 0);
  piola_world *w = make_world();
  assert_int_equal(piola_world_add_solid(w, &bd, NULL), PIOLA_OK);
  assert_int_equal(piola_world_checkpoint_supported(w, NULL), 1);
  char dir[64], path[96];
  assert_int_equal(test_make_scratch_folder(dir, sizeof dir, "piola_null_world"), 0);
  snprintf(path, sizeof path, "%s/c.bin", dir);
  uint64_t key = piola_world_scene_key(w, NULL, 0);
  /* a NULL world adds no body to the scene's key */
  assert_true(piola_world_scene_key(NULL, "{}", 2) != piola_world_scene_key(w, "{}", 2));
  assert_true(piola_world_scene_key(NULL, "{}", 2) == piola_world_scene_key(NULL, "{}", 2));
  assert_int_equal(piola_world_checkpoint_write(w, path, key, -1), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "frame must be >= 0, got -1"));
  assert_int_equal(access(path, F_OK), -1);
  assert_int_equal(piola_world_checkpoint_write(w, path, key, 0), PIOLA_OK);
  int32_t frame = -1;
  assert_int_equal(piola_world_checkpoint_read(w, path, key, &frame), PIOLA_OK);
  assert_int_equal(frame, 0);
  assert_int_equal(test_remove_scratch_folder(dir), 0);
  piola_world_destroy(w);
  free_tets(&cube);
}

/* Body stats: the kinetic energy and momentum are the sums over the nodes, and the energies
 * are those of the kind-specific stats. */
static void stats_agree_with_the_nodes_and_the_kinds(void **state) {
  (void)state;
  piola_tet_mesh cube = block(2, 0.2, 0.05);
  piola_tri_mesh sheet = sheet_above(0.4);
  piola_world *w = make_world();
  piola_solid_def bd = solid_def(&cube, "cube");
  bd.velocity = (piola_vec3){0.3, -0.2, 0.1};
  bd.initial_matrix.m[0][0] = 1.1; /* stretched: some elastic energy */
  piola_shell_def sd = shell_def(&sheet, "cloth");
  sd.velocity = (piola_vec3){0, 0.5, 0};
  assert_int_equal(piola_world_add_solid(w, &bd, NULL), PIOLA_OK);
  assert_int_equal(piola_world_add_shell(w, &sd, NULL), PIOLA_OK);
  for (int step = 0; step < 2; ++step) {
    for (int32_t p = 0; p < piola_world_body_count(w); ++p) {
      piola_body_id id = piola_world_body_at(w, p);
      piola_body_stats st = piola_world_body_stats(w, id);
      const double *v = piola_world_body_velocities(w, id), *m = piola_world_body_masses(w, id);
      double ke = 0, mom[3] = {0, 0, 0}, speed2 = 0;
      for (int32_t i = 0; i < piola_world_body_node_count(w, id); ++i)
        for (int k = 0; k < 3; ++k) {
          ke += 0.5 * m[i] * v[3 * i + k] * v[3 * i + k];
          mom[k] += m[i] * v[3 * i + k];
          speed2 += v[3 * i + k] * v[3 * i + k];
        }
      assert_true(speed2 > 0);
      assert_close(st.kinetic_energy, ke, 1e-12 * ke);
      for (int k = 0; k < 3; ++k) assert_close(st.momentum[k], mom[k], 1e-12 * sqrt(2 * ke));
      if (piola_world_body_kind(w, id) == PIOLA_BODY_SOLID) {
        piola_solid_stats s = piola_world_solid_stats(w, piola_world_body_index(w, id));
        assert_true(s.elastic_energy > 0);
        assert_true(st.kinetic_energy == s.kinetic_energy && st.elastic_energy == s.elastic_energy);
        assert_int_equal(st.inverted_count, s.inverted_count);
      } else {
        piola_world_shell_stats s = piola_world_shell_get_stats(w, piola_world_body_index(w, id));
        assert_close(st.kinetic_energy, s.kinetic_energy, 1e-15 * ke);
        assert_true(st.elastic_energy == s.membrane_energy + s.bending_energy);
        assert_int_equal(st.inverted_count, s.inverted_count);
      }
    }
    assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  }
  /* set_state through the id is the solid's set_state */
  piola_body_id cube_id = piola_world_body_of(w, PIOLA_BODY_SOLID, 0);
  int32_t n = piola_world_body_node_count(w, cube_id);
  double *v = calloc(3 * (size_t)n, sizeof *v);
  assert_int_equal(piola_world_body_set_state(w, cube_id, NULL, v), PIOLA_OK);
  assert_true(piola_world_body_stats(w, cube_id).kinetic_energy == 0);
  free(v);
  piola_world_destroy(w);
  free_tets(&cube);
  piola_tri_mesh_free(&sheet);
}

/* A cloth falling on a block, both in the collision surface and the cloth coupled one-way to
 * the block: the same bits whether the shell or the solids were added first (bodies step
 * and enter the collision surface in kind order). */
static void result_does_not_depend_on_the_order_of_adds(void **state) {
  (void)state;
  piola_tet_mesh cube = block(2, 0.2, 0.0), cube2 = block(2, 0.1, 0.0);
  for (int32_t i = 0; i < cube2.vertex_count; ++i) cube2.positions[3 * i] += 0.4;
  piola_tri_mesh sheet = sheet_above(0.201);
  double *result[2][3];
  const int steps = 60; /* the cloth meets the sagging block after ~40 */
  for (int order = 0; order < 2; ++order) {
    piola_world *w = make_world();
    piola_solid_def a = solid_def(&cube, "a"), b = solid_def(&cube2, "b");
    piola_shell_def s = shell_def(&sheet, "cloth");
    if (order == 0) {
      assert_int_equal(piola_world_add_solid(w, &a, NULL), PIOLA_OK);
      assert_int_equal(piola_world_add_solid(w, &b, NULL), PIOLA_OK);
      assert_int_equal(piola_world_add_shell(w, &s, NULL), PIOLA_OK);
    } else {
      assert_int_equal(piola_world_add_shell(w, &s, NULL), PIOLA_OK);
      assert_int_equal(piola_world_add_solid(w, &a, NULL), PIOLA_OK);
      assert_int_equal(piola_world_add_solid(w, &b, NULL), PIOLA_OK);
    }
    piola_step_stats stats = {0};
    for (int k = 0; k < steps; ++k) {
      piola_step_stats one;
      assert_int_equal(piola_world_step(w, 0, &one), PIOLA_OK);
      stats.contacts += one.contacts;
      stats.colliding += one.colliding;
    }
    assert_true(stats.colliding > 0); /* the block rests on the ground */
    assert_true(stats.contacts > 0);  /* and the cloth on the block */
    const piola_body_id ids[3] = {piola_world_body_of(w, PIOLA_BODY_SOLID, 0),
                                  piola_world_body_of(w, PIOLA_BODY_SOLID, 1),
                                  piola_world_body_of(w, PIOLA_BODY_SHELL, 0)};
    for (int k = 0; k < 3; ++k) {
      size_t bytes = 3 * sizeof(double) * (size_t)piola_world_body_node_count(w, ids[k]);
      result[order][k] = malloc(2 * bytes);
      memcpy(result[order][k], piola_world_body_positions(w, ids[k]), bytes);
      memcpy((char *)result[order][k] + bytes, piola_world_body_velocities(w, ids[k]), bytes);
    }
    if (order == 1) {
      for (int k = 0; k < 3; ++k) {
        size_t bytes = 3 * sizeof(double) * (size_t)piola_world_body_node_count(w, ids[k]);
        assert_memory_equal(result[0][k], result[1][k], 2 * bytes);
      }
    }
    piola_world_destroy(w);
  }
  for (int o = 0; o < 2; ++o)
    for (int k = 0; k < 3; ++k) free(result[o][k]);
  free_tets(&cube), free_tets(&cube2);
  piola_tri_mesh_free(&sheet);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(ids_survive_insertions),
      cmocka_unit_test(ids_that_name_no_body_are_refused),
      cmocka_unit_test(a_null_world_is_refused),
      cmocka_unit_test(stats_agree_with_the_nodes_and_the_kinds),
      cmocka_unit_test(result_does_not_depend_on_the_order_of_adds),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
