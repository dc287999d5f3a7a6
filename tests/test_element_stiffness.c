/* The implicit integrators' stiffness (src/force/element_stiffness.c, stiffness_matrix.c):
 *  - dP/dF (unprojected) against central differences of P, for every model and both
 *    inversion extensions, on random, flat, collapsed and inverted F away from the
 *    threshold kinks, muscle fibres included (fibre stretch away from its kinks too);
 *  - the projected dP/dF and the projected element stiffness have no negative eigenvalue,
 *    and the projection leaves a positive definite dP/dF unchanged;
 *  - the 3x3 projection against the exact one, every count of negative eigenvalues,
 *    repeated and nearly repeated ones, magnitudes from 1e-200 to 1e200;
 *  - the assembled matrix equals the dense sum of element matrices built from the 9 x 9
 *    projected dP/dF (an independent path), is symmetric, and maps a rigid translation to
 *    the mass term only;
 *  - the assembly's one-evaluation stress and derivative give the public functions' values
 *    for every model and inversion mode, above the threshold (its shortcut) and below;
 *  - the Newton tail's matrix is the force derivative on a compressed body and the projected
 *    matrix in every pair near collapse or inverted. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "force/element_stiffness.h"
#include "force/elastic_body_internal.h"
#include "force/stiffness_matrix.h"
#include "piola/diagonalize.h"
#include "test_elastic_body_fixtures.h"

/* P(F) as the force loop forms it: U Phat V^T plus the fibre part. */
static void stress_at(const piola_material *m, const piola_mat3 *f, const double *fiber,
                      double activation, double p[9]) {
  piola_mat3 u, v;
  piola_vec3 fh;
  assert_int_equal(piola_diagonalize3(f, &u, &fh, &v), PIOLA_OK);
  double fhat[3] = {fh.x, fh.y, fh.z}, ph[3][3] = {{0}}, d[3];
  piola_material_stress(m, fhat, d);
  for (int i = 0; i < 3; ++i) ph[i][i] = d[i];
  if (fiber && m->model == PIOLA_MODEL_HGO) {
    double fam[6], f9[9], pf[9];
    assert_int_equal(piola_material_hgo_families(m, fiber, fam), PIOLA_OK);
    for (int k = 0; k < 9; ++k) f9[k] = f->m[k / 3][k % 3];
    piola_material_hgo_fiber_stress(m, f9, fam, pf);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double s = pf[3 * i + j];
        for (int a = 0; a < 3; ++a) s += u.m[i][a] * ph[a][a] * v.m[j][a];
        p[3 * i + j] = s;
      }
    return;
  }
  if (fiber) {
    double ah[3], pf[3][3];
    for (int r = 0; r < 3; ++r) ah[r] = v.m[0][r] * fiber[0] + v.m[1][r] * fiber[1] + v.m[2][r] * fiber[2];
    piola_material_fiber_stress(m, fhat, ah, activation, pf);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) ph[i][j] += pf[i][j];
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) s += u.m[i][a] * ph[a][b] * v.m[j][b];
      p[3 * i + j] = s;
    }
}

static void random_rotation(test_rng *rng, double r[3][3]) {
  double q[9];
  fixture_random_rotation(rng, q);
  for (int k = 0; k < 9; ++k) r[k / 3][k % 3] = q[k];
}

/* F = R1 diag(f) R2 */
static piola_mat3 compose(test_rng *rng, const double f[3]) {
  double a[3][3], b[3][3];
  random_rotation(rng, a);
  random_rotation(rng, b);
  piola_mat3 out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += a[i][k] * f[k] * b[k][j];
      out.m[i][j] = s;
    }
  return out;
}

/* Diagonal values away from the kinks: the inversion threshold (0.3 and, for the
 * neo-Hookean variant, 0.5), the spline's 0.8 and 1.2, and from each other. */
static const double SHAPES[][3] = {
    {1.13, 0.94, 0.71},    /* random-ish stretch */
    {1.41, 1.05, 0.62},    /* larger stretch */
    {1.1, 0.9, 1e-4},      /* flat */
    {0.9, 1e-3, 4e-4},     /* collapsed to a line */
    {3e-3, 2e-3, 1e-3},    /* collapsed to a point */
    {1.05, 0.9, -0.2},     /* inverted */
    {0.67, 0.45, -0.12},   /* inverted, two entries below the threshold */
    {0.25, 0.2, -0.1},     /* inverted, all entries below the threshold */
    {0.95, 0.7, 0.1},      /* one entry below the threshold */
};
enum { SHAPE_COUNT = sizeof SHAPES / sizeof SHAPES[0] };

static void check_model(piola_material_model model, piola_inversion_mode mode, double threshold) {
  piola_material_def def = piola_default_material_def();
  def.model = model;
  def.youngs_modulus = 1e5;
  def.poisson_ratio = 0.4;
  def.inversion_mode = mode;
  def.inversion_threshold = threshold;
  piola_material m;
  assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
  test_rng rng = test_rng_seeded(17 + 3 * model + mode);
  const double activation = 0.6;
  for (int s = 0; s < SHAPE_COUNT; ++s) {
    if (threshold > 0.4 && (s == 6 || s == 8)) continue; /* near 0.5 / mixed kinks differ */
    for (int rep = 0; rep < 3; ++rep) {
      piola_mat3 f = compose(&rng, SHAPES[s]);
      double fiber_store[3], *fiber = NULL;
      if (model == PIOLA_MODEL_MUSCLE) {
        /* a fibre whose stretch is away from the kinks of T (1, the toe 1.2, the bump's
         * ends 0.5 and 1.5) */
        for (int tries = 0; tries < 100; ++tries) {
          double a[3] = {test_rng_normal(&rng), test_rng_normal(&rng), test_rng_normal(&rng)};
          double n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
          double w2 = 0;
          for (int i = 0; i < 3; ++i) {
            double wi = (f.m[i][0] * a[0] + f.m[i][1] * a[1] + f.m[i][2] * a[2]) / n;
            w2 += wi * wi;
          }
          double lam = sqrt(w2);
          if (fabs(lam - 1) < 0.03 || fabs(lam - 1.2) < 0.03 || fabs(lam - 0.5) < 0.03 ||
              fabs(lam - 1.5) < 0.03)
            continue;
          for (int i = 0; i < 3; ++i) fiber_store[i] = a[i] / n;
          fiber = fiber_store;
          break;
        }
        assert_non_null(fiber);
      }
      if (model == PIOLA_MODEL_HGO) {
        /* a fibre whose families' E are away from the tension-only kink at E = 0 */
        for (int tries = 0; tries < 200 && !fiber; ++tries) {
          double a[3] = {test_rng_normal(&rng), test_rng_normal(&rng), test_rng_normal(&rng)};
          double fam[6], f9[9];
          if (piola_material_hgo_families(&m, a, fam) != PIOLA_OK) continue;
          for (int k = 0; k < 9; ++k) f9[k] = f.m[k / 3][k % 3];
          int far = 1;
          for (int q = 0; q < 2; ++q) {
            double w2 = 0;
            for (int i = 0; i < 3; ++i) {
              const double wi = f9[3 * i] * fam[3 * q] + f9[3 * i + 1] * fam[3 * q + 1] + f9[3 * i + 2] * fam[3 * q + 2];
              w2 += wi * wi;
            }
            far &= fabs(w2 - 1) > 0.03; /* kappa = 0: E = I4 - 1 */
          }
          if (!far) continue;
          for (int i = 0; i < 3; ++i) fiber_store[i] = a[i];
          fiber = fiber_store;
        }
        assert_non_null(fiber);
      }
      double c[81], cp[81];
      piola__element_dpdf(&m, &f, fiber, activation, 0, c);
      piola__element_dpdf(&m, &f, fiber, activation, 1, cp);
      double scale = 0;
      for (int k = 0; k < 81; ++k) scale = fmax(scale, fabs(c[k]));
      assert_true(scale > 0 && isfinite(scale));
      /* central differences, step far below the smallest entry and gap of this F */
      double fmin_entry = 1e30;
      for (int k = 0; k < 3; ++k) fmin_entry = fmin(fmin_entry, fabs(SHAPES[s][k]));
      const double h = fmin(1e-6, 1e-3 * fmin_entry);
      double worst = 0;
      for (int kl = 0; kl < 9; ++kl) {
        piola_mat3 fp = f, fm = f;
        fp.m[kl / 3][kl % 3] += h;
        fm.m[kl / 3][kl % 3] -= h;
        double pp[9], pm[9];
        stress_at(&m, &fp, fiber, activation, pp);
        stress_at(&m, &fm, fiber, activation, pm);
        for (int ij = 0; ij < 9; ++ij)
          worst = fmax(worst, fabs((pp[ij] - pm[ij]) / (2 * h) - c[9 * ij + kl]));
      }
      if (!(worst <= 2e-5 * scale))
        fail_msg("%s/%s/c=%g shape %d rep %d: dP/dF differs from central differences by %g "
                 "(scale %g)",
                 piola_material_model_name(model), piola_inversion_mode_name(mode), threshold, s,
                 rep, worst, scale);
      /* projected: symmetric with no negative eigenvalue */
      double sym = 0, lam[9], work[81], pscale = 0;
      for (int a = 0; a < 9; ++a)
        for (int b = 0; b < 9; ++b) {
          sym = fmax(sym, fabs(cp[9 * a + b] - cp[9 * b + a]));
          pscale = fmax(pscale, fabs(cp[9 * a + b]));
        }
      assert_true(sym <= 1e-10 * pscale);
      memcpy(work, cp, sizeof work);
      test_symmetric_eigenvalues(work, 9, lam);
      for (int k = 0; k < 9; ++k)
        if (!(lam[k] >= -1e-9 * pscale))
          fail_msg("%s shape %d: projected dP/dF has eigenvalue %g (scale %g)",
                   piola_material_model_name(model), s, lam[k], pscale);
    }
  }
}

static void test_dpdf_every_model(void **state) {
  (void)state;
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model) {
    check_model((piola_material_model)model, PIOLA_INVERSION_LINEAR, 0.3);
    check_model((piola_material_model)model, PIOLA_INVERSION_CLAMP, 0.3);
  }
  check_model(PIOLA_MODEL_NEOHOOKEAN, PIOLA_INVERSION_LINEAR, 0.5);
}

/* Near rest every model is positive definite: the projection must not change anything. */
static void test_projection_keeps_definite(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(5);
  const double f3[3] = {1.02, 0.99, 0.97};
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model) {
    piola_material m = fixture_material((piola_material_model)model);
    piola_mat3 f = compose(&rng, f3);
    double c[81], cp[81], lam[81], scale = 0, diff = 0;
    piola__element_dpdf(&m, &f, NULL, 0, 0, c);
    piola__element_dpdf(&m, &f, NULL, 0, 1, cp);
    memcpy(lam, c, sizeof lam);
    double ev[9];
    test_symmetric_eigenvalues(lam, 9, ev);
    int definite = 1;
    for (int k = 0; k < 9; ++k) definite &= ev[k] > 0;
    if (!definite) continue; /* rotated linear/corotated have a zero rotation mode at rest */
    for (int k = 0; k < 81; ++k) {
      scale = fmax(scale, fabs(c[k]));
      diff = fmax(diff, fabs(c[k] - cp[k]));
    }
    assert_true(diff <= 1e-12 * scale);
  }
}

/* piola__project_symmetric3 on S = Q diag(lambda) Q^T against the exact projection
 * Q diag(max(lambda, 0)) Q^T: every count of negative eigenvalues, eigenvalues repeated
 * exactly or nearly, next to zero, and magnitudes from 1e-200 to 1e200 (the closed form's
 * cases and the Jacobi fallback's). The projection onto the semi-definite matrices moves by at
 * most the rounding in S, so the tolerance is a few roundings of the largest |lambda|, with
 * room for the positive definite shortcut: it keeps S where the determinant rounds positive,
 * so a negative eigenvalue next to zero with another near zero (-1e-12, 0, 1) stays. The
 * result must be exactly symmetric. */
static void check_projection3(double q[3][3], const double lambda[3]) {
  double s[3][3], exact[3][3], scale = 0;
  for (int i = 0; i < 3; ++i) scale = fmax(scale, fabs(lambda[i]));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      s[i][j] = exact[i][j] = 0;
      for (int k = 0; k < 3; ++k) {
        s[i][j] += q[i][k] * lambda[k] * q[j][k];
        exact[i][j] += q[i][k] * fmax(lambda[k], 0.0) * q[j][k];
      }
    }
  for (int i = 0; i < 3; ++i) /* symmetric input, as the assembly's blocks are */
    for (int j = i + 1; j < 3; ++j) s[j][i] = s[i][j];
  piola__project_symmetric3(s);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      assert_true(s[i][j] == s[j][i]);
      if (!(fabs(s[i][j] - exact[i][j]) <= 2e-12 * scale))
        fail_msg("eigenvalues (%g %g %g): projected entry (%d %d) %.17g, exact %.17g", lambda[0],
                 lambda[1], lambda[2], i, j, s[i][j], exact[i][j]);
    }
}

static void test_projection_of_symmetric3(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(33);
  static const double patterns[][3] = {
      {-1.0, 2.0, 3.0},         {-1.0, -2.0, 3.0},         {-1.0, -2.0, -3.0}, {-1.0, -1.0, 2.0},
      {-1.0, 2.0, 2.0},         {-2.0, -1.0, -1.0},        {-1.0, 1e-9, 1.0},  {-1e-6, 1e-6, 1.0},
      {-1.0, -1e-9, 1e-9},      {-1e-12, 0.0, 1.0},        {-1.0, 0.0, 0.0},   {0.0, 0.0, 0.0},
      {-1.0, 1.0, 1.0 + 1e-12}, {-1.0, -1.0 - 1e-12, 1.0}, {-1e-7, 1.0, 1.0},  {1.0, 2.0, 3.0},
      {-3.0, 1e-15, 1e-15},
  };
  static const double scales[] = {1.0, 1e5, 1e-200, 1e200, 3.7e9};
  const long samples = test_samples(200, 20);
  for (long n = 0; n < samples; ++n) {
    double q9[9], q[3][3];
    fixture_random_rotation(&rng, q9);
    for (int k = 0; k < 9; ++k) q[k / 3][k % 3] = q9[k];
    for (size_t p = 0; p < sizeof patterns / sizeof patterns[0]; ++p)
      for (size_t c = 0; c < sizeof scales / sizeof scales[0]; ++c) {
        const double lambda[3] = {patterns[p][0] * scales[c], patterns[p][1] * scales[c],
                                  patterns[p][2] * scales[c]};
        check_projection3(q, lambda);
      }
    /* and eigenvalues drawn at random, in any order */
    double lambda[3];
    for (int k = 0; k < 3; ++k) lambda[k] = test_rng_uniform(&rng, -2.0, 2.0);
    check_projection3(q, lambda);
  }
  /* the axes themselves (a diagonal input: the adjugate's columns have zeros) */
  double identity[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (size_t p = 0; p < sizeof patterns / sizeof patterns[0]; ++p)
    check_projection3(identity, patterns[p]);
}

/* piola__material_stress_and_derivative against piola_material_stress and
 * piola_material_stress_derivative, value for value (== : the shortcut drops only terms
 * that are exact zeros), on random Fhat with no entry below the threshold (the shortcut),
 * entries exactly at it, and entries below it, inverted ones included (the public path). */
static void test_stress_and_derivative_shortcut(void **state) {
  (void)state;
  static const piola_inversion_mode MODES[3] = {PIOLA_INVERSION_LINEAR, PIOLA_INVERSION_CLAMP,
                                                PIOLA_INVERSION_ENERGY};
  test_rng rng = test_rng_seeded(23);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int mode = 0; mode < 3; ++mode) {
      piola_material_def def = piola_default_material_def();
      def.model = (piola_material_model)model;
      def.youngs_modulus = 1e5;
      def.poisson_ratio = 0.45;
      def.inversion_mode = MODES[mode];
      def.inversion_threshold = 0.3;
      piola_material m;
      assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
      for (int rep = 0; rep < 200; ++rep) {
        double fhat[3];
        for (int k = 0; k < 3; ++k) {
          fhat[k] = test_rng_uniform(&rng, 0.3, 2.5);
          if (rep % 4 == 1 && k == 0) fhat[k] = 0.3; /* at the threshold */
          if (rep % 4 == 2 && k == rep % 3) fhat[k] = test_rng_uniform(&rng, -1.5, 0.29);
          if (rep % 4 == 3) fhat[k] = test_rng_uniform(&rng, -1.5, 2.5); /* any, inverted too */
        }
        double p[3], d[3][3], pref[3], dref[3][3];
        piola__material_stress_and_derivative(&m, fhat, p, d);
        piola_material_stress(&m, fhat, pref);
        piola_material_stress_derivative(&m, fhat, dref);
        for (int i = 0; i < 3; ++i) {
          assert_true(p[i] == pref[i]);
          for (int j = 0; j < 3; ++j) assert_true(d[i][j] == dref[i][j]);
        }
      }
    }
  /* Each model's default inversion: Mooney-Rivlin's, Ogden's and HGO's threshold rises as J
   * falls from 0.96 to 0.94, so an entry above the threshold but below the risen one is
   * clamped and must not take the shortcut. */
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model) {
    piola_material_def def = piola_default_material_def();
    def.model = (piola_material_model)model;
    def.youngs_modulus = 1e5;
    def.poisson_ratio = 0.45;
    piola_material m;
    assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
    for (int rep = 0; rep < 200; ++rep) {
      double fhat[3];
      fhat[0] = test_rng_uniform(&rng, 0.25, 0.7);
      fhat[1] = rep % 2 ? test_rng_uniform(&rng, 0.25, 0.7) : test_rng_uniform(&rng, 1.0, 2.5);
      fhat[2] = test_rng_uniform(&rng, 0.9, 1.0) / (fhat[0] * fhat[1]);
      double p[3], d[3][3], pref[3], dref[3][3];
      piola__material_stress_and_derivative(&m, fhat, p, d);
      piola_material_stress(&m, fhat, pref);
      piola_material_stress_derivative(&m, fhat, dref);
      for (int i = 0; i < 3; ++i) {
        if (p[i] != pref[i])
          fail_msg("%s (default) at fhat (%g, %g, %g): Phat_%d %.17g, public %.17g",
                   piola_material_model_name(m.model), fhat[0], fhat[1], fhat[2], i, p[i], pref[i]);
        for (int j = 0; j < 3; ++j) assert_true(d[i][j] == dref[i][j]);
      }
    }
  }
}

/* 12 x 12 element stiffness -dF/dx of one tet from the 9 x 9 projected dP/dF. */
static void dense_element(const piola_elastic_body *body, int32_t t, double k[144]) {
  piola_mat3 f;
  const int32_t *idx = body->tets + 4 * t;
  double dm[3][3];
  for (int e = 0; e < 9; ++e) dm[e / 3][e % 3] = body->dm_inv[e][t];
  const double *x = body->positions;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int c = 0; c < 3; ++c) s += (x[3 * idx[c + 1] + i] - x[3 * idx[0] + i]) * dm[c][j];
      f.m[i][j] = s;
    }
  const piola_material *m = &body->materials[body->tet_material[t]];
  double fiber[3], *fp = NULL;
  if (body->fiber[0]) {
    for (int i = 0; i < 3; ++i) fiber[i] = body->fiber[i][t];
    fp = fiber;
  }
  double c[81];
  piola__element_dpdf(m, &f, fp, body->activation, 1, c);
  double g[4][3];
  for (int j = 0; j < 3; ++j) {
    g[0][j] = -(dm[0][j] + dm[1][j] + dm[2][j]);
    for (int a = 1; a < 4; ++a) g[a][j] = dm[a - 1][j];
  }
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      for (int i = 0; i < 3; ++i)
        for (int kk = 0; kk < 3; ++kk) {
          double s = 0;
          for (int j = 0; j < 3; ++j)
            for (int l = 0; l < 3; ++l) s += g[a][j] * c[9 * (3 * i + j) + 3 * kk + l] * g[b][l];
          k[12 * (3 * a + i) + 3 * b + kk] = body->rest_volume[t] * body->last_stiffness_scale * s;
        }
}

/* hgo_kappa: HGO's fibre dispersion (0: the fixture's material, the default's 0) */
static void check_body_matrix(piola_material_model model, double squash, double hgo_kappa) {
  piola_tet_mesh mesh = fixture_grid(2, 0.5);
  piola_elastic_body_def def = piola_default_elastic_body_def();
  piola_material mat = fixture_material(model);
  if (hgo_kappa > 0) {
    piola_material_def mdef = piola_default_material_def();
    mdef.model = PIOLA_MODEL_HGO;
    mdef.poisson_ratio = 0.3;
    mdef.hgo.kappa = hgo_kappa;
    assert_int_equal(piola_material_init(&mdef, &mat), PIOLA_OK);
  }
  def.rest_mesh = &mesh;
  def.materials = &mat;
  def.material_count = 1;
  double *fibers = NULL;
  if (model == PIOLA_MODEL_MUSCLE || model == PIOLA_MODEL_HGO) {
    fibers = malloc(sizeof(double) * 3 * (size_t)mesh.tet_count);
    for (int32_t t = 0; t < mesh.tet_count; ++t) fibers[3 * t] = 0.6, fibers[3 * t + 1] = 0.8, fibers[3 * t + 2] = 0;
    def.fiber_directions = fibers;
  }
  piola_elastic_body *body;
  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_OK);
  piola_elastic_body_set_activation(body, 0.7);
  const int32_t n = body->vertex_count;
  test_rng rng = test_rng_seeded(99 + model);
  double *x = malloc(sizeof(double) * 3 * (size_t)n), *forces = malloc(sizeof(double) * 3 * (size_t)n);
  for (int32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k)
      x[3 * i + k] = body->rest_positions[3 * i + k] * (k == 2 ? squash : 1.1) +
                     test_rng_uniform(&rng, -0.05, 0.05);
  assert_int_equal(piola_elastic_body_update(body, x, 1.5, forces, NULL), PIOLA_OK);
  piola__stiffness_matrix mx;
  assert_int_equal(piola__stiffness_matrix_init(&mx, body), PIOLA_OK);
  const double weight = 0.01;
  assert_int_equal(body->damping.edge_count > 0, 1);
  piola__stiffness_matrix_assemble(&mx, body, weight, 0.0, body->masses, 1.0);
  /* dense reference: M + weight K with K summed from 12 x 12 element matrices */
  const int32_t dim = 3 * n;
  double *dense = calloc((size_t)dim * (size_t)dim, sizeof(double));
  double ke[144];
  for (int32_t t = 0; t < body->tet_count; ++t) {
    dense_element(body, t, ke);
    /* each element matrix: symmetric, positive semi-definite, rows sum to zero */
    double lam[12], work[144], kscale = 0;
    for (int e = 0; e < 144; ++e) kscale = fmax(kscale, fabs(ke[e]));
    memcpy(work, ke, sizeof work);
    test_symmetric_eigenvalues(work, 12, lam);
    for (int e = 0; e < 12; ++e) assert_true(lam[e] >= -1e-9 * kscale);
    for (int r = 0; r < 12; ++r)
      for (int c = 0; c < 3; ++c) {
        double sum = 0;
        for (int b = 0; b < 4; ++b) sum += ke[12 * r + 3 * b + c];
        assert_true(fabs(sum) <= 1e-10 * kscale);
      }
    const int32_t *idx = body->tets + 4 * t;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int i = 0; i < 3; ++i)
          for (int k = 0; k < 3; ++k)
            dense[(size_t)(3 * idx[a] + i) * dim + 3 * idx[b] + k] += weight * ke[12 * (3 * a + i) + 3 * b + k];
  }
  for (int32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) dense[(size_t)(3 * i + k) * dim + 3 * i + k] += body->masses[i];
  double *p = malloc(sizeof(double) * dim), *q = malloc(sizeof(double) * dim);
  double *ap = malloc(sizeof(double) * dim), *aq = malloc(sizeof(double) * dim);
  for (int32_t j = 0; j < dim; ++j) p[j] = test_rng_normal(&rng), q[j] = test_rng_normal(&rng);
  piola__stiffness_matrix_apply(&mx, body, body->masses, 1.0, p, ap);
  piola__stiffness_matrix_apply(&mx, body, body->masses, 1.0, q, aq);
  double err = 0, size = 0, pq = 0, qp = 0;
  for (int32_t r = 0; r < dim; ++r) {
    double ref = 0;
    for (int32_t c = 0; c < dim; ++c) ref += dense[(size_t)r * dim + c] * p[c];
    err = fmax(err, fabs(ref - ap[r]));
    size = fmax(size, fabs(ref));
    pq += p[r] * aq[r];
    qp += q[r] * ap[r];
  }
  assert_true(err <= 1e-10 * size);
  assert_true(fabs(pq - qp) <= 1e-12 * (fabs(pq) + fabs(qp)));
  /* the diagonal blocks are the dense ones */
  for (int32_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        assert_true(fabs(mx.diagonal[9 * i + 3 * a + b] - dense[(size_t)(3 * i + a) * dim + 3 * i + b]) <=
                    1e-10 * size);
  /* a rigid translation sees only the mass */
  for (int32_t i = 0; i < n; ++i) p[3 * i] = 0.3, p[3 * i + 1] = -1.2, p[3 * i + 2] = 2.0;
  piola__stiffness_matrix_apply(&mx, body, body->masses, 0.0, p, ap);
  for (int32_t j = 0; j < dim; ++j) assert_true(fabs(ap[j]) <= 1e-12 * size);
  piola__stiffness_matrix_free(&mx);
  free(dense);
  free(p);
  free(q);
  free(ap);
  free(aq);
  free(x);
  free(forces);
  free(fibers);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

/* The largest difference between the assembled K p and central differences of the body's
 * own elastic forces -(df/dx) p along a random direction p, relative to the largest entry of
 * the latter, at a smooth deformation of a grid (a bend and a stretch scaled by `squeeze`,
 * then a rotation), with the assembly's signed_twist as given. */
static double matrix_force_derivative_mismatch(piola_material_model model, double squeeze,
                                               int signed_twist) {
  piola_tet_mesh mesh = fixture_grid(3, 0.3);
  piola_material mat = fixture_material(model);
  piola_elastic_body_def def = piola_default_elastic_body_def();
  def.rest_mesh = &mesh;
  def.materials = &mat;
  def.material_count = 1;
  double *fibers = NULL;
  if (model == PIOLA_MODEL_HGO) { /* fibres in the x-y plane, stretched by the deformation */
    fibers = malloc(sizeof(double) * 3 * (size_t)mesh.tet_count);
    for (int32_t t = 0; t < mesh.tet_count; ++t) fibers[3 * t] = 1, fibers[3 * t + 1] = 0.3 * (t % 3), fibers[3 * t + 2] = 0;
    def.fiber_directions = fibers;
  }
  piola_elastic_body *body;
  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_OK);
  const int32_t n = body->vertex_count, dim = 3 * n;
  double *x = malloc(sizeof(double) * dim), *xp = malloc(sizeof(double) * dim);
  double *f0 = malloc(sizeof(double) * dim), *fp = malloc(sizeof(double) * dim);
  double *fm = malloc(sizeof(double) * dim), *p = malloc(sizeof(double) * dim);
  double *kp = malloc(sizeof(double) * dim);
  test_rng rng = test_rng_seeded(7);
  double r[9];
  fixture_random_rotation(&rng, r);
  for (int32_t i = 0; i < n; ++i) {
    const double *q = body->rest_positions + 3 * i;
    /* a bend and a stretch, then a rotation */
    double y[3] = {squeeze * (q[0] * 1.1 + 0.2 * q[1] * q[1]), squeeze * q[1] * 0.95,
                   squeeze * (q[2] * 1.05 + 0.1 * q[0] * q[1])};
    for (int k = 0; k < 3; ++k) x[3 * i + k] = r[3 * k] * y[0] + r[3 * k + 1] * y[1] + r[3 * k + 2] * y[2];
  }
  for (int32_t j = 0; j < dim; ++j) p[j] = test_rng_normal(&rng);
  const double eps = 1e-6;
  for (int32_t j = 0; j < dim; ++j) xp[j] = x[j] + eps * p[j];
  assert_int_equal(piola_elastic_body_update(body, xp, 1.0, fp, NULL), PIOLA_OK);
  for (int32_t j = 0; j < dim; ++j) xp[j] = x[j] - eps * p[j];
  assert_int_equal(piola_elastic_body_update(body, xp, 1.0, fm, NULL), PIOLA_OK);
  assert_int_equal(piola_elastic_body_update(body, x, 1.0, f0, NULL), PIOLA_OK);
  piola__stiffness_matrix mx;
  assert_int_equal(piola__stiffness_matrix_init(&mx, body), PIOLA_OK);
  /* A = 0 M - 1 (df/dx): A p = -(df/dx) p */
  body->signed_twist = signed_twist;
  piola__stiffness_matrix_assemble(&mx, body, 1.0, 0.0, body->masses, 0.0);
  piola__stiffness_matrix_apply(&mx, body, body->masses, 0.0, p, kp);
  double err = 0, size = 0;
  for (int32_t j = 0; j < dim; ++j) {
    double fd = -(fp[j] - fm[j]) / (2 * eps);
    err = fmax(err, fabs(fd - kp[j]));
    size = fmax(size, fabs(fd));
  }
  assert_true(size > 0 && isfinite(err));
  piola__stiffness_matrix_free(&mx);
  free(x), free(xp), free(f0), free(fp), free(fm), free(p), free(kp), free(fibers);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
  return err / size;
}

/* At a stretched state where no element needs the definiteness fix, the assembled stiffness
 * is the derivative of the body's own elastic forces. */
static void test_matrix_is_force_derivative(void **state) {
  (void)state;
  const piola_material_model models[2] = {PIOLA_MODEL_NEOHOOKEAN, PIOLA_MODEL_HGO}; /* fibres too */
  for (int k = 0; k < 2; ++k) {
    const double mismatch = matrix_force_derivative_mismatch(models[k], 1.0, 0);
    if (!(mismatch <= 1e-5))
      fail_msg("%s: K p differs from -df/dx p by %g of its size",
               piola_material_model_name(models[k]), mismatch);
  }
}

/* Compressed, every element's rotation eigenvalues (P_p + P_q) / (f_p + f_q) are negative:
 * the projected matrix clamps them and is not the derivative of the forces (which is why a
 * Newton iteration on it converges only linearly), while the matrix of Newton's tail
 * (signed_twist) is, for every model whose shear quotients and 3x3 block stay positive
 * there. */
static void test_signed_twist_is_force_derivative_compressed(void **state) {
  (void)state;
  const piola_material_model models[4] = {PIOLA_MODEL_NEOHOOKEAN, PIOLA_MODEL_COROTATED,
                                          PIOLA_MODEL_STABLE_NEOHOOKEAN, PIOLA_MODEL_HGO};
  for (int k = 0; k < 4; ++k) {
    const double projected = matrix_force_derivative_mismatch(models[k], 0.85, 0);
    const double tail = matrix_force_derivative_mismatch(models[k], 0.85, 1);
    if (!(projected >= 1e-3 && tail <= 1e-5))
      fail_msg("%s compressed: K p against -df/dx p, projected %g, signed twist %g of its size",
               piola_material_model_name(models[k]), projected, tail);
  }
}

/* Near collapse or inverted (a pair's f_p + f_q below 1) the tail's matrix is the projected
 * one, pair by pair: there the rotation quotient changes sign through the reflection and an
 * indefinite matrix would aim Newton at a collapsed state's saddle. A compressed pair above
 * the cutoff keeps its negative rotation eigenvalue. */
static void test_signed_twist_only_where_compressed(void **state) {
  (void)state;
  static const double SHAPES_NEAR_COLLAPSE[][3] = {
      {0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {1.0, 1.0, 0.0},  {0.8, 0.3, -0.2},
      {0.6, 0.3, 0.2}, {1.2, 0.45, 0.5}, {0.9, -0.4, 0.4}, {-0.3, -0.3, 1.1}};
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model) {
    piola_material m = fixture_material((piola_material_model)model);
    for (size_t n = 0; n < sizeof SHAPES_NEAR_COLLAPSE / sizeof SHAPES_NEAR_COLLAPSE[0]; ++n) {
      const double *f = SHAPES_NEAR_COLLAPSE[n];
      double phat[3];
      piola_material_stress(&m, f, phat);
      piola__diagonal_stiffness projected, tail;
      piola__diagonal_stiffness_eval(&m, f, phat, PIOLA_STIFFNESS_PROJECTED, &projected);
      piola__diagonal_stiffness_eval(&m, f, phat, PIOLA_STIFFNESS_SIGNED_TWIST, &tail);
      for (int k = 0; k < 3; ++k) {
        const int p = PIOLA__PAIR_P[k], q = PIOLA__PAIR_Q[k];
        const double a = tail.pair_a[k], b = tail.pair_b[k];
        if (f[p] + f[q] < PIOLA__SIGNED_TWIST_LEAST_STRETCH_SUM) {
          if (a != projected.pair_a[k] || b != projected.pair_b[k])
            fail_msg("%s at (%g, %g, %g), pair %d: the tail's block differs from the projected one",
                     piola_material_model_name((piola_material_model)model), f[0], f[1], f[2], k);
        }
        assert_true(isfinite(a) && isfinite(b));
      }
    }
    /* compressed above the cutoff: the rotation eigenvalue a - b keeps its negative sign */
    const double squeezed[3] = {0.8, 0.8, 0.8};
    assert_true(squeezed[0] + squeezed[1] >= PIOLA__SIGNED_TWIST_LEAST_STRETCH_SUM);
    double phat[3];
    piola_material_stress(&m, squeezed, phat);
    if (!(phat[0] + phat[1] < 0)) continue; /* a model whose stress is not compressive here */
    piola__diagonal_stiffness tail;
    piola__diagonal_stiffness_eval(&m, squeezed, phat, PIOLA_STIFFNESS_SIGNED_TWIST, &tail);
    assert_true(tail.pair_a[0] - tail.pair_b[0] < 0);
  }
}

static void test_assembled_matrix(void **state) {
  (void)state;
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model) {
    check_body_matrix((piola_material_model)model, 0.9, 0);  /* stretched and squashed */
    check_body_matrix((piola_material_model)model, -0.4, 0); /* inverted through the plane */
    check_body_matrix((piola_material_model)model, 0.0, 0);  /* flat */
  }
  /* HGO with dispersed fibres: the isotropic part of its fibre term */
  check_body_matrix(PIOLA_MODEL_HGO, 0.9, 0.2);
  check_body_matrix(PIOLA_MODEL_HGO, -0.4, 0.2);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_dpdf_every_model),
      cmocka_unit_test(test_projection_keeps_definite),
      cmocka_unit_test(test_projection_of_symmetric3),
      cmocka_unit_test(test_stress_and_derivative_shortcut),
      cmocka_unit_test(test_assembled_matrix),
      cmocka_unit_test(test_matrix_is_force_derivative),
      cmocka_unit_test(test_signed_twist_is_force_derivative_compressed),
      cmocka_unit_test(test_signed_twist_only_where_compressed),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
