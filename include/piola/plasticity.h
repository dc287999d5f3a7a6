/* piola: multiplicative plasticity and plasticity control (paper sections 6.3 and 7).
 *
 * F = Fe Fp. A plastic state stores Fp^-1 per tet and carries it into the elastic body by
 * replacing the tet's Dm^-1 with Dm^-1 Fp^-1: the force loop then computes Fe = Ds Dm^-1 Fp^-1,
 * its diagonalization, the stress and the forces G = -V0 P(Fe) (Dm^-1 Fp^-1)^T, which are
 * exactly minus the gradient of the elastic energy V0 psi(Fe) (V0 the rest volume: the energy
 * is per unit rest volume). Nothing is added to a force evaluation.
 *
 * piola_plastic_state_update runs the return mapping once per step, from the diagonalization
 * Fe,trial = U Fhat V^T that the body holds from its last update:
 *  1. yield: ||log Fhat|| <= gamma (or ||dev log Fhat|| <= gamma when volume preserving),
 *     gamma = yield + hardening * (accumulated plastic log strain). Entries below 0.01 (flat
 *     or inverted elements) are read as 0.01, so the projection always has positive entries
 *     and plastic flow never absorbs an inversion: Fp never inverts.
 *  2. radial return onto the yield surface; the plastic increment acts in the V frame:
 *     Fp,trial = V exp(delta) V^T Fp with delta = log Fhat - log Fhat,proj.
 *  3. limit: every log-stretch (log singular value) of Fp is kept in [-limit, limit], so
 *     Fp stays well conditioned and the stable step size stays bounded.
 *  4. control (section 7): the final Fp is the point of the segment from the old Fp to the
 *     trial Fp, taken between logarithms of Fp with rotation removed, that is closest to the
 *     goal; with strength > 0 it is then also drawn toward the goal at that rate.
 * Rotations of Fp are dropped where convenient: piola's materials are isotropic, so they do
 * not change energies or forces. See docs/plasticity.md.
 *
 *   piola_plasticity_def def = piola_default_plasticity_def();
 *   def.yield = 0.05; def.limit = 1.0;
 *   piola_plastic_state *plastic;
 *   piola_plastic_state_create(body, &def, &plastic);
 *   // each step, after piola_elastic_body_update(body, x, ...):
 *   piola_plastic_state_update(plastic, dt, &stats);
 */
#ifndef PIOLA_PLASTICITY_H
#define PIOLA_PLASTICITY_H

#include <stdbool.h>
#include <stdint.h>

#include "piola/elastic_body.h"
#include "piola/export.h"
#include "piola/math_types.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum piola_plastic_goal_type {
  PIOLA_PLASTIC_GOAL_NONE = 0, /* no control (default) */
  PIOLA_PLASTIC_GOAL_MAP,      /* goal Fp = goal_map for every tet */
  PIOLA_PLASTIC_GOAL_MESH,     /* goal Fp = Dg Dm^-1 per tet from goal positions */
} piola_plastic_goal_type;

typedef struct piola_plasticity_control_def {
  piola_plastic_goal_type goal;
  piola_mat3 goal_map;          /* dimensionless, det > 0: the goal shape is this map applied
                                   to the rest shape. Default I */
  const double *goal_positions; /* m, 3 * vertex_count: the goal shape as the rest mesh's
                                   vertices moved (same tets). Read at creation only */
  int32_t goal_vertex_count;    /* must equal the body's vertex count */
  double strength;              /* 1/s, >= 0: rate at which Fp is also drawn toward the goal
                                   when the material does not yield. 0 (default) is the
                                   paper's control: only yield-driven flow, steered */
} piola_plasticity_control_def;

typedef struct piola_plasticity_def {
  double yield;           /* gamma, dimensionless log strain, > 0. Default 0.05 */
  double limit;           /* dimensionless, > 0: bound on |log stretch| of Fp. Default 1 */
  double hardening;       /* dimensionless, >= 0: gamma grows by this times the accumulated
                             plastic log strain. Default 0 */
  bool volume_preserving; /* yield on the deviatoric log strain; det Fp stays 1. Not with
                             control. Default false */
  piola_plasticity_control_def control;
} piola_plasticity_def;

PIOLA_API piola_plasticity_def piola_default_plasticity_def(void);

typedef struct piola_plastic_state piola_plastic_state;

/* Creates a plastic state for every tet of body (Fp = I) and binds it to body: body must
 * outlive the state. The state replaces the body's per-tet Dm^-1 by Dm^-1 Fp^-1; destroying
 * the state restores the rest Dm^-1. Errors name the offending parameter or tet. */
PIOLA_API piola_status piola_plastic_state_create(piola_elastic_body *body,
                                                  const piola_plasticity_def *def,
                                                  piola_plastic_state **out);
PIOLA_API void piola_plastic_state_destroy(piola_plastic_state *state);

/* Creates a plastic state for body whose tets inherit the state of tets of another body's
 * state `parent` (same parameters and control): tet t takes Fp, the accumulated plastic
 * strain and the control goal of parent's tet tet_parent[t] (one per tet of body), or starts
 * fresh (Fp = I, no strain) where tet_parent[t] is -1, which a controlled parent does not
 * allow. For a body whose mesh changed (refined, split): body's rest Dm^-1 times the
 * inherited Fp^-1 becomes its effective Dm^-1. body must outlive the state; parent is only
 * read. */
PIOLA_API piola_status piola_plastic_state_create_from(piola_elastic_body *body,
                                                       const piola_plastic_state *parent,
                                                       const int32_t *tet_parent,
                                                       piola_plastic_state **out);

typedef struct piola_plastic_stats {
  int32_t yielded_count;  /* tets whose yield criterion was exceeded in this update */
  int32_t limited_count;  /* tets whose Fp was projected onto the limit */
  double max_fp_stretch;  /* an upper bound (>= 1) on the largest singular value of Fp^-1
                             over all tets: Dm^-1 Fp^-1 is at most this much stiffer than
                             Dm^-1, so the stable step shrinks by this factor */
} piola_plastic_stats;

/* One plastic update from the diagonalization of the body's last update. dt (s, >= 0) is
 * used only by the control strength. Changes no positions or velocities; the new Fp acts
 * from the body's next update. stats may be NULL. */
PIOLA_API piola_status piola_plastic_state_update(piola_plastic_state *state, double dt,
                                                  piola_plastic_stats *stats);

PIOLA_API int32_t piola_plastic_state_tet_count(const piola_plastic_state *state);
/* Fp^-1 of every tet: 9 per tet, row-major (dimensionless). */
PIOLA_API const double *piola_plastic_state_fp_inverse(const piola_plastic_state *state);
/* Accumulated plastic log strain per tet (dimensionless). */
PIOLA_API const double *piola_plastic_state_plastic_strain(const piola_plastic_state *state);
/* Exact extremes over all tets (one SVD per tet): the largest |log singular value| of Fp
 * and the smallest det Fp. */
PIOLA_API void piola_plastic_state_measure(const piola_plastic_state *state,
                                           double *max_log_stretch, double *min_det_fp);
/* Distance of the shape at positions x (m, 3 * vertex_count) to the control goal: the
 * rest-volume-weighted RMS over tets of ||log sqrt(F^T F) - log Fp,goal|| (Frobenius,
 * dimensionless; rotation free). Without control the goal is the rest shape (Fp,goal = I). */
PIOLA_API double piola_plastic_state_goal_distance(const piola_plastic_state *state,
                                                   const double *x);

#ifdef __cplusplus
}
#endif

#endif
