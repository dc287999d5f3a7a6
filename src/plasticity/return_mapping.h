/* The return mapping of paper section 6.3 on a diagonalized trial elastic deformation, and
 * the limit projection of Fp's log-stretches, as pure functions of a few numbers.
 *
 * Why pure functions of the diagonal: the yield criteria are isotropic, so everything the
 * projection needs is Fhat of Fe,trial = U Fhat V^T; the result is a plastic increment
 * delta (a diagonal log strain in the V frame) that plastic_state.c turns into the new
 * Fp^-1. Keeping this apart lets the tests check the projection by hand.
 *
 * Radial return with linear isotropic hardening. With e = log Fhat (entries below
 * PIOLA_PLASTIC_FLAT_FLOOR read as the floor) and d = e (or its deviatoric part when volume
 * is preserved), yield when ||d|| > gamma = yield + hardening * alpha. The return lands on
 * the grown surface: dlambda = (||d|| - gamma) / (1 + hardening), delta = dlambda d / ||d||,
 * alpha += dlambda. Then ||d - delta|| = yield + hardening * (alpha + dlambda): consistent.
 * delta is traceless in the volume-preserving case, so det Fp does not change. The floor
 * keeps log finite on flat and inverted elements and the projected Fhat positive, so Fp
 * never inverts: inversion stays in Fe, whose forces undo it. */
#ifndef PIOLA_PLASTICITY_RETURN_MAPPING_H
#define PIOLA_PLASTICITY_RETURN_MAPPING_H

/* Entries of Fhat below this (100x compression, flat, inverted) count as this value. */
#define PIOLA_PLASTIC_FLAT_FLOOR 0.01

typedef struct plastic_params {
  double yield;          /* gamma at zero accumulated strain */
  double hardening;      /* d gamma / d alpha */
  double limit;          /* bound on |log stretch| of Fp */
  int volume_preserving; /* deviatoric criterion, traceless flow */
} plastic_params;

/* Returns 1 when the criterion is exceeded, with delta (log Fhat,trial - log Fhat,proj,
 * 3 entries) and the increment of accumulated plastic strain *dlambda; 0 otherwise
 * (delta = 0, *dlambda = 0). alpha is the tet's accumulated plastic strain. */
int piola__plastic_return_map(const plastic_params *p, const double fhat[3], double alpha,
                              double delta[3], double *dlambda);

/* Clamps log-stretches l into [-limit, limit]. With keep_sum the sum of l is kept (volume):
 * l_i <- clamp(l_i - mu) with the shift mu that restores the sum (needs |sum| <= 3 limit).
 * Returns 1 when anything changed. */
int piola__plastic_clamp_log_stretches(double l[3], double limit, int keep_sum);

#endif
