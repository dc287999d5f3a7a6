/* The state-aware explicit step bound of a tetrahedral body (stable_step.c; the derivation is
 * in docs/time-stepping.md, "Step size").
 *
 * For each tet e, from its Fhat of the last update, a modulus k_e (Pa) that bounds
 * dF : dP/dF : dF over every unit rank-one dF = a n^T (the squared speed of a plane wave
 * times density; lambda + 2 mu at rest), and its squared inverse rest altitude
 * 1/h_e^2 = max over corners of |grad N_c|^2. The step then obeys
 *     dt <= cfl / max_e sqrt(s k_e / (rho h_e^2))
 * with s the stiffness scale: at rest exactly the rest bound cfl h_min / c of each tet. */
#ifndef PIOLA_FORCE_STABLE_STEP_H
#define PIOLA_FORCE_STABLE_STEP_H

#include <stdint.h>

#include "common/isa.h"
#include "piola/elastic_body.h"

/* stable_step.c is a kernel built once per instruction set (common/isa.h): the plain names
 * below run the chosen variant (kernel_dispatch.c). */
PIOLA_ISA_DECLARE(double, piola__elastic_body_state_rate2,
                  (piola_elastic_body * body, int32_t *worst_tet));
PIOLA_ISA_DECLARE(double, piola__elastic_body_tet_modulus,
                  (const piola_elastic_body *body, int32_t tet, const double fhat[3]));
PIOLA_ISA_DECLARE(double, piola__elastic_body_tet_state_rate2,
                  (const piola_elastic_body *body, int32_t tet));
PIOLA_ISA_DECLARE(double, piola__elastic_body_tet_rest_altitude,
                  (const piola_elastic_body *body, int32_t tet));
PIOLA_ISA_DECLARE(const double *, piola__elastic_body_step_weights, (piola_elastic_body * body));

/* max over tets of k_e / (rho h_e^2) at the body's last update (1/s^2, stiffness scale 1),
 * the plastic stiffening left out (the caller multiplies by its square). *worst_tet (may be
 * NULL) receives the tet that attains it. */
double piola__elastic_body_state_rate2(piola_elastic_body *body, int32_t *worst_tet);

/* The modulus k_e (Pa) of one tet at Fhat fhat (the per-tet term of the bound), scale 1. */
double piola__elastic_body_tet_modulus(const piola_elastic_body *body, int32_t tet,
                                       const double fhat[3]);

/* The term of tet `tet` in piola__elastic_body_state_rate2 (1/s^2, scale 1): its weight
 * 1 / (rho h_e^2) times its modulus at its stored Fhat, with the direction weights of its
 * model (stable_step_anisotropy.h). Valid after a state_rate2 call has built the weights. */
double piola__elastic_body_tet_state_rate2(const piola_elastic_body *body, int32_t tet);

/* The bound's per-tet weights 1 / (rho h_e^2) (m/kg) and the Gram arrays of its direction
 * weights, built on the first call from the Dm^-1 the body has then; NULL when out of memory.
 * The force loop of a body with the step cache calls it so that it can weigh its k. */
const double *piola__elastic_body_step_weights(piola_elastic_body *body);

/* Rest altitude of tet t, 1 / max_c |grad N_c| (m), from its rest Dm^-1. */
double piola__elastic_body_tet_rest_altitude(const piola_elastic_body *body, int32_t tet);

#endif
