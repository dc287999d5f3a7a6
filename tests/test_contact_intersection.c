/* The exact triangle-triangle intersection referee used by the collision tests. */
#include "test_support.h"

#include <math.h>

#include "contact/triangle_intersection.h"

static int meet(const double p[3][3], const double q[3][3]) {
  const double *const a[3] = {p[0], p[1], p[2]}, *const b[3] = {q[0], q[1], q[2]};
  int r = piola__triangles_intersect(a, b);
  /* The answer does not depend on the order of the triangles or of their vertices. */
  const double *const c[3] = {q[2], q[0], q[1]}, *const d[3] = {p[1], p[0], p[2]};
  assert_int_equal(piola__triangles_intersect(c, d), r);
  return r;
}

static void orientation_is_exact(void **state) {
  (void)state;
  double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0};
  double d[3] = {0.3, 0.3, 0};
  assert_int_equal(piola__orient3d_sign(a, b, c, d), 0);
  d[2] = 1e-300;
  assert_int_equal(piola__orient3d_sign(a, b, c, d), 1);
  d[2] = -1e-300;
  assert_int_equal(piola__orient3d_sign(a, b, c, d), -1);
  /* Points within a few ulp of the plane x = y through (12, 12, 0), (24, 24, 0), (0, 0, 1):
   * the rounded determinant is unreliable there, the exact sign is that of x - y. */
  const double pa[3] = {12, 12, 0}, pb[3] = {24, 24, 0}, pc[3] = {0, 0, 1};
  const double ulp = 0x1p-53;
  int reference = 0;
  {
    double far[3] = {0.5 + 1e-3, 0.5, 0.3};
    reference = piola__orient3d_sign(pa, pb, pc, far);
    assert_int_not_equal(reference, 0);
  }
  for (int i = -6; i <= 6; ++i)
    for (int j = -6; j <= 6; ++j) {
      double pd[3] = {0.5 + i * ulp, 0.5 + j * ulp, 0.3};
      int expected = (i > j) - (i < j);
      assert_int_equal(piola__orient3d_sign(pa, pb, pc, pd), expected * reference);
    }
}

static void separated_crossing_and_touching(void **state) {
  (void)state;
  const double t1[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const double above[3][3] = {{0, 0, 0.1}, {1, 0, 0.1}, {0, 1, 0.1}};
  assert_int_equal(meet(t1, above), 0);
  const double piercing[3][3] = {{0.2, 0.2, -1}, {0.3, 0.2, 1}, {0.2, 0.4, 1}};
  assert_int_equal(meet(t1, piercing), 1);
  const double touching_vertex[3][3] = {{0.2, 0.2, 0}, {0.3, 0.2, 1}, {0.2, 0.4, 1}};
  assert_int_equal(meet(t1, touching_vertex), 1);
  const double near_vertex[3][3] = {{0.2, 0.2, 1e-15}, {0.3, 0.2, 1}, {0.2, 0.4, 1}};
  assert_int_equal(meet(t1, near_vertex), 0);
  /* An edge lying across the other triangle's edge, in a perpendicular plane. */
  const double edge_cross[3][3] = {{0.5, -0.5, 0}, {0.5, 0.5, 0}, {0.5, 0, 1}};
  assert_int_equal(meet(t1, edge_cross), 1);
  const double edge_miss[3][3] = {{1.5, -0.5, 0}, {1.5, 0.5, 0}, {1.5, 0, 1}};
  assert_int_equal(meet(t1, edge_miss), 0);
}

static void coplanar_cases(void **state) {
  (void)state;
  const double t1[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const double inside[3][3] = {{0.1, 0.1, 0}, {0.2, 0.1, 0}, {0.1, 0.2, 0}};
  assert_int_equal(meet(t1, inside), 1);
  const double overlapping[3][3] = {{0.5, 0.5, 0}, {-0.5, 0.2, 0}, {0.2, -0.5, 0}};
  assert_int_equal(meet(t1, overlapping), 1);
  const double apart[3][3] = {{1, 1, 0}, {2, 1, 0}, {1, 2, 0}};
  assert_int_equal(meet(t1, apart), 0);
  const double sharing_edge_point[3][3] = {{0.5, 0.5, 0}, {1, 1, 0}, {0.5, 1.5, 0}};
  assert_int_equal(meet(t1, sharing_edge_point), 1);
}

static void degenerate_triangles(void **state) {
  (void)state;
  const double t1[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const double needle[3][3] = {{0.2, 0.2, -1}, {0.2, 0.2, 0}, {0.2, 0.2, 1}};
  assert_int_equal(meet(t1, needle), 1);
  const double needle_out[3][3] = {{0.8, 0.8, -1}, {0.8, 0.8, 0}, {0.8, 0.8, 1}};
  assert_int_equal(meet(t1, needle_out), 0);
  const double both[3][3] = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  const double across[3][3] = {{0.5, 0, -1}, {0.5, 0, 0}, {0.5, 0, 1}};
  assert_int_equal(meet(both, across), -1);
}

/* Random pairs compared with an independent floating-point answer where that answer is
 * clear: the signed distances of one triangle's vertices to the other's plane. */
static void random_pairs_agree_with_plane_separation(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(3);
  const long n = test_samples(20000, 1000);
  long separated = 0;
  for (long it = 0; it < n; ++it) {
    double p[3][3], q[3][3];
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k)
        p[i][k] = test_rng_uniform(&rng, -1, 1), q[i][k] = test_rng_uniform(&rng, -1, 1);
    double u[3], v[3];
    for (int k = 0; k < 3; ++k) u[k] = p[1][k] - p[0][k], v[k] = p[2][k] - p[0][k];
    double nrm[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                     u[0] * v[1] - u[1] * v[0]};
    double dist[3];
    for (int i = 0; i < 3; ++i) {
      dist[i] = 0;
      for (int k = 0; k < 3; ++k) dist[i] += nrm[k] * (q[i][k] - p[0][k]);
    }
    int r = meet((const double(*)[3])p, (const double(*)[3])q);
    if ((dist[0] > 1e-9 && dist[1] > 1e-9 && dist[2] > 1e-9) ||
        (dist[0] < -1e-9 && dist[1] < -1e-9 && dist[2] < -1e-9)) {
      ++separated;
      assert_int_equal(r, 0);
    }
  }
  assert_true(separated > n / 4);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(orientation_is_exact),
      cmocka_unit_test(separated_crossing_and_touching),
      cmocka_unit_test(coplanar_cases),
      cmocka_unit_test(degenerate_triangles),
      cmocka_unit_test(random_pairs_agree_with_plane_separation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
