/* Aggregation and the tentative prolongator; see multigrid_aggregation.h. */
#include "force/multigrid_aggregation.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"

static double block_norm2(const double *b, int bs) {
  double s = 0;
  for (int k = 0; k < bs; ++k) s += b[k] * b[k];
  return s;
}

/* Squared Frobenius norms of the diagonal blocks (0 where a row has none). */
static void diagonal_norms(const piola__block_sparse *a, double *norm2) {
  const int bs = a->rb * a->cb;
  for (int32_t r = 0; r < a->rows; ++r) {
    norm2[r] = 0;
    for (int32_t k = a->row_start[r]; k < a->row_start[r + 1]; ++k)
      if (a->col[k] == r) norm2[r] = block_norm2(a->values + (size_t)bs * (size_t)k, bs);
  }
}

/* Entry k of row r is a strong coupling (off the diagonal). */
static int strong(const piola__block_sparse *a, const double *diag2, double theta2, int32_t r,
                  int32_t k) {
  const int32_t c = a->col[k];
  if (c == r) return 0;
  const int bs = a->rb * a->cb;
  return block_norm2(a->values + (size_t)bs * (size_t)k, bs) > theta2 * sqrt(diag2[r] * diag2[c]);
}

int32_t piola__multigrid_aggregate(const piola__block_sparse *a, double theta, int32_t *aggregate) {
  const int32_t n = a->rows;
  double *diag2 = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1));
  if (!diag2) return -1;
  diagonal_norms(a, diag2);
  const double theta2 = theta * theta;
  for (int32_t i = 0; i < n; ++i) aggregate[i] = -1;
  int32_t count = 0;
  /* (1) nodes whose strong neighbourhood is untouched */
  for (int32_t i = 0; i < n; ++i) {
    if (aggregate[i] >= 0) continue;
    int any = 0, free_around = 1;
    for (int32_t k = a->row_start[i]; k < a->row_start[i + 1] && free_around; ++k)
      if (strong(a, diag2, theta2, i, k)) any = 1, free_around = aggregate[a->col[k]] < 0;
    if (!any || !free_around) continue;
    aggregate[i] = count;
    for (int32_t k = a->row_start[i]; k < a->row_start[i + 1]; ++k)
      if (strong(a, diag2, theta2, i, k)) aggregate[a->col[k]] = count;
    count++;
  }
  /* (2) the rest join the aggregate of their strongest aggregated neighbour (as it was
   * after step 1, so that joins do not chain) */
  int32_t *joined = malloc(sizeof(int32_t) * (size_t)(n > 0 ? n : 1));
  if (!joined) {
    free(diag2);
    return -1;
  }
  memcpy(joined, aggregate, sizeof(int32_t) * (size_t)n);
  const int bs = a->rb * a->cb;
  for (int32_t i = 0; i < n; ++i) {
    if (aggregate[i] >= 0) continue;
    double best = 0;
    for (int32_t k = a->row_start[i]; k < a->row_start[i + 1]; ++k) {
      if (!strong(a, diag2, theta2, i, k) || aggregate[a->col[k]] < 0) continue;
      const double w = block_norm2(a->values + (size_t)bs * (size_t)k, bs);
      if (w > best) best = w, joined[i] = aggregate[a->col[k]];
    }
  }
  memcpy(aggregate, joined, sizeof(int32_t) * (size_t)n);
  free(joined);
  /* (3) what is left and strongly coupled: new aggregates */
  for (int32_t i = 0; i < n; ++i) {
    if (aggregate[i] >= 0) continue;
    int any = 0;
    for (int32_t k = a->row_start[i]; k < a->row_start[i + 1]; ++k)
      if (strong(a, diag2, theta2, i, k)) {
        any = 1;
        if (aggregate[a->col[k]] < 0) aggregate[a->col[k]] = count;
      }
    if (any) aggregate[i] = count++;
  }
  free(diag2);
  return count;
}

/* Modified Gram-Schmidt with a second pass on the m x 6 matrix q (row-major, in place):
 * q = Q, r = R (6x6, upper triangular) with Q R = the input; a column whose remainder is
 * below 1e-10 of its size is dependent: zero in Q, zero row in R. */
static void orthonormalize(double *q, int32_t m, double r[36]) {
  const int nm = PIOLA_MULTIGRID_MODES;
  memset(r, 0, 36 * sizeof(double));
  for (int j = 0; j < nm; ++j) {
    double size = 0;
    for (int32_t i = 0; i < m; ++i) size += q[nm * i + j] * q[nm * i + j];
    for (int pass = 0; pass < 2; ++pass)
      for (int k = 0; k < j; ++k) {
        double d = 0;
        for (int32_t i = 0; i < m; ++i) d += q[nm * i + k] * q[nm * i + j];
        for (int32_t i = 0; i < m; ++i) q[nm * i + j] -= d * q[nm * i + k];
        r[nm * k + j] += d;
      }
    double left = 0;
    for (int32_t i = 0; i < m; ++i) left += q[nm * i + j] * q[nm * i + j];
    if (!(left > 1e-20 * size) || !(left > 0)) {
      for (int32_t i = 0; i < m; ++i) q[nm * i + j] = 0;
      continue;
    }
    const double norm = sqrt(left);
    r[nm * j + j] = norm;
    for (int32_t i = 0; i < m; ++i) q[nm * i + j] /= norm;
  }
}

piola_status piola__multigrid_tentative(const piola__block_sparse *a, const int32_t *aggregate,
                                        int32_t aggregates, const double *modes,
                                        piola__block_sparse *t, double *coarse_modes) {
  const int32_t n = a->rows;
  const int b = a->rb, nm = PIOLA_MULTIGRID_MODES;
  int64_t members = 0;
  for (int32_t i = 0; i < n; ++i) members += aggregate[i] >= 0;
  PIOLA_TRY(piola__block_sparse_alloc(t, n, aggregates, b, nm, members));
  /* the nodes of each aggregate, by counting sort (in row order within one) */
  int32_t *start = calloc((size_t)aggregates + 1, sizeof(int32_t));
  int32_t *node = malloc(sizeof(int32_t) * (size_t)(members > 0 ? members : 1));
  int32_t longest = 1;
  if (start && node) {
    for (int32_t i = 0; i < n; ++i)
      if (aggregate[i] >= 0) start[aggregate[i] + 1]++;
    for (int32_t g = 0; g < aggregates; ++g) {
      if (start[g + 1] > longest) longest = start[g + 1];
      start[g + 1] += start[g];
    }
  }
  double *q = malloc(sizeof(double) * (size_t)nm * (size_t)b * (size_t)longest);
  int32_t *next = malloc(sizeof(int32_t) * ((size_t)aggregates + 1));
  if (!start || !node || !q || !next) {
    free(start), free(node), free(q), free(next);
    piola__block_sparse_free(t);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "multigrid: out of memory");
  }
  memcpy(next, start, sizeof(int32_t) * (size_t)aggregates);
  for (int32_t i = 0; i < n; ++i)
    if (aggregate[i] >= 0) node[next[aggregate[i]]++] = i;
  /* T has one block per aggregated row, in the row's aggregate column */
  int32_t at = 0;
  for (int32_t i = 0; i < n; ++i) {
    if (aggregate[i] >= 0) t->col[at] = aggregate[i];
    at += aggregate[i] >= 0;
    t->row_start[i + 1] = at;
  }
  const size_t tb = (size_t)(b * nm);
  for (int32_t g = 0; g < aggregates; ++g) {
    const int32_t m = start[g + 1] - start[g];
    for (int32_t p = 0; p < m; ++p)
      memcpy(q + tb * (size_t)p, modes + tb * (size_t)node[start[g] + p], tb * sizeof(double));
    orthonormalize(q, m * b, coarse_modes + 36 * (size_t)g);
    for (int32_t p = 0; p < m; ++p) {
      const int32_t i = node[start[g] + p];
      memcpy(t->values + tb * (size_t)t->row_start[i], q + tb * (size_t)p, tb * sizeof(double));
    }
  }
  free(start), free(node), free(q), free(next);
  return PIOLA_OK;
}
