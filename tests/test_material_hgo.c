/* The Holzapfel-Gasser-Ogden model (PIOLA_MODEL_HGO) at the material level: the fibre stress
 * is the gradient of the fibre energy and its dP/dF the derivative of the stress for every F
 * (flat, collapsed, inverted and far past the fibre stretch limit included), both are zero at
 * rest, the families follow the tet's fibre and the axis, the whole stress rotates with world
 * and material, every flat or inverted entry is pushed back, and a two-layer artery inflated
 * with Holzapfel, Gasser and Ogden's (2000) published parameters follows the pressure-radius
 * curve of their equations. */
#include <math.h>
#include <string.h>

#include "piola/diagonalize.h"
#include "piola/material.h"
#include "material/hgo_kernels.h"
#include "material_checks.h"
#include "test_support.h"

static piola_material hgo_material(double kappa, double angle, double nu) {
  piola_material_def def = piola_default_material_def();
  def.model = PIOLA_MODEL_HGO;
  def.poisson_ratio = nu;
  /* the gradient checks sample flat and inverted F, where LINEAR's stress is the energy's
   * gradient along the clamped entries (CLAMP's is not); set explicitly so that they do not
   * follow HGO's default */
  def.inversion_mode = PIOLA_INVERSION_LINEAR;
  def.inversion_threshold = 0.3;
  def.hgo.kappa = kappa;
  def.hgo.fiber_angle_degrees = angle;
  def.hgo.axis[0] = 0.3, def.hgo.axis[1] = -0.2, def.hgo.axis[2] = 1.0;
  piola_material m;
  assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
  return m;
}

static void flat9(piola_mat3 a, double out[9]) {
  for (int k = 0; k < 9; ++k) out[k] = a.m[k / 3][k % 3];
}

/* The whole HGO stress as an element computes it: the matrix through the diagonalization
 * (piola_material_stress on Fhat), the fibres on the full F. Returns the energy density. */
static double whole_stress(const piola_material *m, piola_mat3 f, const double fam[6],
                           piola_mat3 *p) {
  piola_mat3 u, v;
  piola_vec3 fh;
  assert_int_equal(piola_diagonalize3(&f, &u, &fh, &v), PIOLA_OK);
  const double fhat[3] = {fh.x, fh.y, fh.z};
  double ph[3], pf[9], f9[9];
  piola_material_stress(m, fhat, ph);
  flat9(f, f9);
  piola_material_hgo_fiber_stress(m, f9, fam, pf);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = pf[3 * i + j];
      for (int k = 0; k < 3; ++k) s += u.m[i][k] * ph[k] * v.m[j][k];
      p->m[i][j] = s;
    }
  return piola_material_energy_density(m, fhat) + piola_material_hgo_fiber_energy_density(m, f9, fam);
}

static double max_abs9(const double *a, int n) {
  double r = 0;
  for (int k = 0; k < n; ++k) r = fmax(r, fabs(a[k]));
  return r;
}

/* Random F of every kind: moderate, flat, nearly a line, inverted, and stretched far past the
 * fibre stretch limit (1.7 by default). */
static piola_mat3 random_f(test_rng *rng, long k) {
  double s[3];
  for (int i = 0; i < 3; ++i) s[i] = test_rng_uniform(rng, 0.3, 1.9);
  switch (k % 5) {
    case 1: s[0] = -test_rng_uniform(rng, 0.0, 0.8); break;          /* inverted */
    case 2: s[1] = test_rng_uniform(rng, -1e-3, 1e-3); break;        /* flat */
    case 3: s[2] = 0.0, s[1] = test_rng_uniform(rng, 0, 0.05); break; /* nearly a line */
    case 4: s[0] = test_rng_uniform(rng, 3.5, 6.0); break;           /* past the limit */
    default: break;
  }
  return f_with_singular_values(rng, s);
}

/* The fibre stress p at f9 equals the central differences (step h) of the fibre energy, and
 * its derivative d those of the stress: to 1e-5 and to dtol_rel of the largest entries (plus
 * k1). sample and limit (0 for none) name the case in a failure. */
static void fiber_differences_match(const piola_material *m, const double *fam, const double *f9, const double *p,
                                    const double *d, double h, double dtol_rel, long sample, double limit) {
  const double ptol = 1e-5 * (max_abs9(p, 9) + m->hgo.k1), dtol = dtol_rel * (max_abs9(d, 81) + m->hgo.k1);
  for (int e = 0; e < 9; ++e) {
    double fp[9], fm[9], pp[9], pm[9];
    memcpy(fp, f9, sizeof fp), memcpy(fm, f9, sizeof fm);
    fp[e] += h, fm[e] -= h;
    const double dpsi = (piola_material_hgo_fiber_energy_density(m, fp, fam) -
                         piola_material_hgo_fiber_energy_density(m, fm, fam)) / (2 * h);
    if (!(fabs(dpsi - p[e]) <= ptol))
      fail_msg("sample %ld (limit %g): dpsi/dF[%d] = %.9g but P = %.9g", sample, limit, e, dpsi, p[e]);
    piola_material_hgo_fiber_stress(m, fp, fam, pp);
    piola_material_hgo_fiber_stress(m, fm, fam, pm);
    for (int r = 0; r < 9; ++r) {
      const double dp = (pp[r] - pm[r]) / (2 * h);
      if (!(fabs(dp - d[9 * r + e]) <= dtol))
        fail_msg("sample %ld (limit %g): dP[%d]/dF[%d] = %.9g by differences, %.9g returned", sample, limit, r,
                 e, dp, d[9 * r + e]);
    }
  }
}

static void fiber_stress_is_the_energy_gradient_and_its_derivative_exact(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(19);
  const long n = test_samples(2000, 60);
  const double kappas[2] = {0.0, 0.226};
  for (long k = 0; k < n; ++k) {
    const piola_material m = hgo_material(kappas[k % 2], test_rng_uniform(&rng, 0, 90), 0.45);
    double fiber[3], fam[6], f9[9], p[9], d[81];
    random_unit(&rng, fiber);
    if (piola_material_hgo_families(&m, fiber, fam) != PIOLA_OK) continue; /* parallel: rare */
    flat9(random_f(&rng, k), f9);
    piola_material_hgo_fiber_stress(&m, f9, fam, p);
    piola_material_hgo_fiber_stress_derivative(&m, f9, fam, d);
    fiber_differences_match(&m, fam, f9, p, d, 1e-6 * (1.0 + max_abs9(f9, 9)), 1e-5, k, 0);
    /* symmetric and positive semi-definite (no projection needed) */
    for (int r = 0; r < 9; ++r)
      for (int c = 0; c < 9; ++c) assert_close(d[9 * r + c], d[9 * c + r], 1e-9 * (max_abs9(d, 81) + 1));
    for (int t = 0; t < 5; ++t) {
      double x[9], q = 0;
      for (int e = 0; e < 9; ++e) x[e] = test_rng_normal(&rng);
      for (int r = 0; r < 9; ++r)
        for (int c = 0; c < 9; ++c) q += x[r] * d[9 * r + c] * x[c];
      assert_true(q >= -1e-9 * max_abs9(d, 81));
    }
  }
}

/* The F whose family 0 has generalized fibre stretch s = sqrt(1 + E) exactly: a stretch t
 * along the family (the other entries 1), solved for t by bisection (E grows with t). */
static void f_at_fiber_stretch(const piola_material *m, const double fam[6], double s, double f9[9]) {
  double lo = 1.0, hi = 1e4, w[3];
  for (int it = 0; it < 200; ++it) {
    const double t = 0.5 * (lo + hi);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) f9[3 * i + j] = (i == j) + (t - 1.0) * fam[i] * fam[j];
    if (sqrt(1.0 + hgo_invariant(&m->hgo, f9, fam, w)) < s) lo = t; else hi = t;
  }
}

/* Across the fibre stretch limit (materials.md): the energy's gradient is the stress and the
 * stress's derivative dP/dF on both sides and straddling it (it is C2 in the fibre stretch),
 * with and without dispersion, at the default and at other limits. */
static void the_stretch_limit_is_crossed_smoothly(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(25);
  const double kappas[2] = {0.0, 0.226}, limits[3] = {1.7, 1.2, 2.1};
  for (long k = 0; k < test_samples(600, 60); ++k) {
    piola_material_def def = piola_default_material_def();
    def.model = PIOLA_MODEL_HGO;
    def.poisson_ratio = 0.45;
    def.hgo.kappa = kappas[k % 2];
    def.hgo.fiber_stretch_limit = limits[(k / 2) % 3];
    def.hgo.fiber_angle_degrees = test_rng_uniform(&rng, 0, 90);
    piola_material m;
    assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
    double fiber[3], fam[6], f9[9], p[9], d[81];
    random_unit(&rng, fiber);
    if (piola_material_hgo_families(&m, fiber, fam) != PIOLA_OK) continue;
    const double sl = sqrt(1.0 + hgo_limit_strain(&m.hgo));
    /* within a few differencing steps of the limit, both sides */
    f_at_fiber_stretch(&m, fam, sl * (1.0 + test_rng_uniform(&rng, -3e-6, 3e-6)), f9);
    piola_material_hgo_fiber_stress(&m, f9, fam, p);
    piola_material_hgo_fiber_stress_derivative(&m, f9, fam, d);
    fiber_differences_match(&m, fam, f9, p, d, 1e-6, 1e-4, k, sl);
    /* the one-sided values meet: energy, stress and dP/dF just below and just above agree */
    double fb[9], fa[9], pb[9], pa[9], db[81], da[81];
    f_at_fiber_stretch(&m, fam, sl * (1 - 1e-9), fb);
    f_at_fiber_stretch(&m, fam, sl * (1 + 1e-9), fa);
    piola_material_hgo_fiber_stress(&m, fb, fam, pb);
    piola_material_hgo_fiber_stress(&m, fa, fam, pa);
    piola_material_hgo_fiber_stress_derivative(&m, fb, fam, db);
    piola_material_hgo_fiber_stress_derivative(&m, fa, fam, da);
    for (int e = 0; e < 9; ++e) assert_close(pa[e], pb[e], 1e-6 * (max_abs9(pb, 9) + 1));
    for (int e = 0; e < 81; ++e) assert_close(da[e], db[e], 1e-6 * (max_abs9(db, 81) + 1));
  }
}

/* Past the limit the fibres are a spring of constant stiffness in the fibre stretch: their
 * plane-wave stiffness stays below the step bound's hgo_fiber_modulus_bound, which stops
 * growing at the limit, however far the fibres are stretched (a scramble stretches tets
 * hundreds of times); the exponential's stiffness would be e^(k2 E^2) larger. */
static void stiffness_stays_bounded_past_the_limit(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(26);
  for (int kk = 0; kk < 2; ++kk) {
    const piola_material m = hgo_material(kk ? 0.226 : 0.0, 29.0, 0.45);
    const double fiber[3] = {1, 0, 0};
    double fam[6];
    assert_int_equal(piola_material_hgo_families(&m, fiber, fam), PIOLA_OK);
    const double sl = sqrt(1.0 + hgo_limit_strain(&m.hgo));
    double at_limit = 0;
    const double stretches[5] = {1.0, 1.001, 10.0, 100.0, 1000.0}; /* times the limit */
    for (int c = 0; c < 5; ++c) {
      double f9[9], d[81];
      f_at_fiber_stretch(&m, fam, sl * stretches[c], f9);
      piola_material_hgo_fiber_stress_derivative(&m, f9, fam, d);
      /* in the diagonal frame of F, as the step bound sees it */
      piola_mat3 f, u, v;
      piola_vec3 fh;
      for (int e = 0; e < 9; ++e) f.m[e / 3][e % 3] = f9[e];
      assert_int_equal(piola_diagonalize3(&f, &u, &fh, &v), PIOLA_OK);
      const double bound = hgo_fiber_modulus_bound(&m.hgo, fh.x, fh.y, fh.z);
      if (c == 0) at_limit = bound;
      assert_close(bound, at_limit, 1e-9 * at_limit); /* constant past the limit */
      double wave = 0;
      for (int t = 0; t < 400; ++t) { /* unit rank-one dF = x y^T */
        double x[3], y[3], q = 0;
        random_unit(&rng, x);
        random_unit(&rng, y);
        if (t == 0) memcpy(x, fam, sizeof x), memcpy(y, fam, sizeof y); /* along the family */
        for (int r = 0; r < 9; ++r)
          for (int e = 0; e < 9; ++e) q += x[r / 3] * y[r % 3] * d[9 * r + e] * x[e / 3] * y[e % 3];
        wave = fmax(wave, q);
      }
      if (!(wave <= bound * (1 + 1e-9)))
        fail_msg("kappa %g, %g times the limit: plane wave %g above the bound %g", m.hgo.kappa,
                 stretches[c], wave, bound);
      if (c > 1 && !(wave > 0.25 * bound)) /* the fibres still carry: the bound is not loose */
        fail_msg("kappa %g, %g times the limit: plane wave %g, bound %g", m.hgo.kappa, stretches[c], wave, bound);
    }
  }
}

static void the_whole_stress_is_the_energy_gradient(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(20);
  const long n = test_samples(600, 30);
  for (long k = 0; k < n; ++k) {
    const piola_material m = hgo_material(k % 2 ? 0.1 : 0.0, 40.0, 0.4);
    double fiber[3], fam[6];
    random_unit(&rng, fiber);
    if (piola_material_hgo_families(&m, fiber, fam) != PIOLA_OK) continue;
    double s[3];
    for (int i = 0; i < 3; ++i) s[i] = test_rng_uniform(&rng, 0.4, 1.8); /* above the threshold */
    const piola_mat3 f = f_with_singular_values(&rng, s);
    piola_mat3 p, tmp;
    whole_stress(&m, f, fam, &p);
    double pmax = 0;
    for (int i = 0; i < 9; ++i) pmax = fmax(pmax, fabs(p.m[i / 3][i % 3]));
    const double h = 1e-6;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        piola_mat3 fp = f, fm = f;
        fp.m[i][j] += h, fm.m[i][j] -= h;
        const double d = (whole_stress(&m, fp, fam, &tmp) - whole_stress(&m, fm, fam, &tmp)) / (2 * h);
        if (!(fabs(d - p.m[i][j]) <= 1e-5 * (pmax + m.mu)))
          fail_msg("sample %ld: dpsi/dF[%d][%d] = %.9g, P = %.9g", k, i, j, d, p.m[i][j]);
      }
  }
}

static void rest_has_zero_stress_and_energy(void **state) {
  (void)state;
  const double kappas[3] = {0.0, 0.226, 1.0 / 3.0};
  for (int c = 0; c < 3; ++c) {
    const piola_material m = hgo_material(kappas[c], 29.0, 0.45);
    const double fiber[3] = {1, 0, 0}, id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, one[3] = {1, 1, 1};
    double fam[6], p[9], ph[3];
    assert_int_equal(piola_material_hgo_families(&m, fiber, fam), PIOLA_OK);
    piola_material_hgo_fiber_stress(&m, id, fam, p);
    piola_material_stress(&m, one, ph);
    for (int e = 0; e < 9; ++e) assert_true(fabs(p[e]) < 1e-12);
    for (int i = 0; i < 3; ++i) assert_true(fabs(ph[i]) < 1e-9);
    assert_true(fabs(piola_material_hgo_fiber_energy_density(&m, id, fam)) < 1e-15);
    assert_true(fabs(piola_material_energy_density(&m, one)) < 1e-12);
  }
}

/* The families: unit, at +-angle from the fibre, in the plane of the fibre and the axis, and
 * an error when the fibre is parallel to the axis. Compressed fibres carry nothing. */
static void families_and_tension_only(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(21);
  const piola_material m = hgo_material(0.0, 35.0, 0.45);
  for (int k = 0; k < 50; ++k) {
    double fiber[3], fam[6];
    random_unit(&rng, fiber);
    if (piola_material_hgo_families(&m, fiber, fam) != PIOLA_OK) continue;
    for (int a = 0; a < 2; ++a) {
      const double *x = fam + 3 * a;
      assert_close(x[0] * x[0] + x[1] * x[1] + x[2] * x[2], 1.0, 1e-12);
      assert_close(x[0] * fiber[0] + x[1] * fiber[1] + x[2] * fiber[2], cos(35.0 * M_PI / 180), 1e-12);
      /* in the plane of fibre and axis: orthogonal to their cross product */
      const double *ax = m.hgo.axis;
      const double nrm[3] = {fiber[1] * ax[2] - fiber[2] * ax[1], fiber[2] * ax[0] - fiber[0] * ax[2],
                             fiber[0] * ax[1] - fiber[1] * ax[0]};
      assert_close(x[0] * nrm[0] + x[1] * nrm[1] + x[2] * nrm[2], 0.0, 1e-12);
    }
  }
  double fam[6];
  assert_int_not_equal(piola_material_hgo_families(&m, m.hgo.axis, fam), PIOLA_OK);
  assert_non_null(strstr(piola_last_error(), "parallel"));
  /* along the fibre plane compressed: E < 0 for both families, no fibre stress */
  const double fiber[3] = {1, 0, 0};
  assert_int_equal(piola_material_hgo_families(&m, fiber, fam), PIOLA_OK);
  const double f9[9] = {0.8, 0, 0, 0, 1.1, 0, 0, 0, 0.8}, f9b[9] = {1.2, 0, 0, 0, 1.0, 0, 0, 0, 1.0};
  double p[9];
  piola_material_hgo_fiber_stress(&m, f9, fam, p);
  for (int e = 0; e < 9; ++e) assert_true(p[e] == 0.0);
  piola_material_hgo_fiber_stress(&m, f9b, fam, p);
  assert_true(p[0] > 0.0); /* stretched along the fibres: tension */
}

/* P(Q F R^T) with the material (fibre and axis) turned by R = Q P(F) R^T. */
static void stress_rotates_with_world_and_material(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(22);
  for (int k = 0; k < test_samples(200, 20); ++k) {
    piola_material_def def = piola_default_material_def();
    def.model = PIOLA_MODEL_HGO;
    def.poisson_ratio = 0.45;
    def.hgo.kappa = 0.1;
    def.hgo.fiber_angle_degrees = 49.98;
    double axis[3], fiber[3];
    random_unit(&rng, axis);
    random_unit(&rng, fiber);
    memcpy(def.hgo.axis, axis, sizeof axis);
    piola_material m, mr;
    assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
    const piola_mat3 q = random_rotation(&rng), r = random_rotation(&rng);
    double raxis[3], rfiber[3];
    for (int i = 0; i < 3; ++i) {
      raxis[i] = r.m[i][0] * axis[0] + r.m[i][1] * axis[1] + r.m[i][2] * axis[2];
      rfiber[i] = r.m[i][0] * fiber[0] + r.m[i][1] * fiber[1] + r.m[i][2] * fiber[2];
    }
    memcpy(def.hgo.axis, raxis, sizeof raxis);
    assert_int_equal(piola_material_init(&def, &mr), PIOLA_OK);
    double fam[6], rfam[6];
    if (piola_material_hgo_families(&m, fiber, fam) != PIOLA_OK) continue;
    assert_int_equal(piola_material_hgo_families(&mr, rfiber, rfam), PIOLA_OK);
    const piola_mat3 f = random_f(&rng, k); /* every kind, far past the stretch limit included */
    piola_mat3 p, pr;
    const double e0 = whole_stress(&m, f, fam, &p);
    const double e1 = whole_stress(&mr, mat3_mul(mat3_mul(q, f), mat3_transpose(r)), rfam, &pr);
    const piola_mat3 expect = mat3_mul(mat3_mul(q, p), mat3_transpose(r));
    double scale = 0;
    for (int i = 0; i < 9; ++i) scale = fmax(scale, fabs(p.m[i / 3][i % 3]));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) assert_close(pr.m[i][j], expect.m[i][j], 1e-9 * (scale + m.mu));
    assert_close(e1, e0, 1e-9 * (fabs(e0) + m.mu));
  }
}

/* The diagonal-frame evaluation the force loop does (Fhat, families V^T a) equals the
 * full-F one rotated: U Phat_f V^T = P_f(F). */
static void diagonal_frame_matches_the_full_f(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(23);
  const piola_material m = hgo_material(0.2, 62.0, 0.45);
  for (int k = 0; k < 100; ++k) {
    double fiber[3], fam[6], hfam[6], f9[9], p[9], ph[9];
    random_unit(&rng, fiber);
    if (piola_material_hgo_families(&m, fiber, fam) != PIOLA_OK) continue;
    const piola_mat3 f = random_f(&rng, k);
    flat9(f, f9);
    piola_material_hgo_fiber_stress(&m, f9, fam, p);
    piola_mat3 u, v;
    piola_vec3 fh;
    assert_int_equal(piola_diagonalize3(&f, &u, &fh, &v), PIOLA_OK);
    const double fd[9] = {fh.x, 0, 0, 0, fh.y, 0, 0, 0, fh.z};
    for (int a = 0; a < 2; ++a)
      for (int c = 0; c < 3; ++c)
        hfam[3 * a + c] = v.m[0][c] * fam[3 * a] + v.m[1][c] * fam[3 * a + 1] + v.m[2][c] * fam[3 * a + 2];
    piola_material_hgo_fiber_stress(&m, fd, hfam, ph);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double s = 0;
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) s += u.m[i][a] * ph[3 * a + b] * v.m[j][b];
        assert_close(s, p[3 * i + j], 1e-9 * (max_abs9(p, 9) + 1));
      }
    assert_close(piola_material_hgo_fiber_energy_density(&m, fd, hfam),
                 piola_material_hgo_fiber_energy_density(&m, f9, fam),
                 1e-9 * (piola_material_hgo_fiber_energy_density(&m, f9, fam) + 1));
  }
}

/* Every entry f_k <= 0 of Fhat gets a negative diagonal stress (matrix + fibres), whatever the
 * fibres: flat, collapsed to a line or a point, inverted, with stiff fibres pulling; finite
 * for huge stretches. */
static void flat_and_inverted_entries_are_pushed_back(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(24);
  piola_material_def def = piola_default_material_def();
  def.model = PIOLA_MODEL_HGO;
  def.poisson_ratio = 0.45;
  def.hgo.k1 = 1e6; /* fibres 300x stiffer than the matrix */
  def.hgo.k2 = 5.0;
  const piola_inversion_mode modes[3] = {PIOLA_INVERSION_LINEAR, PIOLA_INVERSION_CLAMP,
                                         PIOLA_INVERSION_ENERGY};
  for (int md = 0; md < 3; ++md) {
    def.inversion_mode = modes[md];
    for (int kk = 0; kk < 2; ++kk) {
      def.hgo.kappa = kk ? 0.3 : 0.0;
      piola_material m;
      assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
      for (int k = 0; k < test_samples(2000, 100); ++k) {
        double f[3];
        for (int i = 0; i < 3; ++i) f[i] = test_rng_uniform(&rng, 0.05, 2.0);
        const int kind = k % 4;
        f[0] = kind == 0 ? 0.0 : -test_rng_uniform(&rng, 0.0, 1.5); /* flat or inverted */
        if (kind == 2) f[1] = 0.0;                                   /* a line */
        if (kind == 3) f[1] = f[2] = 0.0;                            /* a point */
        double fiber[3], fam[6], hfam[6];
        random_unit(&rng, fiber);
        if (piola_material_hgo_families(&m, fiber, fam) != PIOLA_OK) continue;
        memcpy(hfam, fam, sizeof fam); /* any frame: take V = I */
        const double fd[9] = {f[0], 0, 0, 0, f[1], 0, 0, 0, f[2]};
        double ph[3], pf[9];
        piola_material_stress(&m, f, ph);
        piola_material_hgo_fiber_stress(&m, fd, hfam, pf);
        for (int i = 0; i < 3; ++i) {
          const double total = ph[i] + pf[4 * i];
          assert_true(isfinite(total));
          if (f[i] <= 0.0 && !(total < 0.0))
            fail_msg("mode %d: f = (%g, %g, %g): entry %d has stress %g (matrix %g, fibres %g)", md,
                     f[0], f[1], f[2], i, total, ph[i], pf[4 * i]);
        }
      }
    }
  }
  piola_material m;
  assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
  const double huge[9] = {1e3, 0, 0, 0, 1e3, 0, 0, 0, -1e3};
  double fam[6], p[9], d[81];
  const double fiber[3] = {1, 0, 0};
  assert_int_equal(piola_material_hgo_families(&m, fiber, fam), PIOLA_OK);
  piola_material_hgo_fiber_stress(&m, huge, fam, p);
  piola_material_hgo_fiber_stress_derivative(&m, huge, fam, d);
  for (int e = 0; e < 9; ++e) assert_true(isfinite(p[e]));
  for (int e = 0; e < 81; ++e) assert_true(isfinite(d[e]));
  assert_true(isfinite(piola_material_hgo_fiber_energy_density(&m, huge, fam)));
}

/* ------------------------------------------------------------------ the artery
 * Holzapfel, Gasser, Ogden, "A new constitutive framework for arterial wall mechanics and a
 * comparative study of material models", J. Elasticity 61 (2000) 1-48, section 5: the
 * rabbit carotid artery (data of Chuong and Fung), two layers, parameters
 *   media      c = 3.0000 kPa, k1 = 2.3632 kPa, k2 = 0.8393, beta = 29.0 deg
 *   adventitia c = 0.3000 kPa, k1 = 0.5620 kPa, k2 = 0.7112, beta = 62.0 deg
 * stress-free (opened) geometry R_i = 0.71 mm, media 0.26 mm and adventitia 0.13 mm thick,
 * opening angle 160 deg; extension-inflation at axial stretch lambda_z = 1.5, pressures up
 * to 21.33 kPa (160 mmHg). Incompressible kinematics: r^2 = r_i^2 + (R^2 - R_i^2) / (k lambda_z),
 * k = 2 pi / (2 pi - alpha), lambda_theta = k r / R, lambda_r = 1 / (lambda_theta lambda_z),
 * and the inner pressure p = integral from r_i to r_o of (sigma_tt - sigma_rr) / r dr.
 * The reference integrand is the paper's closed form (their energy differentiated by hand:
 * sigma_tt - sigma_rr = c (l_t^2 - l_r^2) + 4 k1 E exp(k2 E^2) l_t^2 cos^2 beta,
 * E = l_t^2 cos^2 beta + l_z^2 sin^2 beta - 1, fibres only for E > 0); piola's is the Cauchy stress
 * from its public functions at F = diag(l_r, l_t, l_z) in the (r, theta, z) frame with the
 * fibre field circumferential and the axis axial, so the families are at +-beta from the
 * circumferential direction as in the paper. The paper's curve is this model's response;
 * digitized data points are not used. */
typedef struct artery_layer {
  double c, k1, k2, beta_degrees, r_in, r_out; /* Pa, Pa, -, deg, m, m (stress-free) */
} artery_layer;

static const artery_layer ARTERY[2] = {
    {3000.0, 2363.2, 0.8393, 29.0, 0.71e-3, 0.97e-3},
    {300.0, 562.0, 0.7112, 62.0, 0.97e-3, 1.10e-3},
};

/* sigma_tt - sigma_rr from the paper's closed form. */
static double reference_difference(const artery_layer *l, double lt, double lz) {
  const double lr = 1.0 / (lt * lz), cb = cos(l->beta_degrees * M_PI / 180);
  const double sb = sin(l->beta_degrees * M_PI / 180);
  const double e = lt * lt * cb * cb + lz * lz * sb * sb - 1.0;
  const double fib = e > 0 ? 4.0 * l->k1 * e * exp(l->k2 * e * e) * lt * lt * cb * cb : 0.0;
  return l->c * (lt * lt - lr * lr) + fib;
}

/* The same from piola's material (nearly incompressible: nu = 0.4999; at J = 1 the volume
 * term and the matrix's ln J term vanish). */
static double piola_difference(const piola_material *m, double lt, double lz) {
  const double lr = 1.0 / (lt * lz);
  const double fhat[3] = {lr, lt, lz}, f9[9] = {lr, 0, 0, 0, lt, 0, 0, 0, lz};
  const double fiber[3] = {0, 1, 0}; /* circumferential; the axis is z */
  double fam[6], ph[3], pf[9];
  assert_int_equal(piola_material_hgo_families(m, fiber, fam), PIOLA_OK);
  piola_material_stress(m, fhat, ph);
  piola_material_hgo_fiber_stress(m, f9, fam, pf);
  /* sigma = P F^T / J with J = 1: sigma_ii = P_ii f_i (F diagonal) */
  const double s_rr = (ph[0] + pf[0]) * lr, s_tt = (ph[1] + pf[4]) * lt;
  return s_tt - s_rr;
}

/* Inner pressure (Pa) at deformed inner radius ri, Simpson's rule through both layers. */
static double artery_pressure(const piola_material layers[2], int use_piola, double ri, double lz) {
  const double k = 2 * M_PI / (2 * M_PI - 160.0 * M_PI / 180.0), r0 = ARTERY[0].r_in;
  double p = 0;
  for (int a = 0; a < 2; ++a) {
    const int n = 400; /* even */
    const double h = (ARTERY[a].r_out - ARTERY[a].r_in) / n;
    for (int s = 0; s <= n; ++s) {
      const double rr = ARTERY[a].r_in + s * h; /* reference radius R */
      const double r = sqrt(ri * ri + (rr * rr - r0 * r0) / (k * lz));
      const double lt = k * r / rr;
      const double diff = use_piola ? piola_difference(&layers[a], lt, lz)
                                    : reference_difference(&ARTERY[a], lt, lz);
      /* dr = R dR / (k lz r): integrate over R */
      const double g = diff / r * rr / (k * lz * r);
      p += g * h / 3.0 * (s == 0 || s == n ? 1.0 : (s % 2 ? 4.0 : 2.0));
    }
  }
  return p;
}

static void artery_follows_the_published_inflation_curve(void **state) {
  (void)state;
  piola_material layers[2];
  for (int a = 0; a < 2; ++a) {
    piola_material_def def = piola_default_material_def();
    def.model = PIOLA_MODEL_HGO;
    def.poisson_ratio = 0.4999;
    def.hgo.mu = ARTERY[a].c;
    def.hgo.k1 = ARTERY[a].k1;
    def.hgo.k2 = ARTERY[a].k2;
    def.hgo.kappa = 0.0;
    def.hgo.fiber_angle_degrees = ARTERY[a].beta_degrees;
    def.hgo.axis[0] = 0, def.hgo.axis[1] = 0, def.hgo.axis[2] = 1;
    assert_int_equal(piola_material_init(&def, &layers[a]), PIOLA_OK);
  }
  const double lz = 1.5;
  /* the curve from the unloaded state (p = 0) to 160 mmHg by bisection on r_i */
  double prev_radius = 0, prev_compliance = INFINITY;
  const double pressures[5] = {0.0, 4e3, 8e3, 16e3, 21.33e3};
  for (int q = 0; q < 5; ++q) {
    double lo = 0.2e-3, hi = 3e-3;
    for (int it = 0; it < 100; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (artery_pressure(layers, 0, mid, lz) < pressures[q]) lo = mid; else hi = mid;
    }
    const double ri = 0.5 * (lo + hi);
    const double p_ref = artery_pressure(layers, 0, ri, lz), p = artery_pressure(layers, 1, ri, lz);
    print_message("lambda_z %.1f: p = %6.2f kPa at r_i = %.4f mm (piola %.4f kPa)\n", lz,
                  p_ref / 1e3, ri * 1e3, p / 1e3);
    assert_close(p, p_ref, 1e-4 * fmax(fabs(p_ref), 100.0));
    /* the curve rises, and stiffens: the radius grows ever less per kPa */
    assert_true(ri > prev_radius);
    if (q > 0) {
      const double compliance = (ri - prev_radius) / (pressures[q] - pressures[q - 1]);
      if (q > 1) assert_true(compliance < prev_compliance);
      prev_compliance = compliance;
    }
    prev_radius = ri;
  }
  /* The curve lies below the default fibre stretch limit (so the limit leaves it unchanged):
   * the largest fibre stretch, at each layer's inner surface at 160 mmHg, ... */
  const double k = 2 * M_PI / (2 * M_PI - 160.0 * M_PI / 180.0), ri = prev_radius;
  for (int a = 0; a < 2; ++a) {
    const double rr = ARTERY[a].r_in, r0 = ARTERY[0].r_in;
    const double lt = k * sqrt(ri * ri + (rr * rr - r0 * r0) / (k * lz)) / rr;
    const double b = ARTERY[a].beta_degrees * M_PI / 180;
    const double stretch = sqrt(lt * lt * cos(b) * cos(b) + lz * lz * sin(b) * sin(b));
    print_message("layer %d: largest fibre stretch %.3f at 160 mmHg\n", a, stretch);
    assert_true(stretch < piola_default_material_def().hgo.fiber_stretch_limit);
  }
  /* ... and a limit inside the curve would change it: the test sees the limit. */
  piola_material low[2] = {layers[0], layers[1]};
  for (int a = 0; a < 2; ++a) low[a].hgo.fiber_stretch_limit = 1.5;
  const double p_ref = artery_pressure(layers, 0, ri, lz);
  assert_true(fabs(artery_pressure(low, 1, ri, lz) - p_ref) > 0.01 * p_ref);
}

static void invalid_parameters_are_rejected_by_name(void **state) {
  (void)state;
  piola_material_def base = piola_default_material_def();
  base.model = PIOLA_MODEL_HGO;
  struct {
    double *field;
    double value;
    const char *key;
  } cases[] = {
      {&base.hgo.mu, 0.0, "hgo.mu"},
      {&base.hgo.k1, -1.0, "hgo.k1"},
      {&base.hgo.k2, 0.0, "hgo.k2"},
      {&base.hgo.kappa, 0.34, "hgo.kappa"},
      {&base.hgo.kappa, -0.01, "hgo.kappa"},
      {&base.hgo.fiber_angle_degrees, 91.0, "hgo.fiber_angle_degrees"},
      {&base.hgo.fiber_angle_degrees, NAN, "hgo.fiber_angle_degrees"},
      {&base.hgo.axis[1], INFINITY, "hgo.axis"},
      {&base.hgo.fiber_stretch_limit, 1.0, "hgo.fiber_stretch_limit"},
      {&base.hgo.fiber_stretch_limit, NAN, "hgo.fiber_stretch_limit"},
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
  base.hgo.axis[2] = 0.0;
  piola_material m;
  assert_int_not_equal(piola_material_init(&base, &m), PIOLA_OK);
  assert_non_null(strstr(piola_last_error(), "hgo.axis"));
  base.hgo.axis[2] = 1.0;
  base.youngs_modulus = -1; /* not used by HGO */
  assert_int_equal(piola_material_init(&base, &m), PIOLA_OK);
  assert_close(m.mu, base.hgo.mu, 0);
  assert_close(m.fiber_modulus, 8 * base.hgo.k1, 1e-9);
  assert_true(m.hgo.fiber_stretch_limit == 1.7); /* the default, in force */
  /* GOH 2006's k2: the limit in force is lowered to where k2 E^2 = 12, exp stays finite */
  base.hgo.k2 = 524.6;
  assert_int_equal(piola_material_init(&base, &m), PIOLA_OK);
  assert_close(m.hgo.fiber_stretch_limit, sqrt(1 + sqrt(12 / 524.6)), 1e-12);
  base.hgo.k2 = 0.8393;
  piola_material_model model;
  assert_true(piola_material_model_from_name("hgo", &model) && model == PIOLA_MODEL_HGO);
  assert_string_equal(piola_material_model_name(PIOLA_MODEL_HGO), "hgo");
  double ev[9], vec[9][3][3];
  const double one[3] = {1, 1, 1};
  assert_int_not_equal(piola_material_projected_hessian_eigensystem(&m, one, ev, vec), PIOLA_OK);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(fiber_stress_is_the_energy_gradient_and_its_derivative_exact),
      cmocka_unit_test(the_stretch_limit_is_crossed_smoothly),
      cmocka_unit_test(stiffness_stays_bounded_past_the_limit),
      cmocka_unit_test(the_whole_stress_is_the_energy_gradient),
      cmocka_unit_test(rest_has_zero_stress_and_energy),
      cmocka_unit_test(families_and_tension_only),
      cmocka_unit_test(stress_rotates_with_world_and_material),
      cmocka_unit_test(diagonal_frame_matches_the_full_f),
      cmocka_unit_test(flat_and_inverted_entries_are_pushed_back),
      cmocka_unit_test(artery_follows_the_published_inflation_curve),
      cmocka_unit_test(invalid_parameters_are_rejected_by_name),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
