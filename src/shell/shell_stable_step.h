/* The state-aware explicit step bound of a shell (shell_stable_step.c; the derivation is in
 * docs/time-stepping.md, "Step size", "Shells").
 *
 * Why: a shell's rest bound takes the membrane's wave speed at rest and the hinges' bending
 * stiffness at their rest shape, but a stretched St. Venant-Kirchhoff or spline membrane is
 * far stiffer than at rest, and a compressed triangle turns its hinges' gradients up: a
 * stretched sheet stepped at its rest bound blew up (issue 21). Both terms follow the last
 * update's state here, and the step takes the smaller of the rest and the state bound, as
 * for solids (world_shells.c). */
#ifndef PIOLA_SHELL_STABLE_STEP_H
#define PIOLA_SHELL_STABLE_STEP_H

#include <stdint.h>

#include "piola/shell_body.h"

/* max over triangles of k_t / (rho h_t^2) at the last update (1/s^2, stiffness scale 1):
 * k_t (Pa) bounds dF : dP/dF : dF over every unit rank-one dF of the 3x2 F (in-plane and
 * out-of-plane waves), h_t is the triangle's effective rest altitude (1 / its largest
 * shape-function gradient, plastic rest shape included). At rest k_t = lambda* + 2 mu and
 * the bound is the rest bound. *worst (may be NULL) receives the triangle that sets it. */
double piola__shell_body_membrane_rate2(const piola_shell_body *body, int32_t *worst);

/* Triangle t's effective rest altitude h_t (m), as the bound above takes it. */
double piola__shell_body_triangle_altitude(const piola_shell_body *body, int32_t t);

/* The bending term: a Gershgorin estimate of the hinges' omega^2 (1/s^2,
 * stiffness scale 1) with the hinge-angle gradients of the last update (at the rest build:
 * the rest bound, rest_state.c); 0 without bending
 * stiffness or hinges. */
double piola__shell_body_bending_rate2(const piola_shell_body *body);

#endif
