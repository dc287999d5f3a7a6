/* Smoothed aggregation algebraic multigrid for the implicit step's system matrix, as the
 * conjugate gradient's preconditioner (docs/time-stepping.md, "Implicit integrators").
 *
 * Why. Block Jacobi and IC(0) act on a vertex and its neighbours only, so the error they
 * leave is smooth, and at nu near 1/2 or with stiff materials the CG needs thousands of
 * iterations per frame to carry it across a large mesh (1,700 on the paper's Figure 2 torus
 * at E = 1 MPa, nu = 0.45). Multigrid removes the smooth error on coarser levels, where it
 * is not smooth any more. For elasticity the coarse spaces must carry the rigid-body modes
 * (the near null space of the elastic operator, which mass and damping hardly lift): the
 * smoothed aggregation of Vanek, Mandel and Brezina (1996).
 *
 * The hierarchy (built by piola__multigrid_setup):
 * - level 0 is the filtered matrix S A S + (I - S) (vertex_projection.h) in the edge
 *   pattern's reverse Cuthill-McKee order, stored with both triangles (math/block_sparse.h);
 * - each level's nodes are aggregated on the strong couplings of its blocks, and the
 *   tentative prolongator T carries the 6 rigid-body modes of each aggregate
 *   (multigrid_aggregation.h; modes projected by the constraints on level 0);
 * - the prolongator is T smoothed by one damped Jacobi step, P = (I - omega D^-1 A) T,
 *   omega = 4 / (3 rho), rho the largest eigenvalue of D^-1 A estimated by power iteration
 *   (D the block diagonal); the next level is the Galerkin product P^T A P (6x6 blocks);
 * - coarsening stops at PIOLA_MULTIGRID_COARSE_DOFS unknowns or less, solved by a dense
 *   Cholesky factorization (where aggregation stalls above that, a last level of up to 4x
 *   that size is still factored, a larger one, or the tenth level, only smoothed: a
 *   degree-8 Chebyshev polynomial).
 *
 * The preconditioner is one V-cycle from a zero guess: on each level a Chebyshev smoother of
 * degree PIOLA_MULTIGRID_SMOOTHING in D^-1 A on [rho / 30, 1.1 rho] before and the same
 * after the coarse correction. The smoother is a fixed polynomial in D^-1 A, self-adjoint in
 * the A inner product, and the same before and after, so the V-cycle is a symmetric positive
 * definite operator as the CG needs; its output is projected by S like the other
 * preconditioners' (the filtered matrix maps the free subspace to itself, the V-cycle only
 * approximately).
 *
 * Reuse. The matrix changes little between the Newton iterations of a step: a refresh
 * (piola__multigrid_refresh) rebuilds level 0's values and its block diagonal, updates its
 * rho by 3 power iterations from the last one's vector (keeping the larger estimate), and
 * keeps the coarser levels as they are, which stay a valid (symmetric positive definite)
 * coarse correction; the caller sets up the whole hierarchy once per step.
 *
 * Threads. The products and the smoother's vector work run in parallel over fixed row
 * ranges, each row summed by one thread in a fixed order, and so do the setup's sparse
 * products and transposes (math/block_sparse.h) and the power iterations (their sums as
 * partial sums of fixed ranges, added in order); the aggregation, the tentative prolongator
 * and the coarse solve run on one thread: results are bit-identical for any thread count. */
#ifndef PIOLA_FORCE_STIFFNESS_MULTIGRID_H
#define PIOLA_FORCE_STIFFNESS_MULTIGRID_H

#include <stdint.h>

#include "force/stiffness_matrix.h"
#include "force/vertex_projection.h"
#include "math/block_sparse.h"

#define PIOLA_MULTIGRID_MAX_LEVELS 10
#define PIOLA_MULTIGRID_COARSE_DOFS 600 /* the dense coarse solve's largest size */
#define PIOLA_MULTIGRID_SMOOTHING 2     /* the Chebyshev smoother's degree */
#define PIOLA_MULTIGRID_STRENGTH 0.08   /* theta on level 0, halved on each coarser level */

typedef struct piola__multigrid_level {
  piola__block_sparse a;     /* the level's operator */
  piola__block_sparse p;     /* prolongator from the next level (absent on the last) */
  piola__block_sparse pt;    /* its transpose, the restriction */
  double *inverse_diagonal;  /* b x b per row: the inverse diagonal blocks */
  double rho;                /* largest eigenvalue of D^-1 A (estimate) */
  double *x, *f, *r, *d, *q; /* work vectors of the cycle, rows * b each */
  double *mode;              /* rows * b: the power iteration's last iterate (rho's vector) */
} piola__multigrid_level;

typedef struct piola__multigrid {
  int32_t vertex_count;
  int level_count;
  piola__multigrid_level level[PIOLA_MULTIGRID_MAX_LEVELS];
  int32_t coarse_size;   /* unknowns of the dense coarse solve (0: the last level is smoothed) */
  double *coarse_factor; /* coarse_size^2: its Cholesky factor L, row-major */
  /* level 0's entries from the edge pattern, built once: entry_edge[k] the edge of entry k
   * (-1 the diagonal), transposed when entry_transposed[k] */
  int32_t *entry_edge;
  uint8_t *entry_transposed;
  int32_t setups, refreshes; /* counters, for tests and benchmarks */
} piola__multigrid;

/* Builds level 0's pattern from body's edge pattern. */
piola_status piola__multigrid_init(piola__multigrid *mg, const piola_elastic_body *body);
void piola__multigrid_free(piola__multigrid *mg);

/* Builds the hierarchy for S A S + (I - S), A = matrix as last assembled (its diagonal
 * blocks included), S from constraint(context, i, normal) (NULL: nothing held); the rigid
 * modes from the body's positions at its last update. */
piola_status piola__multigrid_setup(piola__multigrid *mg, const piola__stiffness_matrix *matrix,
                                    const piola_elastic_body *body,
                                    piola__vertex_constraint *constraint, const void *context);

/* Level 0 only: its values, diagonal and rho from matrix and the constraints; the coarser
 * levels as they were (see the header). Needs a setup before. */
void piola__multigrid_refresh(piola__multigrid *mg, const piola__stiffness_matrix *matrix,
                              const piola_elastic_body *body, piola__vertex_constraint *constraint,
                              const void *context);

/* z = V-cycle(r) (3 * vertex_count each, in vertex order; z may not alias r). Not
 * projected: the caller applies S. */
void piola__multigrid_apply(piola__multigrid *mg, const piola_elastic_body *body, const double *r,
                            double *z);

#endif
