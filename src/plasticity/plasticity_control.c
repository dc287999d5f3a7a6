/* Plasticity control: goal logarithms, the segment choice and symmetric log/exp (see
 * plasticity_control.h). */
#include "plasticity/plasticity_control.h"

#include <math.h>

#include "common/status_report.h"
#include "piola/diagonalize.h"

static piola_mat3 load(const double a[9]) {
  piola_mat3 m;
  for (int k = 0; k < 9; ++k) m.m[k / 3][k % 3] = a[k];
  return m;
}

/* l = W diag(d) W^T as 6 numbers */
static void sym_from_eigen(const piola_mat3 *w, const double d[3], double l[6]) {
  static const int rows[6] = {0, 1, 2, 0, 0, 1}, cols[6] = {0, 1, 2, 1, 2, 2};
  for (int k = 0; k < 6; ++k) {
    int i = rows[k], j = cols[k];
    l[k] = w->m[i][0] * d[0] * w->m[j][0] + w->m[i][1] * d[1] * w->m[j][1] +
           w->m[i][2] * d[2] * w->m[j][2];
  }
}

static void full_from_eigen(const piola_mat3 *w, const double d[3], double a[9]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      a[3 * i + j] = w->m[i][0] * d[0] * w->m[j][0] + w->m[i][1] * d[1] * w->m[j][1] +
                     w->m[i][2] * d[2] * w->m[j][2];
}

static double floor_log(double s) { return log(s > 1e-300 ? s : 1e-300); }

void piola__plastic_log_from_fp_inverse(const double a[9], double l[6]) {
  piola_mat3 m = load(a), w, q;
  piola_vec3 s;
  (void)piola_diagonalize3(&m, &w, &s, &q);
  double d[3] = {-floor_log(s.x), -floor_log(s.y), -floor_log(s.z)};
  sym_from_eigen(&w, d, l);
}

/* eigenvalues mu and eigenvectors (columns of w) of the symmetric l */
static void sym_eigen(const double l[6], double mu[3], piola_mat3 *w) {
  double norm = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2] +
                     2.0 * (l[3] * l[3] + l[4] * l[4] + l[5] * l[5]));
  double c = norm + 1.0;
  piola_mat3 m = {{{l[0] + c, l[3], l[4]}, {l[3], l[1] + c, l[5]}, {l[4], l[5], l[2] + c}}}, u;
  piola_vec3 s;
  (void)piola_diagonalize3(&m, &u, &s, w);
  mu[0] = s.x - c, mu[1] = s.y - c, mu[2] = s.z - c;
}

static double clampd(double v, double lim) { return v < -lim ? -lim : (v > lim ? lim : v); }

double piola__plastic_fp_inverse_from_log(const double l[6], double limit, double a[9]) {
  double mu[3], d[3], largest = 0;
  piola_mat3 w;
  sym_eigen(l, mu, &w);
  for (int i = 0; i < 3; ++i) {
    mu[i] = clampd(mu[i], limit);
    largest = fmax(largest, fabs(mu[i]));
    d[i] = exp(-mu[i]);
  }
  full_from_eigen(&w, d, a);
  return largest;
}

piola_status piola__plastic_goal_log(const double fp[9], double limit, double l[6]) {
  piola_mat3 m = load(fp), w, q;
  piola_vec3 s;
  PIOLA_TRY(piola_diagonalize3(&m, &w, &s, &q));
  if (!(s.z > 0)) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "goal deformation is flat or inverted (det %g)",
                                    s.x * s.y * s.z);
  /* Fp = (W Q^T)(Q Sigma Q^T): the rotation-free part is Q Sigma Q^T */
  double d[3] = {clampd(log(s.x), limit), clampd(log(s.y), limit), clampd(log(s.z), limit)};
  sym_from_eigen(&q, d, l);
  return PIOLA_OK;
}

static double sym_dot(const double a[6], const double b[6]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + 2.0 * (a[3] * b[3] + a[4] * b[4] + a[5] * b[5]);
}

double piola__plastic_sym_distance(const double a[6], const double b[6]) {
  double d[6];
  for (int k = 0; k < 6; ++k) d[k] = a[k] - b[k];
  return sqrt(sym_dot(d, d));
}

void piola__plastic_control_select(const double lo[6], const double lt[6], const double lg[6],
                                   double pull, double out[6]) {
  double seg[6], to_goal[6];
  for (int k = 0; k < 6; ++k) seg[k] = lt[k] - lo[k], to_goal[k] = lg[k] - lo[k];
  double len2 = sym_dot(seg, seg), t = 0;
  if (len2 > 0) t = sym_dot(seg, to_goal) / len2;
  t = t < 0 ? 0 : (t > 1 ? 1 : t);
  double p[6];
  for (int k = 0; k < 6; ++k) p[k] = lo[k] + t * seg[k];
  for (int k = 0; k < 6; ++k) out[k] = p[k] + pull * (lg[k] - p[k]);
}
