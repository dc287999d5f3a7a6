/* The muscle model's fibre part: parameters, validation and the public functions. The
 * curves themselves are in muscle_kernels.h (shared with the force loop); the isotropic
 * part (matrix + volume) is the neo-Hookean kernel of material_kernels.h. */
#include <math.h>
#include <string.h>

#include "common/status_report.h"
#include "material/muscle.h"
#include "material/muscle_kernels.h"

piola_muscle_def piola__default_muscle_def(void) {
  piola_muscle_def m;
  memset(&m, 0, sizeof m);
  m.passive_stiffness = 1e5;
  m.passive_toe_stretch = 1.2;
  m.max_active_stress = 1e5;
  m.optimal_stretch = 1.0;
  m.active_width = 0.5;
  return m;
}

piola_status piola__muscle_init(const piola_material_def *def, piola_material *out) {
  const piola_muscle_def *m = &def->muscle;
  const double values[5] = {m->passive_stiffness, m->passive_toe_stretch, m->max_active_stress,
                            m->optimal_stretch, m->active_width};
  static const char *const keys[5] = {"muscle.passive_stiffness", "muscle.passive_toe_stretch",
                                      "muscle.max_active_stress", "muscle.optimal_stretch",
                                      "muscle.active_width"};
  for (int i = 0; i < 5; ++i)
    if (!isfinite(values[i]))
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "%s must be finite, got %g", keys[i], values[i]);
  if (!(m->passive_stiffness >= 0.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "muscle.passive_stiffness must be >= 0 Pa, got %g",
                      m->passive_stiffness);
  if (!(m->passive_toe_stretch > 1.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "muscle.passive_toe_stretch must be > 1, got %g",
                      m->passive_toe_stretch);
  if (!(m->max_active_stress >= 0.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "muscle.max_active_stress must be >= 0 Pa, got %g",
                      m->max_active_stress);
  if (!(m->optimal_stretch > 0.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "muscle.optimal_stretch must be > 0, got %g",
                      m->optimal_stretch);
  if (!(m->active_width > 0.0 && m->active_width < 1.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "muscle.active_width must be in (0, 1), got %g",
                      m->active_width);
  out->muscle = *m;
  /* A bound on the fibre's contribution to the tangent stiffness: the slope of T (passive
   * k, active sigma max|L'| / (lambda_opt w)) plus the geometric term T / lambda (passive
   * <= k, active <= sigma / (lambda_opt (1 - w))), the passive one counted twice. */
  const double lo = m->optimal_stretch, w = m->active_width;
  out->fiber_modulus = 2.0 * m->passive_stiffness +
                       m->max_active_stress * (MUSCLE_BUMP_MAX_SLOPE / (lo * w) + 1.0 / (lo * (1.0 - w)));
  return PIOLA_OK;
}

double piola_material_fiber_tension(const piola_material *material, double stretch,
                                    double activation) {
  if (!material || material->model != PIOLA_MODEL_MUSCLE) return 0.0;
  double t, e;
  muscle_fiber_tension_energy(&material->muscle, fmax(stretch, 0.0),
                              muscle_clamp_activation(activation), &t, &e);
  return t;
}

/* ahat normalised; false for a zero (or non-finite) direction. */
static int unit_fiber(const double fiber[3], double a[3]) {
  const double n = sqrt(fiber[0] * fiber[0] + fiber[1] * fiber[1] + fiber[2] * fiber[2]);
  if (!(n > 0.0) || !isfinite(n)) return 0;
  for (int i = 0; i < 3; ++i) a[i] = fiber[i] / n;
  return 1;
}

void piola_material_fiber_stress(const piola_material *material, const double fhat[3],
                                 const double fiber[3], double activation, double phat[3][3]) {
  memset(phat, 0, 9 * sizeof(double));
  double a[3];
  if (!material || material->model != PIOLA_MODEL_MUSCLE || !unit_fiber(fiber, a)) return;
  double energy;
  const double r = muscle_fiber_factor(&material->muscle, fhat[0], fhat[1], fhat[2], a[0], a[1],
                                       a[2], muscle_clamp_activation(activation), &energy);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) phat[i][j] = r * fhat[i] * a[i] * a[j];
}

double piola_material_fiber_energy_density(const piola_material *material, const double fhat[3],
                                           const double fiber[3], double activation) {
  double a[3];
  if (!material || material->model != PIOLA_MODEL_MUSCLE || !unit_fiber(fiber, a)) return 0.0;
  double energy;
  (void)muscle_fiber_factor(&material->muscle, fhat[0], fhat[1], fhat[2], a[0], a[1], a[2],
                            muscle_clamp_activation(activation), &energy);
  return energy;
}

void piola_material_muscle_stress(const piola_material *material, const double fhat[3],
                                  const double fiber[3], double activation, double phat[3][3]) {
  piola_material_fiber_stress(material, fhat, fiber, activation, phat);
  double d[3];
  piola_material_stress(material, fhat, d);
  for (int i = 0; i < 3; ++i) phat[i][i] += d[i];
}

double piola_material_muscle_energy_density(const piola_material *material, const double fhat[3],
                                            const double fiber[3], double activation) {
  return piola_material_energy_density(material, fhat) +
         piola_material_fiber_energy_density(material, fhat, fiber, activation);
}
