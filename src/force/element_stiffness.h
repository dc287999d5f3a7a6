/* The stiffness of one element: dP/dF, made positive semi-definite, for the implicit
 * integrators (src/sim/implicit_step.c).
 *
 * Why it looks like this. P = U Phat(Fhat) V^T, so in the frame of the diagonalization the
 * derivative dPhat/dFhat (9 x 9) decouples (Teran, Sifakis, Irving and Fedkiw 2005, "Robust
 * quasistatic finite elements and flesh simulation"): the diagonal entries of dFhat drive the
 * diagonal of dPhat through the 3x3 block dPhat_i/dFhat_j that every material model gives
 * (piola_material_stress_derivative), and each off-diagonal pair (dF_pq, dF_qp), p < q,
 * drives only itself through a 2x2 block [[a, b], [b, a]] whose eigenvalues are
 *   (P_p - P_q) / (f_p - f_q)   on (1, 1) (a symmetric shear), and
 *   (P_p + P_q) / (f_p + f_q)   on (1, -1) (a rotation of the pair),
 * with P = Phat and f = Fhat. Both quotients come from Phat alone, so any model that gives
 * its stress and stress derivative gets its stiffness for free. Where a denominator
 * vanishes (equal entries, or f_p = -f_q on an inverted element) the quotient is replaced by
 * its limit, the matching combination of dPhat/dFhat, so the result stays finite on flat,
 * collapsed and inverted elements. The definiteness fix clamps the 2x2 eigenvalues at zero
 * and projects the symmetrized 3x3 block onto its non-negative eigenvalues; the sum is then
 * positive semi-definite for every F. The projection also caps the rotation eigenvalue
 * (P_p + P_q) / (f_p + f_q) at the element's largest other stiffness (the shear quotient and
 * the diagonal of dPhat/dFhat): it grows without bound near a reflection (f_p = -f_q), where
 * the extended stress of most models jumps, and a Newton iteration seeing it would stall.
 *
 * The muscle's fibre term P_f = (T(lambda) / lambda) F a a^T (lambda = |F a|) is not
 * diagonal in that frame, but its derivative has a closed form in any frame:
 *   dP_f/dF = s (I (x) a a^T) + c (w (x) a)(w (x) a)^T,  w = F a,  s = T / lambda,
 *   c = (T' - s) / lambda^2,
 * whose eigenvalues are s >= 0 (the fibre is tension-only) and T' on w (x) a. Projection
 * replaces T' by max(T', 0). */
#ifndef PIOLA_FORCE_ELEMENT_STIFFNESS_H
#define PIOLA_FORCE_ELEMENT_STIFFNESS_H

#include "piola/material.h"
#include "piola/math_types.h"

/* Pair k of the diagonal frame's entries: (0, 1), (0, 2), (1, 2) for k = 0, 1, 2. */
static const int PIOLA__PAIR_P[3] = {0, 0, 1}, PIOLA__PAIR_Q[3] = {1, 2, 2};

/* dPhat/dFhat of the isotropic part in the diagonal frame (Pa). Pair k's block acts on
 * (dFhat_pq, dFhat_qp), p = PIOLA__PAIR_P[k] and q = PIOLA__PAIR_Q[k]. */
typedef struct piola__diagonal_stiffness {
  double block[3][3];          /* dPhat_i / dFhat_j */
  double pair_a[3], pair_b[3]; /* the pair blocks [[a, b], [b, a]] */
} piola__diagonal_stiffness;

/* How far the blocks are made definite: the `project` argument below.
 * - PIOLA_STIFFNESS_EXACT: not at all, dP/dF itself.
 * - PIOLA_STIFFNESS_PROJECTED: the definiteness fix, positive semi-definite for every F.
 * - PIOLA_STIFFNESS_SIGNED_TWIST: the same except that the rotation eigenvalues
 *   (P_p + P_q) / (f_p + f_q) keep their sign (capped at plus and minus the element's other
 *   stiffnesses) in a pair compressed but not near collapse (below). That quotient is the
 *   stress over the stretch, negative wherever the element is compressed, and clamping it at
 *   zero is what keeps a Newton iteration on a compressed solid from converging
 *   quadratically (docs/time-stepping.md, "The Newton tail"); the shear quotients and the
 *   3x3 block stay projected. Not definite: for the implicit step's
 *   tail only, which falls back to the projected matrix when the CG meets negative
 *   curvature. */
/* The signed twist's cutoff: a pair keeps its sign only where f_p + f_q is at least this (a
 * mean stretch of 1/2). Nearer collapse, or inverted, the quotient is large and changes sign
 * through the reflection, and an indefinite Newton matrix there aims at the collapsed state's
 * saddles: armadillo_4k's line collapse unfolded into a shape 58% of its diagonal from rest
 * and settled in 7.5 s instead of 5.3 s (docs/time-stepping.md, "The Newton tail"). */
#define PIOLA__SIGNED_TWIST_LEAST_STRETCH_SUM 1.0

enum {
  PIOLA_STIFFNESS_EXACT = 0,
  PIOLA_STIFFNESS_PROJECTED = 1,
  PIOLA_STIFFNESS_SIGNED_TWIST = 2
};

/* Fills out at fhat (the diagonalization's signed entries) and Phat = phat, made definite as
 * project says (PIOLA_STIFFNESS_*). */
void piola__diagonal_stiffness_eval(const piola_material *material, const double fhat[3],
                                    const double phat[3], int project,
                                    piola__diagonal_stiffness *out);

/* The same with out->block = dPhat/dFhat at fhat given (unprojected; made definite here as
 * project says). */
void piola__diagonal_stiffness_from(const double fhat[3], const double phat[3], int project,
                                    piola__diagonal_stiffness *out);

/* Phat and dPhat/dFhat at fhat: the values of piola_material_stress and
 * piola_material_stress_derivative. Where no entry of fhat is below the inversion threshold
 * (most elements) the extensions add exact zeros, so both are the model's own stress and
 * Hessian there, from one evaluation of the parts its stress kernel evaluates
 * (material_kernels.h; piola__stress_parts_model) instead of one per public function;
 * elsewhere through the public functions. For the implicit assembly, where the two calls
 * were half of its time. */
void piola__material_stress_and_derivative(const piola_material *material, const double fhat[3],
                                           double phat[3], double dphat[3][3]);

/* The model whose parts a model's stress kernel evaluates, where the above takes its
 * one-evaluation path: the model's own (HGO's matrix has its own case among the parts, the
 * neo-Hookean's arithmetic), the muscle's matrix neo-Hookean's; PIOLA_MODEL_COUNT for
 * Mooney-Rivlin, whose public derivative (closed form) differs from its Ogden terms' parts in
 * the last bit, so it takes the public functions. */
piola_material_model piola__stress_parts_model(piola_material_model model);

/* The fibre term's two coefficients at fibre stretch lambda (see above), Pa: s and c with
 * dP_f/dF = s (I (x) a a^T) + c (w (x) a)(w (x) a)^T for a unit a. With project (any but
 * PIOLA_STIFFNESS_EXACT), T' is replaced by max(T', 0). Zero for non-muscle materials and
 * near lambda = 0 (where T = 0). */
void piola__fiber_stiffness_terms(const piola_material *material, double stretch,
                                  double activation, int project, double *s, double *c);

/* The whole dP/dF at F as a 9 x 9 matrix (Pa), row 3 i + j = P_ij, column 3 k + l = F_kl:
 * the isotropic part plus, when fiber is not NULL (a rest-space direction, normalised here),
 * the muscle's fibre term at this activation. project as above. For tests and tools; the
 * assembly works in the diagonal frame directly. */
void piola__element_dpdf(const piola_material *material, const piola_mat3 *f,
                         const double *fiber, double activation, int project, double dpdf[81]);

/* Projects the symmetric part of a (3x3) onto its non-negative eigenvalues, in place. */
void piola__project_symmetric3(double a[3][3]);

#endif
