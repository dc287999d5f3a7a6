/* The elastic body on real meshes from /work/shared/data read by the mesh reader: rest
 * state, fast loop against the scalar reference with inverted tets, 1 thread against 2 (a
 * real comparison only for the torus: small bodies run on one thread). */
#include <math.h>
#include <stdlib.h>

#include "force/elastic_body_internal.h"
#include "support/elastic_referees.h"
#include "piola/mesh_io.h"
#include "test_elastic_body_fixtures.h"

static void check_mesh(const char *relative) {
  piola_tet_mesh mesh;
  piola_status status = piola_tet_mesh_read(test_data_path(relative), &mesh);
  if (status != PIOLA_OK) fail_msg("%s: %s", relative, piola_last_error());
  test_rng rng = test_rng_seeded(41);
  piola_material material = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
  piola_elastic_body *body = fixture_body(&mesh, &material);
  int n = 3 * mesh.vertex_count;
  double *f = malloc(sizeof(double) * (size_t)n), *g = malloc(sizeof(double) * (size_t)n);
  double *x = malloc(sizeof(double) * (size_t)n);

  /* rest: zero force, positive lumped masses summing to density * volume */
  piola_elastic_stats stats;
  assert_int_equal(piola_elastic_body_update(body, mesh.positions, 1.0, f, &stats), PIOLA_OK);
  double mass = 0, volume = 0;
  for (int v = 0; v < mesh.vertex_count; ++v) mass += piola_elastic_body_masses(body)[v];
  const int32_t *tets = piola_elastic_body_tets(body);
  for (int t = 0; t < mesh.tet_count; ++t) {
    double vol = fixture_signed_volume(mesh.positions, tets + 4 * t);
    assert_true(vol > 0);
    volume += vol;
  }
  assert_close(mass, 1000.0 * volume, 1e-9 * mass);
  double extent = 0;
  for (int i = 0; i < n; ++i) extent = fmax(extent, fabs(mesh.positions[i]));
  double force_scale = 1e4 * extent * extent; /* E times an area */
  assert_true(fixture_max_abs(f, n) <= 1e-9 * force_scale);
  assert_int_equal(stats.inverted_count, 0);

  /* deformed with some inverted tets: fast loop = reference; 1 thread = 2 threads */
  double h = cbrt(volume / mesh.tet_count); /* a typical edge */
  for (int i = 0; i < n; ++i) x[i] = mesh.positions[i] + 0.7 * h * test_rng_uniform(&rng, -1, 1);
  assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, &stats), PIOLA_OK);
  if (!(stats.inverted_count > 0)) fail_msg("%s: no inverted tet (of %d)", relative, (int)mesh.tet_count);
  assert_int_equal(piola__elastic_body_update_reference(body, x, 1.0, g, NULL), PIOLA_OK);
  double scale = fixture_max_abs(g, n);
  for (int i = 0; i < n; ++i)
    if (!(fabs(f[i] - g[i]) <= 1e-9 * scale)) fail_msg("%s dof %d: %.15g vs %.15g", relative, i, f[i], g[i]);
  piola_set_thread_count(1);
  assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  piola_set_thread_count(2);
  assert_int_equal(piola_elastic_body_update(body, x, 1.0, g, NULL), PIOLA_OK);
  piola_set_thread_count(0);
  assert_memory_equal(f, g, sizeof(double) * (size_t)n);

  free(f);
  free(g);
  free(x);
  piola_elastic_body_destroy(body);
  piola_tet_mesh_free(&mesh);
}

static void real_meshes_rest_reference_and_determinism(void **state) {
  (void)state;
  check_mesh("gmsh/bar-186.msh");
  check_mesh("gmsh/torus.msh");
  check_mesh("gmsh/msh_tetra.msh");
  check_mesh("vega/torus-easy.veg"); /* 97,878 tets: the loops run in parallel */
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(real_meshes_rest_reference_and_determinism),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
