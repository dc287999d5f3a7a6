/* Fibre directions of a tet mesh (piola_tet_mesh.tet_fibers): copied with the mesh, carried
 * by piola_tet_mesh_transform as material directions (turned by a rotation, kept in length),
 * written and read back exactly through .vtu and .msh, and non-finite ones refused. The
 * round trips with meshio and the messages for bad files are in
 * tests/scripts/test_mesh_fibers.sh. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "piola/mesh.h"
#include "piola/mesh_io.h"

static void grid_with_fibers(piola_tet_mesh *mesh, uint64_t seed) {
  assert_int_equal(piola_tet_mesh_box_grid(2, 2, 1, (piola_vec3){0.1, 0.1, 0.1}, mesh), PIOLA_OK);
  piola_tet_mesh_orient(mesh);
  mesh->tet_fibers = malloc(3 * (size_t)mesh->tet_count * sizeof(double));
  assert_non_null(mesh->tet_fibers);
  test_rng rng = test_rng_seeded(seed);
  for (int32_t i = 0; i < 3 * mesh->tet_count; ++i) mesh->tet_fibers[i] = test_rng_normal(&rng);
  mesh->tet_fibers[0] = mesh->tet_fibers[1] = mesh->tet_fibers[2] = 0; /* a zero fibre */
}

static void copy_keeps_the_fibers(void **state) {
  (void)state;
  piola_tet_mesh a = {0}, b = {0};
  grid_with_fibers(&a, 1);
  assert_int_equal(piola_tet_mesh_copy(&a, &b), PIOLA_OK);
  assert_non_null(b.tet_fibers);
  assert_true(b.tet_fibers != a.tet_fibers);
  assert_memory_equal(a.tet_fibers, b.tet_fibers, 3 * (size_t)a.tet_count * sizeof(double));
  piola_tet_mesh_free(&a);
  piola_tet_mesh_free(&b);
}

static void transform_turns_fibers_and_keeps_their_length(void **state) {
  (void)state;
  piola_tet_mesh a = {0}, before = {0};
  grid_with_fibers(&a, 2);
  assert_int_equal(piola_tet_mesh_copy(&a, &before), PIOLA_OK);
  /* a rotation by 0.7 rad about (1, 2, 2) / 3 */
  double c = cos(0.7), s = sin(0.7), u[3] = {1.0 / 3, 2.0 / 3, 2.0 / 3};
  piola_mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = (i == j ? c : 0) + (1 - c) * u[i] * u[j];
  r.m[0][1] -= s * u[2], r.m[1][0] += s * u[2];
  r.m[0][2] += s * u[1], r.m[2][0] -= s * u[1];
  r.m[1][2] -= s * u[0], r.m[2][1] += s * u[0];
  piola_vec3 shift = {0.5, -1, 2};
  assert_int_equal(piola_tet_mesh_transform(&a, r, shift), PIOLA_OK);
  for (int32_t i = 0; i < a.vertex_count; ++i)
    for (int k = 0; k < 3; ++k) {
      const double *p = before.positions + 3 * i;
      double want = r.m[k][0] * p[0] + r.m[k][1] * p[1] + r.m[k][2] * p[2] + (&shift.x)[k];
      assert_close(a.positions[3 * i + k], want, 1e-15);
    }
  for (int32_t t = 0; t < a.tet_count; ++t)
    for (int k = 0; k < 3; ++k) {
      const double *d = before.tet_fibers + 3 * t;
      double want = r.m[k][0] * d[0] + r.m[k][1] * d[1] + r.m[k][2] * d[2];
      assert_close(a.tet_fibers[3 * t + k], want, 1e-14);
    }
  /* a stretch changes a fibre's direction like a material line, not its length */
  piola_mat3 stretch = {{{3, 0, 0}, {0, 1, 0}, {0, 0, 0.5}}};
  piola_tet_mesh_free(&a);
  assert_int_equal(piola_tet_mesh_copy(&before, &a), PIOLA_OK);
  assert_int_equal(piola_tet_mesh_transform(&a, stretch, (piola_vec3){0, 0, 0}), PIOLA_OK);
  for (int32_t t = 0; t < a.tet_count; ++t) {
    const double *d = before.tet_fibers + 3 * t, *e = a.tet_fibers + 3 * t;
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    assert_close(sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]), len, 1e-14);
    if (len > 0) { /* parallel to (3 dx, dy, 0.5 dz) */
      double m[3] = {3 * d[0], d[1], 0.5 * d[2]};
      double ml = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
      for (int k = 0; k < 3; ++k) assert_close(e[k], m[k] * len / ml, 1e-14);
    }
  }
  /* a mirror or a singular map is refused, the mesh untouched */
  piola_mat3 mirror = {{{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  double x0 = a.positions[3];
  assert_int_equal(piola_tet_mesh_transform(&a, mirror, (piola_vec3){0, 0, 0}), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_true(a.positions[3] == x0);
  /* a non-finite map is a NOT_FINITE input, and the message says which part */
  piola_mat3 id = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}, bad = id;
  bad.m[1][2] = INFINITY;
  assert_int_equal(piola_tet_mesh_transform(&a, bad, (piola_vec3){0, 0, 0}),
                   PIOLA_ERROR_NOT_FINITE);
  assert_non_null(strstr(piola_last_error(), "the matrix has a non-finite entry"));
  assert_int_equal(piola_tet_mesh_transform(&a, id, (piola_vec3){0, NAN, 0}),
                   PIOLA_ERROR_NOT_FINITE);
  assert_non_null(strstr(piola_last_error(), "the translation has a non-finite entry"));
  assert_true(a.positions[3] == x0);
  piola_tet_mesh_free(&a);
  piola_tet_mesh_free(&before);
}

static void fibers_round_trip_through_piola_writers(void **state) {
  (void)state;
  piola_tet_mesh a = {0};
  grid_with_fibers(&a, 3);
  a.tet_fibers[4] = 1.0 / 3.0; /* a value that needs all 17 digits */
  char dir[] = "/tmp/piola_fibers_XXXXXX";
  assert_non_null(mkdtemp(dir));
  const char *exts[] = {".vtu", ".msh"};
  for (int e = 0; e < 2; ++e) {
    char path[256];
    snprintf(path, sizeof path, "%s/mesh%s", dir, exts[e]);
    assert_int_equal(piola_tet_mesh_write(path, &a), PIOLA_OK);
    piola_tet_mesh b = {0};
    if (piola_tet_mesh_read(path, &b) != PIOLA_OK) fail_msg("%s", piola_last_error());
    assert_int_equal(b.tet_count, a.tet_count);
    assert_non_null(b.tet_fibers);
    assert_memory_equal(a.tet_fibers, b.tet_fibers, 3 * (size_t)a.tet_count * sizeof(double));
    piola_tet_mesh_free(&b);
    remove(path);
  }
  /* no fibres in, none out */
  free(a.tet_fibers);
  a.tet_fibers = NULL;
  for (int e = 0; e < 2; ++e) {
    char path[256];
    snprintf(path, sizeof path, "%s/plain%s", dir, exts[e]);
    assert_int_equal(piola_tet_mesh_write(path, &a), PIOLA_OK);
    piola_tet_mesh b = {0};
    assert_int_equal(piola_tet_mesh_read(path, &b), PIOLA_OK);
    assert_null(b.tet_fibers);
    piola_tet_mesh_free(&b);
    remove(path);
  }
  rmdir(dir);
  piola_tet_mesh_free(&a);
}

static void non_finite_fibers_are_refused(void **state) {
  (void)state;
  piola_tet_mesh a = {0};
  grid_with_fibers(&a, 4);
  assert_int_equal(piola_tet_mesh_validate(&a), PIOLA_OK);
  a.tet_fibers[3 * 5 + 1] = NAN;
  assert_int_equal(piola_tet_mesh_validate(&a), PIOLA_ERROR_NOT_FINITE);
  assert_non_null(strstr(piola_last_error(), "tet 5: fibre direction is not finite"));
  piola_tet_mesh_free(&a);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(copy_keeps_the_fibers),
      cmocka_unit_test(transform_turns_fibers_and_keeps_their_length),
      cmocka_unit_test(fibers_round_trip_through_piola_writers),
      cmocka_unit_test(non_finite_fibers_are_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
