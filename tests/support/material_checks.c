/* Shared pieces of the constitutive model tests (material_checks.h). */
#include "material_checks.h"

#include <math.h>

#include "material/material_kernels.h"

piola_material material_of(piola_material_model model, piola_inversion_mode mode,
                           double youngs_modulus, double nu, double threshold) {
  piola_material_def def = piola_default_material_def();
  def.model = model;
  def.inversion_mode = mode;
  def.youngs_modulus = youngs_modulus;
  def.poisson_ratio = nu;
  if (threshold > 0) def.inversion_threshold = threshold;
  piola_material m;
  assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
  return m;
}

void random_point(test_rng *rng, double lo, double hi, double f[3]) {
  for (int i = 0; i < 3; ++i) f[i] = test_rng_uniform(rng, lo, hi);
}

double stress_scale(const piola_material *m, const double f[3]) {
  double p[3];
  piola_material_stress(m, f, p);
  return fabs(p[0]) + fabs(p[1]) + fabs(p[2]) + 2 * m->mu + fabs(m->lambda);
}

int near_spline_breakpoint(const piola_material *m, double x, double gap) {
  if (m->model != PIOLA_MODEL_SPLINE) return 0;
  const piola_material_def def = piola_default_material_def();
  return fabs(x - 1.0) < gap || fabs(x - def.spline.compression_stretch) < gap ||
         fabs(x - def.spline.elongation_stretch) < gap;
}
