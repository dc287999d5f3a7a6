/* Constitutive models: parameters, validation, names, and the public evaluation functions.
 * The stress itself is computed by the inline kernels in material_kernels.h; this file adds
 * what only the non-hot paths need: the energy density and the exact derivative of the
 * extended stress (which needs the third derivative of the energy). */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "common/number_text.h"
#include "common/status_report.h"
#include "material/hgo.h"
#include "material/material_kernels.h"
#include "material/muscle.h"
#include "piola/material.h"

piola_material_def piola_default_material_def(void) {
  piola_material_def def;
  memset(&def, 0, sizeof def);
  def.model = PIOLA_MODEL_NEOHOOKEAN;
  def.youngs_modulus = 1e5;
  def.poisson_ratio = 0.3;
  def.inversion_threshold = 0.0; /* the model's default, resolved by piola_material_init */
  def.inversion_mode = PIOLA_INVERSION_MODEL_DEFAULT;
  def.spline.compression_stretch = 0.8;
  def.spline.elongation_stretch = 1.2;
  def.spline.stiffening = 10.0;
  def.muscle = piola__default_muscle_def();
  /* Ogden 1972, Table 1 fit to Treloar's 1944 data: 6.3, 0.012, -0.1 kg/cm^2 (1 kg/cm^2 =
   * 98066.5 Pa), alpha 1.3, 5.0, -2.0. */
  def.ogden.term_count = 3;
  def.ogden.mu[0] = 6.3 * 98066.5, def.ogden.alpha[0] = 1.3;
  def.ogden.mu[1] = 0.012 * 98066.5, def.ogden.alpha[1] = 5.0;
  def.ogden.mu[2] = -0.1 * 98066.5, def.ogden.alpha[2] = -2.0;
  def.mooney_rivlin.c10 = 1.5e4;
  def.mooney_rivlin.c01 = 5e3;
  def.hgo = piola__default_hgo_def();
  return def;
}

/* Per model, the inversion setting a default def gets, chosen from measurements
 * (docs/materials.md, "Defaults that recover"): the setting that recovered from the most
 * scrambles of bench/bench_scramble_recovery's grid (a seed only slow at 12 s counts when it
 * recovers in 24 s), then the smaller threshold, then LINEAR over CLAMP; below the stretches
 * of the model's own published-curve test. Mooney-Rivlin and Ogden take the best CLAMP
 * threshold below the lateral stretch of rubber in their uniaxial tests (0.447 at stretch 5,
 * 0.377 at Treloar's 7.05; tests/test_material_rubber.c), 158 of 160 each, and with the
 * threshold left unset it rises in elements compressed in volume (to 0.55 and 0.5 below
 * J = 0.94, piola_material_init): 160 of 160 each, rubber's own states (J ~ 1) untouched. HGO
 * (an inflated artery's wall reaches radial stretches of 0.33-0.45, tests/test_material_hgo.c,
 * nearly incompressible) takes CLAMP 0.3, rising the same way to 0.5. Every default
 * recovers from point, line and plane collapse (tests/test_default_inversion.c). */
static const struct {
  piola_inversion_mode mode;
  double threshold;
} model_default_inversion[PIOLA_MODEL_COUNT] = {
    [PIOLA_MODEL_ROTATED_LINEAR] = {PIOLA_INVERSION_CLAMP, 0.3},
    [PIOLA_MODEL_COROTATED] = {PIOLA_INVERSION_CLAMP, 0.4},
    [PIOLA_MODEL_STVK] = {PIOLA_INVERSION_LINEAR, 0.4},
    [PIOLA_MODEL_NEOHOOKEAN] = {PIOLA_INVERSION_CLAMP, 0.5},
    [PIOLA_MODEL_SPLINE] = {PIOLA_INVERSION_CLAMP, 0.3},
    [PIOLA_MODEL_MUSCLE] = {PIOLA_INVERSION_CLAMP, 0.55},
    [PIOLA_MODEL_STABLE_NEOHOOKEAN] = {PIOLA_INVERSION_CLAMP, 0.3},
    [PIOLA_MODEL_MOONEY_RIVLIN] = {PIOLA_INVERSION_CLAMP, 0.4},
    [PIOLA_MODEL_OGDEN] = {PIOLA_INVERSION_CLAMP, 0.37},
    [PIOLA_MODEL_HGO] = {PIOLA_INVERSION_CLAMP, 0.3},
};

void piola_material_default_inversion(piola_material_model model, piola_inversion_mode *mode,
                                      double *threshold) {
  const int known = (int)model >= 0 && model < PIOLA_MODEL_COUNT;
  if (mode) *mode = known ? model_default_inversion[model].mode : PIOLA_INVERSION_LINEAR;
  if (threshold) *threshold = known ? model_default_inversion[model].threshold : 0.3;
}

piola_status piola_youngs_poisson_from_lame(double mu, double lambda, double *youngs_modulus,
                                            double *poisson_ratio) {
  if (!youngs_modulus || !poisson_ratio)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "youngs_poisson_from_lame: NULL output");
  if (!isfinite(mu) || !isfinite(lambda))
    return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                      "lame parameters must be finite, got mu = %g, lambda = %g", mu, lambda);
  if (!(mu > 0.0)) return piola__refuse_value("lame mu must be > 0 Pa", mu);
  /* nu > -1 <=> bulk modulus lambda + 2 mu / 3 > 0. */
  if (!(3.0 * lambda + 2.0 * mu > 0.0))
    return PIOLA_FAIL(
        PIOLA_ERROR_INVALID_ARGUMENT,
        "lame lambda must be > -2 mu / 3 (positive bulk modulus), got %g with mu = %g", lambda, mu);
  *youngs_modulus = mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu);
  *poisson_ratio = lambda / (2.0 * (lambda + mu));
  return PIOLA_OK;
}

static piola_status check_finite(const char *key, double value) {
  if (!isfinite(value))
    return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "%s must be finite, got %g", key, value);
  return PIOLA_OK;
}

/* Ogden terms (Mooney-Rivlin as the terms (2 C10, 2), (-2 C01, -2)) into model_constants; mu
 * = 1/2 sum mu_p alpha_p, lambda from nu with that mu. */
static piola_status ogden_init(const piola_material_def *def, double nu, piola_material *m) {
  double mus[PIOLA_OGDEN_MAX_TERMS], alphas[PIOLA_OGDEN_MAX_TERMS];
  int n;
  if (def->model == PIOLA_MODEL_MOONEY_RIVLIN) {
    PIOLA_TRY(check_finite("mooney_rivlin.c10", def->mooney_rivlin.c10));
    PIOLA_TRY(check_finite("mooney_rivlin.c01", def->mooney_rivlin.c01));
    n = 2;
    mus[0] = 2.0 * def->mooney_rivlin.c10, alphas[0] = 2.0;
    mus[1] = -2.0 * def->mooney_rivlin.c01, alphas[1] = -2.0;
    if (!(def->mooney_rivlin.c10 + def->mooney_rivlin.c01 > 0.0))
      return piola__refuse_value(
          "mooney_rivlin: c10 + c01 must be > 0 Pa (shear modulus 2 (c10 + c01))",
          def->mooney_rivlin.c10 + def->mooney_rivlin.c01);
  } else {
    n = def->ogden.term_count;
    if (n < 1 || n > PIOLA_OGDEN_MAX_TERMS)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "ogden: needs 1 to %d terms, got %d",
                        PIOLA_OGDEN_MAX_TERMS, n);
    for (int p = 0; p < n; ++p) {
      mus[p] = def->ogden.mu[p], alphas[p] = def->ogden.alpha[p];
      if (!isfinite(mus[p]) || mus[p] == 0.0)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "ogden.mu[%d] must be finite and nonzero, got %g",
                          p, mus[p]);
      if (!isfinite(alphas[p]) || alphas[p] == 0.0)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "ogden.alpha[%d] must be finite and nonzero, got %g", p, alphas[p]);
    }
  }
  double shear = 0.0, msum = 0.0;
  for (int p = 0; p < n; ++p) shear += 0.5 * mus[p] * alphas[p], msum += mus[p];
  if (!(shear > 0.0))
    return piola__refuse_value("ogden: the shear modulus 1/2 sum mu_p alpha_p must be > 0 Pa",
                               shear);
  m->mu = shear;
  m->lambda = 2.0 * shear * nu / (1.0 - 2.0 * nu);
  m->model_constants[OGDEN_COUNT] = n;
  m->model_constants[OGDEN_MU_SUM] = msum;
  for (int p = 0; p < n; ++p) {
    m->model_constants[OGDEN_TERMS + 2 * p] = mus[p];
    m->model_constants[OGDEN_TERMS + 2 * p + 1] = alphas[p];
  }
  return PIOLA_OK;
}

piola_status piola_material_init(const piola_material_def *def, piola_material *out) {
  if (!def || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "material_init: NULL argument");
  if ((int)def->model < 0 || def->model >= PIOLA_MODEL_COUNT)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "model: unknown material model %d",
                      (int)def->model);
  if (def->inversion_mode != PIOLA_INVERSION_LINEAR && def->inversion_mode != PIOLA_INVERSION_CLAMP &&
      def->inversion_mode != PIOLA_INVERSION_ENERGY &&
      def->inversion_mode != PIOLA_INVERSION_MODEL_DEFAULT)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "inversion.mode: unknown mode %d",
                      (int)def->inversion_mode);
  piola_inversion_mode mode;
  double default_threshold;
  piola_material_default_inversion(def->model, &mode, &default_threshold);
  if (def->inversion_mode != PIOLA_INVERSION_MODEL_DEFAULT) mode = def->inversion_mode;
  const double e = def->youngs_modulus, nu = def->poisson_ratio;
  const double c = def->inversion_threshold == 0.0 ? default_threshold : def->inversion_threshold;
  /* the Ogden models and HGO take their shear modulus from their own parameters */
  const int own_shear = def->model == PIOLA_MODEL_OGDEN || def->model == PIOLA_MODEL_MOONEY_RIVLIN ||
                        def->model == PIOLA_MODEL_HGO;
  if (!own_shear) PIOLA_TRY(check_finite("youngs_modulus", e));
  PIOLA_TRY(check_finite("poisson_ratio", nu));
  PIOLA_TRY(check_finite("inversion.threshold", c));
  if (!(e > 0.0) && !own_shear) return piola__refuse_value("youngs_modulus must be > 0 Pa", e);
  if (!(nu > -1.0 && nu < 0.5))
    return piola__refuse_value("poisson_ratio must be in (-1, 0.5)", nu);
  if (!(c > 0.0 && c < 1.0))
    return piola__refuse_value(
        "inversion.threshold must be in (0, 1) (or 0 for the model's default)", c);

  piola_material m;
  memset(&m, 0, sizeof m);
  m.model = def->model;
  m.mu = e / (2.0 * (1.0 + nu));
  m.lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  m.threshold = c;
  m.inversion_mode = mode;
  /* The rubber models' and HGO's default threshold rises in elements compressed in volume:
   * their own states (uniaxial tension of rubber, an inflated artery: J ~ 1) keep c, the
   * tangles of scrambled bodies (J well below 1)
   * get the larger threshold that untangles them (docs/materials.md, "Defaults that recover").
   * Only with the model's own threshold in CLAMP (the measured setting). */
  m.threshold_compressed = c;
  m.threshold_volume[0] = 0.94, m.threshold_volume[1] = 0.96;
  if (def->inversion_threshold == 0.0 && mode == PIOLA_INVERSION_CLAMP)
    m.threshold_compressed = def->model == PIOLA_MODEL_MOONEY_RIVLIN ? 0.55
                             : def->model == PIOLA_MODEL_OGDEN       ? 0.5
                             : def->model == PIOLA_MODEL_HGO         ? 0.5
                                                                     : c;

  if (def->model == PIOLA_MODEL_SPLINE) {
    const double a = def->spline.compression_stretch, b = def->spline.elongation_stretch;
    const double st = def->spline.stiffening;
    PIOLA_TRY(check_finite("spline.compression_stretch", a));
    PIOLA_TRY(check_finite("spline.elongation_stretch", b));
    PIOLA_TRY(check_finite("spline.stiffening", st));
    if (!(a > c && a < 1.0))
      return PIOLA_FAIL(
          PIOLA_ERROR_INVALID_ARGUMENT,
          "spline.compression_stretch must be in (inversion.threshold = %g, 1), got %g", c, a);
    if (!(b > 1.0)) return piola__refuse_value("spline.elongation_stretch must be > 1", b);
    if (!(st >= 1.0)) return piola__refuse_value("spline.stiffening must be >= 1", st);
    double *s = m.spline_coefficients;
    s[SPLINE_K0] = 2.0 * m.mu; /* with the pressure term: 2 mu I + lambda 1 1^T at rest */
    s[SPLINE_DK] = (st - 1.0) * s[SPLINE_K0];
    s[SPLINE_WE] = b - 1.0;
    s[SPLINE_WC] = 1.0 - a;
    s[SPLINE_INV_WE] = 1.0 / s[SPLINE_WE];
    s[SPLINE_INV_WC] = 1.0 / s[SPLINE_WC];
  }
  if (def->model == PIOLA_MODEL_MUSCLE) PIOLA_TRY(piola__muscle_init(def, &m));
  if (def->model == PIOLA_MODEL_HGO) PIOLA_TRY(piola__hgo_init(def, &m));
  if (def->model == PIOLA_MODEL_OGDEN || def->model == PIOLA_MODEL_MOONEY_RIVLIN)
    PIOLA_TRY(ogden_init(def, nu, &m));
  material_derive_constants(&m);
  *out = m;
  return PIOLA_OK;
}

static const char *const model_names[PIOLA_MODEL_COUNT] = {
    "rotated_linear", "corotated", "stvk", "neohookean", "spline", "muscle", "stable_neohookean",
    "mooney_rivlin", "ogden", "hgo"};

const char *piola_material_model_name(piola_material_model model) {
  if ((int)model < 0 || model >= PIOLA_MODEL_COUNT) return "unknown";
  return model_names[model];
}

bool piola_material_model_from_name(const char *name, piola_material_model *model) {
  if (!name || !model) return false;
  for (int i = 0; i < PIOLA_MODEL_COUNT; ++i)
    if (strcmp(name, model_names[i]) == 0) {
      *model = (piola_material_model)i;
      return true;
    }
  return false;
}

const char *piola_inversion_mode_name(piola_inversion_mode mode) {
  switch (mode) {
    case PIOLA_INVERSION_LINEAR:
      return "linear";
    case PIOLA_INVERSION_CLAMP:
      return "clamp";
    case PIOLA_INVERSION_ENERGY:
      return "energy";
    case PIOLA_INVERSION_MODEL_DEFAULT:
      return "default";
    default:
      return "unknown";
  }
}

bool piola_inversion_mode_from_name(const char *name, piola_inversion_mode *mode) {
  if (!name || !mode) return false;
  if (strcmp(name, "linear") == 0)
    *mode = PIOLA_INVERSION_LINEAR;
  else if (strcmp(name, "clamp") == 0)
    *mode = PIOLA_INVERSION_CLAMP;
  else if (strcmp(name, "energy") == 0)
    *mode = PIOLA_INVERSION_ENERGY;
  else if (strcmp(name, "default") == 0)
    *mode = PIOLA_INVERSION_MODEL_DEFAULT;
  else
    return false;
  return true;
}

/* ------------------------------------------------------------------ evaluation */

void piola_material_stress(const piola_material *material, const double fhat[3], double phat[3]) {
  material_stress_kernel(material, fhat[0], fhat[1], fhat[2], &phat[0], &phat[1], &phat[2]);
}

/* Clamped point, offsets and the model's parts there. */
typedef struct extension_point {
  double c; /* the threshold in force (material_threshold_at) */
  double fc[3];
  double d[3]; /* f - fc <= 0 */
  int clamped[3];
  material_parts parts;
} extension_point;

static extension_point extension_point_at(const piola_material *m, const double f[3]) {
  extension_point e;
  e.c = MATERIAL_THRESHOLD_RISES(m->model) ? material_threshold_at(m, f[0], f[1], f[2]) : m->threshold;
  for (int i = 0; i < 3; ++i) {
    e.fc[i] = kernel_max(f[i], e.c);
    e.d[i] = f[i] - e.fc[i];
    e.clamped[i] = e.d[i] < 0.0;
  }
  material_model_parts(m->model, m, KERNEL_EXACT_DIVIDE, e.fc[0], e.fc[1], e.fc[2], &e.parts);
  return e;
}

/* A'''(f): the third derivative of the separable energy. */
static double entry_third(const piola_material *m, double f) {
  switch (m->model) {
    case PIOLA_MODEL_STVK:
      return 6.0 * m->mu * f;
    case PIOLA_MODEL_NEOHOOKEAN:
    case PIOLA_MODEL_HGO: /* its matrix is neo-Hookean too */
    case PIOLA_MODEL_MUSCLE:
      return -2.0 * m->mu / (f * f * f);
    case PIOLA_MODEL_MOONEY_RIVLIN:
    case PIOLA_MODEL_OGDEN: {
      const double *o = m->model_constants;
      double t = -2.0 * o[OGDEN_MU_SUM] / (f * f * f);
      for (int p = 0; p < (int)o[OGDEN_COUNT]; ++p) {
        const double alpha = o[OGDEN_TERMS + 2 * p + 1];
        t += o[OGDEN_TERMS + 2 * p] * (alpha - 1.0) * (alpha - 2.0) * pow(f, alpha - 3.0);
      }
      return t;
    }
    case PIOLA_MODEL_SPLINE: {
      const double *s = m->spline_coefficients;
      const double u = f - 1.0;
      const double up = (u > 0.0 && u < s[SPLINE_WE]) ? s[SPLINE_INV_WE] : 0.0;
      const double down = (u < 0.0 && -u < s[SPLINE_WC]) ? s[SPLINE_INV_WC] : 0.0;
      return s[SPLINE_DK] * (up - down);
    }
    default:
      return 0.0;
  }
}

/* T_ijk = d3 psi / df_i df_j df_k of the unextended model at f (all entries > 0). */
static void model_third_derivative(const piola_material *m, const double f[3], double t[3][3][3]) {
  double g[3], h[3][3], kappa;
  const double qm = invariant_terms(m->model, m, KERNEL_EXACT_DIVIDE, f[0], f[1], f[2], g, h, &kappa);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) {
        double tq = 0.0; /* third derivative of the invariant q */
        if ((m->model == PIOLA_MODEL_NEOHOOKEAN || MATERIAL_IS_NEOHOOKEAN_MATRIX(m->model) ||
             MATERIAL_IS_OGDEN(m->model)) &&
            i == j && j == k)
          tq = 2.0 / (f[i] * f[i] * f[i]);
        else if ((m->model == PIOLA_MODEL_COROTATED || m->model == PIOLA_MODEL_SPLINE ||
                  m->model == PIOLA_MODEL_STABLE_NEOHOOKEAN) &&
                 i != j && j != k && i != k)
          tq = 1.0;
        t[i][j][k] = kappa * (h[i][j] * g[k] + h[i][k] * g[j] + h[j][k] * g[i] + qm * tq);
      }
  for (int i = 0; i < 3; ++i) t[i][i][i] += entry_third(m, f[i]);
  if (m->model == PIOLA_MODEL_STABLE_NEOHOOKEAN) {
    /* -mu'/2 ln(u), u = |f|^2 + 1: d3/df_i df_j df_k = 2 mu' (d_ij f_k + d_ik f_j + d_jk f_i) / u^2
     * - 8 mu' f_i f_j f_k / u^3. */
    const double mu_s = m->model_constants[SNH_MU];
    const double u = f[0] * f[0] + f[1] * f[1] + f[2] * f[2] + 1.0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k)
          t[i][j][k] += 2.0 * mu_s * ((i == j) * f[k] + (i == k) * f[j] + (j == k) * f[i]) / (u * u) -
                        8.0 * mu_s * f[i] * f[j] * f[k] / (u * u * u);
  }
}

double piola_material_energy_density(const piola_material *material, const double fhat[3]) {
  double p[3], psi;
  material_stress_energy_kernel(material, fhat[0], fhat[1], fhat[2], &p[0], &p[1], &p[2], &psi);
  return psi;
}

/* d T_012 / d f_i (material_mixed_third) at f, all entries > 0. */
static double mixed_third_slope(const piola_material *m, const double f[3], int i) {
  const double others = f[(i + 1) % 3] * f[(i + 2) % 3];
  switch (m->model) {
    case PIOLA_MODEL_COROTATED:
    case PIOLA_MODEL_SPLINE:
      return 4.0 * m->lambda * others;
    case PIOLA_MODEL_STABLE_NEOHOOKEAN: {
      const double u = f[0] * f[0] + f[1] * f[1] + f[2] * f[2] + 1.0;
      const double j = f[0] * f[1] * f[2], mu_s = m->model_constants[SNH_MU];
      return 4.0 * m->model_constants[SNH_LAMBDA] * others -
             8.0 * mu_s * (others / (u * u * u) - 6.0 * j * f[i] / (u * u * u * u));
    }
    default:
      return 0.0;
  }
}

/* dPhat/dFhat of PIOLA_INVERSION_ENERGY: the Hessian of psi_E (material_kernels.h), symmetric.
 * With m the third index of a pair i != j: off the diagonal K_ij + T_012 d_m + phi'(fc_i) d_j +
 * phi'(fc_j) d_i in every case; on it k(fc) for a clamped entry, K_ii + sum_{a clamped} T_iia
 * d_a + dT_012/df_i d_a d_b + phi''(fc_i) |d|^2 / 2 for an unclamped one (a, b the other two).
 * Not smooth
 * at the threshold (the diagonal jumps from K_ii to k). */
static void energy_mode_derivative(const piola_material *m, const extension_point *e,
                                   double dphat[3][3]) {
  const material_parts *pa = &e->parts;
  const int any_clamped = e->clamped[0] || e->clamped[1] || e->clamped[2];
  double t[3][3][3] = {{{0}}};
  if (any_clamped) model_third_derivative(m, e->fc, t);
  double g[3], h[3], k = m->model_constants[ENERGY_SLOPE];
  for (int i = 0; i < 3; ++i) k += energy_growth(m, e->fc[i], &g[i], &h[i]);
  const double half_d2 = 0.5 * (e->d[0] * e->d[0] + e->d[1] * e->d[1] + e->d[2] * e->d[2]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double v;
      if (i != j) /* phi' vanishes at a clamped entry, d at an unclamped one */
        v = pa->k[i][j] + t[0][1][2] * e->d[3 - i - j] + g[i] * e->d[j] + g[j] * e->d[i];
      else if (e->clamped[i])
        v = k;
      else {
        v = pa->k[i][i] + h[i] * half_d2;
        for (int a = 0; a < 3; ++a) v += t[i][i][a] * e->d[a];
        /* T_012 d_a d_b of Phat_i moves with f_i: the fourth derivative d T_012 / d f_i. */
        v += mixed_third_slope(m, e->fc, i) * e->d[(i + 1) % 3] * e->d[(i + 2) % 3];
      }
      dphat[i][j] = v;
    }
}

void piola_material_stress_derivative(const piola_material *material, const double fhat[3],
                                      double dphat[3][3]) {
  const piola_material *m = material;
  const extension_point e = extension_point_at(m, fhat);
  if (m->inversion_mode == PIOLA_INVERSION_ENERGY) {
    energy_mode_derivative(m, &e, dphat);
    return;
  }
  const material_parts *pa = &e.parts;
  const int linear = m->inversion_mode != PIOLA_INVERSION_CLAMP;
  const int any_clamped = e.clamped[0] || e.clamped[1] || e.clamped[2];
  double t[3][3][3] = {{{0}}};
  if (any_clamped) model_third_derivative(m, e.fc, t);
  const double c = e.c, floor_slope = m->mu;
  const double w = 0.25 * c, cap = fmax(2.0 * m->mu + m->lambda, floor_slope);
  double q[3], dq[3]; /* saturated offsets and their derivatives, 1 / (1 - d / w)^2 */
  for (int k = 0; k < 3; ++k) {
    q[k] = extension_saturation(KERNEL_EXACT_DIVIDE, c, e.d[k]);
    const double r = w / (w - e.d[k]);
    dq[k] = r * r;
  }

  for (int i = 0; i < 3; ++i) {
    const double kii = pa->k[i][i], p = pa->p[i];
    const double s = extension_diagonal_slope(m, KERNEL_EXACT_DIVIDE, c, p, kii);
    const double s_far = extension_far_slope(m, KERNEL_EXACT_DIVIDE, c, p, kii);
    const double raised = floor_slope + fmax(p, 0.0) / c;
    for (int j = 0; j < 3; ++j) {
      double v;
      if (!e.clamped[i]) {
        /* Unclamped row: P_i = p_i(fc) + [LINEAR] sum_k K_ik(fc) q(d_k). */
        if (e.clamped[j]) {
          v = linear ? pa->k[i][j] * dq[j] : 0.0;
        } else {
          v = pa->k[i][j];
          if (linear)
            for (int k = 0; k < 3; ++k) v += t[i][j][k] * q[k];
        }
      } else if (e.clamped[j]) {
        /* Clamped row and column: the extension's own slopes. */
        v = (i == j) ? (linear ? s_far + (s - s_far) * dq[i] : s_far)
                     : (linear ? kernel_max(pa->k[i][j], 0.0) : 0.0);
      } else {
        /* Clamped row, unclamped column j: fc_j = f_j moves p_i, K_ii, K_ik, hence the
         * slopes s and s_far. P_i = p_i + s_far d_i + (s - s_far) q_i + couplings. */
        v = pa->k[i][j];
        const double draised = p > 0.0 ? pa->k[i][j] / c : 0.0;
        if (linear) {
          const double ds = kii >= raised ? t[i][i][j] : draised;
          const double dcapped = kii < cap ? t[i][i][j] : 0.0; /* of min(K_ii, cap) */
          const double ds_far = fmin(kii, cap) >= raised ? dcapped : draised;
          v += ds_far * (e.d[i] - q[i]) + ds * q[i];
          for (int k = 0; k < 3; ++k)
            if (k != i && e.clamped[k] && pa->k[i][k] > 0.0) v += t[i][k][j] * e.d[k];
        } else if (p / c + floor_slope > 0.0) {
          v += pa->k[i][j] / c * e.d[i]; /* the ramp p / c + mu */
        }
      }
      dphat[i][j] = v;
    }
  }
  /* The threshold's rise with J (CLAMP, material_threshold_at): dPhat_i/dc dc/dJ dJ/df_j. */
  const double slope = MATERIAL_THRESHOLD_RISES(m->model) ? material_threshold_volume_slope(m, fhat[0], fhat[1], fhat[2]) : 0.0;
  if (slope != 0.0 && !linear && any_clamped) {
    double g[3];
    clamp_threshold_sensitivity(m, c, pa, e.d[0], e.d[1], e.d[2], g);
    const double dj[3] = {fhat[1] * fhat[2], fhat[0] * fhat[2], fhat[0] * fhat[1]};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) dphat[i][j] += g[i] * slope * dj[j];
  }
}

/* ------------------------------------------------------------------ projected Hessian */

/* Eigenvalues w and orthonormal eigenvectors (columns of q) of the symmetric 3x3 a, by cyclic
 * Jacobi rotations (converges quadratically; 3x3 needs a handful of sweeps). */
static void symmetric_eigen3(double a_in[3][3], double w[3], double q[3][3]) {
  double a[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      a[i][j] = 0.5 * (a_in[i][j] + a_in[j][i]);
      q[i][j] = i == j;
    }
  for (int sweep = 0; sweep < 50; ++sweep) {
    const double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
    const double diag = fabs(a[0][0]) + fabs(a[1][1]) + fabs(a[2][2]);
    if (!(off > 1e-300) || off <= 1e-18 * diag) break;
    for (int p = 0; p < 2; ++p)
      for (int r = p + 1; r < 3; ++r) {
        if (a[p][r] == 0.0) continue;
        const double theta = (a[r][r] - a[p][p]) / (2.0 * a[p][r]);
        const double t = (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
        const double cs = 1.0 / sqrt(t * t + 1.0), sn = t * cs;
        for (int k = 0; k < 3; ++k) { /* a <- a G (columns p, r) */
          const double akp = a[k][p], akr = a[k][r];
          a[k][p] = cs * akp - sn * akr;
          a[k][r] = sn * akp + cs * akr;
        }
        for (int k = 0; k < 3; ++k) { /* a <- G^T a (rows p, r) */
          const double apk = a[p][k], ark = a[r][k];
          a[p][k] = cs * apk - sn * ark;
          a[r][k] = sn * apk + cs * ark;
        }
        for (int k = 0; k < 3; ++k) {
          const double qkp = q[k][p], qkr = q[k][r];
          q[k][p] = cs * qkp - sn * qkr;
          q[k][r] = sn * qkp + cs * qkr;
        }
      }
  }
  for (int i = 0; i < 3; ++i) w[i] = a[i][i];
}

/* (p_i + s p_j) / (f_i + s f_j), s = +-1, or its limit k_ii + s k_ij where the denominator
 * vanishes relative to the entries (a quotient of a cancelled difference there). */
static double pair_eigenvalue(const double f[3], const double p[3], double k[3][3], int i,
                              int j, double s) {
  const double den = f[i] + s * f[j];
  if (fabs(den) <= 1e-7 * (fabs(f[i]) + fabs(f[j])) || den == 0.0)
    return k[i][i] + s * 0.5 * (k[i][j] + k[j][i]);
  return (p[i] + s * p[j]) / den;
}

piola_status piola_material_projected_hessian_eigensystem(const piola_material *material,
                                                          const double fhat[3],
                                                          double eigenvalues[9],
                                                          double eigenvectors[9][3][3]) {
  if (!material || !fhat || !eigenvalues || !eigenvectors)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "projected_hessian_eigensystem: NULL argument");
  const piola_material *m = material;
  if (MATERIAL_IS_NEOHOOKEAN_MATRIX(m->model))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "projected_hessian_eigensystem: the %s model's fibres are not isotropic",
                      piola_material_model_name(m->model));
  const double c = MATERIAL_IS_OGDEN(m->model) ? material_threshold_at(m, fhat[0], fhat[1], fhat[2])
                                               : m->threshold;
  const int clamped = !(fhat[0] >= c && fhat[1] >= c && fhat[2] >= c);
  if (clamped && m->inversion_mode != PIOLA_INVERSION_ENERGY)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "projected_hessian_eigensystem: an entry is below inversion.threshold and "
                      "inversion.mode \"%s\" has no energy there (use \"energy\")",
                      piola_inversion_mode_name(m->inversion_mode));
  double p[3], k[3][3], w[3], q[3][3];
  piola_material_stress(m, fhat, p);
  piola_material_stress_derivative(m, fhat, k);
  symmetric_eigen3(k, w, q);
  memset(eigenvectors, 0, 9 * sizeof eigenvectors[0]);
  for (int s = 0; s < 3; ++s) {
    eigenvalues[s] = w[s];
    for (int i = 0; i < 3; ++i) eigenvectors[s][i][i] = q[i][s];
  }
  static const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  const double r2 = sqrt(0.5);
  for (int n = 0; n < 3; ++n) {
    const int i = pairs[n][0], j = pairs[n][1], l = 3 - i - j;
    double twist, flip;
    if (m->model == PIOLA_MODEL_STABLE_NEOHOOKEAN && !clamped) {
      /* Smith et al. 2018, section 4: closed forms, no division. */
      const double mu_s = m->model_constants[SNH_MU], lambda_s = m->model_constants[SNH_LAMBDA];
      const double ic = fhat[0] * fhat[0] + fhat[1] * fhat[1] + fhat[2] * fhat[2];
      const double base = mu_s * ic / (ic + 1.0);
      const double v = lambda_s * (fhat[0] * fhat[1] * fhat[2] - m->model_constants[SNH_ALPHA]);
      twist = base + v * fhat[l];
      flip = base - v * fhat[l];
    } else {
      twist = pair_eigenvalue(fhat, p, k, i, j, 1.0);
      flip = pair_eigenvalue(fhat, p, k, i, j, -1.0);
    }
    eigenvalues[3 + n] = twist;
    eigenvectors[3 + n][i][j] = r2;
    eigenvectors[3 + n][j][i] = -r2;
    eigenvalues[6 + n] = flip;
    eigenvectors[6 + n][i][j] = r2;
    eigenvectors[6 + n][j][i] = r2;
  }
  for (int e = 0; e < 9; ++e) eigenvalues[e] = fmax(eigenvalues[e], 0.0);
  return PIOLA_OK;
}
