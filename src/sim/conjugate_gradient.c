/* Filtered, preconditioned conjugate gradient; see conjugate_gradient.h.
 *
 * Speed. Per iteration the operator apply dominates, but the vector work around it was ~10%
 * of a step on the 20,186-vertex torus: eight serial passes over 3n doubles (filter, dot,
 * two axpys, the preconditioner into z, dot, the new direction). Here it is two fused
 * passes after the apply (p . q; then A x, filter, x, r and r . M^-1 r together) and one
 * for the new direction, with z never stored (M^-1 r is formed where it is used). The
 * passes split the nodes into CG_CHUNKS fixed ranges, whatever the thread count; each
 * range sums its part of a dot product in index order and the parts are added in range
 * order, so results are bit-identical for any number of threads. */
#include "sim/conjugate_gradient.h"

#include <math.h>

#include "piola/threads.h"

enum { CG_CHUNKS = 16 };
/* below this many nodes the passes run on one thread (a parallel region costs more) */
#define CG_PARALLEL_MIN_NODES 4096

static int32_t chunk_begin(int32_t n, int c) { return (int32_t)((int64_t)n * c / CG_CHUNKS); }

static double sum_parts(const double part[CG_CHUNKS]) {
  double s = 0;
  for (int c = 0; c < CG_CHUNKS; ++c) s += part[c];
  return s;
}

static double dot(int32_t n, const double *a, const double *b) {
  double part[CG_CHUNKS];
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) if (n >= CG_PARALLEL_MIN_NODES)
  for (int c = 0; c < CG_CHUNKS; ++c) {
    double s = 0;
    for (int64_t i = 3 * (int64_t)chunk_begin(n, c); i < 3 * (int64_t)chunk_begin(n, c + 1); ++i) s += a[i] * b[i];
    part[c] = s;
  }
  return sum_parts(part);
}

int32_t piola__cg_solve(const cg_problem *pb, const double *b, double *x, double *work,
                        double *ax) {
  const int32_t n = pb->n;
  const int64_t m = 3 * (int64_t)n;
  const double *inverse_mass = pb->inverse_mass;
  double *r = work, *p = work + m, *q = work + 2 * m;
  const double *q0 = pb->given_ax;
  if (!q0) {
    pb->apply(pb->ctx, x, q);
    q0 = q;
  }
  /* one pass: the copies of A x0, r = S (b - A x0), its size and the first direction */
  double part0[CG_CHUNKS];
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) if (n >= CG_PARALLEL_MIN_NODES)
  for (int c = 0; c < CG_CHUNKS; ++c) {
    const int32_t i0 = chunk_begin(n, c), i1 = chunk_begin(n, c + 1);
    for (int64_t j = 3 * (int64_t)i0; j < 3 * (int64_t)i1; ++j) {
      if (ax) ax[j] = q0[j];
      if (pb->initial_ax && pb->initial_ax != q0) pb->initial_ax[j] = q0[j];
      r[j] = b[j] - q0[j];
    }
    pb->filter(pb->ctx, r, i0, i1);
    double sum = 0;
    for (int32_t i = i0; i < i1; ++i) {
      const double *ri = r + 3 * i;
      sum += (ri[0] * ri[0] + ri[1] * ri[1] + ri[2] * ri[2]) * inverse_mass[i];
      for (int k = 0; k < 3; ++k) p[3 * i + k] = ri[k] * inverse_mass[i];
    }
    part0[c] = sum;
  }
  /* reference size: the residual of the guess, i.e. the correction still to be made (not
   * b, which a moving body's momentum dominates; see the header) */
  double rz = sum_parts(part0);
  double tol2 = pb->tolerance * pb->tolerance * rz;
  if (!(rz > 0) || !isfinite(rz)) return 0;
  int32_t it = 0;
  while (it < pb->max_iterations) {
    ++it;
    pb->apply(pb->ctx, p, q);
    /* p is filtered (p = S p), so p . S q = p . q: taken before the filter, whose q A x
     * needs */
    double pq = dot(n, p, q);
    if (!(pq > 0)) break; /* not positive definite along p (or zero): stop where we are */
    double alpha = rz / pq;
    double part[CG_CHUNKS];
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) if (n >= CG_PARALLEL_MIN_NODES)
    for (int c = 0; c < CG_CHUNKS; ++c) {
      const int32_t i0 = chunk_begin(n, c), i1 = chunk_begin(n, c + 1);
      if (ax)
        for (int64_t j = 3 * (int64_t)i0; j < 3 * (int64_t)i1; ++j) ax[j] += alpha * q[j];
      pb->filter(pb->ctx, q, i0, i1);
      double s = 0;
      for (int32_t i = i0; i < i1; ++i)
        for (int k = 0; k < 3; ++k) {
          int64_t j = 3 * (int64_t)i + k;
          x[j] += alpha * p[j];
          r[j] -= alpha * q[j];
          s += r[j] * r[j] * inverse_mass[i];
        }
      part[c] = s;
    }
    double rz_new = sum_parts(part);
    if (rz_new <= tol2 || !isfinite(rz_new)) break;
    double beta = rz_new / rz;
    rz = rz_new;
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) if (n >= CG_PARALLEL_MIN_NODES)
    for (int c = 0; c < CG_CHUNKS; ++c)
      for (int32_t i = chunk_begin(n, c); i < chunk_begin(n, c + 1); ++i)
        for (int k = 0; k < 3; ++k) p[3 * i + k] = r[3 * i + k] * inverse_mass[i] + beta * p[3 * i + k];
  }
  return it;
}
