/* Stable Neo-Hookean (Smith, de Goes, Kim 2018) and the projected Hessian eigensystem
 * (piola_material_projected_hessian_eigensystem): the model against the paper's energy and
 * stress written on the full 3x3 F (independently of the diagonal-form code), its Lame
 * re-parametrization, and the analytic eigensystem against a dense eigendecomposition of
 * the 9x9 Hessian obtained by central differences of P(F), for Stable Neo-Hookean and for
 * every model in the energy mode, flat, inverted and clamped states included. */
#include "test_support.h"

#include <math.h>
#include <string.h>

#include "math/mat3.h"
#include "piola/diagonalize.h"
#include "piola/material.h"

static piola_material make(piola_material_model model, piola_inversion_mode mode, double nu) {
  piola_material_def def = piola_default_material_def();
  def.model = model;
  def.inversion_mode = mode;
  def.youngs_modulus = 1e5;
  def.poisson_ratio = nu;
  piola_material m;
  assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
  return m;
}

static mat3 random_rotation(test_rng *rng) {
  double q[4], n = 0;
  for (int i = 0; i < 4; ++i) q[i] = test_rng_normal(rng), n += q[i] * q[i];
  n = sqrt(n);
  const double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
  return (mat3){{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                 {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                 {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
}

/* The paper's parameters from E and nu (section 3.4): mu' = 4/3 mu, lambda' = lambda + 5/6 mu,
 * alpha = 1 + 3/4 mu' / lambda'. */
static void paper_parameters(const piola_material *m, double *mu_s, double *lambda_s, double *alpha) {
  *mu_s = 4.0 / 3.0 * m->mu;
  *lambda_s = m->lambda + 5.0 / 6.0 * m->mu;
  *alpha = 1.0 + 0.75 * *mu_s / *lambda_s;
}

static double det3(mat3 f) {
  return f.m[0][0] * (f.m[1][1] * f.m[2][2] - f.m[1][2] * f.m[2][1]) -
         f.m[0][1] * (f.m[1][0] * f.m[2][2] - f.m[1][2] * f.m[2][0]) +
         f.m[0][2] * (f.m[1][0] * f.m[2][1] - f.m[1][1] * f.m[2][0]);
}

/* The paper's energy on F, zero at rest: mu'/2 (I_C - 3) + lambda'/2 (J - alpha)^2
 * - mu'/2 ln(I_C + 1), minus its value at F = I. */
static double paper_energy(const piola_material *m, mat3 f) {
  double mu_s, lambda_s, alpha, ic = 0;
  paper_parameters(m, &mu_s, &lambda_s, &alpha);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) ic += f.m[i][j] * f.m[i][j];
  const double j = det3(f);
  const double rest = 0.5 * lambda_s * (1 - alpha) * (1 - alpha) - 0.5 * mu_s * log(4.0);
  return 0.5 * mu_s * (ic - 3) + 0.5 * lambda_s * (j - alpha) * (j - alpha) - 0.5 * mu_s * log(ic + 1) - rest;
}

/* Its gradient: mu' (1 - 1/(I_C + 1)) F + lambda' (J - alpha) cof F. */
static mat3 paper_stress(const piola_material *m, mat3 f) {
  double mu_s, lambda_s, alpha, ic = 0;
  paper_parameters(m, &mu_s, &lambda_s, &alpha);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) ic += f.m[i][j] * f.m[i][j];
  const double j = det3(f);
  mat3 p;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const int a1 = (a + 1) % 3, a2 = (a + 2) % 3, b1 = (b + 1) % 3, b2 = (b + 2) % 3;
      const double cof = f.m[a1][b1] * f.m[a2][b2] - f.m[a1][b2] * f.m[a2][b1];
      p.m[a][b] = mu_s * (1 - 1 / (ic + 1)) * f.m[a][b] + lambda_s * (j - alpha) * cof;
    }
  return p;
}

/* P(F) and psi(F) through the public diagonal-form functions. */
static mat3 model_stress(const piola_material *m, mat3 f) {
  mat3 u, v;
  piola_vec3 fhat;
  assert_int_equal(piola_diagonalize3(&f, &u, &fhat, &v), PIOLA_OK);
  const double d[3] = {fhat.x, fhat.y, fhat.z};
  double p[3];
  piola_material_stress(m, d, p);
  return mat3_mul_diag_transpose(u, (vec3){p[0], p[1], p[2]}, v);
}

static double model_energy(const piola_material *m, mat3 f) {
  mat3 u, v;
  piola_vec3 fhat;
  assert_int_equal(piola_diagonalize3(&f, &u, &fhat, &v), PIOLA_OK);
  const double d[3] = {fhat.x, fhat.y, fhat.z};
  return piola_material_energy_density(m, d);
}

/* F = A diag(a) B^T with random rotations. */
static mat3 compose(test_rng *rng, const double a[3], mat3 *ra, mat3 *rb) {
  *ra = random_rotation(rng), *rb = random_rotation(rng);
  return mat3_mul_diag_transpose(*ra, (vec3){a[0], a[1], a[2]}, *rb);
}

static void matches_the_paper_on_full_matrices(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(61);
  const double nus[] = {-0.5, 0.0, 0.3, 0.45, 0.499};
  for (size_t n = 0; n < sizeof nus / sizeof nus[0]; ++n) {
    const piola_material m = make(PIOLA_MODEL_STABLE_NEOHOOKEAN, PIOLA_INVERSION_LINEAR, nus[n]);
    for (int s = 0; s < 200; ++s) {
      double a[3];
      for (int i = 0; i < 3; ++i) a[i] = test_rng_uniform(&rng, 0.35, 2.5);
      mat3 ra, rb;
      const mat3 f = compose(&rng, a, &ra, &rb);
      const double psi = paper_energy(&m, f);
      assert_close(model_energy(&m, f), psi, 1e-9 * (fabs(psi) + m.mu));
      const mat3 p = model_stress(&m, f), q = paper_stress(&m, f);
      const double scale = mat3_norm(q) + m.mu;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) assert_close(p.m[i][j], q.m[i][j], 1e-9 * scale);
    }
  }
}

/* Rest: zero energy and stress, and the paper's re-parametrization gives the rest tangent of
 * linear elasticity with the user's E and nu on the full 9x9 Hessian, not only the diagonal
 * block: d2psi/dF2 = mu (d_ik d_jl + d_il d_jk) + lambda d_ij d_kl. */
static void lame_reparametrization_gives_linear_elasticity_at_rest(void **state) {
  (void)state;
  const double nus[] = {-0.5, 0.0, 0.3, 0.45};
  for (size_t n = 0; n < sizeof nus / sizeof nus[0]; ++n) {
    const piola_material m = make(PIOLA_MODEL_STABLE_NEOHOOKEAN, PIOLA_INVERSION_LINEAR, nus[n]);
    const mat3 one = mat3_identity();
    assert_close(paper_energy(&m, one), 0.0, 1e-9 * m.mu);
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) {
        mat3 a = one, b = one;
        a.m[k][l] += h, b.m[k][l] -= h;
        const mat3 pa = paper_stress(&m, a), pb = paper_stress(&m, b);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            const double c = m.mu * ((i == k) * (j == l) + (i == l) * (j == k)) +
                             m.lambda * (i == j) * (k == l);
            assert_close((pa.m[i][j] - pb.m[i][j]) / (2 * h), c, 1e-6 * m.mu);
          }
      }
  }
}

static void sort9(double w[9]) {
  for (int i = 1; i < 9; ++i)
    for (int j = i; j > 0 && w[j] < w[j - 1]; --j) {
      const double t = w[j];
      w[j] = w[j - 1], w[j - 1] = t;
    }
}

typedef mat3 (*stress_of_f)(const piola_material *, mat3);

/* Compares the eigensystem at F = ra diag(a) rb^T with the dense Hessian of stress(F). */
static void check_eigensystem(const piola_material *m, stress_of_f stress, const double a[3],
                              mat3 ra, mat3 rb) {
  const mat3 f = mat3_mul_diag_transpose(ra, (vec3){a[0], a[1], a[2]}, rb);
  double hess[9][9], sym[9][9];
  const double h = 1e-6;
  for (int k = 0; k < 9; ++k) {
    mat3 fa = f, fb = f;
    fa.m[k / 3][k % 3] += h, fb.m[k / 3][k % 3] -= h;
    const mat3 pa = stress(m, fa), pb = stress(m, fb);
    for (int r = 0; r < 9; ++r) hess[r][k] = (pa.m[r / 3][r % 3] - pb.m[r / 3][r % 3]) / (2 * h);
  }
  double scale = 0;
  for (int r = 0; r < 9; ++r)
    for (int k = 0; k < 9; ++k) {
      sym[r][k] = 0.5 * (hess[r][k] + hess[k][r]);
      scale = fmax(scale, fabs(hess[r][k]));
    }
  double w_dense[9], w[9], q[9][3][3];
  double work[9][9];
  memcpy(work, sym, sizeof work);
  test_symmetric_eigenvalues(&work[0][0], 9, w_dense);
  for (int i = 0; i < 9; ++i) w_dense[i] = fmax(w_dense[i], 0.0);
  sort9(w_dense);
  assert_int_equal(piola_material_projected_hessian_eigensystem(m, a, w, q), PIOLA_OK);
  /* Each eigenmatrix U Q V^T: unit, mutually orthogonal, and an eigenvector of the dense
   * Hessian with the returned eigenvalue where it is positive (non-positive where clamped). */
  double vecs[9][9];
  for (int e = 0; e < 9; ++e) {
    const mat3 qe = {{{q[e][0][0], q[e][0][1], q[e][0][2]},
                      {q[e][1][0], q[e][1][1], q[e][1][2]},
                      {q[e][2][0], q[e][2][1], q[e][2][2]}}};
    const mat3 full = mat3_mul_transpose_b(mat3_mul(ra, qe), rb);
    for (int r = 0; r < 9; ++r) vecs[e][r] = full.m[r / 3][r % 3];
  }
  for (int e = 0; e < 9; ++e) {
    for (int g = 0; g < 9; ++g) {
      double dot = 0;
      for (int r = 0; r < 9; ++r) dot += vecs[e][r] * vecs[g][r];
      assert_close(dot, e == g ? 1.0 : 0.0, 1e-9);
    }
    double hv[9], rayleigh = 0;
    for (int r = 0; r < 9; ++r) {
      hv[r] = 0;
      for (int k = 0; k < 9; ++k) hv[r] += sym[r][k] * vecs[e][k];
      rayleigh += vecs[e][r] * hv[r];
    }
    if (w[e] > 0) {
      for (int r = 0; r < 9; ++r)
        if (!(fabs(hv[r] - w[e] * vecs[e][r]) <= 1e-5 * scale))
          fail_msg("%s %s f (%g %g %g): eigenpair %d (value %g): H v - w v = %g in row %d",
                   piola_material_model_name(m->model),
                   piola_inversion_mode_name(m->inversion_mode), a[0], a[1], a[2], e, w[e],
                   hv[r] - w[e] * vecs[e][r], r);
    } else {
      assert_true(w[e] == 0.0);
      assert_true(rayleigh <= 1e-5 * scale);
    }
  }
  sort9(w);
  for (int e = 0; e < 9; ++e)
    if (!(fabs(w[e] - w_dense[e]) <= 1e-5 * scale))
      fail_msg("%s %s f (%g %g %g): sorted projected eigenvalue %d: %g, dense %g",
               piola_material_model_name(m->model), piola_inversion_mode_name(m->inversion_mode),
               a[0], a[1], a[2], e, w[e], w_dense[e]);
}

static void stable_neohookean_eigensystem_matches_dense_hessian(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(62);
  const long samples = test_samples(300, 20);
  const double nus[] = {0.0, 0.3, 0.45};
  for (size_t n = 0; n < sizeof nus / sizeof nus[0]; ++n) {
    const piola_material m = make(PIOLA_MODEL_STABLE_NEOHOOKEAN, PIOLA_INVERSION_LINEAR, nus[n]);
    for (long s = 0; s < samples; ++s) {
      /* Above the threshold (the closed forms), squashed ones with negative eigenvalues, and
       * repeated entries (the twist/flip quotients' limits). */
      double a[3];
      for (int i = 0; i < 3; ++i) a[i] = test_rng_uniform(&rng, 0.31, 2.5);
      if (s % 5 == 0) a[1] = a[0];
      if (s % 7 == 0) a[0] = a[1] = a[2];
      mat3 ra = random_rotation(&rng), rb = random_rotation(&rng);
      check_eigensystem(&m, paper_stress, a, ra, rb);
    }
  }
}

/* Every model (muscle excepted) in the energy mode, entries below the threshold and inverted
 * ones included, away from the threshold where the Hessian jumps. */
static void energy_mode_eigensystem_matches_dense_hessian(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(63);
  const long samples = test_samples(200, 20);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model) {
    if (model == PIOLA_MODEL_MUSCLE || model == PIOLA_MODEL_HGO) continue;
    const piola_material m = make((piola_material_model)model, PIOLA_INVERSION_ENERGY, 0.3);
    for (long s = 0; s < samples; ++s) {
      /* Distinct magnitudes, at least 0.05 from the threshold and from the spline's
       * breakpoints (0.8, 1, 1.2), the negative one the smallest in magnitude. */
      double a[3];
      do {
        for (int i = 0; i < 3; ++i) a[i] = test_rng_uniform(&rng, 0.02, 2.0);
        if (s % 2) a[0] = -fmin(a[0], fmin(a[1], a[2])) * 0.9;
      } while (fabs(fabs(a[0]) - a[1]) < 0.05 || fabs(fabs(a[0]) - a[2]) < 0.05 ||
               fabs(a[1] - a[2]) < 0.05 || fabs(a[0] - 0.3) < 0.05 || fabs(a[1] - 0.3) < 0.05 ||
               fabs(a[2] - 0.3) < 0.05 ||
               (model == PIOLA_MODEL_SPLINE &&
                (fabs(a[1] - 0.8) < 0.05 || fabs(a[2] - 0.8) < 0.05 || fabs(a[1] - 1) < 0.05 ||
                 fabs(a[2] - 1) < 0.05 || fabs(a[1] - 1.2) < 0.05 || fabs(a[2] - 1.2) < 0.05 ||
                 fabs(a[0] - 0.8) < 0.05 || fabs(a[0] - 1) < 0.05 || fabs(a[0] - 1.2) < 0.05)));
      mat3 ra = random_rotation(&rng), rb = random_rotation(&rng);
      check_eigensystem(&m, model_stress, a, ra, rb);
    }
  }
}

static void eigensystem_refuses_what_has_no_energy(void **state) {
  (void)state;
  double w[9], q[9][3][3];
  const double clamped[3] = {1.0, 1.0, 0.1}, free_[3] = {1.2, 1.0, 0.9};
  piola_material m = make(PIOLA_MODEL_NEOHOOKEAN, PIOLA_INVERSION_LINEAR, 0.3);
  assert_int_equal(piola_material_projected_hessian_eigensystem(&m, clamped, w, q),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_material_projected_hessian_eigensystem(&m, free_, w, q), PIOLA_OK);
  m = make(PIOLA_MODEL_MUSCLE, PIOLA_INVERSION_ENERGY, 0.45);
  assert_int_equal(piola_material_projected_hessian_eigensystem(&m, free_, w, q),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  m = make(PIOLA_MODEL_HGO, PIOLA_INVERSION_ENERGY, 0.45);
  assert_int_equal(piola_material_projected_hessian_eigensystem(&m, free_, w, q),
                   PIOLA_ERROR_INVALID_ARGUMENT);
}

/* Stable Neo-Hookean's closed-form twist and flip eigenvalues equal the general quotients
 * (Phat_i +- Phat_j) / (f_i +- f_j). */
static void closed_forms_equal_the_quotients(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(64);
  const piola_material m = make(PIOLA_MODEL_STABLE_NEOHOOKEAN, PIOLA_INVERSION_LINEAR, 0.3);
  for (int s = 0; s < 200; ++s) {
    double a[3], p[3], w[9], q[9][3][3];
    for (int i = 0; i < 3; ++i) a[i] = test_rng_uniform(&rng, 0.31, 3.0);
    piola_material_stress(&m, a, p);
    double raw[6];
    static const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    for (int n = 0; n < 3; ++n) {
      const int i = pairs[n][0], j = pairs[n][1];
      raw[n] = (p[i] + p[j]) / (a[i] + a[j]);
      raw[3 + n] = (p[i] - p[j]) / (a[i] - a[j]);
    }
    assert_int_equal(piola_material_projected_hessian_eigensystem(&m, a, w, q), PIOLA_OK);
    for (int n = 0; n < 6; ++n) {
      if (fabs(a[pairs[n % 3][0]] - a[pairs[n % 3][1]]) < 1e-3) continue;
      assert_close(w[3 + n], fmax(raw[n], 0.0), 1e-6 * (fabs(raw[n]) + m.mu));
    }
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(matches_the_paper_on_full_matrices),
      cmocka_unit_test(lame_reparametrization_gives_linear_elasticity_at_rest),
      cmocka_unit_test(stable_neohookean_eigensystem_matches_dense_hessian),
      cmocka_unit_test(energy_mode_eigensystem_matches_dense_hessian),
      cmocka_unit_test(eigensystem_refuses_what_has_no_energy),
      cmocka_unit_test(closed_forms_equal_the_quotients),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
