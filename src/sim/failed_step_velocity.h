/* The velocity a backward Euler step leaves when its Newton did not converge on the last
 * try (docs/time-stepping.md, "What a failed step keeps"). Masses in kg, positions in m,
 * velocities in m/s, over all n nodes. */
#ifndef PIOLA_SIM_FAILED_STEP_VELOCITY_H
#define PIOLA_SIM_FAILED_STEP_VELOCITY_H

#include <stdint.h>

/* v <- the rigid motion at the kept positions x that carries the momentum the step began
 * with at (x_old, v_old): linear momentum plus dt times gravity's (g in m/s^2, dt in s),
 * angular momentum about the centre of mass. The deformation's velocity is dropped. A body
 * collapsed onto a line keeps no spin about it, one collapsed to a point none at all; one
 * flattened towards a line spins up as 1 / thickness^2 (the caller's energy check,
 * keep_failed_step in implicit_step.c, turns that down). */
void piola__failed_step_velocity(int32_t n, const double *mass, const double *x_old,
                                 const double *v_old, const double *x, const double g[3], double dt,
                                 double *v);

/* v += the rotation about the centre of mass of x that gives v the angular momentum
 * (x_old, v_old) had about theirs: a kept unconverged iterate's velocity (x - x_old) / dt
 * has the right linear momentum (every Newton direction is corrected to it) but not this.
 * About an axis along which the body is collapsed nothing changes. */
void piola__failed_step_keep_angular_momentum(int32_t n, const double *mass, const double *x_old,
                                              const double *v_old, const double *x, double *v);

#endif
