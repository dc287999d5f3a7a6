/* Constitutive models: parameters, validation, names, and the public evaluation functions.
 * The stress itself is computed by the inline kernels in material_kernels.h; this file adds
 * what only the non-hot paths need: the energy density and the exact derivative of the
 * extended stress (which needs the third derivative of the energy). */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "common/status_report.h"
#include "material/material_kernels.h"
#include "material/muscle.h"
#include "piola/material.h"

piola_material_def piola_default_material_def(void) {
  piola_material_def def;
  memset(&def, 0, sizeof def);
  def.model = PIOLA_MODEL_NEOHOOKEAN;
  def.youngs_modulus = 1e5;
  def.poisson_ratio = 0.3;
  def.inversion_threshold = 0.3;
  def.inversion_mode = PIOLA_INVERSION_LINEAR;
  def.spline.compression_stretch = 0.8;
  def.spline.elongation_stretch = 1.2;
  def.spline.stiffening = 10.0;
  def.muscle = piola__default_muscle_def();
  return def;
}

piola_status piola_youngs_poisson_from_lame(double mu, double lambda, double *youngs_modulus,
                                            double *poisson_ratio) {
  if (!youngs_modulus || !poisson_ratio)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "youngs_poisson_from_lame: NULL output");
  if (!isfinite(mu) || !isfinite(lambda))
    return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                      "lame parameters must be finite, got mu = %g, lambda = %g", mu, lambda);
  if (!(mu > 0.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "lame mu must be > 0 Pa, got %g", mu);
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

piola_status piola_material_init(const piola_material_def *def, piola_material *out) {
  if (!def || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "material_init: NULL argument");
  if ((int)def->model < 0 || def->model >= PIOLA_MODEL_COUNT)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "model: unknown material model %d",
                      (int)def->model);
  if (def->inversion_mode != PIOLA_INVERSION_LINEAR && def->inversion_mode != PIOLA_INVERSION_CLAMP)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "inversion.mode: unknown mode %d",
                      (int)def->inversion_mode);
  const double e = def->youngs_modulus, nu = def->poisson_ratio, c = def->inversion_threshold;
  PIOLA_TRY(check_finite("youngs_modulus", e));
  PIOLA_TRY(check_finite("poisson_ratio", nu));
  PIOLA_TRY(check_finite("inversion.threshold", c));
  if (!(e > 0.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "youngs_modulus must be > 0 Pa, got %g", e);
  if (!(nu > -1.0 && nu < 0.5))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "poisson_ratio must be in (-1, 0.5), got %g",
                      nu);
  if (!(c > 0.0 && c < 1.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "inversion.threshold must be in (0, 1), got %g",
                      c);

  piola_material m;
  memset(&m, 0, sizeof m);
  m.model = def->model;
  m.mu = e / (2.0 * (1.0 + nu));
  m.lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  m.threshold = c;
  m.inversion_mode = def->inversion_mode;

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
    if (!(b > 1.0))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "spline.elongation_stretch must be > 1, got %g", b);
    if (!(st >= 1.0))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "spline.stiffening must be >= 1, got %g", st);
    double *s = m.spline_coefficients;
    s[SPLINE_K0] = 2.0 * m.mu; /* with the pressure term: 2 mu I + lambda 1 1^T at rest */
    s[SPLINE_DK] = (st - 1.0) * s[SPLINE_K0];
    s[SPLINE_WE] = b - 1.0;
    s[SPLINE_WC] = 1.0 - a;
    s[SPLINE_INV_WE] = 1.0 / s[SPLINE_WE];
    s[SPLINE_INV_WC] = 1.0 / s[SPLINE_WC];
  }
  if (def->model == PIOLA_MODEL_MUSCLE) PIOLA_TRY(piola__muscle_init(def, &m));
  *out = m;
  return PIOLA_OK;
}

static const char *const model_names[PIOLA_MODEL_COUNT] = {"rotated_linear", "corotated", "stvk",
                                                           "neohookean", "spline", "muscle"};

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
  double fc[3];
  double d[3]; /* f - fc <= 0 */
  int clamped[3];
  material_parts parts;
} extension_point;

static extension_point extension_point_at(const piola_material *m, const double f[3]) {
  extension_point e;
  for (int i = 0; i < 3; ++i) {
    e.fc[i] = kernel_max(f[i], m->threshold);
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
    case PIOLA_MODEL_MUSCLE:
      return -2.0 * m->mu / (f * f * f);
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
        if ((m->model == PIOLA_MODEL_NEOHOOKEAN || m->model == PIOLA_MODEL_MUSCLE) && i == j &&
            j == k)
          tq = 2.0 / (f[i] * f[i] * f[i]);
        else if ((m->model == PIOLA_MODEL_COROTATED || m->model == PIOLA_MODEL_SPLINE) && i != j &&
                 j != k && i != k)
          tq = 1.0;
        t[i][j][k] = kappa * (h[i][j] * g[k] + h[i][k] * g[j] + h[j][k] * g[i] + qm * tq);
      }
  for (int i = 0; i < 3; ++i) t[i][i][i] += entry_third(m, f[i]);
}

double piola_material_energy_density(const piola_material *material, const double fhat[3]) {
  double p[3], psi;
  material_stress_energy_kernel(material, fhat[0], fhat[1], fhat[2], &p[0], &p[1], &p[2], &psi);
  return psi;
}

void piola_material_stress_derivative(const piola_material *material, const double fhat[3],
                                      double dphat[3][3]) {
  const piola_material *m = material;
  const extension_point e = extension_point_at(m, fhat);
  const material_parts *pa = &e.parts;
  const int linear = m->inversion_mode != PIOLA_INVERSION_CLAMP;
  const int any_clamped = e.clamped[0] || e.clamped[1] || e.clamped[2];
  double t[3][3][3] = {{{0}}};
  if (any_clamped) model_third_derivative(m, e.fc, t);
  const double c = m->threshold, floor_slope = m->mu;
  const double w = 0.25 * c, cap = fmax(2.0 * m->mu + m->lambda, floor_slope);
  double q[3], dq[3]; /* saturated offsets and their derivatives, 1 / (1 - d / w)^2 */
  for (int k = 0; k < 3; ++k) {
    q[k] = extension_saturation(m, KERNEL_EXACT_DIVIDE, e.d[k]);
    const double r = w / (w - e.d[k]);
    dq[k] = r * r;
  }

  for (int i = 0; i < 3; ++i) {
    const double kii = pa->k[i][i], p = pa->p[i];
    const double s = extension_diagonal_slope(m, KERNEL_EXACT_DIVIDE, p, kii);
    const double s_far = extension_far_slope(m, KERNEL_EXACT_DIVIDE, p, kii);
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
}
