/* What the tests of the constitutive models share (test_material.c,
 * test_material_energy_mode.c, test_material_hgo.c, test_muscle.c): building a material,
 * random points Fhat, random directions, rotations and F of given singular values, a stress
 * scale for relative tolerances, and where the spline model's derivative has breakpoints. */
#ifndef PIOLA_TEST_MATERIAL_CHECKS_H
#define PIOLA_TEST_MATERIAL_CHECKS_H

#include "piola/diagonalize.h"
#include "piola/material.h"
#include "test_support.h"

/* The material of model and inversion mode with E = youngs_modulus (Pa), Poisson ratio nu
 * and the default parameters otherwise; threshold > 0 sets the inversion threshold. */
piola_material material_of(piola_material_model model, piola_inversion_mode mode,
                           double youngs_modulus, double nu, double threshold);

/* f: three entries uniform in [lo, hi). */
void random_point(test_rng *rng, double lo, double hi, double f[3]);

/* a: a random unit vector (uniform on the sphere). */
void random_unit(test_rng *rng, double a[3]);

/* A random rotation (uniform, from a normalized Gaussian quaternion). */
piola_mat3 random_rotation(test_rng *rng);

/* a b and a^T. */
piola_mat3 mat3_mul(piola_mat3 a, piola_mat3 b);
piola_mat3 mat3_transpose(piola_mat3 a);

/* F = R1 diag(s) R2^T with random rotations R1, R2 (a negative entry of s inverts). */
piola_mat3 f_with_singular_values(test_rng *rng, const double s[3]);

/* |P(f)|_1 + 2 mu + |lambda| (Pa): a scale of the stress around f. */
double stress_scale(const piola_material *m, const double f[3]);

/* True when x is within gap of a breakpoint of the spline model (1 and the default
 * compression and elongation stretches); false for the other models. */
int near_spline_breakpoint(const piola_material *m, double x, double gap);

#endif
