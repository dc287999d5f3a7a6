/* Constitutive models in diagonal form: consistency (energy -> stress -> derivative by finite
 * differences), rest state, small-strain elasticity, the inversion extension (continuity,
 * finiteness, restoring sign), symmetries, parameter validation. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "material/material_kernels.h"
#include "material_checks.h"
#include "piola/material.h"

#define N_MODES 2
static const piola_inversion_mode modes[N_MODES] = {PIOLA_INVERSION_LINEAR, PIOLA_INVERSION_CLAMP};
static const double youngs = 1e5;

/* The model's default threshold, set explicitly: the extension with a fixed threshold, whose
 * properties the tests below check (the rubber models' default rise of the threshold with
 * compression, which a threshold left unset gets, has its own test at the end). */
static piola_material make(piola_material_model model, piola_inversion_mode mode, double nu) {
  double threshold;
  piola_material_default_inversion(model, NULL, &threshold);
  return material_of(model, mode, youngs, nu, threshold);
}

/* Variant v of 2 N_MODES of `model`: every inversion mode (v % N_MODES), with a positive
 * lambda (nu = 0.4) and then a negative one (auxetic, nu = -0.3). */
static piola_material variant_material(int model, int variant) {
  return make((piola_material_model)model, modes[variant % N_MODES], variant < N_MODES ? 0.4 : -0.3);
}

static double energy(const piola_material *m, double f0, double f1, double f2) {
  const double f[3] = {f0, f1, f2};
  return piola_material_energy_density(m, f);
}

/* Central difference of the energy along entry i. */
static double energy_fd(const piola_material *m, const double f[3], int i, double h) {
  double a[3] = {f[0], f[1], f[2]}, b[3] = {f[0], f[1], f[2]};
  a[i] += h, b[i] -= h;
  return (piola_material_energy_density(m, a) - piola_material_energy_density(m, b)) / (2 * h);
}

/* Central difference of the stress along entry j: column j of dPhat/dFhat. */
static void stress_fd(const piola_material *m, const double f[3], int j, double h, double col[3]) {
  double a[3] = {f[0], f[1], f[2]}, b[3] = {f[0], f[1], f[2]}, pa[3], pb[3];
  a[j] += h, b[j] -= h;
  piola_material_stress(m, a, pa);
  piola_material_stress(m, b, pb);
  for (int i = 0; i < 3; ++i) col[i] = (pa[i] - pb[i]) / (2 * h);
}

/* True when f is within `gap` of a place where the stress derivative jumps: the threshold,
 * and for the spline model its breakpoints. */
static int near_kink(const piola_material *m, const double f[3], double gap) {
  for (int i = 0; i < 3; ++i)
    if (fabs(f[i] - m->threshold) < gap || near_spline_breakpoint(m, f[i], gap)) return 1;
  return 0;
}

/* ------------------------------------------------------------------ rest and small strain */

static void rest_state_is_stress_free_with_linear_elastic_tangent(void **state) {
  (void)state;
  const double nus[] = {-0.3, 0.0, 0.3, 0.49};
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int mode = 0; mode < N_MODES; ++mode)
      for (size_t n = 0; n < sizeof nus / sizeof nus[0]; ++n) {
        const piola_material m = make((piola_material_model)model, modes[mode], nus[n]);
        const double one[3] = {1, 1, 1};
        double p[3], k[3][3];
        piola_material_stress(&m, one, p);
        piola_material_stress_derivative(&m, one, k);
        for (int i = 0; i < 3; ++i) assert_close(p[i], 0.0, 1e-12 * youngs);
        assert_close(piola_material_energy_density(&m, one), 0.0, 1e-12 * youngs);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            assert_close(k[i][j], (i == j ? 2 * m.mu : 0.0) + m.lambda, 1e-9 * youngs);
      }
}

/* Pull along entry 0 by a small strain with the lateral entries stress-free (found by
 * Newton's method on the public stress and derivative): stress / strain must be Young's
 * modulus and lateral strain / strain must be minus Poisson's ratio. */
static void uniaxial_small_strain_gives_youngs_modulus_and_poisson_ratio(void **state) {
  (void)state;
  const double nus[] = {-0.2, 0.25, 0.45};
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (size_t n = 0; n < sizeof nus / sizeof nus[0]; ++n) {
      const piola_material m = make((piola_material_model)model, PIOLA_INVERSION_LINEAR, nus[n]);
      const double eps = 1e-6;
      double f[3] = {1 + eps, 1, 1}, p[3], k[3][3];
      for (int it = 0; it < 20; ++it) {
        piola_material_stress(&m, f, p);
        piola_material_stress_derivative(&m, f, k);
        /* Symmetric lateral update: f1 = f2 = x, residual P1 = 0. */
        const double dx = -p[1] / (k[1][1] + k[1][2]);
        f[1] += dx, f[2] += dx;
      }
      piola_material_stress(&m, f, p);
      /* The Ogden models and HGO take their shear modulus from their own parameters (E
       * follows from it). */
      const double e = MATERIAL_IS_OGDEN(m.model) || m.model == PIOLA_MODEL_HGO
                           ? 2 * m.mu * (1 + nus[n])
                           : youngs;
      assert_close(p[1], 0.0, 1e-7 * e * eps);
      assert_close(p[0] / eps, e, 1e-4 * e);
      assert_close((f[1] - 1) / eps, -nus[n], 1e-4);
    }
}

/* ------------------------------------------------------------------ consistency */

static void stress_is_energy_gradient_above_threshold(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(11);
  const long samples = test_samples(400, 20);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int variant = 0; variant < 2 * N_MODES; ++variant) {
      const piola_material m = variant_material(model, variant);
      for (long s = 0; s < samples; ++s) {
        double f[3], p[3];
        random_point(&rng, m.threshold + 0.01, 2.5, f);
        if (near_kink(&m, f, 1e-4)) continue;
        piola_material_stress(&m, f, p);
        const double tol = 1e-7 * stress_scale(&m, f);
        for (int i = 0; i < 3; ++i) assert_close(energy_fd(&m, f, i, 1e-6), p[i], tol);
      }
    }
}

/* Past the threshold the energy is built so that its derivative along every clamped entry
 * is exactly the extended stress (see docs/materials.md); with all entries clamped that is
 * the whole gradient. */
static void stress_is_energy_gradient_along_clamped_entries(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(12);
  const long samples = test_samples(400, 20);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int variant = 0; variant < 2 * N_MODES; ++variant) {
      const piola_material m = variant_material(model, variant);
      for (long s = 0; s < samples; ++s) {
        double f[3], p[3];
        random_point(&rng, -3.0, 2.5, f);
        f[s % 3] = test_rng_uniform(&rng, -3.0, m.threshold - 0.01); /* at least one clamped */
        if (near_kink(&m, f, 1e-4)) continue;
        piola_material_stress(&m, f, p);
        const double tol = 1e-7 * stress_scale(&m, f);
        for (int i = 0; i < 3; ++i)
          if (f[i] < m.threshold) assert_close(energy_fd(&m, f, i, 1e-6), p[i], tol);
      }
    }
}

static void derivative_matches_finite_differences_everywhere(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(13);
  const long samples = test_samples(600, 30);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int variant = 0; variant < 2 * N_MODES; ++variant) {
      const piola_material m = variant_material(model, variant);
      long checked = 0;
      for (long s = 0; s < samples; ++s) {
        double f[3], k[3][3], col[3];
        random_point(&rng, -3.0, 3.0, f);
        if (near_kink(&m, f, 1e-4)) continue;
        piola_material_stress_derivative(&m, f, k);
        const double tol = 1e-6 * stress_scale(&m, f);
        for (int j = 0; j < 3; ++j) {
          stress_fd(&m, f, j, 1e-7, col);
          for (int i = 0; i < 3; ++i) {
            if (fabs(col[i] - k[i][j]) > tol)
              fail_msg("%s mode %d at (%g, %g, %g): dP[%d][%d] = %.10g, finite difference %.10g",
                       piola_material_model_name(m.model), (int)m.inversion_mode, f[0], f[1], f[2],
                       i, j, k[i][j], col[i]);
          }
        }
        ++checked;
      }
      assert_true(checked > samples / 2);
    }
}

static void derivative_is_symmetric_where_a_potential_exists(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(14);
  const long samples = test_samples(200, 10);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int mode = 0; mode < N_MODES; ++mode) {
      const piola_material m = make((piola_material_model)model, modes[mode], 0.3);
      for (long s = 0; s < samples; ++s) {
        double f[3], k[3][3];
        /* The model itself, and (LINEAR and CLAMP alike) all entries clamped at once. */
        const int all_clamped = s % 2;
        random_point(&rng, all_clamped ? -4.0 : m.threshold, all_clamped ? m.threshold : 3.0, f);
        piola_material_stress_derivative(&m, f, k);
        const double tol = 1e-12 * stress_scale(&m, f);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < i; ++j) assert_close(k[i][j], k[j][i], tol);
      }
    }
}

/* ------------------------------------------------------------------ the extension */

static void extension_is_continuous_at_the_threshold(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(15);
  const long samples = test_samples(300, 20);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int mode = 0; mode < N_MODES; ++mode) {
      piola_material m = make((piola_material_model)model, modes[mode], 0.3);
      /* StVK's Taylor slope at the default threshold is negative (its stress peaks at
       * f = 1/sqrt(3) under uniaxial compression), so the extension always raises it there:
       * C1 is checked for StVK with a threshold above that peak. */
      if (m.model == PIOLA_MODEL_STVK) m.threshold = 0.8;
      const double c = m.threshold, h = 1e-9;
      long slope_checked = 0;
      for (long s = 0; s < samples; ++s) {
        double f[3];
        random_point(&rng, c + 0.05, 2.0, f);
        const int i = (int)(s % 3);
        double above[3] = {f[0], f[1], f[2]}, below[3] = {f[0], f[1], f[2]};
        above[i] = c + h, below[i] = c - h;
        double pa[3], pb[3], ka[3][3], kb[3][3], k0[3][3], p0[3];
        piola_material_stress(&m, above, pa);
        piola_material_stress(&m, below, pb);
        const double scale = stress_scale(&m, above);
        for (int r = 0; r < 3; ++r) assert_close(pa[r], pb[r], 1e-6 * scale);
        assert_close(energy(&m, above[0], above[1], above[2]),
                     energy(&m, below[0], below[1], below[2]), 1e-6 * scale);
        piola_material_stress_derivative(&m, above, ka);
        piola_material_stress_derivative(&m, below, kb);
        if (m.inversion_mode == PIOLA_INVERSION_CLAMP) {
          /* C0: below the threshold the clamped column is flat except the restoring ramp. */
          for (int r = 0; r < 3; ++r)
            if (r != i) assert_close(kb[r][i], 0.0, 0.0);
          continue;
        }
        /* C1 wherever the Taylor slope did not have to be raised (see docs). */
        double at[3] = {f[0], f[1], f[2]};
        at[i] = c;
        piola_material_stress(&m, at, p0);
        piola_material_stress_derivative(&m, at, k0);
        if (k0[i][i] < m.mu + fmax(p0[i], 0.0) / c) {
          assert_true(kb[i][i] > k0[i][i]); /* raised, never lowered */
          continue;
        }
        for (int r = 0; r < 3; ++r)
          for (int q = 0; q < 3; ++q) assert_close(ka[r][q], kb[r][q], 1e-5 * scale);
        ++slope_checked;
      }
      if (m.inversion_mode == PIOLA_INVERSION_LINEAR && slope_checked <= samples / 4)
        fail_msg("%s: C1 checked at only %ld of %ld points", piola_material_model_name(m.model),
                 slope_checked, samples);
    }
}

/* The definition itself: below the threshold the stress is the relaxed and saturated Taylor
 * expansion around fc (LINEAR, see below and docs/materials.md) or P(fc) (CLAMP), computed here from the public values at the clamped point, wherever the
 * restoring safeguards are inactive (all couplings nonnegative and the diagonal slope not
 * raised; for CLAMP the clamped stress already compressive enough). */
static void extension_is_the_taylor_expansion_where_no_safeguard_acts(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(20);
  const long samples = test_samples(400, 20);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int mode = 0; mode < N_MODES; ++mode) {
      const piola_material m = make((piola_material_model)model, modes[mode], 0.3);
      const double c = m.threshold;
      long checked = 0;
      for (long s = 0; s < samples; ++s) {
        double f[3], fc[3], d[3], p[3], pc[3], kc[3][3];
        random_point(&rng, 0.5, 1.5, f);
        const int n_clamped = 1 + (int)(s % 3);
        for (int i = 0; i < n_clamped; ++i) f[i] = test_rng_uniform(&rng, -2.0, c - 1e-3);
        for (int i = 0; i < 3; ++i) fc[i] = f[i] < c ? c : f[i], d[i] = f[i] - fc[i];
        piola_material_stress(&m, fc, pc);
        piola_material_stress_derivative(&m, fc, kc);
        int safe = 1;
        for (int i = 0; i < n_clamped; ++i) {
          if (m.inversion_mode == PIOLA_INVERSION_CLAMP) {
            safe &= pc[i] <= -m.mu * c;
          } else {
            safe &= kc[i][i] >= m.mu + fmax(pc[i], 0.0) / c;
            for (int j = 0; j < n_clamped; ++j) safe &= (i == j) || kc[i][j] >= 0.0;
          }
        }
        if (!safe) continue;
        piola_material_stress(&m, f, p);
        /* LINEAR (docs/materials.md): the Taylor expansion with the diagonal slope relaxing
         * from K_ii to s_far = max(min(K_ii, 2 mu + lambda), mu + max(p, 0)/c) and the
         * couplings into unclamped rows saturating, through q(d) = d w / (w - d), w = c/4. */
        const double w = 0.25 * c;
        for (int i = 0; i < 3; ++i) {
          double expected = pc[i];
          if (m.inversion_mode == PIOLA_INVERSION_LINEAR) {
            const double qi = d[i] * w / (w - d[i]);
            if (d[i] < 0.0) {
              const double far = fmax(fmin(kc[i][i], 2.0 * m.mu + m.lambda),
                                      m.mu + fmax(pc[i], 0.0) / c);
              expected += far * d[i] + (kc[i][i] - far) * qi;
              for (int j = 0; j < 3; ++j)
                if (j != i) expected += kc[i][j] * d[j];
            } else {
              for (int j = 0; j < 3; ++j) expected += kc[i][j] * d[j] * w / (w - d[j]);
            }
          }
          assert_close(p[i], expected, 1e-10 * stress_scale(&m, f));
        }
        ++checked;
      }
      /* StVK's slope at c = 0.3 is always raised (LINEAR); everything else must be checked. */
      if (!(m.model == PIOLA_MODEL_STVK && m.inversion_mode == PIOLA_INVERSION_LINEAR) &&
          checked < samples / 10)
        fail_msg("%s mode %d: only %ld of %ld samples free of safeguards",
                 piola_material_model_name(m.model), (int)m.inversion_mode, checked, samples);
    }
}

static void check_finite_and_restoring(const piola_material *m, const double f[3]) {
  double p[3], k[3][3];
  piola_material_stress(m, f, p);
  piola_material_stress_derivative(m, f, k);
  const double psi = piola_material_energy_density(m, f);
  assert_true(isfinite(psi));
  for (int i = 0; i < 3; ++i) {
    assert_true(isfinite(p[i]));
    for (int j = 0; j < 3; ++j) assert_true(isfinite(k[i][j]));
    if (f[i] <= 0.0 && !(p[i] < 0.0))
      fail_msg("%s mode %d at (%g, %g, %g): Phat[%d] = %g does not push back",
               piola_material_model_name(m->model), (int)m->inversion_mode, f[0], f[1], f[2], i,
               p[i]);
    /* Past the threshold the slope of a clamped entry is never softening. */
    if (f[i] < m->threshold && m->inversion_mode == PIOLA_INVERSION_LINEAR)
      assert_true(k[i][i] >= m->mu * (1 - 1e-12));
  }
}

static void flat_and_inverted_entries_are_finite_and_pushed_back(void **state) {
  (void)state;
  const double fixed[][3] = {{0, 0, 0},
                             {-1, -1, -1},
                             {-1e6, -1e6, -1e6},
                             {0, 1, 1},
                             {-0.5, 1, 1},
                             {-1e6, 1, 1},
                             {0, 0, 1},
                             {-2, 0, 3},
                             {-0.01, 5, 5},
                             {-0.01, 10, 10},
                             {0, 10, 0.1},
                             {-3, -2, 8},
                             {-1e-300, 1, 1},
                             {-0.2, 0.3, 0.3},
                             {1e3, -1e3, 1e3},
                             {0.1, 0.2, -50},
                             /* The documented range of finiteness: |f| up to 1e30. */
                             {1e30, 1e30, 1e30},
                             {-1e30, 1e30, 1e30},
                             {-1e30, -1e30, -1e30},
                             {-1e30, 1e-30, 1e30}};
  test_rng rng = test_rng_seeded(16);
  const long samples = test_samples(2000, 50);
  const double nus[] = {-0.5, 0.3, 0.49};
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int mode = 0; mode < N_MODES; ++mode)
      for (size_t n = 0; n < sizeof nus / sizeof nus[0]; ++n) {
        const piola_material m = make((piola_material_model)model, modes[mode], nus[n]);
        for (size_t c = 0; c < sizeof fixed / sizeof fixed[0]; ++c)
          check_finite_and_restoring(&m, fixed[c]);
        for (long s = 0; s < samples; ++s) {
          double f[3];
          random_point(&rng, -10.0, 10.0, f);
          check_finite_and_restoring(&m, f);
        }
      }
}

/* The paper's Figure 3 complaint: St. Venant-Kirchhoff softens under compression past
 * f = 1/sqrt(3) and pushes inverted elements the wrong way. Extended, it pushes back. */
static void stvk_pushes_back_where_the_plain_model_would_not(void **state) {
  (void)state;
  const piola_material m = make(PIOLA_MODEL_STVK, PIOLA_INVERSION_LINEAR, 0.3);
  double prev = -INFINITY;
  for (double f0 = 1.0; f0 >= -2.0; f0 -= 0.01) {
    const double f[3] = {f0, 1, 1};
    double p[3];
    piola_material_stress(&m, f, p);
    if (f0 + 0.01 < m.threshold) assert_true(p[0] < prev); /* monotone past the threshold */
    if (f0 < 0.99) assert_true(p[0] < 0.0);
    prev = p[0];
  }
  /* Plain StVK at f0 = -0.5 (others 1) would give a positive (inverting) stress:
   * P0 = f0 (mu (f0^2 - 1) + lambda/2 (f0^2 - 1)) = +0.375 (mu + lambda/2). */
  const double f[3] = {-0.5, 1, 1};
  double p[3];
  piola_material_stress(&m, f, p);
  assert_true(p[0] < -0.3 * m.mu);
}

/* ------------------------------------------------------------------ symmetry */

static void stress_commutes_with_permutations(void **state) {
  (void)state;
  static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  test_rng rng = test_rng_seeded(17);
  const long samples = test_samples(200, 10);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int mode = 0; mode < N_MODES; ++mode) {
      const piola_material m = make((piola_material_model)model, modes[mode], 0.35);
      for (long s = 0; s < samples; ++s) {
        double f[3], p[3], k[3][3];
        random_point(&rng, -2.0, 3.0, f);
        piola_material_stress(&m, f, p);
        piola_material_stress_derivative(&m, f, k);
        const double psi = piola_material_energy_density(&m, f);
        const double tol = 1e-12 * stress_scale(&m, f);
        for (int q = 1; q < 6; ++q) {
          const int *pi = perms[q];
          double g[3], pg[3], kg[3][3];
          for (int i = 0; i < 3; ++i) g[i] = f[pi[i]];
          piola_material_stress(&m, g, pg);
          piola_material_stress_derivative(&m, g, kg);
          assert_close(piola_material_energy_density(&m, g), psi, 1e-12 * (fabs(psi) + youngs));
          for (int i = 0; i < 3; ++i) {
            assert_close(pg[i], p[pi[i]], tol);
            for (int j = 0; j < 3; ++j) assert_close(kg[i][j], k[pi[i]][pi[j]], tol);
          }
        }
      }
    }
}

/* ------------------------------------------------------------------ the spline model */

static void spline_is_soft_at_rest_and_stiff_past_its_stretches(void **state) {
  (void)state;
  piola_material_def def = piola_default_material_def();
  def.model = PIOLA_MODEL_SPLINE;
  def.spline.stiffening = 7.0;
  piola_material m;
  assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
  const double rest_slope = 2 * m.mu, stiff_slope = 7.0 * rest_slope;
  double last_a1 = -INFINITY;
  for (double f0 = 0.35; f0 <= 2.0; f0 += 0.005) {
    /* Lateral entries 1: the pressure part of dP00 is lambda (f1 f2)^2 = lambda. */
    const double f[3] = {f0, 1, 1};
    double k[3][3], p[3];
    piola_material_stress_derivative(&m, f, k);
    piola_material_stress(&m, f, p);
    const double a2 = k[0][0] - m.lambda;           /* slope of the 1D curve */
    const double a1 = p[0] - m.lambda * (f0 - 1.0); /* the 1D curve itself */
    if (f0 < def.spline.compression_stretch - 1e-9 || f0 > def.spline.elongation_stretch + 1e-9)
      assert_close(a2, stiff_slope, 1e-9 * stiff_slope);
    else
      assert_true(a2 >= rest_slope * (1 - 1e-12) && a2 <= stiff_slope * (1 + 1e-12));
    assert_true(a1 > last_a1); /* monotone curve, zero only at rest */
    assert_true((f0 - 1.0) * a1 >= 0.0);
    last_a1 = a1;
  }
  /* Continuity of the 1D slope across the breakpoints (C1 spline). */
  const double breaks[] = {def.spline.compression_stretch, 1.0, def.spline.elongation_stretch};
  for (int b = 0; b < 3; ++b) {
    const double lo[3] = {breaks[b] - 1e-9, 1, 1}, hi[3] = {breaks[b] + 1e-9, 1, 1};
    double klo[3][3], khi[3][3];
    piola_material_stress_derivative(&m, lo, klo);
    piola_material_stress_derivative(&m, hi, khi);
    assert_close(klo[0][0], khi[0][0], 1e-6 * stiff_slope);
  }
}

/* The vectorizable logarithm the neo-Hookean kernel uses agrees with libm's to a few ulp. */
static void kernel_log_matches_libm(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(19);
  const long samples = test_samples(200000, 1000);
  const double special[] = {
      1.0,        2.0,    0.5,      1.4142135623730951,     1.4142135623730954,
      0.3,        1e-310, 4.9e-324, 1.7976931348623157e308, 1.0 + 1e-15,
      1.0 - 1e-16};
  for (size_t i = 0; i < sizeof special / sizeof special[0]; ++i)
    assert_close(kernel_log(special[i]), log(special[i]), 4 * 2.2e-16 * fabs(log(special[i])));
  for (long s = 0; s < samples; ++s) {
    const double x =
        s % 2 ? exp(test_rng_uniform(&rng, -740.0, 709.0)) : test_rng_uniform(&rng, 0.0, 4.0);
    const double ref = log(x);
    assert_close(kernel_log(x), ref, 4 * 2.2e-16 * fabs(ref) + 1e-300);
  }
}

/* The divide-free reciprocal of the force loop's lane kernels is within 2 ulp of 1/x over
 * the range piola uses it on (and far beyond). */
static void kernel_recip_fast_is_within_two_ulp(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(20);
  const long samples = test_samples(200000, 1000);
  const double special[] = {1.0, 2.0, 0.5, 1.7071067811865475, 2.414213562373095, 1e-300, 1e300,
                            3.0, 1.0 + 1e-15, 1.0 - 1e-16, 0.9999999999999999};
  for (size_t i = 0; i < sizeof special / sizeof special[0]; ++i)
    assert_close(kernel_recip_fast(special[i]), 1.0 / special[i], 2 * 2.2e-16 / special[i]);
  for (long s = 0; s < samples; ++s) {
    const double x =
        s % 2 ? exp(test_rng_uniform(&rng, -700.0, 700.0)) : test_rng_uniform(&rng, 0.01, 4.0);
    assert_close(kernel_recip_fast(x), 1.0 / x, 2 * 2.2e-16 / x);
  }
}

/* The lane kernels (fast reciprocal, no divides) agree with the exact kernels behind the
 * public functions to a few ulp of the stress scale, inverted and deeply inverted points
 * included; they are not bit-identical (kernels_and_public_functions_agree_bitwise covers
 * the exact ones). */
static void lane_kernels_match_the_exact_kernels(void **state) {
  (void)state;
  typedef void (*kernel)(const piola_material *, double, double, double, double *, double *,
                         double *);
  const kernel lanes[PIOLA_MODEL_COUNT] = {
      rotated_linear_stress_lanes, corotated_stress_lanes, stvk_stress_lanes,
      neohookean_stress_lanes,     spline_stress_lanes,    neohookean_stress_lanes,
      stable_neohookean_stress_lanes, ogden_stress_lanes, ogden_stress_lanes,
      neohookean_stress_lanes}; /* HGO's matrix is neo-Hookean */
  test_rng rng = test_rng_seeded(21);
  const long samples = test_samples(2000, 50);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int mode = 0; mode < N_MODES; ++mode) {
      const piola_material m = make((piola_material_model)model, modes[mode], 0.3);
      for (long s = 0; s < samples; ++s) {
        double f[3], p[3], q[3];
        random_point(&rng, s % 2 ? -5.0 : -0.5, 3.0, f);
        piola_material_stress(&m, f, p);
        lanes[model](&m, f[0], f[1], f[2], &q[0], &q[1], &q[2]);
        const double scale = fabs(p[0]) + fabs(p[1]) + fabs(p[2]) + m.mu;
        for (int i = 0; i < 3; ++i)
          if (!(fabs(p[i] - q[i]) <= 1e-14 * scale))
            fail_msg("model %d mode %d f (%.17g %.17g %.17g) entry %d: lanes %.17g exact %.17g",
                     model, mode, f[0], f[1], f[2], i, q[i], p[i]);
      }
    }
}

/* ------------------------------------------------------------------ API contracts */

static void kernels_and_public_functions_agree_bitwise(void **state) {
  (void)state;
  typedef void (*kernel)(const piola_material *, double, double, double, double *, double *,
                         double *);
  const kernel kernels[PIOLA_MODEL_COUNT] = {rotated_linear_stress, corotated_stress, stvk_stress,
                                             neohookean_stress, spline_stress,
                                             neohookean_stress /* muscle's isotropic part */,
                                             stable_neohookean_stress, ogden_stress, ogden_stress,
                                             neohookean_stress /* HGO's matrix */};
  typedef void (*energy_kernel)(const piola_material *, double, double, double, double *, double *,
                                double *, double *);
  const energy_kernel energy_kernels[PIOLA_MODEL_COUNT] = {
      rotated_linear_stress_energy, corotated_stress_energy, stvk_stress_energy,
      neohookean_stress_energy, spline_stress_energy, neohookean_stress_energy,
      stable_neohookean_stress_energy, ogden_stress_energy, ogden_stress_energy,
      neohookean_stress_energy};
  test_rng rng = test_rng_seeded(18);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int mode = 0; mode < N_MODES; ++mode) {
      const piola_material m = make((piola_material_model)model, modes[mode], 0.3);
      for (int s = 0; s < 50; ++s) {
        double f[3], p[3], q[3], r[3], e[3], g[3], psi_e, psi_g;
        random_point(&rng, -2.0, 3.0, f);
        piola_material_stress(&m, f, p);
        kernels[model](&m, f[0], f[1], f[2], &q[0], &q[1], &q[2]);
        material_stress_kernel(&m, f[0], f[1], f[2], &r[0], &r[1], &r[2]);
        energy_kernels[model](&m, f[0], f[1], f[2], &e[0], &e[1], &e[2], &psi_e);
        material_stress_energy_kernel(&m, f[0], f[1], f[2], &g[0], &g[1], &g[2], &psi_g);
        const double psi = piola_material_energy_density(&m, f);
        for (int i = 0; i < 3; ++i) {
          assert_true(p[i] == q[i]);
          assert_true(p[i] == r[i]);
          assert_true(p[i] == e[i]);
          assert_true(p[i] == g[i]);
        }
        assert_true(psi == psi_e);
        assert_true(psi == psi_g);
      }
    }
}

static void expect_rejected(piola_material_def def, const char *key, const char *value) {
  piola_material m;
  piola_clear_error();
  const piola_status s = piola_material_init(&def, &m);
  assert_true(s == PIOLA_ERROR_INVALID_ARGUMENT || s == PIOLA_ERROR_NOT_FINITE);
  const char *msg = piola_last_error();
  if (!strstr(msg, key) || !strstr(msg, value))
    fail_msg("message \"%s\" should name %s and %s", msg, key, value);
}

static void invalid_parameters_are_rejected_by_name(void **state) {
  (void)state;
  const piola_material_def base = piola_default_material_def();
  piola_material_def d;
  d = base, d.youngs_modulus = 0.0, expect_rejected(d, "youngs_modulus", "0");
  d = base, d.youngs_modulus = -5.0, expect_rejected(d, "youngs_modulus", "-5");
  d = base, d.youngs_modulus = NAN, expect_rejected(d, "youngs_modulus", "nan");
  d = base, d.youngs_modulus = INFINITY, expect_rejected(d, "youngs_modulus", "inf");
  d = base, d.poisson_ratio = 0.5, expect_rejected(d, "poisson_ratio", "0.5");
  /* one rounding above the bound reads as above it, not as "got 0.5" */
  d = base, d.poisson_ratio = nextafter(0.5, 1),
  expect_rejected(d, "poisson_ratio", "got 0.5000000000000001");
  d = base, d.poisson_ratio = -1.0, expect_rejected(d, "poisson_ratio", "-1");
  d = base, d.poisson_ratio = NAN, expect_rejected(d, "poisson_ratio", "nan");
  d = base, d.inversion_threshold = -0.1, expect_rejected(d, "inversion.threshold", "-0.1");
  d = base, d.inversion_threshold = 1.0, expect_rejected(d, "inversion.threshold", "1");
  d = base, d.inversion_threshold = -INFINITY, expect_rejected(d, "inversion.threshold", "inf");
  d = base, d.inversion_mode = (piola_inversion_mode)7, expect_rejected(d, "inversion.mode", "7");
  char count[16];
  snprintf(count, sizeof count, "%d", (int)PIOLA_MODEL_COUNT);
  d = base, d.model = PIOLA_MODEL_COUNT, expect_rejected(d, "model", count);
  d = base, d.model = PIOLA_MODEL_SPLINE;
  piola_material_def e;
  e = d, e.spline.compression_stretch = 0.25,
  expect_rejected(e, "spline.compression_stretch", "0.25");
  e = d, e.spline.compression_stretch = 1.0, expect_rejected(e, "spline.compression_stretch", "1");
  e = d, e.spline.elongation_stretch = 1.0, expect_rejected(e, "spline.elongation_stretch", "1");
  e = d, e.spline.stiffening = 0.5, expect_rejected(e, "spline.stiffening", "0.5");
  e = d, e.spline.stiffening = NAN, expect_rejected(e, "spline.stiffening", "nan");
  /* The spline shape is checked only for the spline model. */
  piola_material m;
  d = base, d.model = PIOLA_MODEL_STVK, d.spline.stiffening = 0.0;
  assert_int_equal(piola_material_init(&d, &m), PIOLA_OK);
  assert_int_equal(piola_material_init(NULL, &m), PIOLA_ERROR_INVALID_ARGUMENT);
}

static void names_and_lame_parameters_round_trip(void **state) {
  (void)state;
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model) {
    piola_material_model back;
    assert_true(piola_material_model_from_name(
        piola_material_model_name((piola_material_model)model), &back));
    assert_int_equal(back, model);
  }
  piola_material_model back;
  assert_false(piola_material_model_from_name("neo-hookean", &back));
  assert_false(piola_material_model_from_name(NULL, &back));
  assert_string_equal(piola_material_model_name(PIOLA_MODEL_NEOHOOKEAN), "neohookean");
  assert_string_equal(piola_material_model_name(PIOLA_MODEL_SPLINE), "spline");
  for (int mode = 0; mode < N_MODES; ++mode) {
    piola_inversion_mode parsed;
    assert_true(piola_inversion_mode_from_name(piola_inversion_mode_name(modes[mode]), &parsed));
    assert_int_equal(parsed, modes[mode]);
  }
  piola_inversion_mode parsed_mode;
  assert_string_equal(piola_inversion_mode_name(PIOLA_INVERSION_LINEAR), "linear");
  assert_string_equal(piola_inversion_mode_name(PIOLA_INVERSION_ENERGY), "energy");
  assert_true(piola_inversion_mode_from_name("energy", &parsed_mode) &&
              parsed_mode == PIOLA_INVERSION_ENERGY);
  assert_string_equal(piola_material_model_name(PIOLA_MODEL_STABLE_NEOHOOKEAN), "stable_neohookean");
  assert_false(piola_inversion_mode_from_name("C1", &parsed_mode));
  assert_true(piola_inversion_mode_from_name("default", &parsed_mode) &&
              parsed_mode == PIOLA_INVERSION_MODEL_DEFAULT);
  assert_string_equal(piola_inversion_mode_name(PIOLA_INVERSION_MODEL_DEFAULT), "default");

  const double nus[] = {-0.9, -0.1, 0.0, 0.3, 0.499};
  for (size_t n = 0; n < sizeof nus / sizeof nus[0]; ++n) {
    const piola_material m = make(PIOLA_MODEL_COROTATED, PIOLA_INVERSION_LINEAR, nus[n]);
    double e, nu;
    assert_int_equal(piola_youngs_poisson_from_lame(m.mu, m.lambda, &e, &nu), PIOLA_OK);
    assert_close(e, youngs, 1e-9 * youngs);
    assert_close(nu, nus[n], 1e-12);
  }
  double e, nu;
  assert_int_equal(piola_youngs_poisson_from_lame(0.0, 1.0, &e, &nu), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_youngs_poisson_from_lame(1.0, -1.0, &e, &nu),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_youngs_poisson_from_lame(NAN, 1.0, &e, &nu), PIOLA_ERROR_NOT_FINITE);
}

/* The rubber models' and HGO's default (CLAMP, threshold left unset): the threshold rises from c to
 * threshold_compressed as J falls through threshold_volume (docs/materials.md "Defaults that
 * recover"). Its dPhat/dFhat, the rise's term dPhat/dc dc/dJ dJ/df included, equals the central
 * difference of the stress in and around the rise, away from the kinks (an entry at the
 * threshold in force); at J above the rise the stress is that of the fixed threshold c (rubber's
 * own states keep the model); and a threshold set explicitly has no rise. */
static void threshold_rise_derivative_is_the_stress_difference(void **state) {
  (void)state;
  const piola_material_model models[3] = {PIOLA_MODEL_MOONEY_RIVLIN, PIOLA_MODEL_OGDEN,
                                          PIOLA_MODEL_HGO};
  test_rng rng = test_rng_seeded(1919);
  const long cases = test_samples(400, 40);
  for (int mi = 0; mi < 3; ++mi) {
    const piola_material m = material_of(models[mi], PIOLA_INVERSION_MODEL_DEFAULT, youngs, 0.3, 0);
    const piola_material fixed = make(models[mi], PIOLA_INVERSION_CLAMP, 0.3);
    assert_int_equal(m.inversion_mode, PIOLA_INVERSION_CLAMP);
    assert_true(m.threshold_compressed > m.threshold);
    assert_true(fixed.threshold_compressed == fixed.threshold);
    int checked = 0, in_rise = 0;
    for (long c = 0; c < cases; ++c) {
      /* one or two entries around the thresholds, J in and around the rise */
      double f[3];
      f[0] = test_rng_uniform(&rng, 0.25, 0.7);
      f[1] = c % 2 ? test_rng_uniform(&rng, 0.25, 0.7) : test_rng_uniform(&rng, 1.0, 2.5);
      const double j = test_rng_uniform(&rng, 0.92, 0.98);
      f[2] = j / (f[0] * f[1]);
      const double cf = material_threshold_at(&m, f[0], f[1], f[2]);
      if (fabs(f[0] - cf) < 2e-3 || fabs(f[1] - cf) < 2e-3 || fabs(f[2] - cf) < 2e-3) continue;
      double k[3][3], col[3], p[3], pf[3];
      piola_material_stress_derivative(&m, f, k);
      for (int jj = 0; jj < 3; ++jj) {
        stress_fd(&m, f, jj, 1e-7, col);
        for (int i = 0; i < 3; ++i) assert_close(k[i][jj], col[i], 1e-5 * stress_scale(&m, f));
      }
      ++checked;
      in_rise += cf > m.threshold && cf < m.threshold_compressed &&
                 (f[0] < cf || f[1] < cf || f[2] < cf);
      if (j >= m.threshold_volume[1] + 1e-9) { /* above the rise: the fixed threshold's stress */
        piola_material_stress(&m, f, p);
        piola_material_stress(&fixed, f, pf);
        for (int i = 0; i < 3; ++i) assert_true(p[i] == pf[i]);
      }
    }
    assert_true(checked > cases / 2);
    assert_true(in_rise > cases / 20); /* the rise's own term was exercised */
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(threshold_rise_derivative_is_the_stress_difference),
      cmocka_unit_test(rest_state_is_stress_free_with_linear_elastic_tangent),
      cmocka_unit_test(uniaxial_small_strain_gives_youngs_modulus_and_poisson_ratio),
      cmocka_unit_test(stress_is_energy_gradient_above_threshold),
      cmocka_unit_test(stress_is_energy_gradient_along_clamped_entries),
      cmocka_unit_test(derivative_matches_finite_differences_everywhere),
      cmocka_unit_test(derivative_is_symmetric_where_a_potential_exists),
      cmocka_unit_test(extension_is_continuous_at_the_threshold),
      cmocka_unit_test(extension_is_the_taylor_expansion_where_no_safeguard_acts),
      cmocka_unit_test(flat_and_inverted_entries_are_finite_and_pushed_back),
      cmocka_unit_test(stvk_pushes_back_where_the_plain_model_would_not),
      cmocka_unit_test(stress_commutes_with_permutations),
      cmocka_unit_test(spline_is_soft_at_rest_and_stiff_past_its_stretches),
      cmocka_unit_test(kernel_log_matches_libm),
      cmocka_unit_test(kernel_recip_fast_is_within_two_ulp),
      cmocka_unit_test(lane_kernels_match_the_exact_kernels),
      cmocka_unit_test(kernels_and_public_functions_agree_bitwise),
      cmocka_unit_test(invalid_parameters_are_rejected_by_name),
      cmocka_unit_test(names_and_lame_parameters_round_trip),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
