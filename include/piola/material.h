/* piola: isotropic constitutive models in diagonal form (paper section 6).
 *
 * A model is a function of the diagonal Fhat of the invertible diagonalization
 * F = U Fhat V^T: it gives the diagonal first Piola-Kirchhoff stress Phat (Pa), the energy
 * density psi (J/m^3 = Pa) and the 3x3 derivative dPhat_i/dFhat_j (Pa). The full stress
 * is P = U diag(Phat) V^T.
 *
 * Inversion extension: below the compression threshold c on any entry of Fhat the model is
 * replaced, in that entry, by its value at the clamped point (PIOLA_INVERSION_CLAMP, C0) or
 * by its first-order Taylor expansion around the clamped point (PIOLA_INVERSION_LINEAR, C1),
 * continued through zero into negative (inverted) entries, with the slope
 * relaxing towards at most the rest stiffness and the cross terms into unclamped entries
 * saturating away from the threshold (exact Taylor value and slope at it); all entries below
 * c are expanded together. Each model has its own default mode and threshold
 * (piola_material_default_inversion), chosen so that a scrambled or collapsed body recovers
 * (docs/materials.md, "Defaults that recover"). In clamped entries the slope is raised where
 * the plain expansion
 * would not push back (e.g. St. Venant-Kirchhoff, whose own slope there is negative), so the
 * result is finite for every Fhat with entries up to 1e30 in magnitude (flat, collapsed and
 * inverted included; only the models' own growth, e.g. corotated's energy ~ f^6, overflows
 * far beyond that), and every entry f_i <= 0 gets Phat_i < 0: an inverted element is always
 * pushed back. PIOLA_INVERSION_ENERGY extends the energy instead (Stomakhin et al. 2012): the
 * stress is then the exact gradient of the reported energy everywhere and the derivative is
 * a symmetric Hessian. See docs/materials.md.
 *
 * Usage:
 *   piola_material_def def = piola_default_material_def();
 *   def.model = PIOLA_MODEL_NEOHOOKEAN;
 *   def.youngs_modulus = 1e5;   // Pa
 *   def.poisson_ratio = 0.45;
 *   piola_material mat;
 *   if (piola_material_init(&def, &mat) != PIOLA_OK) puts(piola_last_error());
 *   piola_material_stress(&mat, fhat, phat); */
#ifndef PIOLA_MATERIAL_H
#define PIOLA_MATERIAL_H

#include <stdbool.h>

#include "piola/export.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum piola_material_model {
  PIOLA_MODEL_ROTATED_LINEAR = 0, /* Phat = 2 mu (Fhat - I) + lambda tr(Fhat - I) I (paper) */
  PIOLA_MODEL_COROTATED,          /* 2 mu (Fhat - I) + lambda (J - 1) J Fhat^-1 */
  PIOLA_MODEL_STVK,               /* St. Venant-Kirchhoff: Fhat (2 mu E + lambda tr(E) I) */
  PIOLA_MODEL_NEOHOOKEAN,         /* mu (Fhat - Fhat^-1) + lambda ln(J) Fhat^-1 */
  PIOLA_MODEL_SPLINE,             /* the paper's "biological" model: see piola_spline_def */
  PIOLA_MODEL_MUSCLE,             /* transversely isotropic muscle (section 6.1): the isotropic
                                     part (matrix + volume) is neo-Hookean with E, nu; the
                                     fibre part is piola_material_fiber_stress. See
                                     piola_muscle_def and docs/materials.md */
  PIOLA_MODEL_STABLE_NEOHOOKEAN,  /* Smith, de Goes, Kim 2018: mu'/2 (I_C - 3) + lambda'/2 (J - alpha)^2
                                     - mu'/2 ln(I_C + 1), with mu' = 4/3 mu, lambda' = lambda + 5/6 mu,
                                     alpha = 1 + mu / lambda' (docs/materials.md) */
  PIOLA_MODEL_MOONEY_RIVLIN,      /* C10 sum (f_i^2 - 1) + C01 sum (f_i^-2 - 1) - 2 (C10 - C01) ln J
                                     + lambda/2 (ln J)^2: see piola_mooney_rivlin_def */
  PIOLA_MODEL_OGDEN,              /* sum_p mu_p / alpha_p sum_i (f_i^alpha_p - 1) - (sum_p mu_p) ln J
                                     + lambda/2 (ln J)^2: see piola_ogden_def */
  PIOLA_MODEL_HGO,                /* Holzapfel-Gasser-Ogden fibre-reinforced tissue (arteries): a
                                     neo-Hookean matrix (shear modulus hgo.mu) plus two collagen
                                     fibre families with exponential stiffening. See
                                     piola_hgo_def and docs/materials.md */
  PIOLA_MODEL_COUNT
} piola_material_model;

typedef enum piola_inversion_mode {
  PIOLA_INVERSION_LINEAR = 0, /* C1: first-order Taylor expansion at the threshold */
  PIOLA_INVERSION_CLAMP,      /* C0: the stress at the clamped point */
  PIOLA_INVERSION_ENERGY,     /* the energy extended past the threshold (Stomakhin, Howes,
                                 Schroeder, Teran 2012): the stress is its exact gradient */
  PIOLA_INVERSION_MODEL_DEFAULT, /* in a piola_material_def only: the model's default mode
                                    (piola_material_default_inversion); never in an
                                    initialized piola_material */
} piola_inversion_mode;

/* Shape of the spline ("biological") model: soft near rest, stiffer past the thresholds. */
typedef struct piola_spline_def {
  double compression_stretch; /* dimensionless, in (threshold, 1): stiff below it. Default 0.8 */
  double elongation_stretch;  /* dimensionless, > 1: stiff above it. Default 1.2 */
  double stiffening;          /* dimensionless, >= 1: slope outside the thresholds divided by
                                 the slope at rest. Default 10 */
} piola_spline_def;

/* The fibre part of PIOLA_MODEL_MUSCLE. With lambda = |F a| the stretch along the unit fibre
 * direction a (material space), the fibre carries a tension T(lambda) (Pa, force per rest
 * area across the fibre) and never a compression:
 *   passive  T_p = 0 for lambda <= 1; a quadratic toe whose slope rises from 0 to
 *            passive_stiffness up to passive_toe_stretch; linear with that slope beyond.
 *   active   T_a = activation * max_active_stress * L((lambda / optimal_stretch - 1) / active_width)
 *            with the force-length bump L(s) = (1 - s^2)^2 for |s| < 1, else 0.
 * Energy density psi_f = integral from 1 to lambda of T; stress P_f = (T / lambda) F a a^T,
 * which in the diagonal frame is Fhat times the symmetric (T / lambda) ahat ahat^T with
 * ahat = V^T a (paper section 6.1). */
typedef struct piola_muscle_def {
  double passive_stiffness;   /* Pa, >= 0: slope of the passive fibre tension past the toe.
                                 Default 1e5 */
  double passive_toe_stretch; /* dimensionless, > 1: where the passive slope is reached.
                                 Default 1.2 */
  double max_active_stress;   /* Pa, >= 0: isometric tension at full activation and optimal
                                 stretch. Default 1e5 */
  double optimal_stretch;     /* dimensionless, > 0: fibre stretch of peak active tension.
                                 Default 1 (the rest length is optimal) */
  double active_width;        /* dimensionless, in (0, 1): half width of the force-length
                                 bump, relative to optimal_stretch. Default 0.5 */
} piola_muscle_def;

/* Ogden (1972) in principal stretches, N terms, compressible through a ln J volume term:
 *   psi = sum_p mu_p / alpha_p sum_i (f_i^alpha_p - 1) - (sum_p mu_p) ln J + lambda/2 (ln J)^2
 * Its shear modulus is mu = 1/2 sum_p mu_p alpha_p (must be > 0); lambda comes from
 * poisson_ratio with that mu (youngs_modulus is not used). For incompressible deformations
 * (J = 1) this is Ogden's energy; Mooney-Rivlin and neo-Hookean are its two- and one-term
 * cases (alpha = 2, -2). */
#define PIOLA_OGDEN_MAX_TERMS 6
typedef struct piola_ogden_def {
  int term_count;                     /* 1..PIOLA_OGDEN_MAX_TERMS. Default 3 */
  double mu[PIOLA_OGDEN_MAX_TERMS];    /* Pa, each nonzero. Default Ogden's 1972 fit to
                                          Treloar's rubber: 6.18e5, 1.18e3, -9.81e3 */
  double alpha[PIOLA_OGDEN_MAX_TERMS]; /* dimensionless, each nonzero. Default 1.3, 5, -2 */
} piola_ogden_def;

/* Mooney-Rivlin in principal stretches, compressible through the same ln J volume term:
 *   psi = C10 sum_i (f_i^2 - 1) + C01 sum_i (f_i^-2 - 1) - 2 (C10 - C01) ln J + lambda/2 (ln J)^2
 * which for J = 1 is the classical C10 (I1 - 3) + C01 (I2 - 3). Shear modulus
 * mu = 2 (C10 + C01) (must be > 0); lambda from poisson_ratio (youngs_modulus is not used). */
typedef struct piola_mooney_rivlin_def {
  double c10; /* Pa. Default 1.5e4 */
  double c01; /* Pa. Default 5e3 */
} piola_mooney_rivlin_def;

/* Holzapfel, Gasser, Ogden 2000 (J. Elasticity 61), with the fibre dispersion of Gasser,
 * Ogden, Holzapfel 2006 (J. R. Soc. Interface 3):
 *   psi = psi_nh(F; mu, lambda) + sum_{a = +,-} k1 / (2 k2) (exp(k2 <E_a>^2) - 1)
 *   E_a = kappa (I1 - 3) + (1 - 3 kappa) (I4_a - 1),  I1 = |F|^2,  I4_a = |F a|^2
 * with psi_nh the neo-Hookean energy (matrix and ln J volume term, its inversion
 * extension), <E> = max(E, 0) (fibres bear no compression). The two unit family directions
 * a_+- = cos(angle) m +- sin(angle) n lie in the plane of the tet's fibre direction m (the
 * solid's fibre field, e.g. circumferential in an artery) and axis (n = the part of axis
 * perpendicular to m, normalised), at +-fiber_angle_degrees from m. Past the fibre stretch
 * fiber_stretch_limit the fibre energy continues as a spring of constant stiffness instead of
 * the exponential (finite for every F; docs/materials.md). */
typedef struct piola_hgo_def {
  double mu;                  /* Pa, > 0: shear modulus of the neo-Hookean matrix (HGO's c).
                                 Default 3000 (HGO 2000, rabbit carotid media) */
  double k1;                  /* Pa, >= 0: fibre stiffness. Default 2363.2 */
  double k2;                  /* dimensionless, > 0: fibre stiffening. Default 0.8393 */
  double kappa;               /* dimensionless, in [0, 1/3]: fibre dispersion (0 aligned,
                                 1/3 isotropic). Default 0 */
  double fiber_angle_degrees; /* degrees, in [0, 90]: angle of each family from the tet's
                                 fibre direction. Default 29 */
  double axis[3];             /* nonzero (normalised): the fibre plane's second direction, in
                                 rest (scene) coordinates. Default (0, 0, 1) */
  double fiber_stretch_limit; /* dimensionless, > 1: the fibre stretch sqrt(1 + E) past which
                                 the fibre energy is continued as a spring of constant
                                 stiffness instead of the exponential (docs/materials.md).
                                 Default 1.7 */
} piola_hgo_def;

typedef struct piola_material_def {
  piola_material_model model;
  double youngs_modulus;      /* Pa, > 0. Default 1e5 */
  double poisson_ratio;       /* dimensionless, in (-1, 0.5). Default 0.3 */
  double inversion_threshold; /* dimensionless, in (0, 1): compression threshold c, or 0
                                 (default): the model's default threshold */
  piola_inversion_mode inversion_mode; /* Default PIOLA_INVERSION_MODEL_DEFAULT: the model's
                                          default mode. The defaults of both per model:
                                          piola_material_default_inversion */
  piola_spline_def spline;    /* used by PIOLA_MODEL_SPLINE only */
  piola_ogden_def ogden;      /* used by PIOLA_MODEL_OGDEN only */
  piola_mooney_rivlin_def mooney_rivlin; /* used by PIOLA_MODEL_MOONEY_RIVLIN only */
  piola_hgo_def hgo;          /* used by PIOLA_MODEL_HGO only (youngs_modulus is not used;
                                 poisson_ratio sets lambda with hgo.mu) */
  piola_muscle_def muscle;    /* used by PIOLA_MODEL_MUSCLE only; youngs_modulus and
                                 poisson_ratio give its matrix and volume part (use nu close
                                 to 0.5, e.g. 0.45, for a quasi-incompressible muscle) */
} piola_material_def;

/* The defaults above, written once. */
PIOLA_API piola_material_def piola_default_material_def(void);

/* The inversion mode and threshold (dimensionless) that a model gets when its def leaves them
 * at their defaults (PIOLA_INVERSION_MODEL_DEFAULT, 0): per model, the setting measured to
 * recover from the most scrambles and from point, line and plane collapse
 * (docs/materials.md, "Defaults that recover"). */
PIOLA_API void piola_material_default_inversion(piola_material_model model,
                                                piola_inversion_mode *mode, double *threshold);

/* Young's modulus (Pa) and Poisson's ratio from Lame parameters mu, lambda (Pa). */
PIOLA_API piola_status piola_youngs_poisson_from_lame(double mu, double lambda,
                                                      double *youngs_modulus,
                                                      double *poisson_ratio);

/* A validated model, ready to evaluate. Plain data: copy it freely. */
typedef struct piola_material {
  piola_material_model model;
  double mu;                  /* Pa, Lame's second parameter (shear modulus) */
  double lambda;              /* Pa, Lame's first parameter */
  double threshold;           /* dimensionless compression threshold c */
  piola_inversion_mode inversion_mode;
  double threshold_compressed; /* CLAMP: the threshold where J <= threshold_volume[0]; it rises
                                  from threshold smoothly as J falls from threshold_volume[1]
                                  (material_threshold_at). Equal to threshold (off) unless the
                                  model's default sets it (Mooney-Rivlin, Ogden, HGO:
                                  docs/materials.md, "Defaults that recover") */
  double threshold_volume[2];  /* J (low, high) of that rise */
  double spline_coefficients[16]; /* precomputed spline pieces, model-internal */
  double model_constants[24]; /* precomputed constants, model-internal (Stable Neo-Hookean's
                                 mu', lambda', alpha; the energy extension's slope; the
                                 Ogden / Mooney-Rivlin terms) */
  piola_muscle_def muscle;    /* PIOLA_MODEL_MUSCLE: the validated fibre parameters */
  piola_hgo_def hgo;          /* PIOLA_MODEL_HGO: the validated parameters (axis unit) */
  double fiber_modulus;       /* Pa: bound on the fibre's tangent stiffness at full activation
                                 (0 for other models), added to lambda + 2 mu in the CFL
                                 wave speed */
} piola_material;

/* Checks def (E > 0, nu in (-1, 0.5), threshold in (0, 1), spline shape) and fills out.
 * On error returns PIOLA_ERROR_INVALID_ARGUMENT with a message naming the parameter. */
PIOLA_API piola_status piola_material_init(const piola_material_def *def, piola_material *out);

/* Diagonal stress Phat (Pa) at the diagonal deformation fhat, extension included. */
PIOLA_API void piola_material_stress(const piola_material *material, const double fhat[3],
                                     double phat[3]);

/* Energy density (J/m^3) at fhat, extension included (see docs/materials.md for what it
 * means past the threshold). Zero at rest. */
PIOLA_API double piola_material_energy_density(const piola_material *material, const double fhat[3]);

/* dPhat_i / dFhat_j (Pa): the exact derivative of the extended stress. Symmetric where the
 * stress has a potential (no entry below the threshold, or all three below it; everywhere
 * with PIOLA_INVERSION_ENERGY, whose stress is the gradient of the extended energy). */
PIOLA_API void piola_material_stress_derivative(const piola_material *material,
                                                const double fhat[3], double dphat[3][3]);

/* The eigensystem of the Hessian d2psi/dF2 (9x9, Pa) of an isotropic energy at F = U Fhat V^T,
 * in the diagonal frame, with negative eigenvalues clamped to zero: the projected Hessian
 * that makes an implicit solver's element stiffness positive semi-definite (Teran et al.
 * 2005; Smith, de Goes, Kim 2018, section 4). The Hessian is
 *   sum_k eigenvalues[k] vec(U Q_k V^T) vec(U Q_k V^T)^T,   Q_k = eigenvectors[k]
 * with Q_k orthonormal under the Frobenius product. Q_0..Q_2 are diagonal (the scaling
 * modes: the eigenvectors of dPhat/dFhat); Q_3..Q_8 are (e_i e_j^T -+ e_j e_i^T) / sqrt 2 for
 * (i, j) = (0, 1), (0, 2), (1, 2): Q_3..Q_5 twist (antisymmetric), Q_6..Q_8 flip (symmetric), with the
 * eigenvalues (Phat_i + Phat_j) / (f_i + f_j) and (Phat_i - Phat_j) / (f_i - f_j).
 * For PIOLA_MODEL_STABLE_NEOHOOKEAN with no entry below the inversion threshold the twist and
 * flip eigenvalues are the closed forms mu' r +- lambda' (J - alpha) f_k (r = I_C / (I_C + 1),
 * k the third index) and need no division. Available for every model in
 * PIOLA_INVERSION_ENERGY mode or with no entry below the threshold (where the stress is the
 * gradient of an energy); elsewhere (LINEAR or CLAMP with a clamped entry, or a muscle, whose
 * fibres are not isotropic) returns PIOLA_ERROR_INVALID_ARGUMENT. Where f_i = +-f_j the
 * quotients are replaced by their limits (dPhat_i/dFhat_i +- dPhat_i/dFhat_j). */
PIOLA_API piola_status piola_material_projected_hessian_eigensystem(const piola_material *material,
                                                                   const double fhat[3],
                                                                   double eigenvalues[9],
                                                                   double eigenvectors[9][3][3]);

/* ------------------------------------------------------------------ muscle fibres
 * For a PIOLA_MODEL_MUSCLE material (all zero for other models). fiber is the fibre
 * direction in the frame of the diagonalization, ahat = V^T a (any length; it is normalised,
 * a zero vector means no fibre); activation (dimensionless) is clamped to [0, 1]. The
 * functions above give the isotropic part; these give the fibre part and the sum. */

/* Fibre tension T (Pa) at fibre stretch lambda >= 0. */
PIOLA_API double piola_material_fiber_tension(const piola_material *material, double stretch,
                                              double activation);

/* Fibre part of the stress in the diagonal frame, Pa: phat[i][j] = (T / lambda) f_i ahat_i
 * ahat_j = (Fhat S)_ij with S symmetric. Finite for every fhat (flat and inverted too). */
PIOLA_API void piola_material_fiber_stress(const piola_material *material, const double fhat[3],
                                           const double fiber[3], double activation,
                                           double phat[3][3]);

/* Fibre energy density, J/m^3: the integral of T from stretch 1 to lambda = |Fhat ahat|. */
PIOLA_API double piola_material_fiber_energy_density(const piola_material *material,
                                                     const double fhat[3], const double fiber[3],
                                                     double activation);

/* The whole muscle stress in the diagonal frame: diag(piola_material_stress) plus the fibre
 * part. P = U phat V^T. */
PIOLA_API void piola_material_muscle_stress(const piola_material *material, const double fhat[3],
                                            const double fiber[3], double activation,
                                            double phat[3][3]);

/* Isotropic plus fibre energy density, J/m^3. */
PIOLA_API double piola_material_muscle_energy_density(const piola_material *material,
                                                      const double fhat[3], const double fiber[3],
                                                      double activation);

/* ------------------------------------------------------------------ HGO fibres
 * For a PIOLA_MODEL_HGO material (errors or zeros for other models). The functions above give
 * the matrix (neo-Hookean) part; these give the two fibre families' part. */

/* The two unit family directions (rest space, family a at families[3 a]) of a tet whose
 * fibre direction is fiber (any length). The functions below take them in this layout. PIOLA_ERROR_INVALID_ARGUMENT for a zero fibre, or one parallel to hgo.axis while
 * the fibre angle is not 0 (the fibre plane is undefined). */
PIOLA_API piola_status piola_material_hgo_families(const piola_material *material,
                                                   const double fiber[3], double families[6]);

/* Fibre part of the stress, Pa, row-major P[3 i + j], at the deformation gradient f
 * (row-major 3x3, any frame) for the unit family directions in that frame (e.g. the
 * diagonal frame: f = Fhat, families V^T a):
 *   P_f = sum_a 2 psi'(E_a) (kappa F + (1 - 3 kappa) F a a^T). Finite for every f. */
PIOLA_API void piola_material_hgo_fiber_stress(const piola_material *material, const double f[9],
                                               const double families[6], double p[9]);

/* Fibre energy density, J/m^3 (zero at rest and wherever both E_a <= 0). */
PIOLA_API double piola_material_hgo_fiber_energy_density(const piola_material *material,
                                                         const double f[9],
                                                         const double families[6]);

/* dP_f/dF (Pa), 9 x 9, row 3 i + j = P_ij, column 3 k + l = F_kl:
 *   sum_a 4 psi''(E_a) G_a (x) G_a + 2 psi'(E_a) (kappa I (x) I + (1 - 3 kappa) I (x) a a^T),
 * G_a = kappa F + (1 - 3 kappa) F a a^T: symmetric positive semi-definite (psi', psi'' >= 0),
 * so an implicit solver needs no projection for it. */
PIOLA_API void piola_material_hgo_fiber_stress_derivative(const piola_material *material,
                                                          const double f[9],
                                                          const double families[6],
                                                          double dpdf[81]);

/* Name used in scene files: "rotated_linear", "corotated", "stvk", "neohookean", "spline",
 * "muscle", "stable_neohookean", "mooney_rivlin", "ogden", "hgo". */
PIOLA_API const char *piola_material_model_name(piola_material_model model);

/* Parses a scene-file name; false if unknown. */
PIOLA_API bool piola_material_model_from_name(const char *name, piola_material_model *model);

/* Name used in scene files for the inversion mode: "linear" (C1), "clamp" (C0), "energy", or
 * "default" (PIOLA_INVERSION_MODEL_DEFAULT). */
PIOLA_API const char *piola_inversion_mode_name(piola_inversion_mode mode);

/* Parses "linear", "clamp", "energy" or "default"; false if unknown. */
PIOLA_API bool piola_inversion_mode_from_name(const char *name, piola_inversion_mode *mode);

/* ------------------------------------------------------------------ membrane models (shells) */

/* In-plane stress Phat (Pa) of a shell at the 2-entry diagonal deformation fhat: the
 * material's model evaluated at (fhat[0], fhat[1], 1) with the plane-stress Lame parameter
 * lambda* = 2 mu lambda / (lambda + 2 mu), inversion extension included. */
PIOLA_API void piola_membrane_stress(const piola_material *material, const double fhat[2],
                                     double phat[2]);

/* Its energy density (J/m^3); piola_membrane_stress is its derivative. Zero at rest. */
PIOLA_API double piola_membrane_energy_density(const piola_material *material,
                                               const double fhat[2]);

#ifdef __cplusplus
}
#endif

#endif
