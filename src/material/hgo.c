/* The Holzapfel-Gasser-Ogden model's fibre part: parameters, validation and the public
 * functions. The curves are in hgo_kernels.h (shared with the force loop); the matrix part
 * is the neo-Hookean kernel of material_kernels.h. */
#include <math.h>
#include <string.h>

#include "common/status_report.h"
#include "material/hgo.h"
#include "material/hgo_kernels.h"

piola_hgo_def piola__default_hgo_def(void) {
  /* Holzapfel, Gasser, Ogden 2000, section 4: the media of a rabbit carotid artery. */
  piola_hgo_def h;
  memset(&h, 0, sizeof h);
  h.mu = 3000.0;
  h.k1 = 2363.2;
  h.k2 = 0.8393;
  h.kappa = 0.0;
  h.fiber_angle_degrees = 29.0;
  h.axis[2] = 1.0;
  h.fiber_stretch_limit = 1.7; /* past arterial layers' rupture (docs/materials.md) */
  return h;
}

piola_status piola__hgo_init(const piola_material_def *def, piola_material *out) {
  const piola_hgo_def *h = &def->hgo;
  const double values[9] = {h->mu, h->k1, h->k2, h->kappa, h->fiber_angle_degrees,
                            h->axis[0], h->axis[1], h->axis[2], h->fiber_stretch_limit};
  static const char *const keys[9] = {"hgo.mu", "hgo.k1", "hgo.k2", "hgo.kappa",
                                      "hgo.fiber_angle_degrees", "hgo.axis", "hgo.axis", "hgo.axis",
                                      "hgo.fiber_stretch_limit"};
  for (int i = 0; i < 9; ++i)
    if (!isfinite(values[i]))
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "%s must be finite, got %g", keys[i], values[i]);
  if (!(h->mu > 0.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "hgo.mu must be > 0 Pa, got %g", h->mu);
  if (!(h->k1 >= 0.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "hgo.k1 must be >= 0 Pa, got %g", h->k1);
  if (!(h->k2 > 0.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "hgo.k2 must be > 0, got %g", h->k2);
  if (!(h->kappa >= 0.0 && h->kappa <= 1.0 / 3.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "hgo.kappa must be in [0, 1/3], got %g",
                      h->kappa);
  if (!(h->fiber_stretch_limit > 1.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "hgo.fiber_stretch_limit must be > 1, got %g",
                      h->fiber_stretch_limit);
  if (!(h->fiber_angle_degrees >= 0.0 && h->fiber_angle_degrees <= 90.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "hgo.fiber_angle_degrees must be in [0, 90], got %g", h->fiber_angle_degrees);
  const double n = sqrt(h->axis[0] * h->axis[0] + h->axis[1] * h->axis[1] + h->axis[2] * h->axis[2]);
  if (!(n > 0.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "hgo.axis must be a nonzero vector");
  out->hgo = *h;
  for (int i = 0; i < 3; ++i) out->hgo.axis[i] = h->axis[i] / n;
  /* the limit in force: lowered to where k2 E^2 = HGO_EXP_CAP (hgo_kernels.h) */
  out->hgo.fiber_stretch_limit = fmin(h->fiber_stretch_limit, sqrt(1.0 + sqrt(HGO_EXP_CAP / h->k2)));
  /* the matrix: neo-Hookean with shear modulus hgo.mu, lambda from poisson_ratio */
  const double nu = def->poisson_ratio;
  out->mu = h->mu;
  out->lambda = 2.0 * h->mu * nu / (1.0 - 2.0 * nu);
  const double angle = h->fiber_angle_degrees * (M_PI / 180.0);
  out->model_constants[HGO_COS_ANGLE] = cos(angle);
  out->model_constants[HGO_SIN_ANGLE] = h->fiber_angle_degrees == 0.0 ? 0.0 : sin(angle);
  const double q = 1.0 - 2.0 * h->kappa;
  out->fiber_modulus = 8.0 * h->k1 * q * q; /* both families' largest plane wave at rest */
  return PIOLA_OK;
}

static int is_hgo(const piola_material *m) { return m && m->model == PIOLA_MODEL_HGO; }

piola_status piola_material_hgo_families(const piola_material *material, const double fiber[3],
                                         double families[6]) {
  if (!is_hgo(material) || !fiber || !families)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "hgo_families: needs an \"hgo\" material");
  const double n = sqrt(fiber[0] * fiber[0] + fiber[1] * fiber[1] + fiber[2] * fiber[2]);
  if (!(n > 0.0) || !isfinite(n))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "hgo_families: zero or non-finite fibre");
  const double m[3] = {fiber[0] / n, fiber[1] / n, fiber[2] / n};
  double fam[2][3];
  const int ok = hgo_families_from_fiber(material, m, fam);
  memcpy(families, fam, sizeof fam);
  if (!ok)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "hgo_families: the fibre (%g, %g, %g) is parallel to hgo.axis, so the plane "
                      "of the two families is undefined",
                      m[0], m[1], m[2]);
  return PIOLA_OK;
}

void piola_material_hgo_fiber_stress(const piola_material *material, const double f[9],
                                     const double families[6], double p[9]) {
  memset(p, 0, 9 * sizeof(double));
  if (!is_hgo(material)) return;
  const piola_hgo_def *h = &material->hgo;
  for (int a = 0; a < 2; ++a) {
    double w[3], psi, slope, curvature;
    hgo_fiber_curve(h, hgo_invariant(h, f, families + 3 * a, w), &psi, &slope, &curvature);
    const double g = 2.0 * slope * h->kappa, r = 2.0 * slope * (1.0 - 3.0 * h->kappa);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) p[3 * i + j] += g * f[3 * i + j] + r * w[i] * families[3 * a + j];
  }
}

double piola_material_hgo_fiber_energy_density(const piola_material *material, const double f[9],
                                               const double families[6]) {
  if (!is_hgo(material)) return 0.0;
  double energy = 0.0;
  for (int a = 0; a < 2; ++a) {
    double w[3], psi, slope, curvature;
    hgo_fiber_curve(&material->hgo, hgo_invariant(&material->hgo, f, families + 3 * a, w), &psi,
                    &slope, &curvature);
    energy += psi;
  }
  return energy;
}

void piola_material_hgo_fiber_stress_derivative(const piola_material *material, const double f[9],
                                                const double families[6], double dpdf[81]) {
  memset(dpdf, 0, 81 * sizeof(double));
  if (!is_hgo(material)) return;
  const piola_hgo_def *h = &material->hgo;
  for (int a = 0; a < 2; ++a) {
    const double *n = families + 3 * a;
    double g[9], c4, s2;
    hgo_family_derivative(h, f, n, g, &c4, &s2);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) {
            double v = c4 * g[3 * i + j] * g[3 * k + l];
            if (i == k) v += s2 * (h->kappa * (j == l) + (1.0 - 3.0 * h->kappa) * n[j] * n[l]);
            dpdf[9 * (3 * i + j) + 3 * k + l] += v;
          }
  }
}
