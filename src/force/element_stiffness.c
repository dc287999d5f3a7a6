/* Element stiffness dP/dF in the diagonal frame, made positive semi-definite (see
 * element_stiffness.h for the why). Built only from the public material functions
 * (piola_material_stress_derivative and the stress it differentiates), so a new model gets
 * its stiffness without code here. */
#include <math.h>
#include <string.h>

#include "force/element_stiffness.h"
#include "material/material_kernels.h"
#include "material/muscle_kernels.h"
#include "piola/diagonalize.h"

/* Eigen-decomposition of a symmetric 3x3 by cyclic Jacobi rotations: a becomes diagonal
 * (the eigenvalues), q collects the rotations (columns are eigenvectors). A dozen sweeps
 * reach rounding for any input; the loop stops earlier once the off-diagonal part is below
 * rounding of the diagonal. */
static void jacobi_eigen3(double a[3][3], double q[3][3]) {
  memset(q, 0, 9 * sizeof(double));
  q[0][0] = q[1][1] = q[2][2] = 1.0;
  for (int sweep = 0; sweep < 16; ++sweep) {
    double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
    if (!(off > 1e-32 * diag)) break;
    for (int k = 0; k < 3; ++k) {
      const int p = PIOLA__PAIR_P[k], r = PIOLA__PAIR_Q[k];
      if (a[p][r] == 0.0) continue;
      /* the rotation in plane (p, r) that zeroes a[p][r] */
      double theta = (a[r][r] - a[p][p]) / (2.0 * a[p][r]);
      double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
      double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
      for (int i = 0; i < 3; ++i) { /* columns p, r of a and q */
        double aip = a[i][p], air = a[i][r];
        a[i][p] = c * aip - s * air;
        a[i][r] = s * aip + c * air;
        double qip = q[i][p], qir = q[i][r];
        q[i][p] = c * qip - s * qir;
        q[i][r] = s * qip + c * qir;
      }
      for (int j = 0; j < 3; ++j) { /* rows p, r of a */
        double apj = a[p][j], arj = a[r][j];
        a[p][j] = c * apj - s * arj;
        a[r][j] = s * apj + c * arj;
      }
    }
  }
}

void piola__project_symmetric3(double a[3][3]) {
  double s[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s[i][j] = 0.5 * (a[i][j] + a[j][i]);
  /* the common case, positive definite already (Sylvester's criterion), costs no eigen
   * decomposition */
  double m2 = s[0][0] * s[1][1] - s[0][1] * s[0][1];
  double det = s[0][0] * (s[1][1] * s[2][2] - s[1][2] * s[1][2]) -
               s[0][1] * (s[0][1] * s[2][2] - s[1][2] * s[0][2]) +
               s[0][2] * (s[0][1] * s[1][2] - s[1][1] * s[0][2]);
  if (s[0][0] > 0 && m2 > 0 && det > 0) {
    memcpy(a, s, sizeof s);
    return;
  }
  double q[3][3];
  jacobi_eigen3(s, q);
  double lam[3] = {fmax(s[0][0], 0.0), fmax(s[1][1], 0.0), fmax(s[2][2], 0.0)};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      a[i][j] = q[i][0] * lam[0] * q[j][0] + q[i][1] * lam[1] * q[j][1] + q[i][2] * lam[2] * q[j][2];
}

int piola__stress_evaluates_own_parts(piola_material_model model) {
  switch (model) {
    case PIOLA_MODEL_ROTATED_LINEAR:
    case PIOLA_MODEL_COROTATED:
    case PIOLA_MODEL_STVK:
    case PIOLA_MODEL_NEOHOOKEAN:
    case PIOLA_MODEL_SPLINE:
    case PIOLA_MODEL_STABLE_NEOHOOKEAN:
    case PIOLA_MODEL_OGDEN:
      return 1;
    default:
      return 0;
  }
}

void piola__material_stress_and_derivative(const piola_material *material, const double fhat[3],
                                           double phat[3], double dphat[3][3]) {
  /* the default's rise with J (material_threshold_at) can clamp entries above
   * material->threshold */
  const double c = material_threshold_largest(material);
  if (fhat[0] >= c && fhat[1] >= c && fhat[2] >= c && piola__stress_evaluates_own_parts(material->model)) {
    /* no entry clamped: every extension term is an exact zero, the parts are the answer */
    material_parts parts;
    material_model_parts(material->model, material, KERNEL_EXACT_DIVIDE, fhat[0], fhat[1],
                         fhat[2], &parts);
    memcpy(phat, parts.p, sizeof parts.p);
    memcpy(dphat, parts.k, sizeof parts.k);
    return;
  }
  piola_material_stress(material, fhat, phat);
  piola_material_stress_derivative(material, fhat, dphat);
}

void piola__diagonal_stiffness_eval(const piola_material *material, const double fhat[3],
                                    const double phat[3], int project,
                                    piola__diagonal_stiffness *out) {
  piola_material_stress_derivative(material, fhat, out->block);
  piola__diagonal_stiffness_from(fhat, phat, project, out);
}

void piola__diagonal_stiffness_from(const double fhat[3], const double phat[3], int project,
                                    piola__diagonal_stiffness *out) {
  double(*d)[3] = out->block;
  for (int k = 0; k < 3; ++k) {
    const int p = PIOLA__PAIR_P[k], q = PIOLA__PAIR_Q[k];
    const double fp = fhat[p], fq = fhat[q];
    /* below this gap the quotient loses most of its digits: take its limit instead */
    const double gap = 1e-6 * fmax(fmax(fabs(fp), fabs(fq)), 1e-3);
    double shear, twist;
    if (fabs(fp - fq) > gap)
      shear = (phat[p] - phat[q]) / (fp - fq);
    else
      shear = 0.5 * (d[p][p] - d[p][q] + d[q][q] - d[q][p]);
    if (fabs(fp + fq) > gap)
      twist = (phat[p] + phat[q]) / (fp + fq);
    else
      twist = 0.5 * (d[p][p] + d[p][q] + d[q][p] + d[q][q]);
    if (project != PIOLA_STIFFNESS_EXACT) {
      shear = fmax(shear, 0.0);
      /* near f_p = -f_q (an inverted element close to a reflection) the stress is not
       * continuous unless P_p + P_q vanishes there, and the quotient grows without bound;
       * such a stiff rotation mode only stalls Newton, so it is capped at the element's
       * other stiffnesses (from below too where it keeps its sign) */
      const double cap = fmax(shear, fmax(fabs(d[p][p]), fabs(d[q][q])));
      const int signed_twist = project == PIOLA_STIFFNESS_SIGNED_TWIST &&
                               fp + fq >= PIOLA__SIGNED_TWIST_LEAST_STRETCH_SUM;
      const double least = signed_twist ? -cap : 0.0;
      twist = fmin(fmax(twist, least), cap);
    }
    out->pair_a[k] = 0.5 * (shear + twist);
    out->pair_b[k] = 0.5 * (shear - twist);
  }
  if (project != PIOLA_STIFFNESS_EXACT) piola__project_symmetric3(out->block);
}

void piola__fiber_stiffness_terms(const piola_material *material, double stretch,
                                  double activation, int project, double *s, double *c) {
  *s = *c = 0.0;
  if (material->model != PIOLA_MODEL_MUSCLE || !(stretch > 0.0)) return;
  const double a = muscle_clamp_activation(activation);
  const double tension = piola_material_fiber_tension(material, stretch, a);
  double slope = muscle_fiber_tension_slope(&material->muscle, stretch, a);
  if (project) slope = fmax(slope, 0.0);
  *s = tension / stretch;
  *c = (slope - *s) / (stretch * stretch);
}

void piola__element_dpdf(const piola_material *material, const piola_mat3 *f,
                         const double *fiber, double activation, int project, double dpdf[81]) {
  piola_mat3 u, v;
  piola_vec3 fh;
  memset(dpdf, 0, 81 * sizeof(double));
  if (piola_diagonalize3(f, &u, &fh, &v) != PIOLA_OK) return;
  double fhat[3] = {fh.x, fh.y, fh.z}, phat[3];
  piola_material_stress(material, fhat, phat);
  piola__diagonal_stiffness k;
  piola__diagonal_stiffness_eval(material, fhat, phat, project, &k);
  /* dPhat/dFhat as a 9 x 9 in the diagonal frame */
  double c[81] = {0};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c[9 * (4 * i) + 4 * j] = k.block[i][j];
  for (int n = 0; n < 3; ++n) {
    const int p = PIOLA__PAIR_P[n], q = PIOLA__PAIR_Q[n], pq = 3 * p + q, qp = 3 * q + p;
    c[9 * pq + pq] = c[9 * qp + qp] = k.pair_a[n];
    c[9 * pq + qp] = c[9 * qp + pq] = k.pair_b[n];
  }
  /* rotate: dP_ij = sum U_ip V_jr dPhat_pr, dFhat_qs = sum U_kq V_ls dF_kl */
  double rot[9][9]; /* rot[3 i + j][3 p + r] = U_ip V_jr */
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int p = 0; p < 3; ++p)
        for (int r = 0; r < 3; ++r) rot[3 * i + j][3 * p + r] = u.m[i][p] * v.m[j][r];
  double tmp[81];
  for (int a = 0; a < 9; ++a)
    for (int b = 0; b < 9; ++b) {
      double sum = 0;
      for (int e = 0; e < 9; ++e) sum += c[9 * a + e] * rot[b][e];
      tmp[9 * a + b] = sum;
    }
  for (int a = 0; a < 9; ++a)
    for (int b = 0; b < 9; ++b) {
      double sum = 0;
      for (int e = 0; e < 9; ++e) sum += rot[a][e] * tmp[9 * e + b];
      dpdf[9 * a + b] = sum;
    }
  if (fiber && material->model == PIOLA_MODEL_HGO) {
    /* HGO's fibres: their dP/dF is positive semi-definite as it is (material.h) */
    double fam[6], fm[9], d[81];
    if (piola_material_hgo_families(material, fiber, fam) != PIOLA_OK) return;
    for (int e = 0; e < 9; ++e) fm[e] = f->m[e / 3][e % 3];
    piola_material_hgo_fiber_stress_derivative(material, fm, fam, d);
    for (int e = 0; e < 81; ++e) dpdf[e] += d[e];
    return;
  }
  if (!fiber || material->model != PIOLA_MODEL_MUSCLE) return;
  double an = sqrt(fiber[0] * fiber[0] + fiber[1] * fiber[1] + fiber[2] * fiber[2]);
  if (!(an > 0)) return;
  double a[3] = {fiber[0] / an, fiber[1] / an, fiber[2] / an}, w[3];
  for (int i = 0; i < 3; ++i) w[i] = f->m[i][0] * a[0] + f->m[i][1] * a[1] + f->m[i][2] * a[2];
  double s, cc;
  piola__fiber_stiffness_terms(material, sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]),
                               activation, project, &s, &cc);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int kk = 0; kk < 3; ++kk)
        for (int l = 0; l < 3; ++l)
          dpdf[9 * (3 * i + j) + 3 * kk + l] +=
              (i == kk ? s * a[j] * a[l] : 0.0) + cc * w[i] * a[j] * w[kk] * a[l];
}
