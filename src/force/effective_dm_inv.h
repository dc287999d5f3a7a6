/* A small hook that lets plasticity replace a tet's Dm^-1 by an effective one.
 *
 * Why: with F = Fe Fp and F = Ds Dm^-1, the elastic part is Fe = Ds (Dm^-1 Fp^-1), and the
 * forces of the energy V0 psi(Fe) are G = -V0 P(Fe) (Dm^-1 Fp^-1)^T. So the force loop,
 * damping and the reference loop all stay as they are when they read Dm^-1 Fp^-1 in place
 * of Dm^-1: plasticity costs nothing per force evaluation. The plastic state keeps its own
 * copy of the rest Dm^-1; these functions only read and write the body's SoA entries and
 * the per-tet diagonalization of the last update, so the force code's layout stays private
 * to src/force. */
#ifndef PIOLA_FORCE_EFFECTIVE_DM_INV_H
#define PIOLA_FORCE_EFFECTIVE_DM_INV_H

#include <stdint.h>

#include "piola/elastic_body.h"

/* Tet t's current (effective) Dm^-1, row-major 9 entries (1/m). */
void piola__elastic_body_get_dm_inv(const piola_elastic_body *body, int32_t t, double out[9]);
/* Replaces tet t's Dm^-1 by m (row-major, 1/m). Forces change from the next update. */
void piola__elastic_body_set_dm_inv(piola_elastic_body *body, int32_t t, const double m[9]);
/* Rest volumes V0 (m^3), tet_count entries (padded storage). */
const double *piola__elastic_body_rest_volumes(const piola_elastic_body *body);
/* U and V of tet t from the last update, row-major 9 entries each (either may be NULL). */
void piola__elastic_body_get_rotations(const piola_elastic_body *body, int32_t t, double u[9],
                                       double v[9]);

/* The SoA lanes the blocked plastic update works on: entry k (row-major) of tet t's
 * effective Dm^-1 is dm_inv[k][t], of its V from the last update v[k][t], for t below
 * *padded_tet_count (a multiple of 8; padding tets have Dm^-1 = 0). */
void piola__elastic_body_plastic_lanes(piola_elastic_body *body, double *dm_inv[9], const double *v[9],
                                       int32_t *padded_tet_count);

#endif
