/* A block incomplete Cholesky factorization IC(0) of the implicit step's system matrix, as
 * the conjugate gradient's preconditioner (docs/time-stepping.md, "Implicit integrators").
 *
 * Why. Block Jacobi sees one vertex at a time; on meshes with sliver elements or at nu near
 * 1/2 the matrix couples neighbours far more strongly than a vertex's own block says, and
 * the CG needs hundreds of iterations per Newton system. IC(0) keeps the couplings along the
 * mesh edges: A ~ U^T D U with U unit upper triangular on exactly the matrix's edge pattern
 * (no fill) in its row order (reverse Cuthill-McKee, damping_matrix.h), D block diagonal.
 *
 * The factored matrix is the filtered one, S A S + (I - S), S the per-vertex projection of
 * the constraints (all of a fixed vertex, the normal of a held one): it is symmetric positive
 * definite, maps the free subspace to itself, and so does its inverse, so the preconditioner
 * fits the filtered CG without further projections.
 *
 * Breakdown. An incomplete factorization of an SPD matrix that is not an M-matrix (elasticity
 * at nu near 1/2, sliver elements) can meet a pivot block D_i that is not positive definite.
 * Then the factorization starts over with every diagonal block scaled by 1 + shift
 * (Manteuffel 1980), the shift growing by 4x from PIOLA_IC_FIRST_SHIFT; at
 * PIOLA_IC_LAST_SHIFT a pivot that still fails takes its own (shifted) diagonal block instead.
 * Every D_i is then SPD and U is unit triangular, so U^T D U is symmetric positive definite
 * whatever the matrix: what the CG needs of a preconditioner.
 *
 * Cost. The factorization is one pass over the rows with one 3x3 product per pair of a row's
 * later neighbours (pair-to-edge lookups are built once per pattern); each application is a
 * forward and a backward substitution, each about the cost of one matrix product, and
 * sequential (one thread): results do not depend on the thread count. */
#ifndef PIOLA_FORCE_STIFFNESS_INCOMPLETE_CHOLESKY_H
#define PIOLA_FORCE_STIFFNESS_INCOMPLETE_CHOLESKY_H

#include <stdint.h>

#include "force/stiffness_matrix.h"
#include "force/vertex_projection.h"

#define PIOLA_IC_FIRST_SHIFT 1e-3
#define PIOLA_IC_LAST_SHIFT 1.0

typedef struct piola__incomplete_cholesky {
  int32_t vertex_count;
  int32_t edge_count;
  int32_t *pair_start; /* vertex_count + 1, by row: that row's pairs of later neighbours */
  int32_t *pair_edge;  /* per pair (a, b), a ranked before b: the edge (a, b), or -1 */
  double *upper;        /* 9 per edge: U_ij, i ranked first (row-major) */
  double *inverse_pivot; /* 9 per vertex: D_i^-1 */
  double *scratch;       /* 9 per edge of the longest row: D_i U_ij while row i is factored */
  double shift;           /* the diagonal shift of the last factorization (dimensionless) */
  int32_t restarts;       /* breakdowns of the last factorization */
  int32_t fallback_rows;  /* rows of the last factorization that fell back to their block */
} piola__incomplete_cholesky;

/* Sizes the factor for body's edge pattern and builds the pair lookups. */
piola_status piola__incomplete_cholesky_init(piola__incomplete_cholesky *factor,
                                             const piola_elastic_body *body);
void piola__incomplete_cholesky_free(piola__incomplete_cholesky *factor);

/* Factors S A S + (I - S) for matrix (as last assembled, its diagonal blocks included) with
 * S from constraint(context, i, normal) (NULL: nothing held). */
void piola__incomplete_cholesky_factor(piola__incomplete_cholesky *factor,
                                       const piola__stiffness_matrix *matrix,
                                       const piola_elastic_body *body,
                                       piola__vertex_constraint *constraint,
                                       const void *context);

/* z = (U^T D U)^-1 r (3 * vertex_count each; z may not alias r). */
void piola__incomplete_cholesky_apply(const piola__incomplete_cholesky *factor,
                                      const piola_elastic_body *body, const double *r,
                                      double *z);

#endif
