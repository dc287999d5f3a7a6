/* piola_elastic_body_settling_estimate (piola/settling.h) against dense references built
 * from the body's own forces: the rest stiffness K by central differences of the elastic
 * forces at rest, the damping matrix C by applying the damping forces to unit velocities, the
 * lumped masses M, and the eigenvalues of M^-1/2 K M^-1/2 by the tests' Jacobi solver. */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "block_scenes.h"
#include "piola/elastic_body.h"
#include "piola/settling.h"

static piola_elastic_body *make_body(const piola_tet_mesh *mesh, piola_material_model model,
                                     piola_material *material) {
  piola_material_def def = piola_default_material_def();
  def.model = model;
  def.youngs_modulus = 2e4;
  def.poisson_ratio = 0.3;
  assert_int_equal(piola_material_init(&def, material), PIOLA_OK);
  piola_elastic_body_def bd = piola_default_elastic_body_def();
  bd.rest_mesh = mesh;
  bd.materials = material;
  bd.material_count = 1;
  bd.density = 1000;
  piola_elastic_body *body = NULL;
  assert_int_equal(piola_elastic_body_create(&bd, &body), PIOLA_OK);
  return body;
}

/* Sorted eigenvalues of M^-1/2 A M^-1/2 (n = 3 * vertex count), a destroyed. */
static void mass_scaled_eigenvalues(double *a, const double *mass, int n, double *lambda) {
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) a[i * n + j] /= sqrt(mass[i / 3] * mass[j / 3]);
  test_symmetric_eigenvalues(a, n, lambda);
  for (int i = 1; i < n; ++i) /* insertion sort */
    for (int j = i; j > 0 && lambda[j] < lambda[j - 1]; --j) {
      double t = lambda[j];
      lambda[j] = lambda[j - 1], lambda[j - 1] = t;
    }
}

/* K = -df/dx at rest by central differences (the forces are linear near rest to O(h^2)). */
static double *rest_stiffness(piola_elastic_body *body) {
  const int nv = piola_elastic_body_vertex_count(body), n = 3 * nv;
  double *k = calloc((size_t)n * n, sizeof(double)), *x = malloc((size_t)n * sizeof(double));
  double *fp = malloc((size_t)n * sizeof(double)), *fm = malloc((size_t)n * sizeof(double));
  assert_non_null(k), assert_non_null(x), assert_non_null(fp), assert_non_null(fm);
  memcpy(x, piola_elastic_body_rest_positions(body), (size_t)n * sizeof(double));
  const double h = 1e-6;
  for (int j = 0; j < n; ++j) {
    const double x0 = x[j];
    x[j] = x0 + h;
    assert_int_equal(piola_elastic_body_update(body, x, 1, fp, NULL), PIOLA_OK);
    x[j] = x0 - h;
    assert_int_equal(piola_elastic_body_update(body, x, 1, fm, NULL), PIOLA_OK);
    x[j] = x0;
    for (int i = 0; i < n; ++i) k[i * n + j] = -(fp[i] - fm[i]) / (2 * h);
  }
  for (int i = 0; i < n; ++i) /* symmetrize the differencing noise */
    for (int j = 0; j < i; ++j) k[i * n + j] = k[j * n + i] = 0.5 * (k[i * n + j] + k[j * n + i]);
  free(x), free(fp), free(fm);
  return k;
}

/* The lowest non-rigid frequency is the 7th eigenvalue of the dense M^-1/2 K M^-1/2 (six
 * zeros: the rigid motions), for models whose linearization at rest differs in form
 * (rotated linear, neo-Hookean, Ogden: the same mu and lambda). */
static void lowest_frequency_matches_the_dense_eigenvalue(void **state) {
  (void)state;
  piola_tet_mesh mesh = block_mesh(4, 2, 1, 0.8, 0.2, 0.1); /* a plate: bending is lowest */
  const piola_material_model models[] = {PIOLA_MODEL_ROTATED_LINEAR, PIOLA_MODEL_NEOHOOKEAN,
                                         PIOLA_MODEL_STABLE_NEOHOOKEAN};
  for (int m = 0; m < 3; ++m) {
    piola_material material;
    piola_elastic_body *body = make_body(&mesh, models[m], &material);
    const int n = 3 * piola_elastic_body_vertex_count(body);
    double *k = rest_stiffness(body), *lambda = malloc((size_t)n * sizeof(double));
    assert_non_null(lambda);
    mass_scaled_eigenvalues(k, piola_elastic_body_masses(body), n, lambda);
    for (int i = 0; i < 6; ++i) assert_true(fabs(lambda[i]) < 1e-6 * lambda[n - 1]);
    assert_true(lambda[6] > 1e-3 * lambda[7]); /* nothing else is free */
    piola_settling_estimate est;
    assert_int_equal(piola_elastic_body_settling_estimate(body, 100, 50, &est), PIOLA_OK);
    assert_close(est.lowest_frequency, sqrt(lambda[6]), 1e-3 * sqrt(lambda[6]));
    free(k), free(lambda);
    piola_elastic_body_destroy(body);
  }
  block_mesh_free(&mesh);
}

/* Damping proportional to stiffness (beta, alpha) = s (mu, lambda) damps every mode with
 * c = s omega^2; the decay rate is c / 2 below critical damping and the slow root of
 * r^2 - c r + omega^2 = 0 above; the overdamped floor is 1 / s. */
static void damping_and_decay_of_the_lowest_mode(void **state) {
  (void)state;
  piola_tet_mesh mesh = block_mesh(4, 2, 1, 0.8, 0.2, 0.1);
  piola_material material;
  piola_elastic_body *body = make_body(&mesh, PIOLA_MODEL_COROTATED, &material);
  /* C from the damping forces at rest: they are linear in v */
  const int n = 3 * piola_elastic_body_vertex_count(body);
  double *x = malloc((size_t)n * sizeof(double)), *f = malloc((size_t)n * sizeof(double));
  assert_non_null(x), assert_non_null(f);
  memcpy(x, piola_elastic_body_rest_positions(body), (size_t)n * sizeof(double));
  assert_int_equal(piola_elastic_body_update(body, x, 1, f, NULL), PIOLA_OK);
  piola_settling_estimate est;
  assert_int_equal(piola_elastic_body_settling_estimate(body, 0, 0, &est), PIOLA_OK);
  const double w = est.lowest_frequency;
  assert_true(w > 0);
  assert_true(est.lowest_damping == 0 && est.decay_rate == 0);
  assert_true(isinf(piola_settling_time(&est, 1, 0.01)));
  for (int c = 0; c < 2; ++c) {
    /* c = 0.5 w (well below critical damping), then 8 w (well above) */
    const double s = (c == 0 ? 0.5 : 8.0) / w;
    assert_int_equal(piola_elastic_body_settling_estimate(body, s * material.mu, s * material.lambda, &est), PIOLA_OK);
    assert_close(est.lowest_damping, s * w * w, 1e-6 * s * w * w);
    const double cd = est.lowest_damping, r = est.lowest_decay_rate;
    if (c == 0) assert_close(r, 0.5 * cd, 1e-12 * cd);
    else {
      assert_close(r * r - cd * r + w * w, 0, 1e-9 * w * w);
      assert_true(r < 0.5 * cd);
    }
    assert_close(est.relaxation_rate, 1 / s, 1e-12 / s);
    assert_close(est.decay_rate, fmin(r, 1 / s), 0);
    /* the crossing time is the bounding-box diagonal over the dilatational wave speed */
    const double cp = sqrt((material.lambda + 2 * material.mu) / 1000);
    assert_close(est.crossing_time, sqrt(0.8 * 0.8 + 0.2 * 0.2 + 0.1 * 0.1) / cp, 1e-12);
    assert_close(est.reexpansion_time, 8 * fmax(est.crossing_time, s), 1e-12);
    assert_close(piola_settling_time(&est, 0.5, 0.005), est.reexpansion_time + log(100) / est.decay_rate, 1e-12);
    assert_close(piola_settling_time(&est, 0.001, 0.005), 0, 0);
  }
  /* what the estimate assumes: at rest the body's damping forces with (beta, alpha) =
   * s (mu, lambda) are s times the rest stiffness's (here from differences of the forces) */
  double *k = rest_stiffness(body), *v = calloc((size_t)n, sizeof(double));
  assert_non_null(v);
  assert_int_equal(piola_elastic_body_update(body, x, 1, f, NULL), PIOLA_OK);
  double kmax = 0;
  for (int i = 0; i < n * n; ++i) kmax = fmax(kmax, fabs(k[i]));
  const double s = 0.3;
  for (int j = 0; j < n; ++j) {
    v[j] = 1;
    piola_elastic_body_damping_forces(body, v, s * material.mu, s * material.lambda, f);
    v[j] = 0;
    for (int i = 0; i < n; ++i) assert_close(-f[i], s * k[i * n + j], 1e-6 * s * kmax);
  }
  free(k), free(v);
  assert_int_equal(piola_elastic_body_settling_estimate(body, -1, 0, &est), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_elastic_body_settling_estimate(body, NAN, 0, &est), PIOLA_ERROR_INVALID_ARGUMENT);
  free(x), free(f);
  piola_elastic_body_destroy(body);
  block_mesh_free(&mesh);
}

/* Two tets that share nothing: one moves freely against the other, so the lowest frequency
 * is 0 and nothing predicts a settling. */
static void separate_pieces_have_no_settling_time(void **state) {
  (void)state;
  double x[24] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 3, 0, 0, 4, 0, 0, 3, 1, 0, 3, 0, 1};
  int32_t tets[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  piola_tet_mesh mesh;
  memset(&mesh, 0, sizeof mesh);
  mesh.positions = x, mesh.vertex_count = 8, mesh.tets = tets, mesh.tet_count = 2;
  piola_material material;
  piola_elastic_body *body = make_body(&mesh, PIOLA_MODEL_NEOHOOKEAN, &material);
  piola_settling_estimate est;
  assert_int_equal(piola_elastic_body_settling_estimate(body, 100, 100, &est), PIOLA_OK);
  assert_true(est.lowest_frequency == 0 && est.decay_rate == 0);
  assert_true(isinf(piola_settling_time(&est, 1, 0.01)));
  piola_elastic_body_destroy(body);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(lowest_frequency_matches_the_dense_eigenvalue),
      cmocka_unit_test(damping_and_decay_of_the_lowest_mode),
      cmocka_unit_test(separate_pieces_have_no_settling_time),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
