/* The per-tet plastic state (plastic_state.c): Fp^-1, accumulated strain, cheap bounds for
 * the common no-yield case, and the control's logarithms.
 *
 * Why it looks like this. The update runs every step over every tet, and most tets do not
 * yield in most steps, so the common path must cost a few comparisons: each tet keeps the
 * stretch interval [quick_lo, quick_hi] inside which no entry of Fhat can yield (|log f| <=
 * gamma / sqrt 3 on every entry implies ||log Fhat|| <= gamma, and the deviatoric norm is no
 * larger). Only tets outside take logarithms. For the limit, a tet that yielded gets cheap
 * bounds on the eigenvalues of B = Fp^-1 Fp^-T: lambda_max <= tr/3 + sqrt(2/3) |dev B| and
 * lambda_min >= max(tr/3 - sqrt(2/3) |dev B|, det B / lambda_max^2); an exact SVD and clamp
 * run only when those bounds leave the limit. The bound on the largest singular value of
 * Fp^-1 is kept per tet: it scales the CFL step. Fp^-1 is stored AoS (9 per tet): the update
 * reads and writes whole matrices of a few tets. */
#ifndef PIOLA_PLASTICITY_PLASTIC_STATE_H
#define PIOLA_PLASTICITY_PLASTIC_STATE_H

#include <stdint.h>

#include "piola/plasticity.h"
#include "plasticity/return_mapping.h"

struct piola_plastic_state {
  piola_elastic_body *body;
  int32_t tet_count;
  plastic_params params;
  double limit_cap;       /* e^limit */
  double *rest_dm_inv;    /* 9 per tet: the body's Dm^-1 at creation */
  double *fp_inv;         /* 9 per tet */
  double *alpha;          /* accumulated plastic strain */
  double *quick_lo, *quick_hi;
  double *stretch_bound;  /* upper bound on sigma_max(Fp^-1) */
  /* control */
  int controlled;
  double strength;        /* 1/s */
  double *goal_log;       /* 6 per tet */
  double *log_fp;         /* 6 per tet: log of the rotation-free Fp */
};

#endif
