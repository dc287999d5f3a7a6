/* Block IC(0) of the implicit step's system matrix; see stiffness_incomplete_cholesky.h.
 *
 * Right-looking on the edge pattern: each vertex i, in row order, takes its pivot D_i (its
 * accumulated diagonal block), its row U_ij = D_i^-1 W_ij from the accumulated edge blocks
 * W_ij, and then subtracts U_ia^T D_i U_ib = U_ia^T W_ib from every later block (a, b) that
 * the pattern holds (a = b: the diagonal; edges missing from the pattern are dropped: the
 * "(0)"). Every contribution to a row comes from rows before it, so each is complete when
 * its row is reached. */
#include "force/stiffness_incomplete_cholesky.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "math/mat3.h"

/* The upper edge of row `row` to vertex `col`, or -1 (a row's columns increase). */
static int32_t find_edge(const piola__damping_matrix *d, int32_t row, int32_t col) {
  int32_t lo = d->row_start[row], hi = d->row_start[row + 1];
  while (lo < hi) {
    int32_t mid = lo + (hi - lo) / 2;
    if (d->col[mid] < col) lo = mid + 1;
    else hi = mid;
  }
  return lo < d->row_start[row + 1] && d->col[lo] == col ? lo : -1;
}

piola_status piola__incomplete_cholesky_init(piola__incomplete_cholesky *f,
                                             const piola_elastic_body *body) {
  memset(f, 0, sizeof *f);
  const piola__damping_matrix *d = &body->damping;
  const int32_t n = body->vertex_count;
  f->vertex_count = n, f->edge_count = d->edge_count;
  int64_t pairs = 0;
  int32_t longest = 1;
  for (int32_t r = 0; r < n; ++r) {
    int64_t k = d->row_start[r + 1] - d->row_start[r];
    pairs += k * (k - 1) / 2;
    if (k > longest) longest = (int32_t)k;
  }
  if (pairs > INT32_MAX) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "incomplete Cholesky: pattern too large");
  f->pair_start = malloc(sizeof(int32_t) * ((size_t)n + 1));
  f->pair_edge = malloc(sizeof(int32_t) * (size_t)(pairs > 0 ? pairs : 1));
  f->upper = malloc(sizeof(double) * 9 * (size_t)(d->edge_count > 0 ? d->edge_count : 1));
  f->inverse_pivot = malloc(sizeof(double) * 9 * (size_t)(n > 0 ? n : 1));
  f->scratch = malloc(sizeof(double) * 9 * (size_t)longest);
  if (!f->pair_start || !f->pair_edge || !f->upper || !f->inverse_pivot || !f->scratch) {
    piola__incomplete_cholesky_free(f);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "incomplete Cholesky: out of memory");
  }
  /* pair (p, q), p < q in the row's list: the edge between their vertices, stored as e when
   * p's vertex is ranked first and as -(e + 2) when q's is; -1 when the pattern lacks it */
  int32_t at = 0;
  for (int32_t r = 0; r < n; ++r) {
    f->pair_start[r] = at;
    for (int32_t p = d->row_start[r]; p < d->row_start[r + 1]; ++p)
      for (int32_t q = p + 1; q < d->row_start[r + 1]; ++q) {
        const int32_t a = d->col[p], b = d->col[q];
        int32_t e;
        if (d->rank[a] < d->rank[b]) {
          e = find_edge(d, d->rank[a], b);
        } else {
          e = find_edge(d, d->rank[b], a);
          if (e >= 0) e = -(e + 2);
        }
        f->pair_edge[at++] = e;
      }
  }
  f->pair_start[n] = at;
  return PIOLA_OK;
}

void piola__incomplete_cholesky_free(piola__incomplete_cholesky *f) {
  free(f->pair_start), free(f->pair_edge), free(f->upper), free(f->inverse_pivot);
  free(f->scratch);
  memset(f, 0, sizeof *f);
}

/* True when the symmetric block a is positive definite (leading minors). */
static int positive_definite(const double a[9]) {
  const double m1 = a[0], m2 = a[0] * a[4] - a[1] * a[3];
  const double m3 = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
                    a[2] * (a[3] * a[7] - a[4] * a[6]);
  return m1 > 0 && m2 > 0 && m3 > 0 && isfinite(m3);
}

/* c = a b (3x3, row-major) */
static inline void mul(const double *a, const double *b, double *c) {
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
      c[3 * r + k] = a[3 * r] * b[k] + a[3 * r + 1] * b[3 + k] + a[3 * r + 2] * b[6 + k];
}

/* c -= a^T b */
static inline void sub_transpose_mul(const double *a, const double *b, double *c) {
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
      c[3 * r + k] -= a[r] * b[k] + a[3 + r] * b[3 + k] + a[6 + r] * b[6 + k];
}

/* One attempt at factoring with the diagonal blocks scaled by 1 + shift. Returns 0 when a
 * pivot is not positive definite (breakdown) and give_up is 0; with give_up such a pivot
 * takes its own shifted block and the factorization goes on (counted in fallback_rows). */
static int factor_shifted(piola__incomplete_cholesky *f, const piola__stiffness_matrix *matrix,
                          const piola_elastic_body *body, piola__vertex_constraint *constraint,
                          const void *context, double shift, int give_up) {
  const piola__damping_matrix *d = &body->damping;
  const int32_t n = body->vertex_count;
  /* accumulators: pivots in inverse_pivot, edge blocks W_ij = S_i A_ij S_j in upper
   * (A_ij = -S_ij, the edge-difference form of stiffness_matrix.h) */
  for (int32_t i = 0; i < n; ++i) {
    const piola__vertex_projection s = piola__vertex_projection_of(constraint, context, i);
    double *a = f->inverse_pivot + 9 * (size_t)i;
    piola__filtered_diagonal(&s, matrix->diagonal + 9 * (size_t)i, a);
    for (int c = 0; c < 9; ++c) a[c] *= 1 + shift;
  }
  for (int32_t r = 0; r < n; ++r) {
    const piola__vertex_projection si =
        piola__vertex_projection_of(constraint, context, d->order[r]);
    for (int32_t e = d->row_start[r]; e < d->row_start[r + 1]; ++e) {
      double *w = f->upper + 9 * (size_t)e;
      for (int c = 0; c < 9; ++c) w[c] = -matrix->blocks[9 * (size_t)e + c];
      const piola__vertex_projection sj =
          piola__vertex_projection_of(constraint, context, d->col[e]);
      piola__project_rows(&si, w, 3);
      piola__project_columns(&sj, w);
    }
  }
  int32_t fallbacks = 0;
  for (int32_t r = 0; r < n; ++r) {
    const int32_t i = d->order[r];
    double *pivot = f->inverse_pivot + 9 * (size_t)i, dblock[9];
    for (int rr = 0; rr < 3; ++rr)
      for (int c = 0; c < 3; ++c) dblock[3 * rr + c] = 0.5 * (pivot[3 * rr + c] + pivot[3 * c + rr]);
    if (!positive_definite(dblock)) {
      if (!give_up) return 0;
      const piola__vertex_projection s = piola__vertex_projection_of(constraint, context, i);
      piola__filtered_diagonal(&s, matrix->diagonal + 9 * (size_t)i, dblock);
      for (int c = 0; c < 9; ++c) dblock[c] *= 1 + shift;
      fallbacks++;
    }
    piola__invert3_or_diagonal(dblock, pivot);
    const int32_t e0 = d->row_start[r], e1 = d->row_start[r + 1];
    for (int32_t e = e0; e < e1; ++e) {
      double *u = f->upper + 9 * (size_t)e, *w = f->scratch + 9 * (size_t)(e - e0);
      memcpy(w, u, 9 * sizeof(double));
      mul(pivot, w, u);
      /* the later pivot: D_a -= U_ia^T W_ia */
      sub_transpose_mul(u, w, f->inverse_pivot + 9 * (size_t)d->col[e]);
    }
    int32_t at = f->pair_start[r];
    for (int32_t p = e0; p < e1; ++p)
      for (int32_t q = p + 1; q < e1; ++q) {
        const int32_t e = f->pair_edge[at++];
        if (e == -1) continue;
        if (e >= 0)
          sub_transpose_mul(f->upper + 9 * (size_t)p, f->scratch + 9 * (size_t)(q - e0),
                            f->upper + 9 * (size_t)e);
        else
          sub_transpose_mul(f->upper + 9 * (size_t)q, f->scratch + 9 * (size_t)(p - e0),
                            f->upper + 9 * (size_t)(-e - 2));
      }
  }
  f->fallback_rows = fallbacks;
  return 1;
}

void piola__incomplete_cholesky_factor(piola__incomplete_cholesky *f,
                                       const piola__stiffness_matrix *matrix,
                                       const piola_elastic_body *body,
                                       piola__vertex_constraint *constraint,
                                       const void *context) {
  /* Manteuffel's shifted factorization: on breakdown the diagonal grows by a factor
   * 1 + shift and the factorization starts over, the shift quadrupling from
   * PIOLA_IC_FIRST_SHIFT; the next factorization starts one step below the shift that
   * worked (the matrices of successive Newton iterations are alike), and from 0 again once
   * that reaches the first shift. */
  double shift = f->shift > PIOLA_IC_FIRST_SHIFT ? 0.25 * f->shift : 0.0;
  f->restarts = 0;
  while (!factor_shifted(f, matrix, body, constraint, context, shift,
                         shift >= PIOLA_IC_LAST_SHIFT)) {
    shift = shift > 0 ? 4 * shift : PIOLA_IC_FIRST_SHIFT;
    f->restarts++;
  }
  f->shift = shift;
}

void piola__incomplete_cholesky_apply(const piola__incomplete_cholesky *f,
                                      const piola_elastic_body *body, const double *r,
                                      double *z) {
  const piola__damping_matrix *d = &body->damping;
  const int32_t n = body->vertex_count;
  /* U^T y = r, rows in order: y_i = r_i - sum over earlier neighbours k of U_ki^T y_k */
  for (int32_t row = 0; row < n; ++row) {
    const int32_t i = d->order[row];
    double y0 = r[3 * i], y1 = r[3 * i + 1], y2 = r[3 * i + 2];
    for (int32_t k = d->lower_start[row]; k < d->lower_start[row + 1]; ++k) {
      const double *u = f->upper + 9 * (size_t)d->lower_edge[k];
      const double *yk = z + 3 * (size_t)d->lower_col[k];
      y0 -= u[0] * yk[0] + u[3] * yk[1] + u[6] * yk[2];
      y1 -= u[1] * yk[0] + u[4] * yk[1] + u[7] * yk[2];
      y2 -= u[2] * yk[0] + u[5] * yk[1] + u[8] * yk[2];
    }
    z[3 * i] = y0, z[3 * i + 1] = y1, z[3 * i + 2] = y2;
  }
  /* U z = D^-1 y, rows backwards: z_i = D_i^-1 y_i - sum over later neighbours j of U_ij z_j */
  for (int32_t row = n - 1; row >= 0; --row) {
    const int32_t i = d->order[row];
    const double *b = f->inverse_pivot + 9 * (size_t)i, *y = z + 3 * i;
    double z0 = b[0] * y[0] + b[1] * y[1] + b[2] * y[2];
    double z1 = b[3] * y[0] + b[4] * y[1] + b[5] * y[2];
    double z2 = b[6] * y[0] + b[7] * y[1] + b[8] * y[2];
    for (int32_t k = d->row_start[row]; k < d->row_start[row + 1]; ++k) {
      const double *u = f->upper + 9 * (size_t)k, *zj = z + 3 * (size_t)d->col[k];
      z0 -= u[0] * zj[0] + u[1] * zj[1] + u[2] * zj[2];
      z1 -= u[3] * zj[0] + u[4] * zj[1] + u[5] * zj[2];
      z2 -= u[6] * zj[0] + u[7] * zj[1] + u[8] * zj[2];
    }
    z[3 * i] = z0, z[3 * i + 1] = z1, z[3 * i + 2] = z2;
  }
}
