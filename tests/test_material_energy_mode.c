/* inversion.mode "energy" (PIOLA_INVERSION_ENERGY, after Stomakhin, Howes, Schroeder, Teran
 * 2012), for every isotropic model: the stress is the exact gradient of the extended energy
 * everywhere (past the threshold, across it, inverted), its derivative is the central
 * difference of the stress wherever it is smooth and is symmetric, the rest state is
 * linear elasticity, and flat, collapsed and inverted entries get finite restoring stress. */
#include "test_support.h"

#include <math.h>
#include <string.h>

#include "material/material_kernels.h"
#include "material_checks.h"
#include "piola/material.h"

static piola_material make(piola_material_model model, double nu, double threshold) {
  return material_of(model, PIOLA_INVERSION_ENERGY, 1e5, nu, threshold);
}

/* Random points that visit every region: all above the threshold, one, two or three entries
 * below it (inverted too), and entries right at the threshold. */
static void region_point(test_rng *rng, long s, double c, double f[3]) {
  random_point(rng, c, 2.5, f);
  const int below = (int)(s % 4);
  for (int i = 0; i < below; ++i) f[(s / 4 + i) % 3] = test_rng_uniform(rng, -2.0, c);
  if (s % 11 == 0) f[s % 3] = c + test_rng_uniform(rng, -1e-7, 1e-7);
}

/* Where the derivative jumps: the threshold, the spline's breakpoints, and a clamped entry
 * whose clamped-point stress changes sign (the slope k_i has a kink there). */
static int near_kink(const piola_material *m, const double f[3], double gap) {
  const double c = m->threshold;
  const double fc[3] = {fmax(f[0], c), fmax(f[1], c), fmax(f[2], c)};
  double pc[3];
  piola_material_stress(m, fc, pc);
  const double ps = fabs(pc[0]) + fabs(pc[1]) + fabs(pc[2]) + m->mu;
  for (int i = 0; i < 3; ++i) {
    if (fabs(f[i] - c) < gap) return 1;
    if (f[i] < c && fabs(pc[i]) < 1e-3 * ps) return 1;
    if (near_spline_breakpoint(m, f[i], gap)) return 1;
  }
  return 0;
}

static const double nus[] = {0.3, -0.3, 0.45};
#define N_NUS 3

static void rest_is_stress_free_with_linear_elastic_tangent(void **state) {
  (void)state;
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int n = 0; n < N_NUS; ++n) {
      const piola_material m = make((piola_material_model)model, nus[n], 0.3);
      const double one[3] = {1, 1, 1};
      double p[3], k[3][3];
      piola_material_stress(&m, one, p);
      piola_material_stress_derivative(&m, one, k);
      assert_close(piola_material_energy_density(&m, one), 0.0, 1e-9 * m.mu);
      for (int i = 0; i < 3; ++i) {
        assert_close(p[i], 0.0, 1e-9 * m.mu);
        for (int j = 0; j < 3; ++j)
          assert_close(k[i][j], (i == j ? 2 * m.mu : 0.0) + m.lambda, 1e-7 * m.mu);
      }
    }
}

/* The heart of the mode: P = d psi / d f everywhere, past the threshold and across it. */
static void stress_is_the_energy_gradient_everywhere(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(41);
  const long samples = test_samples(3000, 100);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int n = 0; n < N_NUS; ++n) {
      const piola_material m = make((piola_material_model)model, nus[n], n == 2 ? 0.5 : 0.3);
      for (long s = 0; s < samples; ++s) {
        double f[3], p[3];
        region_point(&rng, s, m.threshold, f);
        piola_material_stress(&m, f, p);
        const double h = 1e-6, scale = stress_scale(&m, f);
        for (int i = 0; i < 3; ++i) {
          double a[3] = {f[0], f[1], f[2]}, b[3] = {f[0], f[1], f[2]}, ka[3][3], kb[3][3];
          a[i] += h, b[i] -= h;
          const double fd =
              (piola_material_energy_density(&m, a) - piola_material_energy_density(&m, b)) / (2 * h);
          /* A central difference across the threshold, where the curvature jumps, is off by up
           * to h times the jump. */
          piola_material_stress_derivative(&m, a, ka);
          piola_material_stress_derivative(&m, b, kb);
          const double kink = fabs(f[i] - m.threshold) < h ? h * fabs(ka[i][i] - kb[i][i]) : 0.0;
          if (!(fabs(fd - p[i]) <= 2e-6 * scale + kink))
            fail_msg("%s nu %g f (%.17g %.17g %.17g) entry %d: stress %.12g, energy slope %.12g",
                     piola_material_model_name(m.model), nus[n], f[0], f[1], f[2], i, p[i], fd);
        }
      }
    }
}

static void derivative_is_the_stress_difference_where_smooth_and_symmetric(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(42);
  const long samples = test_samples(3000, 100);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int n = 0; n < N_NUS; ++n) {
      const piola_material m = make((piola_material_model)model, nus[n], n == 2 ? 0.5 : 0.3);
      long checked = 0;
      for (long s = 0; s < samples; ++s) {
        double f[3], k[3][3];
        region_point(&rng, s, m.threshold, f);
        piola_material_stress_derivative(&m, f, k);
        const double scale = stress_scale(&m, f);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            if (!(fabs(k[i][j] - k[j][i]) <= 1e-9 * (fabs(k[i][j]) + fabs(k[j][i]) + m.mu)))
              fail_msg("%s f (%.17g %.17g %.17g): dP%d/df%d = %.12g but dP%d/df%d = %.12g",
                       piola_material_model_name(m.model), f[0], f[1], f[2], i, j, k[i][j], j, i,
                       k[j][i]);
        if (near_kink(&m, f, 1e-4)) continue;
        ++checked;
        const double h = 1e-6;
        for (int j = 0; j < 3; ++j) {
          double a[3] = {f[0], f[1], f[2]}, b[3] = {f[0], f[1], f[2]}, pa[3], pb[3];
          a[j] += h, b[j] -= h;
          piola_material_stress(&m, a, pa);
          piola_material_stress(&m, b, pb);
          for (int i = 0; i < 3; ++i) {
            const double fd = (pa[i] - pb[i]) / (2 * h);
            const double kscale = fabs(k[i][j]) + fabs(fd) + scale;
            if (!(fabs(fd - k[i][j]) <= 1e-5 * kscale))
              fail_msg("%s nu %g f (%.17g %.17g %.17g): dP%d/df%d = %.12g, difference %.12g",
                       piola_material_model_name(m.model), nus[n], f[0], f[1], f[2], i, j,
                       k[i][j], fd);
          }
        }
      }
      assert_true(checked > samples / 2);
    }
}

/* Value and energy continuous at the threshold; the energy's slope too (C1 energy). */
static void energy_and_stress_are_continuous_at_the_threshold(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(43);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model) {
    const piola_material m = make((piola_material_model)model, 0.3, 0.3);
    for (int s = 0; s < 200; ++s) {
      double f[3];
      random_point(&rng, 0.35, 2.0, f);
      f[s % 3] = m.threshold;
      double above[3] = {f[0], f[1], f[2]}, below[3] = {f[0], f[1], f[2]}, pa[3], pb[3];
      above[s % 3] += 1e-9, below[s % 3] -= 1e-9;
      piola_material_stress(&m, above, pa);
      piola_material_stress(&m, below, pb);
      const double scale = stress_scale(&m, f);
      for (int i = 0; i < 3; ++i) assert_close(pa[i], pb[i], 1e-6 * scale);
      assert_close(piola_material_energy_density(&m, above), piola_material_energy_density(&m, below),
                   1e-7 * scale);
    }
  }
}

/* Finite everywhere (deep inversion and huge stretch included); and every flat or inverted
 * entry f_i <= 0 has Phat_i < 0 whenever the other two entries are at most 2 (the lateral
 * stretch up to which the slope k is made to guarantee it, docs/materials.md) and f is in the
 * diagonalization's convention (at most one negative entry, the smallest in magnitude): flat,
 * collapsed to a line or a point, inverted. */
static void flat_collapsed_and_inverted_entries_are_finite_and_pushed_back(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(44);
  const long samples = test_samples(4000, 200);
  const double cases[][3] = {{0, 0, 0},     {0, 1, 1},   {1, 0, 0},      {2, 0, 0},
                             {-0.01, 2, 2}, {-1, 1, 1},  {-0.5, 0.5, 2}, {0, 2, 0.1},
                             {2, 1e-9, -1e-9}, {2, 2, -2}, {-1e-3, 1e-3, 1e-3}, {0, 0, 1}};
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int n = 0; n < N_NUS; ++n)
      for (int ci = 0; ci < 2; ++ci) {
        const piola_material m = make((piola_material_model)model, nus[n], ci ? 0.5 : 0.3);
        const long total = samples + (long)(sizeof cases / sizeof cases[0]);
        for (long s = 0; s < total; ++s) {
          double f[3], p[3], k[3][3];
          if (s < samples) {
            /* The diagonalization's convention: at most one negative entry, the one of
             * smallest magnitude. */
            random_point(&rng, 0.0, 2.0, f);
            const int i = (int)(s % 3);
            const double smallest = fmin(f[(i + 1) % 3], f[(i + 2) % 3]);
            if (s % 4) f[i] = -test_rng_uniform(&rng, 0.0, smallest);
          } else {
            memcpy(f, cases[s - samples], sizeof f);
          }
          piola_material_stress(&m, f, p);
          piola_material_stress_derivative(&m, f, k);
          assert_true(isfinite(piola_material_energy_density(&m, f)));
          for (int i = 0; i < 3; ++i) {
            assert_true(isfinite(p[i]));
            for (int j = 0; j < 3; ++j) assert_true(isfinite(k[i][j]));
            if (f[i] <= 0.0 && !(p[i] < 0.0))
              fail_msg("%s nu %g c %g f (%g %g %g): entry %d is not pushed back (P = %g)",
                       piola_material_model_name(m.model), nus[n], m.threshold, f[0], f[1], f[2],
                       i, p[i]);
          }
        }
        /* Finite far out: huge stretch with deep inversion. */
        const double far[][3] = {{-1e6, 1e6, 1e6}, {1e8, 1e8, -1e-8}, {-1e30, 1, 1},
                                 {-1e6, 1, 1},     {-1, 1e-9, 0},     {-1e3, 2, 1e-3}};
        for (int c = 0; c < 6; ++c) {
          double p[3];
          piola_material_stress(&m, far[c], p);
          for (int i = 0; i < 3; ++i) assert_true(isfinite(p[i]));
        }
      }
}

/* Inside the region where no entry is clamped the mode changes nothing: the energy mode equals
 * the model (and LINEAR) there. */
static void above_the_threshold_it_is_the_model_itself(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(45);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model) {
    const piola_material e = make((piola_material_model)model, 0.3, 0.3);
    piola_material l = e;
    l.inversion_mode = PIOLA_INVERSION_LINEAR;
    for (int s = 0; s < 200; ++s) {
      double f[3], pe[3], pl[3], ke[3][3], kl[3][3];
      random_point(&rng, 0.31, 3.0, f);
      piola_material_stress(&e, f, pe);
      piola_material_stress(&l, f, pl);
      piola_material_stress_derivative(&e, f, ke);
      piola_material_stress_derivative(&l, f, kl);
      for (int i = 0; i < 3; ++i) {
        assert_true(pe[i] == pl[i]);
        for (int j = 0; j < 3; ++j) assert_true(ke[i][j] == kl[i][j]);
      }
      assert_true(piola_material_energy_density(&e, f) == piola_material_energy_density(&l, f));
    }
  }
}

/* Along one entry pushed from c/2 through flat into deep inversion, with the others held
 * (unstretched, stretched, very stretched, mixed), the energy grows strictly: no spurious
 * minimum past the threshold. */
static void energy_grows_monotonically_into_inversion(void **state) {
  (void)state;
  const double others[][2] = {{1, 1}, {1.5, 1.5}, {2, 2}, {0.5, 2}, {0.3, 0.3}};
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (size_t o = 0; o < sizeof others / sizeof others[0]; ++o) {
      const piola_material m = make((piola_material_model)model, 0.3, 0.3);
      double previous = INFINITY;
      for (double x = 0.5 * m.threshold; x >= -3.0; x -= 0.01) {
        const double f[3] = {x, others[o][0], others[o][1]};
        const double psi = piola_material_energy_density(&m, f);
        assert_true(isfinite(psi));
        if (previous != INFINITY && !(psi > previous))
          fail_msg("%s others (%g %g): energy %g at %g not above %g",
                   piola_material_model_name(m.model), others[o][0], others[o][1], psi, x, previous);
        previous = psi;
      }
    }
}

/* The force loop's lane kernels (fast reciprocal) agree with the exact kernels to a few ulp of
 * the stress scale; the exact kernels, run-time dispatch and public functions bitwise. */
static void kernels_agree(void **state) {
  (void)state;
  typedef void (*kernel)(const piola_material *, double, double, double, double *, double *,
                         double *);
  const kernel exact[PIOLA_MODEL_COUNT] = {
      rotated_linear_stress_energy_mode, corotated_stress_energy_mode,
      stvk_stress_energy_mode,           neohookean_stress_energy_mode,
      spline_stress_energy_mode,         neohookean_stress_energy_mode,
      stable_neohookean_stress_energy_mode, ogden_stress_energy_mode, ogden_stress_energy_mode,
      neohookean_stress_energy_mode}; /* HGO's matrix is neo-Hookean */
  const kernel lanes[PIOLA_MODEL_COUNT] = {
      rotated_linear_stress_energy_mode_lanes, corotated_stress_energy_mode_lanes,
      stvk_stress_energy_mode_lanes,           neohookean_stress_energy_mode_lanes,
      spline_stress_energy_mode_lanes,         neohookean_stress_energy_mode_lanes,
      stable_neohookean_stress_energy_mode_lanes, ogden_stress_energy_mode_lanes,
      ogden_stress_energy_mode_lanes, neohookean_stress_energy_mode_lanes};
  test_rng rng = test_rng_seeded(46);
  const long samples = test_samples(2000, 50);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model) {
    const piola_material m = make((piola_material_model)model, 0.3, 0.3);
    for (long s = 0; s < samples; ++s) {
      double f[3], p[3], q[3], r[3], g[3], psi;
      random_point(&rng, s % 2 ? -5.0 : -0.5, 3.0, f);
      piola_material_stress(&m, f, p);
      exact[model](&m, f[0], f[1], f[2], &q[0], &q[1], &q[2]);
      lanes[model](&m, f[0], f[1], f[2], &r[0], &r[1], &r[2]);
      material_stress_energy_kernel(&m, f[0], f[1], f[2], &g[0], &g[1], &g[2], &psi);
      assert_true(psi == piola_material_energy_density(&m, f));
      const double scale = fabs(p[0]) + fabs(p[1]) + fabs(p[2]) + m.mu;
      for (int i = 0; i < 3; ++i) {
        assert_true(p[i] == q[i]);
        assert_true(p[i] == g[i]);
        if (!(fabs(p[i] - r[i]) <= 1e-14 * scale))
          fail_msg("%s f (%.17g %.17g %.17g) entry %d: lanes %.17g exact %.17g",
                   piola_material_model_name(m.model), f[0], f[1], f[2], i, r[i], p[i]);
      }
    }
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(rest_is_stress_free_with_linear_elastic_tangent),
      cmocka_unit_test(stress_is_the_energy_gradient_everywhere),
      cmocka_unit_test(derivative_is_the_stress_difference_where_smooth_and_symmetric),
      cmocka_unit_test(energy_and_stress_are_continuous_at_the_threshold),
      cmocka_unit_test(flat_collapsed_and_inverted_entries_are_finite_and_pushed_back),
      cmocka_unit_test(above_the_threshold_it_is_the_model_itself),
      cmocka_unit_test(energy_grows_monotonically_into_inversion),
      cmocka_unit_test(kernels_agree),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
