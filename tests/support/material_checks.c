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

void random_unit(test_rng *rng, double a[3]) {
  double n;
  do {
    for (int i = 0; i < 3; ++i) a[i] = test_rng_normal(rng);
    n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  } while (n < 1e-3);
  for (int i = 0; i < 3; ++i) a[i] /= n;
}

piola_mat3 random_rotation(test_rng *rng) {
  double q[4], n = 0;
  for (int i = 0; i < 4; ++i) q[i] = test_rng_normal(rng), n += q[i] * q[i];
  n = sqrt(n);
  const double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
  piola_mat3 r = {{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                   {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                   {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
  return r;
}

piola_mat3 mat3_mul(piola_mat3 a, piola_mat3 b) {
  piola_mat3 c;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      c.m[i][j] = 0;
      for (int k = 0; k < 3; ++k) c.m[i][j] += a.m[i][k] * b.m[k][j];
    }
  return c;
}

piola_mat3 mat3_transpose(piola_mat3 a) {
  piola_mat3 t;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t.m[i][j] = a.m[j][i];
  return t;
}

piola_mat3 f_with_singular_values(test_rng *rng, const double s[3]) {
  piola_mat3 d = {{{s[0], 0, 0}, {0, s[1], 0}, {0, 0, s[2]}}};
  return mat3_mul(mat3_mul(random_rotation(rng), d), mat3_transpose(random_rotation(rng)));
}
