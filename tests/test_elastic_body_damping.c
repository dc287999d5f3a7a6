/* Damping forces (section 6.2, the robust variant with rigid rotations projected out):
 * linear, symmetric negative semi-definite, torque-free, zero for rigid velocities, nonzero
 * on flat and inverted tets. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "force/elastic_body_internal.h"
#include "support/elastic_referees.h"
#include "test_elastic_body_fixtures.h"

static double dot(const double *a, const double *b, int n) {
  double s = 0;
  for (int i = 0; i < n; ++i) s += a[i] * b[i];
  return s;
}

static void random_vector(test_rng *rng, double *v, int n) {
  for (int i = 0; i < n; ++i) v[i] = test_rng_uniform(rng, -1, 1);
}

/* A body on a 3^3 grid updated at a random deformed state with some inverted and flat tets. */
static piola_elastic_body *deformed_body(test_rng *rng, piola_tet_mesh *mesh, double noise) {
  *mesh = fixture_grid(3, 1.0 / 3.0);
  static piola_material material;
  material = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
  piola_elastic_body *body = fixture_body(mesh, &material);
  int n = 3 * mesh->vertex_count;
  double *x = malloc(sizeof(double) * (size_t)n), *f = malloc(sizeof(double) * (size_t)n);
  for (int i = 0; i < n; ++i) x[i] = mesh->positions[i] + noise * test_rng_uniform(rng, -1, 1);
  for (int v = 0; v < 8; ++v) x[3 * v + 2] = 0.0; /* flatten a few tets near the bottom */
  assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  free(x);
  free(f);
  return body;
}

static void damping_is_linear_symmetric_and_dissipative(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(21);
  long samples = test_samples(30, 3);
  for (int config = 0; config < 3; ++config) {
    piola_tet_mesh mesh;
    piola_elastic_body *body = deformed_body(&rng, &mesh, config == 0 ? 0.0 : 0.2 * config);
    int n = 3 * mesh.vertex_count;
    double *v = malloc(sizeof(double) * (size_t)n), *w = malloc(sizeof(double) * (size_t)n);
    double *dv = malloc(sizeof(double) * (size_t)n), *dw = malloc(sizeof(double) * (size_t)n);
    double *dsum = malloc(sizeof(double) * (size_t)n), *sum = malloc(sizeof(double) * (size_t)n);
    const double beta = 2.0, alpha = 0.7;
    for (long s = 0; s < samples; ++s) {
      random_vector(&rng, v, n);
      random_vector(&rng, w, n);
      piola_elastic_body_damping_forces(body, v, beta, alpha, dv);
      piola_elastic_body_damping_forces(body, w, beta, alpha, dw);
      double scale = sqrt(dot(dv, dv, n) * dot(w, w, n)) + sqrt(dot(dw, dw, n) * dot(v, v, n));
      double wdv = dot(w, dv, n), vdw = dot(v, dw, n);
      if (!(fabs(wdv - vdw) <= 1e-12 * scale)) fail_msg("w.Dv = %.17g, v.Dw = %.17g", wdv, vdw);
      assert_true(dot(v, dv, n) <= 0.0);
      assert_true(dot(v, dv, n) < -1e-6 * sqrt(dot(dv, dv, n) * dot(v, v, n)));
      for (int i = 0; i < n; ++i) sum[i] = 2.5 * v[i] - 1.5 * w[i];
      piola_elastic_body_damping_forces(body, sum, beta, alpha, dsum);
      for (int i = 0; i < n; ++i) assert_close(dsum[i], 2.5 * dv[i] - 1.5 * dw[i], 1e-12 * scale);
    }
    free(v);
    free(w);
    free(dv);
    free(dw);
    free(dsum);
    free(sum);
    piola_elastic_body_destroy(body);
    fixture_mesh_free(&mesh);
  }
}

/* Each tet's damping forces have zero net force and zero torque about the origin at the
 * positions of the last update, also for deformed, flat and inverted tets; and a rigid
 * rotation of a deformed body is not damped. */
static void damping_conserves_momentum_and_angular_momentum(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(23);
  piola_tet_mesh mesh = fixture_single_tet(1.0);
  piola_material material = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
  piola_elastic_body *body = fixture_body(&mesh, &material);
  long samples = test_samples(300, 20);
  for (long s = 0; s < samples; ++s) {
    double x[12], v[12], f[12], d[12];
    random_vector(&rng, x, 12);
    if (s % 4 == 0) /* flat */
      for (int i = 0; i < 3; ++i) x[9 + i] = 0.5 * x[i] + 0.5 * x[3 + i];
    random_vector(&rng, v, 12);
    assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
    piola_elastic_body_damping_forces(body, v, 1.5, 0.5, d);
    double scale = fixture_max_abs(d, 12) * (fixture_max_abs(x, 12) + 1.0) + 1e-300;
    double torque[3] = {0, 0, 0};
    for (int c = 0; c < 4; ++c) {
      const double *p = x + 3 * c, *g = d + 3 * c;
      torque[0] += p[1] * g[2] - p[2] * g[1];
      torque[1] += p[2] * g[0] - p[0] * g[2];
      torque[2] += p[0] * g[1] - p[1] * g[0];
    }
    for (int i = 0; i < 3; ++i) {
      assert_true(fabs(d[i] + d[3 + i] + d[6 + i] + d[9 + i]) <= 1e-12 * scale);
      if (!(fabs(torque[i]) <= 1e-9 * scale)) fail_msg("sample %ld: torque %g, scale %g", s, torque[i], scale);
    }
    /* rigid rotation about a random axis through a random point */
    double w[3], o[3];
    random_vector(&rng, w, 3);
    random_vector(&rng, o, 3);
    for (int c = 0; c < 4; ++c) {
      double q[3] = {x[3 * c] - o[0], x[3 * c + 1] - o[1], x[3 * c + 2] - o[2]};
      v[3 * c] = w[1] * q[2] - w[2] * q[1];
      v[3 * c + 1] = w[2] * q[0] - w[0] * q[2];
      v[3 * c + 2] = w[0] * q[1] - w[1] * q[0];
    }
    piola_elastic_body_damping_forces(body, v, 1.5, 0.5, d);
    assert_true(fixture_max_abs(d, 12) <= 1e-9 * (fixture_max_abs(v, 12) + 1e-300) * 10.0);
  }
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

static void rigid_velocities_are_not_damped_at_rest(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(22);
  piola_tet_mesh mesh = fixture_grid(3, 1.0 / 3.0);
  piola_material material = fixture_material(PIOLA_MODEL_COROTATED);
  piola_elastic_body *body = fixture_body(&mesh, &material);
  int n = 3 * mesh.vertex_count;
  double *x = malloc(sizeof(double) * (size_t)n), *f = malloc(sizeof(double) * (size_t)n);
  double *v = malloc(sizeof(double) * (size_t)n);
  /* at rest, rigidly rotated and translated: U = V R-related, Fhat = I */
  double r[9];
  fixture_random_rotation(&rng, r);
  for (int p = 0; p < mesh.vertex_count; ++p)
    for (int i = 0; i < 3; ++i)
      x[3 * p + i] = 1.0 + r[3 * i] * mesh.positions[3 * p] + r[3 * i + 1] * mesh.positions[3 * p + 1] +
                     r[3 * i + 2] * mesh.positions[3 * p + 2];
  assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  for (int s = 0; s < 5; ++s) {
    double t[3], w[3];
    for (int i = 0; i < 3; ++i) {
      t[i] = test_rng_uniform(&rng, -1, 1);
      w[i] = test_rng_uniform(&rng, -1, 1);
    }
    /* translation plus infinitesimal rotation about the point (1, 1, 1) */
    for (int p = 0; p < mesh.vertex_count; ++p) {
      double q[3] = {x[3 * p] - 1, x[3 * p + 1] - 1, x[3 * p + 2] - 1};
      v[3 * p] = t[0] + w[1] * q[2] - w[2] * q[1];
      v[3 * p + 1] = t[1] + w[2] * q[0] - w[0] * q[2];
      v[3 * p + 2] = t[2] + w[0] * q[1] - w[1] * q[0];
    }
    piola_elastic_body_damping_forces(body, v, 3.0, 1.0, f);
    /* a non-rigid velocity of the same size gives forces of order beta * |v| * area / h */
    assert_true(fixture_max_abs(f, n) <= 1e-12 * 3.0);
  }
  /* ...while a stretching velocity is damped */
  for (int p = 0; p < mesh.vertex_count; ++p)
    for (int i = 0; i < 3; ++i) v[3 * p + i] = i == 0 ? mesh.positions[3 * p] : 0.0;
  piola_elastic_body_damping_forces(body, v, 3.0, 1.0, f);
  assert_true(fixture_max_abs(f, n) > 0.1);
  free(x);
  free(f);
  free(v);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

static void flat_and_inverted_tets_are_still_damped(void **state) {
  (void)state;
  piola_tet_mesh mesh = fixture_single_tet(1.0);
  piola_material material = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
  piola_elastic_body *body = fixture_body(&mesh, &material);
  double configs[3][12] = {
      {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, 0},  /* flat */
      {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, -0.5},   /* inverted */
      {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},      /* a point */
  };
  for (int c = 0; c < 3; ++c) {
    double f[12], d[12];
    assert_int_equal(piola_elastic_body_update(body, configs[c], 1.0, f, NULL), PIOLA_OK);
    /* corner 3 moving along z: the velocity gradient is not rigid */
    double v[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1};
    piola_elastic_body_damping_forces(body, v, 1.0, 0.5, d);
    for (int i = 0; i < 12; ++i) assert_true(isfinite(d[i]));
    assert_true(d[11] < 0); /* opposes the motion of corner 3 */
    assert_true(dot(v, d, 12) < 0);
  }
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

/* The fast blocked operator (prepared per-tet records, vectorized apply) against the scalar
 * reference of the original formulation, at deformed states with flat, inverted and
 * collapsed tets, and after a second update (the records must follow the new state). */
static void fast_damping_matches_the_reference(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(24);
  long samples = test_samples(10, 2);
  for (int config = 0; config < 3; ++config) {
    piola_tet_mesh mesh;
    piola_elastic_body *body = deformed_body(&rng, &mesh, 0.25 * config);
    int n = 3 * mesh.vertex_count;
    double *v = malloc(sizeof(double) * (size_t)n), *fast = malloc(sizeof(double) * (size_t)n);
    double *ref = malloc(sizeof(double) * (size_t)n), *x = malloc(sizeof(double) * (size_t)n);
    for (long s = 0; s < samples; ++s) {
      if (s % 2 == 1) { /* a new update between applies */
        for (int i = 0; i < n; ++i) x[i] = mesh.positions[i] + 0.3 * test_rng_uniform(&rng, -1, 1);
        for (int i = 0; i < 3; ++i) x[i] = x[3 + i] = x[6 + i] = x[9 + i]; /* a point */
        assert_int_equal(piola_elastic_body_update(body, x, 1.0, fast, NULL), PIOLA_OK);
      }
      random_vector(&rng, v, n);
      double beta = test_rng_uniform(&rng, 0, 3), alpha = test_rng_uniform(&rng, 0, 3);
      piola_elastic_body_damping_forces(body, v, beta, alpha, fast);
      piola__elastic_body_damping_reference(body, v, beta, alpha, ref);
      double scale = fixture_max_abs(ref, n);
      assert_true(scale > 0);
      /* the assembled matrix sums the same terms in another order: rounding only */
      for (int i = 0; i < n; ++i)
        if (!(fabs(fast[i] - ref[i]) <= 1e-12 * scale))
          fail_msg("config %d sample %ld entry %d: fast %.17g, reference %.17g", config, s, i, fast[i], ref[i]);
    }
    free(v);
    free(fast);
    free(ref);
    free(x);
    piola_elastic_body_destroy(body);
    fixture_mesh_free(&mesh);
  }
}

/* Rigid velocities (translation plus rotation about any point) of a strongly deformed body
 * with flat and inverted tets are not damped. */
static void rigid_velocities_are_not_damped_when_deformed(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(25);
  piola_tet_mesh mesh;
  piola_elastic_body *body = deformed_body(&rng, &mesh, 0.4);
  int n = 3 * mesh.vertex_count;
  const double *x = body->positions;
  double *v = malloc(sizeof(double) * (size_t)n), *f = malloc(sizeof(double) * (size_t)n);
  double *g = malloc(sizeof(double) * (size_t)n);
  random_vector(&rng, g, n);
  piola_elastic_body_damping_forces(body, g, 2.0, 1.0, f);
  double typical = fixture_max_abs(f, n); /* forces of a generic velocity of the same size */
  for (int s = 0; s < 5; ++s) {
    double t[3], w[3], o[3];
    random_vector(&rng, t, 3);
    random_vector(&rng, w, 3);
    random_vector(&rng, o, 3);
    for (int p = 0; p < mesh.vertex_count; ++p) {
      double q[3] = {x[3 * p] - o[0], x[3 * p + 1] - o[1], x[3 * p + 2] - o[2]};
      v[3 * p] = t[0] + w[1] * q[2] - w[2] * q[1];
      v[3 * p + 1] = t[1] + w[2] * q[0] - w[0] * q[2];
      v[3 * p + 2] = t[2] + w[0] * q[1] - w[1] * q[0];
    }
    piola_elastic_body_damping_forces(body, v, 2.0, 1.0, f);
    if (!(fixture_max_abs(f, n) <= 1e-10 * typical))
      fail_msg("rigid velocity %d: force %g, generic %g", s, fixture_max_abs(f, n), typical);
  }
  free(v);
  free(f);
  free(g);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

/* Bit-for-bit the same forces for 1 and 2 threads, with the matrix assembled under each
 * thread count (an update between the two), on a body large enough for the parallel
 * assembly and product; and they match the reference. */
static void damping_does_not_depend_on_the_thread_count(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(26);
  piola_tet_mesh mesh = fixture_grid(16, 0.1);
  assert_true(mesh.tet_count >= PIOLA_TET_BLOCK * PIOLA_PARALLEL_MIN_BLOCKS);
  assert_true(mesh.vertex_count >= PIOLA_PARALLEL_MIN_VERTICES);
  piola_material material = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
  piola_elastic_body *body = fixture_body(&mesh, &material);
  int n = 3 * mesh.vertex_count;
  double *x = malloc(sizeof(double) * (size_t)n), *f = malloc(sizeof(double) * (size_t)n);
  double *v = malloc(sizeof(double) * (size_t)n), *d[2];
  for (int i = 0; i < n; ++i) x[i] = mesh.positions[i] + 0.07 * test_rng_uniform(&rng, -1, 1);
  random_vector(&rng, v, n);
  for (int k = 0; k < 2; ++k) {
    d[k] = malloc(sizeof(double) * (size_t)n);
    piola_set_thread_count(k + 1);
    assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
    piola_elastic_body_damping_forces(body, v, 0.5, 0.2, d[k]);
  }
  piola_set_thread_count(0);
  assert_true(fixture_max_abs(d[0], n) > 0);
  assert_memory_equal(d[0], d[1], sizeof(double) * (size_t)n);
  /* assembled by tet ranges in parallel, some edges through private slots: still the same
   * operator */
  assert_true(body->damping.shared_count > 0);
  piola__elastic_body_damping_reference(body, v, 0.5, 0.2, f);
  double scale = fixture_max_abs(f, n);
  for (int i = 0; i < n; ++i) assert_true(fabs(d[0][i] - f[i]) <= 1e-12 * scale);
  free(d[0]);
  free(d[1]);
  free(x);
  free(f);
  free(v);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

/* With the tets and vertices of a grid numbered at random, the parallel tet ranges share
 * most edges, which then all go through private slots, and the matrix rows follow a
 * Cuthill-McKee order instead of the vertex numbers: the operator is the same, on 1 or 2
 * threads. */
static void damping_of_shuffled_tets_matches_the_reference(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(27);
  piola_tet_mesh mesh = fixture_grid(14, 0.1);
  int32_t *perm = malloc(sizeof(int32_t) * (size_t)mesh.vertex_count);
  double *moved = malloc(sizeof(double) * 3 * (size_t)mesh.vertex_count);
  for (int32_t i = 0; i < mesh.vertex_count; ++i) perm[i] = i;
  for (int32_t i = mesh.vertex_count - 1; i > 0; --i) {
    int32_t r = (int32_t)(test_rng_uniform(&rng, 0, 1) * (i + 1));
    if (r > i) r = i;
    int32_t tmp = perm[i];
    perm[i] = perm[r];
    perm[r] = tmp;
  }
  for (int32_t i = 0; i < mesh.vertex_count; ++i)
    for (int k = 0; k < 3; ++k) moved[3 * perm[i] + k] = mesh.positions[3 * i + k];
  memcpy(mesh.positions, moved, sizeof(double) * 3 * (size_t)mesh.vertex_count);
  for (int32_t c = 0; c < 4 * mesh.tet_count; ++c) mesh.tets[c] = perm[mesh.tets[c]];
  free(perm);
  free(moved);
  for (int32_t t = mesh.tet_count - 1; t > 0; --t) {
    int32_t r = (int32_t)(test_rng_uniform(&rng, 0, 1) * (t + 1));
    if (r > t) r = t;
    for (int c = 0; c < 4; ++c) {
      int32_t tmp = mesh.tets[4 * t + c];
      mesh.tets[4 * t + c] = mesh.tets[4 * r + c];
      mesh.tets[4 * r + c] = tmp;
    }
  }
  piola_material material = fixture_material(PIOLA_MODEL_COROTATED);
  piola_elastic_body *body = fixture_body(&mesh, &material);
  assert_true(body->damping.shared_count > body->damping.edge_count / 2);
  int32_t renumbered = 0;
  for (int32_t i = 0; i < mesh.vertex_count; ++i) renumbered += body->damping.rank[i] != i;
  assert_true(renumbered > mesh.vertex_count / 2);
  int n = 3 * mesh.vertex_count;
  double *x = malloc(sizeof(double) * (size_t)n), *f = malloc(sizeof(double) * (size_t)n);
  double *v = malloc(sizeof(double) * (size_t)n), *ref = malloc(sizeof(double) * (size_t)n);
  for (int i = 0; i < n; ++i) x[i] = mesh.positions[i] + 0.08 * test_rng_uniform(&rng, -1, 1);
  random_vector(&rng, v, n);
  for (int threads = 1; threads <= 2; ++threads) {
    piola_set_thread_count(threads);
    assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
    piola_elastic_body_damping_forces(body, v, 1.2, 0.4, f);
    piola__elastic_body_damping_reference(body, v, 1.2, 0.4, ref);
    double scale = fixture_max_abs(ref, n);
    assert_true(scale > 0);
    for (int i = 0; i < n; ++i)
      if (!(fabs(f[i] - ref[i]) <= 1e-12 * scale)) fail_msg("entry %d: %.17g against %.17g", i, f[i], ref[i]);
  }
  piola_set_thread_count(0);
  free(x);
  free(f);
  free(v);
  free(ref);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(damping_is_linear_symmetric_and_dissipative),
      cmocka_unit_test(damping_conserves_momentum_and_angular_momentum),
      cmocka_unit_test(rigid_velocities_are_not_damped_at_rest),
      cmocka_unit_test(flat_and_inverted_tets_are_still_damped),
      cmocka_unit_test(fast_damping_matches_the_reference),
      cmocka_unit_test(rigid_velocities_are_not_damped_when_deformed),
      cmocka_unit_test(damping_does_not_depend_on_the_thread_count),
      cmocka_unit_test(damping_of_shuffled_tets_matches_the_reference),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
