/* piola_tet_mesh_box_grid: a structured box of 6 tets per cell. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "piola/mesh.h"
#include "piola/mesh_quality.h"
#include "test_support.h"

static void grid_fills_the_box_conformingly(void **state) {
  (void)state;
  const int nx = 3, ny = 2, nz = 4;
  const piola_vec3 h = {0.1, 0.25, 0.05};
  piola_tet_mesh m;
  assert_int_equal(piola_tet_mesh_box_grid(nx, ny, nz, h, &m), PIOLA_OK);
  assert_int_equal(m.vertex_count, (nx + 1) * (ny + 1) * (nz + 1));
  assert_int_equal(m.tet_count, 6 * nx * ny * nz);
  /* the documented vertex numbering and placement */
  const double *p = m.positions + 3 * (2 + (nx + 1) * (1 + (ny + 1) * 3));
  assert_close(p[0], 2 * h.x, 1e-15);
  assert_close(p[1], 1 * h.y, 1e-15);
  assert_close(p[2], 3 * h.z, 1e-15);
  /* every tet is a sixth of its cell, none degenerate, and together they fill the box */
  double cell = h.x * h.y * h.z, total = 0;
  for (int32_t t = 0; t < m.tet_count; ++t) {
    double v = piola_tet_mesh_signed_volume(&m, t);
    assert_close(fabs(v), cell / 6, 1e-12 * cell);
    total += fabs(v);
  }
  assert_close(total, nx * ny * nz * cell, 1e-12 * nx * ny * nz * cell);
  /* after orientation the boundary is the box surface: closed, manifold, genus 0, and
   * 2 triangles per boundary cell face */
  piola_tet_mesh_orient(&m);
  for (int32_t t = 0; t < m.tet_count; ++t) assert_true(piola_tet_mesh_signed_volume(&m, t) > 0);
  piola_tri_mesh surface;
  assert_int_equal(piola_tet_mesh_boundary(&m, &surface), PIOLA_OK);
  assert_int_equal(surface.triangle_count, 4 * (nx * ny + ny * nz + nx * nz));
  piola_surface_topology topology;
  assert_int_equal(piola_tri_mesh_topology(&surface, &topology), PIOLA_OK);
  assert_true(topology.closed);
  assert_true(topology.manifold);
  assert_int_equal(topology.euler_characteristic, 2);
  assert_close(piola_tri_mesh_enclosed_volume(&surface), nx * ny * nz * cell, 1e-12);
  piola_tri_mesh_free(&surface);
  piola_tet_mesh_free(&m);
}

static void bad_grids_are_refused(void **state) {
  (void)state;
  piola_tet_mesh m;
  assert_int_equal(piola_tet_mesh_box_grid(0, 1, 1, (piola_vec3){1, 1, 1}, &m),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "cell counts"));
  assert_int_equal(piola_tet_mesh_box_grid(1, 1, 1, (piola_vec3){1, -1, 1}, &m),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_tet_mesh_box_grid(1, 1, 1, (piola_vec3){1, NAN, 1}, &m),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_tet_mesh_box_grid(2000, 2000, 2000, (piola_vec3){1, 1, 1}, &m),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  assert_null(m.positions);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(grid_fills_the_box_conformingly),
      cmocka_unit_test(bad_grids_are_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
