/* The muscle model (PIOLA_MODEL_MUSCLE) at the material level: the fibre stress is the
 * gradient of the fibre energy for every F (flat and inverted ones included), the model
 * reduces to its isotropic part when passive and unstretched, activation pulls along the
 * fibre, stresses rotate with world and material (the fibre rotated with the material) and
 * preserve angular momentum, and inverted elements are pushed back. */
#include <math.h>
#include <string.h>

#include "piola/diagonalize.h"
#include "piola/material.h"
#include "material_checks.h"
#include "test_support.h"

static piola_material muscle_material(double youngs, double nu) {
  piola_material_def def = piola_default_material_def();
  def.model = PIOLA_MODEL_MUSCLE;
  def.youngs_modulus = youngs;
  def.poisson_ratio = nu;
  /* the extension these checks were written for: the gradient checks sample flat and inverted
   * F, where LINEAR's stress is the energy's gradient along the clamped entries (CLAMP's, the
   * muscle's default, is not) */
  def.inversion_mode = PIOLA_INVERSION_LINEAR;
  def.inversion_threshold = 0.3;
  def.muscle.passive_stiffness = 2e5;
  def.muscle.passive_toe_stretch = 1.15;
  def.muscle.max_active_stress = 3e5;
  def.muscle.optimal_stretch = 1.05;
  def.muscle.active_width = 0.45;
  piola_material m;
  assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
  return m;
}

/* What an element computes: diagonalize F, rotate the material fibre a by V, evaluate in the
 * diagonal frame, rotate back. fiber_only selects the fibre part alone. */
static double world_stress(const piola_material *m, piola_mat3 f, const double a[3], double act,
                           int fiber_only, piola_mat3 *p) {
  piola_mat3 u, v;
  piola_vec3 fh;
  assert_int_equal(piola_diagonalize3(&f, &u, &fh, &v), PIOLA_OK);
  const double fhat[3] = {fh.x, fh.y, fh.z};
  double ahat[3], ph[3][3];
  for (int k = 0; k < 3; ++k) ahat[k] = v.m[0][k] * a[0] + v.m[1][k] * a[1] + v.m[2][k] * a[2];
  double psi;
  if (fiber_only) {
    piola_material_fiber_stress(m, fhat, ahat, act, ph);
    psi = piola_material_fiber_energy_density(m, fhat, ahat, act);
  } else {
    piola_material_muscle_stress(m, fhat, ahat, act, ph);
    psi = piola_material_muscle_energy_density(m, fhat, ahat, act);
  }
  if (p)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double s = 0;
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) s += u.m[i][k] * ph[k][l] * v.m[j][l];
        p->m[i][j] = s;
      }
  return psi;
}

static double max_abs(piola_mat3 a) {
  double r = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r = fmax(r, fabs(a.m[i][j]));
  return r;
}

/* Central differences of the energy over the 9 entries of F against P. */
static void check_gradient(const piola_material *m, piola_mat3 f, const double a[3], double act,
                           int fiber_only) {
  piola_mat3 p;
  world_stress(m, f, a, act, fiber_only, &p);
  const double h = 1e-6;
  const double tol = 2e-5 * (max_abs(p) + 1e3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      piola_mat3 fp = f, fm = f;
      fp.m[i][j] += h;
      fm.m[i][j] -= h;
      const double d = (world_stress(m, fp, a, act, fiber_only, NULL) -
                        world_stress(m, fm, a, act, fiber_only, NULL)) / (2 * h);
      if (!(fabs(d - p.m[i][j]) <= tol))
        fail_msg("dpsi/dF[%d][%d] = %.9g but P = %.9g (act %g)", i, j, d, p.m[i][j], act);
    }
}

static void fiber_stress_is_the_energy_gradient_everywhere(void **state) {
  (void)state;
  const piola_material m = muscle_material(5e4, 0.45);
  test_rng rng = test_rng_seeded(81);
  const long n = test_samples(3000, 50);
  int inverted = 0, flat = 0, stretched = 0;
  for (long k = 0; k < n; ++k) {
    double s[3];
    for (int i = 0; i < 3; ++i) s[i] = test_rng_uniform(&rng, 0.2, 1.8);
    const int kind = (int)(k % 4);
    if (kind == 1) s[0] = -test_rng_uniform(&rng, 0.0, 0.8), inverted++; /* inverted */
    if (kind == 2) s[1] = test_rng_uniform(&rng, -1e-3, 1e-3), flat++;   /* flattened */
    if (kind == 3) s[2] = 0.0, s[1] = test_rng_uniform(&rng, 0, 0.05), flat++; /* nearly a line */
    double a[3];
    random_unit(&rng, a);
    const double act = test_rng_uniform(&rng, 0.0, 1.0);
    const piola_mat3 f = f_with_singular_values(&rng, s);
    check_gradient(&m, f, a, act, 1);
    double fa = 0;
    for (int i = 0; i < 3; ++i) {
      double c = f.m[i][0] * a[0] + f.m[i][1] * a[1] + f.m[i][2] * a[2];
      fa += c * c;
    }
    stretched += sqrt(fa) > m.muscle.passive_toe_stretch;
  }
  assert_true(inverted > 0 && flat > 0 && stretched > 0); /* every regime was visited */
}

/* Where the isotropic extension has a potential (no entry below the threshold) the whole
 * model's stress is the gradient of its whole energy. */
static void muscle_stress_is_the_energy_gradient(void **state) {
  (void)state;
  const piola_material m = muscle_material(5e4, 0.45);
  test_rng rng = test_rng_seeded(82);
  const long n = test_samples(2000, 40);
  for (long k = 0; k < n; ++k) {
    double s[3], a[3];
    for (int i = 0; i < 3; ++i) s[i] = test_rng_uniform(&rng, 0.45, 1.8);
    random_unit(&rng, a);
    check_gradient(&m, f_with_singular_values(&rng, s), a, test_rng_uniform(&rng, 0, 1), 0);
  }
}

static void passive_unstretched_muscle_is_its_isotropic_part(void **state) {
  (void)state;
  const piola_material m = muscle_material(5e4, 0.45);
  piola_material_def nd = piola_default_material_def();
  nd.model = PIOLA_MODEL_NEOHOOKEAN;
  nd.youngs_modulus = 5e4;
  nd.poisson_ratio = 0.45;
  nd.inversion_mode = PIOLA_INVERSION_LINEAR; /* as muscle_material */
  nd.inversion_threshold = 0.3;
  piola_material neo;
  assert_int_equal(piola_material_init(&nd, &neo), PIOLA_OK);
  test_rng rng = test_rng_seeded(83);
  const long n = test_samples(5000, 100);
  long checked = 0;
  for (long k = 0; k < n; ++k) {
    double f[3], a[3];
    for (int i = 0; i < 3; ++i) f[i] = test_rng_uniform(&rng, -0.5, 1.3);
    random_unit(&rng, a);
    const double lambda = sqrt(pow(f[0] * a[0], 2) + pow(f[1] * a[1], 2) + pow(f[2] * a[2], 2));
    double ph[3][3], iso[3];
    piola_material_muscle_stress(&m, f, a, 0.0, ph);
    piola_material_stress(&neo, f, iso);
    const double psi = piola_material_muscle_energy_density(&m, f, a, 0.0);
    if (lambda <= 1.0) {
      ++checked;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) assert_true(ph[i][j] == (i == j ? iso[i] : 0.0));
      assert_true(psi == piola_material_energy_density(&neo, f));
    } else {
      /* a stretched passive fibre pulls back: more energy than the matrix alone */
      assert_true(psi > piola_material_energy_density(&neo, f));
    }
  }
  assert_true(checked > n / 4);
  /* the isotropic functions of a muscle material are exactly neo-Hookean */
  const double f[3] = {0.7, 1.2, -0.1};
  double p1[3], p2[3], d1[3][3], d2[3][3];
  piola_material_stress(&m, f, p1);
  piola_material_stress(&neo, f, p2);
  piola_material_stress_derivative(&m, f, d1);
  piola_material_stress_derivative(&neo, f, d2);
  assert_memory_equal(p1, p2, sizeof p1);
  assert_memory_equal(d1, d2, sizeof d1);
  /* other models have no fibre part */
  double pf[3][3];
  const double a[3] = {1, 0, 0}, g[3] = {1.3, 1, 1};
  piola_material_fiber_stress(&neo, g, a, 1.0, pf);
  for (int i = 0; i < 9; ++i) assert_true(pf[i / 3][i % 3] == 0.0);
}

static void activation_pulls_along_the_fibre(void **state) {
  (void)state;
  const piola_material m = muscle_material(5e4, 0.45);
  const piola_muscle_def *d = &m.muscle;
  /* the curves: peak active tension at the optimal stretch, none far from it, none at all
   * below stretch 1 when passive */
  const double passive = piola_material_fiber_tension(&m, d->optimal_stretch, 0.0);
  const double toe = d->passive_toe_stretch - 1, u = d->optimal_stretch - 1; /* in the toe */
  assert_close(passive, d->passive_stiffness * u * u / (2 * toe), 1e-9 * d->passive_stiffness);
  assert_close(piola_material_fiber_tension(&m, d->optimal_stretch, 1.0) - passive,
               d->max_active_stress, 1e-9 * d->max_active_stress);
  assert_close(piola_material_fiber_tension(&m, d->optimal_stretch, 0.4) - passive,
               0.4 * d->max_active_stress, 1e-9 * d->max_active_stress);
  assert_true(piola_material_fiber_tension(&m, 0.9, 0.0) == 0.0);
  assert_true(piola_material_fiber_tension(&m, d->optimal_stretch * (1 - d->active_width) * 0.99,
                                           1.0) == 0.0);
  assert_true(piola_material_fiber_tension(&m, 0.0, 1.0) == 0.0);
  /* past the toe the passive slope is passive_stiffness */
  const double t1 = piola_material_fiber_tension(&m, 1.3, 0.0), t2 = piola_material_fiber_tension(&m, 1.4, 0.0);
  assert_close((t2 - t1) / 0.1, d->passive_stiffness, 1e-6 * d->passive_stiffness);
  /* activation is clamped to [0, 1] */
  assert_true(piola_material_fiber_tension(&m, 1.0, 7.0) == piola_material_fiber_tension(&m, 1.0, 1.0));
  assert_true(piola_material_fiber_tension(&m, 1.0, -1.0) == 0.0);

  /* at rest, the active stress is a tension sigma a a^T along the fibre, whatever a: it
   * pulls the faces across the fibre inwards, and nothing across it */
  test_rng rng = test_rng_seeded(84);
  for (int k = 0; k < 50; ++k) {
    double a[3];
    random_unit(&rng, a);
    const double act = test_rng_uniform(&rng, 0.1, 1.0);
    const double one[3] = {1, 1, 1};
    double ph[3][3];
    piola_material_fiber_stress(&m, one, a, act, ph);
    const double sigma = piola_material_fiber_tension(&m, 1.0, act);
    assert_true(sigma > 0);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) assert_close(ph[i][j], sigma * a[i] * a[j], 1e-9 * sigma);
    /* shortening along the fibre lowers the energy: the muscle wants to contract */
    const double shorter[3] = {1 - 0.05 * fabs(a[0]), 1 - 0.05 * fabs(a[1]), 1 - 0.05 * fabs(a[2])};
    assert_true(piola_material_fiber_energy_density(&m, shorter, a, act) < 0.0);
  }
}

/* P(Q F R^T, R a) = Q P(F, a) R^T for rotations Q (world) and R (material), and P F^T is
 * symmetric (angular momentum). */
static void stress_rotates_with_world_and_material(void **state) {
  (void)state;
  const piola_material m = muscle_material(5e4, 0.45);
  test_rng rng = test_rng_seeded(85);
  const long n = test_samples(2000, 40);
  for (long k = 0; k < n; ++k) {
    double s[3], a[3], ra[3];
    for (int i = 0; i < 3; ++i) s[i] = test_rng_uniform(&rng, 0.2, 1.7);
    if (k % 3 == 1) s[k % 2] = -test_rng_uniform(&rng, 0.0, 0.15);
    random_unit(&rng, a);
    const double act = test_rng_uniform(&rng, 0, 1);
    const piola_mat3 f = f_with_singular_values(&rng, s);
    const piola_mat3 q = random_rotation(&rng), r = random_rotation(&rng);
    for (int i = 0; i < 3; ++i) ra[i] = r.m[i][0] * a[0] + r.m[i][1] * a[1] + r.m[i][2] * a[2];
    piola_mat3 p, pr;
    const double psi = world_stress(&m, f, a, act, 0, &p);
    const double psi_r = world_stress(&m, mat3_mul(mat3_mul(q, f), mat3_transpose(r)), ra, act, 0, &pr);
    const piola_mat3 expect = mat3_mul(mat3_mul(q, p), mat3_transpose(r));
    const double tol = 1e-9 * (max_abs(p) + 1e3);
    assert_close(psi, psi_r, 1e-9 * (fabs(psi) + 1e3));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) assert_close(pr.m[i][j], expect.m[i][j], tol);
    const piola_mat3 pft = mat3_mul(p, mat3_transpose(f));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < i; ++j) assert_close(pft.m[i][j], pft.m[j][i], tol * 3);
  }
}

/* Every flat or inverted entry f_k <= 0 gets Phat_kk < 0 (pushed back towards positive),
 * whatever the fibre direction and activation, and everything stays finite. */
static void inverted_entries_are_pushed_back(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(86);
  const long n = test_samples(20000, 200);
  for (int variant = 0; variant < 2; ++variant) {
    piola_material_def def = piola_default_material_def();
    def.model = PIOLA_MODEL_MUSCLE;
    def.youngs_modulus = 1e4; /* a soft matrix under strong fibres */
    def.poisson_ratio = 0.45;
    def.muscle.max_active_stress = 5e5;
    def.muscle.passive_stiffness = 5e5;
    def.inversion_mode = variant ? PIOLA_INVERSION_CLAMP : PIOLA_INVERSION_LINEAR;
    piola_material m;
    assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
    for (long k = 0; k < n; ++k) {
      double f[3], a[3], ph[3][3];
      for (int i = 0; i < 3; ++i) f[i] = test_rng_uniform(&rng, 0.0, 3.0);
      const int neg = (int)(k % 3);
      f[neg] = k % 7 == 0 ? 0.0 : -test_rng_uniform(&rng, 0.0, 1.0) * fmin(f[(neg + 1) % 3], f[(neg + 2) % 3]);
      random_unit(&rng, a);
      const double act = test_rng_uniform(&rng, 0, 1);
      piola_material_muscle_stress(&m, f, a, act, ph);
      for (int i = 0; i < 9; ++i) assert_true(isfinite(ph[i / 3][i % 3]));
      if (!(ph[neg][neg] < 0.0))
        fail_msg("f = (%g %g %g), a = (%g %g %g), act %g: Phat[%d][%d] = %g is not restoring",
                 f[0], f[1], f[2], a[0], a[1], a[2], act, neg, neg, ph[neg][neg]);
      assert_true(isfinite(piola_material_muscle_energy_density(&m, f, a, act)));
    }
    /* a tet collapsed to a point: finite, and no fibre stress */
    double zero[3] = {0, 0, 0}, ph[3][3];
    const double a[3] = {0.6, 0.8, 0};
    piola_material_fiber_stress(&m, zero, a, 1.0, ph);
    for (int i = 0; i < 9; ++i) assert_true(ph[i / 3][i % 3] == 0.0);
  }
}

static void invalid_muscle_parameters_are_rejected_by_name(void **state) {
  (void)state;
  piola_material_def base = piola_default_material_def();
  base.model = PIOLA_MODEL_MUSCLE;
  struct {
    double *field;
    double value;
    const char *key;
  } cases[] = {
      {&base.muscle.passive_stiffness, -1.0, "muscle.passive_stiffness"},
      {&base.muscle.passive_toe_stretch, 1.0, "muscle.passive_toe_stretch"},
      {&base.muscle.max_active_stress, -5.0, "muscle.max_active_stress"},
      {&base.muscle.optimal_stretch, 0.0, "muscle.optimal_stretch"},
      {&base.muscle.active_width, 1.0, "muscle.active_width"},
      {&base.muscle.active_width, NAN, "muscle.active_width"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    const double old = *cases[i].field;
    *cases[i].field = cases[i].value;
    piola_material m;
    assert_int_not_equal(piola_material_init(&base, &m), PIOLA_OK);
    if (!strstr(piola_last_error(), cases[i].key))
      fail_msg("\"%s\" should name %s", piola_last_error(), cases[i].key);
    *cases[i].field = old;
  }
  piola_material m;
  assert_int_equal(piola_material_init(&base, &m), PIOLA_OK);
  assert_true(m.fiber_modulus > 0);
  piola_material_model model;
  assert_true(piola_material_model_from_name("muscle", &model) && model == PIOLA_MODEL_MUSCLE);
  assert_string_equal(piola_material_model_name(PIOLA_MODEL_MUSCLE), "muscle");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(fiber_stress_is_the_energy_gradient_everywhere),
      cmocka_unit_test(muscle_stress_is_the_energy_gradient),
      cmocka_unit_test(passive_unstretched_muscle_is_its_isotropic_part),
      cmocka_unit_test(activation_pulls_along_the_fibre),
      cmocka_unit_test(stress_rotates_with_world_and_material),
      cmocka_unit_test(inverted_entries_are_pushed_back),
      cmocka_unit_test(invalid_muscle_parameters_are_rejected_by_name),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
