/* The derivatives of a shell's forces, for the implicit integrators (src/sim/implicit_step.c;
 * docs/shells.md, "Implicit stiffness").
 *
 * Why it looks like this. A backward Euler or quasistatic Newton step needs df/dx and
 * df/dv of every force, symmetric and negative semi-definite (as df/dx; the system matrix
 * M - dt^2 K - dt D is then positive definite).
 *  - Membrane: P = U Phat(Fhat) V^T with a 3x2 F. In the frame of the diagonalization
 *    (the columns u0, u1 of U completed by their normal n, and V) dP/dF decouples as for
 *    solids (element_stiffness.h): the 2x2 block dPhat_i/dFhat_j on the diagonal entries, one
 *    2x2 block [[a, b], [b, a]] on the pair (dFhat_01, dFhat_10) with eigenvalues
 *    (P0 - P1)/(f0 - f1) and (P0 + P1)/(f0 + f1), and, new for a 3x2 F, one number per
 *    column on its out-of-plane entry dFhat_2j = n . dF v_j: turning u_j towards n changes P
 *    by (P_j / f_j) n v_j^T. The projection clamps each of these eigenvalues at zero (the
 *    2x2 diagonal block through its eigenvalues), limits replace the quotients where a
 *    denominator vanishes, and the quotients that blow up near a reflection or a collapse
 *    (P0 + P1)/(f0 + f1) and P_j/f_j are capped at the triangle's other stiffnesses, as for
 *    solids. Without the projection it is the exact derivative of the force wherever the
 *    force is smooth.
 *  - Bending: E = D w (Phi(theta) - Phi(theta0)) has the Hessian
 *    D w (Phi''(theta) grad theta grad theta^T + Phi'(theta) hess theta). The second term is
 *    indefinite and vanishes at the rest angle; the Gauss-Newton form keeps the first with
 *    Phi'' = cos(theta/2)/2 clamped at zero: symmetric, semi-definite, exact at rest.
 *  - Damping is linear in v, so df/dv is exact: the membrane's -V0 U N U^T per corner pair
 *    (N from Phat = beta (A + A^T) + alpha tr(A) I, A = U^T Fdot V), the hinge's
 *    -(eta w / 2) grad theta grad theta^T.
 * All of them are translation invariant (their block rows sum to zero), so the system matrix
 * is stored in the solids' edge-difference form (stiffness_matrix.h) on the shell's own
 * pattern: the pairs of vertices that share a triangle or a hinge (the two corners opposite
 * a hinge's edge are coupled too). Rows are vertices in index order, each listing all its
 * neighbours, so the product and the diagonal blocks need no transposes; the assembly is
 * serial and in element order, so results do not depend on the thread count. */
#ifndef PIOLA_SHELL_STIFFNESS_H
#define PIOLA_SHELL_STIFFNESS_H

#include <stdint.h>

#include "force/stiffness_matrix.h"
#include "piola/shell_body.h"

/* df/dx of triangle t at the body's last update, times its stiffness scale (N/m): 9 x 9,
 * row 3 a + i, column 3 b + j = d f_{a,i} / d x_{b,j} for corners a, b. With project,
 * symmetric negative semi-definite. */
void piola__shell_triangle_stiffness(const piola_shell_body *body, int32_t t, int project,
                                     double out[81]);

/* Gauss-Newton df/dx of hinge h at the last update (N/m), 12 x 12 over its vertices
 * x1, x2, x3, x4 (piola_shell_body_hinges order): -D s w max(Phi''(theta), 0) grad grad^T. */
void piola__shell_hinge_stiffness(const piola_shell_body *body, int32_t h, double out[144]);

/* df/dv of triangle t's in-plane damping (9 x 9, N s/m) at viscosities beta, alpha (Pa s),
 * and of hinge h's bending damping (12 x 12), from the last update. */
void piola__shell_triangle_damping(const piola_shell_body *body, int32_t t, double beta,
                                   double alpha, double out[81]);
void piola__shell_hinge_damping(const piola_shell_body *body, int32_t h, double out[144]);

/* The system matrix of a shell (stiffness_matrix.h's struct and weights): init builds the
 * body's pattern on first use and sizes matrix for it; assemble forms
 * S = stiffness_weight K + damping_weight D (K projected; D at viscosities beta, alpha) and
 * the diagonal blocks with mass_weight M; apply gives out = A p. */
piola_status piola__shell_stiffness_matrix_init(piola__stiffness_matrix *matrix,
                                                piola_shell_body *body);
void piola__shell_stiffness_matrix_assemble(piola__stiffness_matrix *matrix,
                                            const piola_shell_body *body, double stiffness_weight,
                                            double damping_weight, double beta, double alpha,
                                            const double *mass, double mass_weight);
void piola__shell_stiffness_matrix_apply(const piola__stiffness_matrix *matrix,
                                         const piola_shell_body *body, const double *mass,
                                         double mass_weight, const double *p, double *out);

#endif
