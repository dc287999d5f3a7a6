/* piola: a tetrahedral elastic body: rest state, elastic forces and damping forces.
 *
 * The body owns its rest state (Dm^-1, Bm = -V0 Dm^-T, rest volumes V0, lumped masses) and,
 * after each piola_elastic_body_update, the per-tet diagonalization F = U Fhat V^T at the
 * positions it was given. Damping forces reuse those rotations (paper section 6.2), so the
 * step loop diagonalizes once per step.
 *
 * Forces are computed in parallel with OpenMP and are bit-for-bit identical whatever the
 * number of threads: every tet writes its own nodal forces, and every vertex then sums its
 * incident tets in a fixed order.
 *
 *   piola_elastic_body_def def = piola_default_elastic_body_def();
 *   def.rest_mesh = &mesh; def.materials = &material; def.material_count = 1;
 *   def.density = 1000;  // kg/m^3
 *   piola_elastic_body *body;
 *   if (piola_elastic_body_create(&def, &body) != PIOLA_OK) puts(piola_last_error());
 *   piola_elastic_body_update(body, x, 1.0, forces, &stats); */
#ifndef PIOLA_ELASTIC_BODY_H
#define PIOLA_ELASTIC_BODY_H

#include <stdint.h>

#include "piola/export.h"
#include "piola/material.h"
#include "piola/mesh.h"
#include "piola/status.h"
#include "piola/threads.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct piola_elastic_body piola_elastic_body;

typedef struct piola_elastic_body_def {
  const piola_tet_mesh *rest_mesh;  /* rest positions (m) and tets; copied. Tets with negative
                                       rest volume are reoriented; a degenerate one is an
                                       error naming its index. */
  const piola_material *materials;  /* material_count validated materials */
  int32_t material_count;
  const int32_t *tet_materials;     /* tet_count indices into materials, or NULL: all use 0 */
  double density;                   /* kg/m^3, > 0. Default 1000 */
  const double *fiber_directions;   /* 3 per tet: the fibre direction of each tet in rest
                                       (material) space, normalised on copy; a zero or
                                       non-finite one is an error naming the tet. NULL
                                       (default): no fibres. Used by tets whose material is
                                       PIOLA_MODEL_MUSCLE (paper section 6.1) */
  const double *material_fractions; /* per tet, in (0, 1]: the share of the tet's volume that
                                       holds material (a tet copy of the virtual node
                                       algorithm, docs/fracture.md). Its mass and its elastic
                                       and damping forces are scaled by it; the geometry (and
                                       so the step bound) is the full tet's. NULL (default):
                                       every tet is whole */
} piola_elastic_body_def;

PIOLA_API piola_elastic_body_def piola_default_elastic_body_def(void);

PIOLA_API piola_status piola_elastic_body_create(const piola_elastic_body_def *def,
                                                 piola_elastic_body **out);
PIOLA_API void piola_elastic_body_destroy(piola_elastic_body *body);

PIOLA_API int32_t piola_elastic_body_vertex_count(const piola_elastic_body *body);
PIOLA_API int32_t piola_elastic_body_tet_count(const piola_elastic_body *body);
/* 4 * tet_count vertex indices, after reorientation. */
PIOLA_API const int32_t *piola_elastic_body_tets(const piola_elastic_body *body);
/* 3 * vertex_count rest positions, m. */
PIOLA_API const double *piola_elastic_body_rest_positions(const piola_elastic_body *body);
/* vertex_count lumped masses, kg (a quarter of each incident tet's rest mass). */
PIOLA_API const double *piola_elastic_body_masses(const piola_elastic_body *body);
/* Smallest rest altitude over all tets, m: the length in the CFL condition. */
PIOLA_API double piola_elastic_body_min_rest_altitude(const piola_elastic_body *body);
/* Largest dilatational wave speed sqrt((lambda + 2 mu + fibre modulus) / density) over the
 * materials, m/s (the fibre modulus is piola_material.fiber_modulus, 0 without fibres). */
PIOLA_API double piola_elastic_body_max_wave_speed(const piola_elastic_body *body);

/* Activation of the muscle fibres (dimensionless, clamped to [0, 1]; NaN gives 0), used by
 * the next updates. Default 0: fibres are passive. */
PIOLA_API void piola_elastic_body_set_activation(piola_elastic_body *body, double activation);
PIOLA_API double piola_elastic_body_activation(const piola_elastic_body *body);
/* Fibre directions in rest space, 3 per tet (unit), or NULL when the body has none. */
PIOLA_API const double *piola_elastic_body_fiber_directions(const piola_elastic_body *body);

typedef struct piola_elastic_stats {
  double elastic_energy;   /* J */
  int32_t inverted_count;  /* tets with det F < 0 */
  double min_det_f;        /* smallest det F over the tets */
} piola_elastic_stats;

/* Computes F, its diagonalization and the elastic forces at positions x (3 * vertex_count,
 * m). forces (3 * vertex_count, N) is overwritten. stiffness_scale (dimensionless, >= 0)
 * multiplies every stress; 0 turns elasticity off. stats may be NULL. Non-finite positions
 * return PIOLA_ERROR_NOT_FINITE and leave forces unchanged. */
PIOLA_API piola_status piola_elastic_body_update(piola_elastic_body *body, const double *x,
                                                 double stiffness_scale, double *forces,
                                                 piola_elastic_stats *stats);

/* Damping forces at nodal velocities v (3 * vertex_count, m/s), using the rotations U, V of
 * the last update (section 6.2): Phat = beta (Fdot_hat + Fdot_hat^T) + alpha tr(Fdot_hat) I
 * in the rotated frame, with shear viscosity beta and bulk viscosity alpha in Pa s. It is
 * linear in v and never vanishes on flat or inverted tets. forces (N) is overwritten. */
PIOLA_API void piola_elastic_body_damping_forces(const piola_elastic_body *body, const double *v,
                                                 double shear_viscosity, double bulk_viscosity,
                                                 double *forces);

/* Per-tet values from the last update (tet_count each): det F, energy density (J/m^3),
 * and the diagonal Fhat (3 per tet). */
PIOLA_API const double *piola_elastic_body_det_f(const piola_elastic_body *body);
PIOLA_API const double *piola_elastic_body_energy_density(const piola_elastic_body *body);
PIOLA_API const double *piola_elastic_body_fhat(const piola_elastic_body *body);

/* piola_set_thread_count (the number of threads piola uses) is in piola/threads.h, included
 * above. */

#ifdef __cplusplus
}
#endif

#endif
