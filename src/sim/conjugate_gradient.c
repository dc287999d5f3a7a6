/* Filtered, preconditioned conjugate gradient; see conjugate_gradient.h. */
#include "sim/conjugate_gradient.h"

#include <math.h>

static double dot(int64_t m, const double *a, const double *b) {
  double s = 0;
  for (int64_t i = 0; i < m; ++i) s += a[i] * b[i];
  return s;
}

static void precondition(const cg_problem *pb, const double *r, double *z) {
  for (int32_t i = 0; i < pb->n; ++i)
    for (int k = 0; k < 3; ++k) z[3 * i + k] = r[3 * i + k] * pb->inverse_mass[i];
}

int32_t piola__cg_solve(const cg_problem *pb, const double *b, double *x, double *work,
                        double *ax) {
  const int64_t m = 3 * (int64_t)pb->n;
  double *r = work, *z = work + m, *p = work + 2 * m, *q = work + 3 * m;
  /* reference size: the filtered right-hand side */
  for (int64_t i = 0; i < m; ++i) r[i] = b[i];
  pb->filter(pb->ctx, r);
  precondition(pb, r, z);
  double bnorm2 = dot(m, r, z);
  pb->apply(pb->ctx, x, q);
  if (ax)
    for (int64_t i = 0; i < m; ++i) ax[i] = q[i];
  for (int64_t i = 0; i < m; ++i) r[i] = b[i] - q[i];
  pb->filter(pb->ctx, r);
  precondition(pb, r, z);
  double rz = dot(m, r, z);
  double tol2 = pb->tolerance * pb->tolerance * bnorm2;
  if (!(bnorm2 > 0) || rz <= tol2) return 0;
  for (int64_t i = 0; i < m; ++i) p[i] = z[i];
  int32_t it = 0;
  while (it < pb->max_iterations) {
    ++it;
    pb->apply(pb->ctx, p, q);
    /* p is filtered (p = S p), so p . S q = p . q: taken before the filter, whose q A x
     * needs */
    double pq = dot(m, p, q);
    if (!(pq > 0)) break; /* not positive definite along p (or zero): stop where we are */
    double alpha = rz / pq;
    if (ax)
      for (int64_t i = 0; i < m; ++i) ax[i] += alpha * q[i];
    pb->filter(pb->ctx, q);
    for (int64_t i = 0; i < m; ++i) {
      x[i] += alpha * p[i];
      r[i] -= alpha * q[i];
    }
    precondition(pb, r, z);
    double rz_new = dot(m, r, z);
    if (rz_new <= tol2 || !isfinite(rz_new)) break;
    double beta = rz_new / rz;
    rz = rz_new;
    for (int64_t i = 0; i < m; ++i) p[i] = z[i] + beta * p[i];
  }
  return it;
}
