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

/* A unit eigenvector v of symmetric t for its simple eigenvalue lambda: the largest column of
 * the adjugate of t - lambda I (the cross products of its rows), each of which is a multiple
 * of v. 0 where that column is zero. */
static int adjugate_eigenvector3(double t[3][3], double lambda, double v[3]) {
  const double r[3][3] = {{t[0][0] - lambda, t[0][1], t[0][2]},
                          {t[1][0], t[1][1] - lambda, t[1][2]},
                          {t[2][0], t[2][1], t[2][2] - lambda}};
  double best = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double *x = r[PIOLA__PAIR_P[k]], *y = r[PIOLA__PAIR_Q[k]];
    const double c[3] = {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2],
                         x[0] * y[1] - x[1] * y[0]};
    const double n2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    if (n2 > best) {
      best = n2;
      memcpy(v, c, sizeof c);
    }
  }
  if (!(best > 0.0)) return 0;
  const double inv = 1.0 / sqrt(best);
  for (int i = 0; i < 3; ++i) v[i] *= inv;
  return 1;
}

/* x^T t y for symmetric t. */
static double bilinear3(double t[3][3], const double x[3], const double y[3]) {
  double sum = 0.0;
  for (int i = 0; i < 3; ++i) sum += x[i] * (t[i][0] * y[0] + t[i][1] * y[1] + t[i][2] * y[2]);
  return sum;
}

/* The eigen decomposition of symmetric t (entries at most 1 in magnitude) in closed form:
 * eigenvalues lam and unit eigenvectors u[k]. The characteristic cubic of (t - q I) / p (q
 * the mean of the diagonal) solved by its trigonometric form gives the eigenvalue farthest
 * from the other two accurately, but the two nearer ones only to the square root of the
 * rounding where they nearly coincide (a double root of the cubic moves that much); so only
 * the far one is taken from it, with its vector from the adjugate, and the other two from
 * the 2x2 block of t on the plane orthogonal to that vector, whose closed form is exact to
 * rounding. 0 where a vector is not found. */
static int closed_form_eigensystem3(double t[3][3], double lam[3], double u[3][3]) {
  const double q = (t[0][0] + t[1][1] + t[2][2]) / 3.0;
  const double off = t[0][1] * t[0][1] + t[0][2] * t[0][2] + t[1][2] * t[1][2];
  const double d0 = t[0][0] - q, d1 = t[1][1] - q, d2 = t[2][2] - q;
  const double p = sqrt((d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * off) / 6.0);
  if (!(p > 0.0)) { /* t = q I */
    memset(u, 0, 9 * sizeof(double));
    for (int k = 0; k < 3; ++k) lam[k] = q, u[k][k] = 1.0;
    return 1;
  }
  const double b00 = d0 / p, b11 = d1 / p, b22 = d2 / p, b01 = t[0][1] / p, b02 = t[0][2] / p,
               b12 = t[1][2] / p;
  const double half_det = 0.5 * (b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02) +
                                 b02 * (b01 * b12 - b11 * b02));
  const double phi = acos(fmin(fmax(half_det, -1.0), 1.0)) / 3.0;
  /* half_det >= 0: the largest is the far one, else the smallest */
  lam[0] = half_det >= 0.0 ? q + 2.0 * p * cos(phi) : q + 2.0 * p * cos(phi + 2.0943951023931957);
  if (!adjugate_eigenvector3(t, lam[0], u[0])) return 0;
  /* an orthonormal pair e, f spanning the plane orthogonal to v = u[0]: e = axis x v for the
   * axis along v's smallest entry */
  const double *v = u[0];
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (fabs(v[i]) < fabs(v[k])) k = i;
  double e[3] = {0, 0, 0};
  e[(k + 1) % 3] = -v[(k + 2) % 3];
  e[(k + 2) % 3] = v[(k + 1) % 3];
  const double en = 1.0 / sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
  for (int i = 0; i < 3; ++i) e[i] *= en;
  const double f[3] = {v[1] * e[2] - v[2] * e[1], v[2] * e[0] - v[0] * e[2],
                       v[0] * e[1] - v[1] * e[0]};
  /* the 2x2 block [[a, c], [c, b]] on (e, f): eigenvalues mid +- radius, the larger one's
   * vector (h + radius, c) or (c, radius - h), whichever does not cancel */
  const double a = bilinear3(t, e, e), b = bilinear3(t, f, f), c = bilinear3(t, e, f);
  const double h = 0.5 * (a - b), mid = 0.5 * (a + b), radius = sqrt(h * h + c * c);
  lam[1] = mid + radius, lam[2] = mid - radius;
  double x = h >= 0.0 ? h + radius : c, y = h >= 0.0 ? c : radius - h;
  const double xy = sqrt(x * x + y * y);
  /* xy = 0: the block is a multiple of I, and any pair will do */
  x = xy > 0.0 ? x / xy : 1.0, y = xy > 0.0 ? y / xy : 0.0;
  for (int i = 0; i < 3; ++i) {
    u[1][i] = x * e[i] + y * f[i];
    u[2][i] = -y * e[i] + x * f[i];
  }
  return 1;
}

/* The projection of symmetric s in closed form into a, on s scaled by its largest entry
 * (no square or product then overflows or underflows whatever s's magnitude): s less its
 * negative eigenvalue's term, or its positive eigenvalue's term alone, or s, or zero,
 * whichever takes fewest terms. 0 (a untouched) where an entry is not finite or a vector is
 * not found. */
static int closed_form_projection3(double s[3][3], double a[3][3]) {
  double m = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m = fmax(m, fabs(s[i][j]));
  if (!(m < INFINITY) || isnan(s[0][0] + s[0][1] + s[0][2] + s[1][1] + s[1][2] + s[2][2])) return 0;
  if (m == 0.0) {
    memset(a, 0, 9 * sizeof(double));
    return 1;
  }
  double t[3][3], lam[3], u[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t[i][j] = s[i][j] / m;
  if (!closed_form_eigensystem3(t, lam, u)) return 0;
  const int negative = (lam[0] < 0.0) + (lam[1] < 0.0) + (lam[2] < 0.0);
  if (negative == 0) {
    memcpy(a, s, 9 * sizeof(double));
  } else if (negative == 3) {
    memset(a, 0, 9 * sizeof(double));
  } else {
    /* the single eigenvalue on its side of zero */
    int single = 0;
    while ((lam[single] < 0.0) != (negative == 1)) ++single;
    const double *w = u[single], l = lam[single];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        a[i][j] = m * (negative == 1 ? t[i][j] - l * w[i] * w[j] : l * w[i] * w[j]);
  }
  /* the terms above are symmetric up to the order of a product's factors: made exactly so */
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) a[j][i] = a[i][j];
  return 1;
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
  /* an indefinite block (compressed and inverted elements: every tet of a collapsed body)
   * in closed form; Jacobi's rotations, three sweeps each, were a sixth of a backward Euler
   * run recovering from a collapse (BENCHMARKS.md). Jacobi remains for what the closed form
   * cannot take: numbers that are not finite, an eigenvector it cannot find. */
  if (closed_form_projection3(s, a)) return;
  double q[3][3];
  jacobi_eigen3(s, q);
  double lam[3] = {fmax(s[0][0], 0.0), fmax(s[1][1], 0.0), fmax(s[2][2], 0.0)};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      a[i][j] = q[i][0] * lam[0] * q[j][0] + q[i][1] * lam[1] * q[j][1] + q[i][2] * lam[2] * q[j][2];
}

piola_material_model piola__stress_parts_model(piola_material_model model) {
  switch (model) {
    case PIOLA_MODEL_MUSCLE:
      return PIOLA_MODEL_NEOHOOKEAN;
    case PIOLA_MODEL_MOONEY_RIVLIN:
      return PIOLA_MODEL_COUNT;
    default:
      return model;
  }
}

void piola__material_stress_and_derivative(const piola_material *material, const double fhat[3],
                                           double phat[3], double dphat[3][3]) {
  /* the default's rise with J (material_threshold_at) can clamp entries above
   * material->threshold */
  const double c = material_threshold_largest(material);
  const piola_material_model parts_model = piola__stress_parts_model(material->model);
  if (fhat[0] >= c && fhat[1] >= c && fhat[2] >= c && parts_model != PIOLA_MODEL_COUNT) {
    /* no entry clamped: every extension term is an exact zero, the parts are the answer */
    material_parts parts;
    material_model_parts(parts_model, material, KERNEL_EXACT_DIVIDE, fhat[0], fhat[1], fhat[2],
                         &parts);
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
