/* Fibres in the force loop: the muscle's (the anisotropic part of paper section 6.1) and the
 * Holzapfel-Gasser-Ogden model's two families (hgo_kernels.h, formed per tet from the fibre
 * direction and the material's axis, applied as -V0 P_f Dm^-T), added to a block's nodal
 * forces after its isotropic part.
 *
 * The hook is one call in finish_blocks (force_lanes.c), made only for bodies with fibres,
 * so bodies without them pay nothing and the isotropic loop stays as it is. The fibre a of
 * each tet is rotated into the diagonal frame, ahat = V^T a, and its stress there is
 * Phat_f = Fhat (T / lambda) ahat ahat^T (muscle_kernels.h). Back in world space that is the
 * rank-one P_f = U Phat_f V^T = (T / lambda) (U Fhat ahat) a^T, so its forces are
 * G_f = -V0 P_f Dm^-T = -V0 (T / lambda) (U Fhat ahat) (Dm^-1 a)^T: two 3-vectors per tet,
 * cheaper than forming the 3x3 matrix. */
#ifndef PIOLA_FORCE_FIBER_LANES_H
#define PIOLA_FORCE_FIBER_LANES_H

#include "common/isa.h"
#include "force/elastic_body_internal.h"

/* The three are kernels, built once per instruction set (common/isa.h); the force lanes call
 * their own variant of the first, the rest of the library the plain-named wrappers of the
 * others (kernel_dispatch.c). */

/* Adds the fibre forces of block base / PIOLA_TET_BLOCK, times stiffness_scale, into tf (the
 * block's 12 rows of PIOLA_TET_BLOCK lanes, row 3 c + i = component i of corner c), from the
 * block's Fhat and the U, V the SVD stored in the body. When psi is not NULL the fibre
 * energy density (unscaled) is added to psi's lanes. */
PIOLA_ISA_DECLARE(void, piola__fiber_forces_lanes,
                  (const piola_elastic_body *body, int32_t base, double fhat[3][PIOLA_TET_BLOCK],
                   double stiffness_scale, double *tf, double *psi));

/* Fibre energy density (J/m^3, unscaled) of tet t from the state of the last update. */
PIOLA_ISA_DECLARE(double, piola__fiber_energy_density, (const piola_elastic_body *body, int32_t t));
double piola__fiber_energy_density(const piola_elastic_body *body, int32_t t);

/* Copies and normalises def->fiber_directions into the body (rest_state.c calls it). */
PIOLA_ISA_DECLARE(piola_status, piola__fiber_copy,
                  (piola_elastic_body *body, const piola_elastic_body_def *def));
piola_status piola__fiber_copy(piola_elastic_body *body, const piola_elastic_body_def *def);

#endif
