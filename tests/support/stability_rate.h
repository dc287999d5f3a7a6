/* The linearized stability limit of an explicit step at a frozen state, shared by
 * tests/test_stable_step.c and bench/bench_scramble_bound.c. No cmocka here: the benchmark
 * links it. */
#ifndef PIOLA_TESTS_STABILITY_RATE_H
#define PIOLA_TESTS_STABILITY_RATE_H

#include "piola/elastic_body.h"

/* Largest eigenvalue of M^-1 K (1/s^2) of `body` at positions x, in *rate2: `iterations` steps
 * of power iteration on the mass-symmetrized M^-1/2 K M^-1/2 from the caller's start vector u
 * (3 n values, 0 on vertices of zero mass; overwritten), K u from central differences of the
 * elastic force with step 1e-7 max |x| (exact for the linear part; a free body's rigid modes
 * only add zeros). Leaves the body updated at x. Returns PIOLA_OK, or the status of the first
 * update that failed (the iteration runs on). */
piola_status largest_stability_rate2(piola_elastic_body *body, const double *x, double *u,
                                     int iterations, double *rate2);

#endif
