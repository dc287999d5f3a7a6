/* piola: how fast a damped body settles back to its rest shape (docs/time-stepping.md,
 * "Recovery").
 *
 * Near rest every hyperelastic model is linear elasticity with its rest Lame parameters, and
 * the damping of section 6.2 is the same operator with the viscosities in their place: the
 * stiffness K = K(mu, lambda) and the damping C = K(beta, alpha) of the rest mesh, with the
 * lumped masses M. A vibration mode phi of M^-1 K (frequency omega) then obeys
 *   x'' + c x' + omega^2 x = 0,  c = phi^T C phi / phi^T M phi,
 * and decays at r = c / 2 while c < 2 omega, at the slow root (c - sqrt(c^2 - 4 omega^2)) / 2
 * when overdamped. The slowest mode to settle is the lowest vibration (the largest shapes:
 * bending of limbs, twisting) or the heavily overdamped high modes, which relax at no less
 * than the smallest mu / beta, lambda / alpha. piola_elastic_body_settling_estimate computes
 * both from the actual mesh: the lowest non-rigid mode by inverse iteration (each iteration
 * a Jacobi-preconditioned conjugate-gradient solve with K, the rigid motions projected out). */
#ifndef PIOLA_SETTLING_H
#define PIOLA_SETTLING_H

#include "piola/elastic_body.h"
#include "piola/export.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct piola_settling_estimate {
  double lowest_frequency;  /* omega_1, rad/s: the lowest non-rigid vibration of the rest mesh
                               (0 when the mesh has parts not joined by tets) */
  double lowest_damping;    /* c_1, 1/s: that mode's damping coefficient */
  double lowest_decay_rate; /* 1/s: that mode's decay rate, r(omega_1, c_1) above */
  double relaxation_rate;   /* 1/s: min(mu / beta, lambda / alpha) over the materials, the
                               floor of the overdamped modes' decay (infinite without damping) */
  double decay_rate;        /* r = min(lowest_decay_rate, relaxation_rate), 1/s */
  double crossing_time;     /* D / c_p, s: a dilatational wave across the bounding-box
                               diagonal D (c_p = sqrt((lambda + 2 mu) / density) of the
                               slowest material, fibres left out) */
  double reexpansion_time;  /* s: 8 max(D / c_p, 1 / relaxation_rate), how long a body
                               collapsed to a point, a line or a plane takes to re-expand
                               and untangle before its shape error decays at decay_rate (a
                               measured bound, docs/time-stepping.md "Recovery") */
  double diagonal;          /* D, m: the rest bounding box's diagonal */
  int iterations;           /* inverse iterations taken */
} piola_settling_estimate;

/* Estimates body's settling under shear and bulk viscosity (Pa s, >= 0) from its rest mesh,
 * rest Lame parameters (fibres left out: they add no rest stiffness in compression) and
 * lumped masses. Costs a few conjugate-gradient solves with the rest stiffness: about a
 * second for a few thousand tets with slivers. PIOLA_ERROR_INVALID_ARGUMENT for a negative
 * or non-finite viscosity. */
PIOLA_API piola_status piola_elastic_body_settling_estimate(const piola_elastic_body *body,
                                                            double shear_viscosity,
                                                            double bulk_viscosity,
                                                            piola_settling_estimate *out);

/* Predicted time (s) for the shape error (m, the largest distance of a vertex from the rest
 * shape after the best rigid motion) of a collapsed body to fall from initial_error to
 * tolerance: reexpansion_time + ln(initial_error / tolerance) / decay_rate; 0 when
 * initial_error <= tolerance, infinite when decay_rate is 0. */
PIOLA_API double piola_settling_time(const piola_settling_estimate *estimate, double initial_error,
                                     double tolerance);

#ifdef __cplusplus
}
#endif

#endif
