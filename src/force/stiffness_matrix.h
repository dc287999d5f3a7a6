/* The implicit integrators' system matrix on the damping matrix's edge pattern.
 *
 * Newton's method for a backward Euler step solves
 *   (m_w M - dt^2 K - dt D) dx = -g,
 * with K = df/dx the elastic force's derivative, made negative semi-definite per element
 * (element_stiffness.h: the projected dP/dF; in Newton's tail the rotation eigenvalues keep
 * their sign), D the damping matrix and m_w 1 (0 in quasistatics, where a small multiple of
 * M regularizes). K and D are both translation
 * invariant (their block rows sum to zero) and symmetric, and they live on the same pairs of
 * vertices: the mesh edges. So the matrix is stored like the damping matrix
 * (damping_matrix.h), reusing its pattern, its row order and its per-tet slots: one 3x3 block
 * S_ij = dt^2 K_ij + dt D_ij per edge, and the product is written in edge differences,
 *   (A p)_i = m_w m_i p_i - sum over edges (i, j) of S_ij (p_j - p_i),
 * so a rigid translation only sees the mass term, exactly. The diagonal blocks
 * A_ii = m_w m_i I + sum_j S_ij are kept for the block-Jacobi preconditioner.
 *
 * Assembly: each tet adds its 6 corner-pair blocks -V0 U M_ab U^T (the diagonal-frame
 * product of element_stiffness.h with the rows g_a of Dm^-1 rotated by V), plus the muscle
 * fibre term, in the damping assembly's fixed tet ranges and slots, so results do not depend
 * on the thread count. */
#ifndef PIOLA_FORCE_STIFFNESS_MATRIX_H
#define PIOLA_FORCE_STIFFNESS_MATRIX_H

#include <stdint.h>

#include "force/damping_matrix.h"
#include "force/element_stiffness.h"
#include "piola/elastic_body.h"

typedef struct piola__stiffness_matrix {
  int32_t vertex_count;
  int32_t slot_count;   /* edges, then the private slots of shared edges */
  double *blocks;       /* 9 per slot: S_ij of each edge (N/m, force per displacement) */
  double *diagonal;     /* 9 per vertex: A_ii */
  double *inverse_diagonal; /* 9 per vertex: A_ii^-1 (block Jacobi) */
} piola__stiffness_matrix;

/* Allocates for body's pattern (its damping matrix must exist: piola_elastic_body_create
 * builds it). */
piola_status piola__stiffness_matrix_init(piola__stiffness_matrix *matrix,
                                          const piola_elastic_body *body);
void piola__stiffness_matrix_free(piola__stiffness_matrix *matrix);

/* Assembles S = stiffness_weight K + damping_weight D (K from the body's last update,
 * scaled by its stiffness scale; D the body's damping matrix, which the caller has
 * prepared, read only when damping_weight != 0) and the diagonal blocks with
 * mass_weight M. Weights in s^2, s and 1 for a backward Euler step. */
void piola__stiffness_matrix_assemble(piola__stiffness_matrix *matrix,
                                      const piola_elastic_body *body, double stiffness_weight,
                                      double damping_weight, const double *mass,
                                      double mass_weight);

/* Recomputes the diagonal blocks and their inverses with mass_weight M, the edge blocks as
 * last assembled: the same bits as assembling again with this mass weight, for the cost of
 * one pass over the rows. */
void piola__stiffness_matrix_set_mass_weight(piola__stiffness_matrix *matrix,
                                             const piola_elastic_body *body, const double *mass,
                                             double mass_weight);

/* out = A p (3 * vertex_count). */
void piola__stiffness_matrix_apply(const piola__stiffness_matrix *matrix,
                                   const piola_elastic_body *body, const double *mass,
                                   double mass_weight, const double *p, double *out);

/* How the body's assembly makes dP/dF definite: PIOLA_STIFFNESS_PROJECTED, or
 * PIOLA_STIFFNESS_SIGNED_TWIST while body->signed_twist is set (element_stiffness.h). */
int piola__stiffness_projection(const piola_elastic_body *body);

/* The material's part of tet t's stiffness at the body's last update: dPhat/dFhat in the
 * diagonal frame, made definite as piola__stiffness_projection says (element_stiffness.h). */
void piola__tet_diagonal_stiffness(const piola_elastic_body *body, int32_t t,
                                   piola__diagonal_stiffness *k);

/* The 6 corner-pair blocks df_a/dx_b (a < b in the order 01 02 03 12 13 23, row-major) of
 * tet t of body at its last update, made definite as above, times the body's stiffness
 * scale. For tests and the assembly. */
void piola__tet_stiffness_blocks(const piola_elastic_body *body, int32_t t, double out[54]);

#endif
