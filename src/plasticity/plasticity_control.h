/* Plasticity control (paper section 7) and the logarithms it works in.
 *
 * Why logarithms of the rotation-free part: a plastic deformation Fp = R S matters only
 * through S (isotropic materials), and log S is a symmetric matrix in a linear space where
 * "the segment from the old Fp to the trial Fp" and "the point closest to the goal" are
 * plain vector geometry: t* = clamp(<Lg - Lo, Lt - Lo> / |Lt - Lo|^2, 0, 1). Symmetric
 * matrices are stored as 6 numbers (xx, yy, zz, xy, xz, yz) with the off-diagonal entries
 * counted twice in the inner product, so it is the Frobenius one.
 *
 * Eigen-decompositions use the public piola_diagonalize3: for Fp^-1 (det > 0) its SVD
 * W Sigma Q^T gives S = W Sigma^-1 W^T; for a symmetric L it is applied to L + c I with c
 * large enough that the matrix is positive definite, where the SVD is the eigen-decomposition.
 *
 * The log-stretches of every result are clamped to the limit, so control can never take Fp
 * outside the well-conditioned set (the spectral-norm ball of log S is convex, so points of
 * a segment between admissible ends stay admissible anyway). */
#ifndef PIOLA_PLASTICITY_CONTROL_H
#define PIOLA_PLASTICITY_CONTROL_H

#include "piola/status.h"

/* L = log S with S the rotation-free part of Fp = A^-1 (A = Fp^-1 row-major, det A > 0). */
void piola__plastic_log_from_fp_inverse(const double a[9], double l[6]);
/* A = exp(-L) (symmetric Fp^-1) after clamping L's eigenvalues into [-limit, limit].
 * Returns the largest |eigenvalue| after clamping. */
double piola__plastic_fp_inverse_from_log(const double l[6], double limit, double a[9]);
/* log of the rotation-free part of a goal Fp (row-major, det > 0), eigenvalues clamped to
 * [-limit, limit]. Fails when det Fp <= 0. */
piola_status piola__plastic_goal_log(const double fp[9], double limit, double l[6]);
/* The control choice: the point of the segment lo -> lt closest to lg, then moved toward
 * lg by the fraction pull in [0, 1]. Result in out (may alias lo or lt). */
void piola__plastic_control_select(const double lo[6], const double lt[6], const double lg[6],
                                   double pull, double out[6]);
/* Frobenius norm of a - b for symmetric 6-vectors. */
double piola__plastic_sym_distance(const double a[6], const double b[6]);

#endif
