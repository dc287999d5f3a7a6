/* Rotation invariance of the full stress P = U Phat(Fhat) V^T through the public invertible
 * diagonalization: P(R F Q^T) = R P(F) Q^T and psi(R F Q^T) = psi(F) for proper rotations
 * R, Q, for every model and inversion mode, including inverted and nearly flat F. */
#include "test_support.h"

#include <math.h>

#include "math/mat3.h"
#include "piola/diagonalize.h"
#include "piola/material.h"

static mat3 random_rotation(test_rng *rng) {
  /* Unit quaternion from four normals. */
  double q[4], n = 0;
  for (int i = 0; i < 4; ++i) q[i] = test_rng_normal(rng), n += q[i] * q[i];
  n = sqrt(n);
  const double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
  return (mat3){{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                 {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                 {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
}

/* Full first Piola-Kirchhoff stress and energy density of F. */
static mat3 full_stress(const piola_material *m, mat3 f, double *psi) {
  mat3 u, v;
  piola_vec3 fhat;
  assert_int_equal(piola_diagonalize3(&f, &u, &fhat, &v), PIOLA_OK);
  const double d[3] = {fhat.x, fhat.y, fhat.z};
  double p[3];
  piola_material_stress(m, d, p);
  *psi = piola_material_energy_density(m, d);
  return mat3_mul_diag_transpose(u, (vec3){p[0], p[1], p[2]}, v);
}

static void stress_rotates_with_the_deformation(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(31);
  const long samples = test_samples(300, 20);
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int mode = 0; mode < 3; ++mode) {
      piola_material_def def = piola_default_material_def();
      def.model = (piola_material_model)model;
      def.inversion_mode = (piola_inversion_mode[]){PIOLA_INVERSION_LINEAR, PIOLA_INVERSION_CLAMP, PIOLA_INVERSION_ENERGY}[mode];
      piola_material m;
      assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
      for (long s = 0; s < samples; ++s) {
        /* F = A diag(a) B^T with rotations A, B and distinct magnitudes in random order; a
         * third of them inverted (the negative entry is the one of smallest magnitude, as
         * in the diagonalization's convention), some with an entry near zero. The stress
         * of F computed through piola_diagonalize3, which sorts and may flip signs, must
         * equal A diag(Phat(a)) B^T: Phat must commute with what the diagonalization does. */
        double a[3];
        for (int i = 0; i < 3; ++i) a[i] = test_rng_uniform(&rng, 0.05, 2.0);
        if (s % 7 == 0) a[s % 3] = 1e-4;
        if (s % 3 == 0) {
          int k = 0;
          for (int i = 1; i < 3; ++i)
            if (a[i] < a[k]) k = i;
          a[k] = -a[k];
        }
        const mat3 ra = random_rotation(&rng), rb = random_rotation(&rng);
        const mat3 f = mat3_mul_diag_transpose(ra, (vec3){a[0], a[1], a[2]}, rb);
        double pa[3];
        piola_material_stress(&m, a, pa);
        const mat3 expected_f = mat3_mul_diag_transpose(ra, (vec3){pa[0], pa[1], pa[2]}, rb);
        const double psi_a = piola_material_energy_density(&m, a);

        double psi_f, psi_g;
        const mat3 pf = full_stress(&m, f, &psi_f);
        const double scale = mat3_norm(expected_f) + m.mu;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) assert_close(pf.m[i][j], expected_f.m[i][j], 1e-9 * scale);
        assert_close(psi_f, psi_a, 1e-9 * (fabs(psi_a) + m.mu));

        /* And rotating the deformation rotates the stress: P(R F Q^T) = R P(F) Q^T. */
        const mat3 r = random_rotation(&rng), q = random_rotation(&rng);
        const mat3 pg = full_stress(&m, mat3_mul_transpose_b(mat3_mul(r, f), q), &psi_g);
        const mat3 expected_g = mat3_mul_transpose_b(mat3_mul(r, expected_f), q);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) assert_close(pg.m[i][j], expected_g.m[i][j], 1e-9 * scale);
        assert_close(psi_g, psi_a, 1e-9 * (fabs(psi_a) + m.mu));
      }
    }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(stress_rotates_with_the_deformation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
