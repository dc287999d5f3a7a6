/* What the tests of the constitutive models share (test_material.c,
 * test_material_energy_mode.c): building a material, random points Fhat, a stress scale for
 * relative tolerances, and where the spline model's derivative has breakpoints. */
#ifndef PIOLA_TEST_MATERIAL_CHECKS_H
#define PIOLA_TEST_MATERIAL_CHECKS_H

#include "piola/material.h"
#include "test_support.h"

/* The material of model and inversion mode with E = youngs_modulus (Pa), Poisson ratio nu
 * and the default parameters otherwise; threshold > 0 sets the inversion threshold. */
piola_material material_of(piola_material_model model, piola_inversion_mode mode,
                           double youngs_modulus, double nu, double threshold);

/* f: three entries uniform in [lo, hi). */
void random_point(test_rng *rng, double lo, double hi, double f[3]);

/* |P(f)|_1 + 2 mu + |lambda| (Pa): a scale of the stress around f. */
double stress_scale(const piola_material *m, const double f[3]);

/* True when x is within gap of a breakpoint of the spline model (1 and the default
 * compression and elongation stretches); false for the other models. */
int near_spline_breakpoint(const piola_material *m, double x, double gap);

#endif
