/* The per-tet plastic state (plastic_state.c) and its blocked update (plastic_lanes.c):
 * Fp^-1, accumulated strain, the rest Dm^-1, bounds for the CFL step, and the control's
 * logarithms.
 *
 * Why it looks like this. The update runs every step over every tet. Most tets do not yield
 * in most steps, so that path must cost a few comparisons: with gamma = yield + hardening
 * alpha, every entry of Fhat inside [exp(-gamma/sqrt3), exp(gamma/sqrt3)] implies
 * ||log Fhat|| <= gamma (and the deviatoric norm is no larger), so no logarithm is needed.
 * But while material is worked every tet may yield in the same step, and then the update
 * must stay well below the cost of a force evaluation. So it runs on the force loop's
 * blocks of 8 tets (PIOLA_TET_BLOCK lanes, see force/elastic_body_internal.h), on explicit
 * 8-lane vectors: the radial return with the branch-free log/exp of math/v8_logexp.h, the
 * increment M = V exp(-delta) V^T (from two columns of V), Fp^-1 M, cheap bounds on the singular
 * values of the result and the new effective Dm^-1 = Dm^-1,rest Fp^-1 M = (old effective
 * Dm^-1) M, written into the body's SoA lanes with masked stores, so tets that do not yield
 * keep their bits. On big meshes the update is bound by memory traffic (about 390 bytes per
 * yielding tet), so it reads only what the force loop left (Fhat and V of Fe,trial), Fp^-1,
 * and the body's effective Dm^-1 that it rewrites anyway; the rest Dm^-1 (kept in the same
 * blocked SoA layout: block b's entry k of lane l at rest_lanes[72 b + 8 k + l]) is read only
 * to recompute one yielding block in PIOLA_PLASTIC_REFRESH per update, which keeps the
 * rounding of the carried product from piling up. A block none of whose tets leaves the
 * quick interval costs one comparison per entry. Blocks go in chunks, in two passes (return
 * map of all, then the flow of those that yield): shorter loop bodies let the processor
 * overlap blocks, whose work is a long chain of dependent operations.
 *
 * A tet whose cheap bounds leave the limit (bounds on the eigenvalues of B = Fp^-1 Fp^-T:
 * lambda_max <= tr/3 + sqrt(2/3) |dev B|, lambda_min >= max(tr/3 - sqrt(2/3) |dev B|,
 * det B / lambda_max^2)) gets the exact SVD and clamp on the block's lanes too (one-sided
 * Jacobi, verified per lane). Exceptions stay scalar: a lane whose Jacobi did not converge,
 * the limit of volume-preserving solids (a bisection), and controlled solids throughout
 * (their control step works on matrix logarithms per tet). The scalar path is also the
 * reference the tests compare the blocked one with.
 *
 * Determinism. Blocks are independent and the reductions are integer counts and a maximum,
 * so results are bit-for-bit the same for any thread count.
 *
 * Fp^-1 is stored AoS (9 per tet) because the public getter returns it so; the block
 * transposes its 8 tets' matrices in and out. The bound on the largest singular value of
 * Fp^-1 is kept per tet and its maximum per block: it scales the CFL step. */
#ifndef PIOLA_PLASTICITY_PLASTIC_STATE_H
#define PIOLA_PLASTICITY_PLASTIC_STATE_H

#include <stdint.h>

#include "common/isa.h"
#include "piola/plasticity.h"
#include "plasticity/return_mapping.h"

struct piola_plastic_state {
  piola_elastic_body *body;
  int32_t tet_count;
  plastic_params params;
  int32_t padded_count;   /* tet_count rounded up to a multiple of PIOLA_PLASTIC_LANES */
  double limit_cap;       /* e^limit */
  double quick_lo0, quick_hi0; /* the quick interval at alpha = 0 */
  double *rest_lanes;     /* the body's Dm^-1 at creation, blocked SoA (see above) */
  double *fp_inv;         /* 9 per tet, AoS */
  double *alpha;          /* accumulated plastic strain, padded_count entries */
  double *stretch_bound;  /* upper bound on sigma_max(Fp^-1), padded_count entries */
  double *block_bound;    /* max of stretch_bound over each block */
  int32_t refresh_phase;  /* blocks b with b % PIOLA_PLASTIC_REFRESH == this take their
                             effective Dm^-1 from the rest data in this update */
  /* control */
  int controlled;
  double strength;        /* 1/s */
  double *goal_log;       /* 6 per tet */
  double *log_fp;         /* 6 per tet: log of the rotation-free Fp */
};

#define PIOLA_PLASTIC_LANES 8
/* The blocked update carries a yielding tet's effective Dm^-1 forward (old one times the
 * increment, so the rest data stays unread); every this many updates (a power of 2) each
 * block is recomputed from the rest data instead, which bounds the rounding drift. */
#define PIOLA_PLASTIC_REFRESH 256

/* Entry k (row-major) of tet t's rest Dm^-1. */
static inline double piola__plastic_rest_entry(const piola_plastic_state *s, int32_t t, int k) {
  return s->rest_lanes[(size_t)(t / PIOLA_PLASTIC_LANES) * 9 * PIOLA_PLASTIC_LANES +
                       (size_t)k * PIOLA_PLASTIC_LANES + (size_t)(t % PIOLA_PLASTIC_LANES)];
}

/* Writes tet t's effective Dm^-1 = Dm^-1,rest Fp^-1 into the body. */
void piola__plastic_commit_tet(piola_plastic_state *s, int32_t t);

/* Exact limit of Fp^-1 = a (row-major): SVD, clamp of the log-stretches, rotation dropped.
 * Returns the largest singular value of the result. */
double piola__plastic_exact_limit(double a[9], const plastic_params *p);

/* The blocked update of blocks [first, end) (not for controlled states): returns the number
 * of tets that yielded, adds the limited ones to *limited, refreshes their block_bound and
 * writes the largest of them (at least 1) to *bound. plastic_lanes.c, a kernel built once
 * per instruction set (common/isa.h); the plain name runs the chosen variant. */
#define PIOLA_PLASTIC_UPDATE_BLOCKS_PARAMS \
  (piola_plastic_state * s, int32_t first, int32_t end, int32_t *limited, double *bound)
PIOLA_ISA_DECLARE(int32_t, piola__plastic_update_blocks, PIOLA_PLASTIC_UPDATE_BLOCKS_PARAMS);
int32_t piola__plastic_update_blocks PIOLA_PLASTIC_UPDATE_BLOCKS_PARAMS;

/* The scalar per-tet update of every tet (the path of controlled states, and the tests'
 * reference for the blocked one); same contract as piola_plastic_state_update. */
void piola__plastic_state_update_scalar(piola_plastic_state *s, double dt, piola_plastic_stats *stats);

#endif
