/* Smoothed aggregation multigrid; see stiffness_multigrid.h. */
#include "force/stiffness_multigrid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "force/multigrid_aggregation.h"
#include "piola/threads.h"

/* power iterations for rho: at a setup from a fixed start, at a refresh from the last
 * iterate (rho then only grows within a step: an overestimate only widens the smoother's
 * interval, an underestimate could make it amplify the top of the spectrum) */
enum { RANGES = 16, POWER_ITERATIONS = 12, REFRESH_POWER_ITERATIONS = 3, LAST_LEVEL_SMOOTHING = 8 };
/* below this many rows the vector passes run on one thread */
#define MULTIGRID_PARALLEL_MIN_ROWS 4096
/* the Chebyshev interval [rho / CHEBYSHEV_RATIO, CHEBYSHEV_UPPER rho]: the upper bound
 * covers the power iteration's underestimate */
#define CHEBYSHEV_RATIO 30.0
#define CHEBYSHEV_UPPER 1.1

/* ------------------------------------------------------------------ small dense blocks */

/* L L^T = a (n x n, row-major, the lower triangle read) in place; a pivot that is not
 * positive (rounding on a semi-definite matrix) takes a tiny fraction of its diagonal, so
 * the factor stays finite and the product symmetric positive definite. */
static void cholesky_in_place(double *a, int32_t n) {
  for (int32_t j = 0; j < n; ++j) {
    const double original = a[(size_t)n * j + j];
    double s = original;
    for (int32_t k = 0; k < j; ++k) s -= a[(size_t)n * j + k] * a[(size_t)n * j + k];
    const double floor = 1e-12 * (original > 0 ? original : 1.0);
    const double pivot = sqrt(s > floor ? s : floor);
    a[(size_t)n * j + j] = pivot;
    for (int32_t i = j + 1; i < n; ++i) {
      double t = a[(size_t)n * i + j];
      for (int32_t k = 0; k < j; ++k) t -= a[(size_t)n * i + k] * a[(size_t)n * j + k];
      a[(size_t)n * i + j] = t / pivot;
    }
    for (int32_t i = 0; i < j; ++i) a[(size_t)n * i + j] = 0;
  }
}

/* x = (L L^T)^-1 x */
static void cholesky_solve(const double *l, int32_t n, double *x) {
  for (int32_t i = 0; i < n; ++i) {
    double s = x[i];
    for (int32_t k = 0; k < i; ++k) s -= l[(size_t)n * i + k] * x[k];
    x[i] = s / l[(size_t)n * i + i];
  }
  for (int32_t i = n - 1; i >= 0; --i) {
    double s = x[i];
    for (int32_t k = i + 1; k < n; ++k) s -= l[(size_t)n * k + i] * x[k];
    x[i] = s / l[(size_t)n * i + i];
  }
}

/* inv = a^-1 for a symmetric positive definite b x b block (b <= 6), by its Cholesky
 * factor. */
static void invert_block(const double *a, int b, double *inv) {
  double l[36];
  for (int i = 0; i < b; ++i)
    for (int j = 0; j < b; ++j) l[b * i + j] = 0.5 * (a[b * i + j] + a[b * j + i]);
  cholesky_in_place(l, b);
  for (int c = 0; c < b; ++c) {
    double e[6] = {0, 0, 0, 0, 0, 0};
    e[c] = 1;
    cholesky_solve(l, b, e);
    for (int r = 0; r < b; ++r) inv[b * r + c] = e[r];
  }
}

/* The entry of row r's diagonal block (columns increase in a row). */
static int32_t diagonal_entry(const piola__block_sparse *a, int32_t r) {
  for (int32_t k = a->row_start[r]; k < a->row_start[r + 1]; ++k)
    if (a->col[k] == r) return k;
  return -1;
}

/* ------------------------------------------------------------------ level 0 */

typedef struct entry_key {
  int32_t col, edge;
  uint8_t transposed;
} entry_key;

static int compare_entry(const void *a, const void *b) {
  const int32_t x = ((const entry_key *)a)->col, y = ((const entry_key *)b)->col;
  return (x > y) - (x < y);
}

static void level_free(piola__multigrid_level *l) {
  piola__block_sparse_free(&l->a), piola__block_sparse_free(&l->p);
  piola__block_sparse_free(&l->pt);
  free(l->inverse_diagonal), free(l->x), free(l->f), free(l->r), free(l->d), free(l->q);
  free(l->mode);
  memset(l, 0, sizeof *l);
}

/* The level's diagonal inverses and work vectors for its a. */
static piola_status level_vectors(piola__multigrid_level *l) {
  const size_t n = (size_t)(l->a.rows > 0 ? l->a.rows : 1), b = (size_t)l->a.rb;
  l->inverse_diagonal = malloc(sizeof(double) * n * b * b);
  l->x = malloc(sizeof(double) * n * b), l->f = malloc(sizeof(double) * n * b);
  l->r = malloc(sizeof(double) * n * b), l->d = malloc(sizeof(double) * n * b);
  l->q = malloc(sizeof(double) * n * b), l->mode = malloc(sizeof(double) * n * b);
  if (!l->inverse_diagonal || !l->x || !l->f || !l->r || !l->d || !l->q || !l->mode)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "multigrid: out of memory");
  return PIOLA_OK;
}

piola_status piola__multigrid_init(piola__multigrid *mg, const piola_elastic_body *body) {
  memset(mg, 0, sizeof *mg);
  const piola__damping_matrix *d = &body->damping;
  const int32_t n = body->vertex_count;
  mg->vertex_count = n;
  const int64_t entries = (int64_t)n + 2 * (int64_t)d->edge_count;
  piola__multigrid_level *l0 = &mg->level[0];
  piola_status status = piola__block_sparse_alloc(&l0->a, n, n, 3, 3, entries);
  int32_t longest = 1;
  for (int32_t r = 0; r < n; ++r) {
    const int32_t k =
        1 + d->row_start[r + 1] - d->row_start[r] + d->lower_start[r + 1] - d->lower_start[r];
    if (k > longest) longest = k;
  }
  entry_key *row = malloc(sizeof(entry_key) * (size_t)longest);
  mg->entry_edge = malloc(sizeof(int32_t) * (size_t)(entries > 0 ? entries : 1));
  mg->entry_transposed = malloc((size_t)(entries > 0 ? entries : 1));
  if (status == PIOLA_OK && (!row || !mg->entry_edge || !mg->entry_transposed))
    status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "multigrid: out of memory");
  if (status == PIOLA_OK) status = level_vectors(l0);
  if (status != PIOLA_OK) {
    free(row);
    piola__multigrid_free(mg);
    return status;
  }
  /* row r is vertex order[r]; its entries: the diagonal, the upper edges, the lower edges
   * (transposed), sorted by the other vertex's row */
  int32_t at = 0;
  for (int32_t r = 0; r < n; ++r) {
    int32_t count = 0;
    row[count++] = (entry_key){r, -1, 0};
    for (int32_t k = d->row_start[r]; k < d->row_start[r + 1]; ++k)
      row[count++] = (entry_key){d->rank[d->col[k]], k, 0};
    for (int32_t k = d->lower_start[r]; k < d->lower_start[r + 1]; ++k)
      row[count++] = (entry_key){d->rank[d->lower_col[k]], d->lower_edge[k], 1};
    qsort(row, (size_t)count, sizeof(entry_key), compare_entry);
    for (int32_t k = 0; k < count; ++k, ++at) {
      l0->a.col[at] = row[k].col;
      mg->entry_edge[at] = row[k].edge;
      mg->entry_transposed[at] = row[k].transposed;
    }
    l0->a.row_start[r + 1] = at;
  }
  free(row);
  mg->level_count = 1;
  return PIOLA_OK;
}

/* Frees the levels below level 0 and level 0's prolongator. */
static void free_coarse_levels(piola__multigrid *mg) {
  for (int k = 1; k < PIOLA_MULTIGRID_MAX_LEVELS; ++k) level_free(&mg->level[k]);
  piola__block_sparse_free(&mg->level[0].p), piola__block_sparse_free(&mg->level[0].pt);
  free(mg->coarse_factor);
  mg->coarse_factor = NULL, mg->coarse_size = 0, mg->level_count = 1;
}

void piola__multigrid_free(piola__multigrid *mg) {
  free_coarse_levels(mg);
  level_free(&mg->level[0]);
  free(mg->entry_edge), free(mg->entry_transposed);
  memset(mg, 0, sizeof *mg);
}

typedef struct fill_pass {
  piola__multigrid *mg;
  const piola__stiffness_matrix *matrix;
  const piola__damping_matrix *d;
  const piola__vertex_projection *s; /* per row */
} fill_pass;

/* Rows r0 .. r1 - 1 of level 0: S_i A_ij S_j, the filtered diagonal blocks. */
static void fill_rows(const fill_pass *c, int32_t r0, int32_t r1) {
  piola__block_sparse *a = &c->mg->level[0].a;
  for (int32_t r = r0; r < r1; ++r) {
    for (int32_t k = a->row_start[r]; k < a->row_start[r + 1]; ++k) {
      double *out = a->values + 9 * (size_t)k;
      const int32_t e = c->mg->entry_edge[k];
      if (e < 0) {
        piola__filtered_diagonal(&c->s[r], c->matrix->diagonal + 9 * (size_t)c->d->order[r], out);
        continue;
      }
      const double *blk = c->matrix->blocks + 9 * (size_t)e;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          out[3 * i + j] = -(c->mg->entry_transposed[k] ? blk[3 * j + i] : blk[3 * i + j]);
      piola__project_rows(&c->s[r], out, 3);
      piola__project_columns(&c->s[a->col[k]], out);
    }
  }
}

/* ------------------------------------------------------------------ per-level passes */

/* A pass over a level's rows; each row's unknowns are touched by one thread only. */
typedef struct vector_pass {
  const piola__multigrid_level *l;
  int kind;
  double c1, c2;
} vector_pass;

enum {
  PASS_INVERT_DIAGONAL, /* inverse_diagonal from a's diagonal blocks */
  PASS_START,           /* r = D^-1 (f - q), d = c2 r, x = d (c1 = 0) or x += d (c1 != 0) */
  PASS_CHEBYSHEV,       /* r -= D^-1 q (q = A d), d = c1 d + c2 r, x += d */
  PASS_RESIDUAL         /* r = f - q (q = A x) */
};

/* Rows r0 .. r1 - 1 of one of the passes but PASS_INVERT_DIAGONAL, for blocks of B: always
 * inlined with B and KIND constants (vector_rows), so the block loops unroll and the kind's
 * branches fold; written generically they were a quarter of a V-cycle on the rubber torus of
 * BENCHMARKS.md. */
static inline __attribute__((always_inline)) void pass_rows(const vector_pass *c, int32_t r0,
                                                            int32_t r1, const int b,
                                                            const int kind) {
  const piola__multigrid_level *l = c->l;
  const int bb = b * b;
  for (int32_t row = r0; row < r1; ++row) {
    const double *dinv = l->inverse_diagonal + (size_t)bb * (size_t)row;
    double *x = l->x + (size_t)b * row, *f = l->f + (size_t)b * row;
    double *r = l->r + (size_t)b * row, *d = l->d + (size_t)b * row;
    const double *q = l->q + (size_t)b * row;
    if (kind == PASS_RESIDUAL) {
      for (int i = 0; i < b; ++i) r[i] = f[i] - q[i];
      continue;
    }
    double v[6];
    for (int i = 0; i < b; ++i) v[i] = kind == PASS_START ? f[i] - q[i] : q[i];
    for (int i = 0; i < b; ++i) {
      double s = 0;
      for (int j = 0; j < b; ++j) s += dinv[b * i + j] * v[j];
      if (kind == PASS_START) {
        r[i] = s;
        d[i] = c->c2 * s;
        x[i] = c->c1 != 0 ? x[i] + d[i] : d[i];
      } else {
        r[i] -= s;
      }
    }
    if (kind == PASS_CHEBYSHEV)
      for (int i = 0; i < b; ++i) d[i] = c->c1 * d[i] + c->c2 * r[i], x[i] += d[i];
  }
}

/* pass_rows for blocks of B (a constant, or the level's block size), each kind its own
 * instance */
#define PASS_ROWS(NAME, B)                                                      \
  static void NAME(const vector_pass *c, int32_t r0, int32_t r1) {              \
    switch (c->kind) {                                                          \
      case PASS_START: pass_rows(c, r0, r1, B, PASS_START); break;              \
      case PASS_CHEBYSHEV: pass_rows(c, r0, r1, B, PASS_CHEBYSHEV); break;      \
      default: pass_rows(c, r0, r1, B, PASS_RESIDUAL); break;                   \
    }                                                                           \
  }

PASS_ROWS(pass_rows_3, 3)
PASS_ROWS(pass_rows_6, 6)
PASS_ROWS(pass_rows_any, c->l->a.rb)

static void vector_rows(const vector_pass *c, int32_t r0, int32_t r1) {
  const piola__multigrid_level *l = c->l;
  const int b = l->a.rb, bb = b * b;
  if (c->kind == PASS_INVERT_DIAGONAL) {
    for (int32_t row = r0; row < r1; ++row) {
      double *dinv = l->inverse_diagonal + (size_t)bb * (size_t)row;
      const int32_t k = diagonal_entry(&l->a, row);
      if (k >= 0)
        invert_block(l->a.values + (size_t)bb * (size_t)k, b, dinv);
      else
        memset(dinv, 0, sizeof(double) * (size_t)bb);
    }
    return;
  }
  if (b == 3)
    pass_rows_3(c, r0, r1);
  else if (b == 6)
    pass_rows_6(c, r0, r1);
  else
    pass_rows_any(c, r0, r1);
}

static void over_rows(const piola__multigrid_level *l, int kind, double c1, double c2) {
  const vector_pass c = {l, kind, c1, c2};
  const int32_t n = l->a.rows;
#pragma omp parallel for schedule(static) \
    num_threads(piola_thread_count()) if (n >= MULTIGRID_PARALLEL_MIN_ROWS)
  for (int k = 0; k < RANGES; ++k)
    vector_rows(&c, (int32_t)((int64_t)n * k / RANGES), (int32_t)((int64_t)n * (k + 1) / RANGES));
}

/* Chebyshev smoothing of A x = f on level l, degree `degree` in D^-1 A on
 * [rho / CHEBYSHEV_RATIO, CHEBYSHEV_UPPER rho] (Saad, Iterative Methods, algorithm 12.1),
 * from x = 0 (zero_start) or from x. A fixed polynomial: the same operator every call. */
static void chebyshev(const piola__multigrid_level *l, int degree, int zero_start) {
  const double upper = CHEBYSHEV_UPPER * l->rho, lower = upper / CHEBYSHEV_RATIO;
  const double theta = 0.5 * (upper + lower), delta = 0.5 * (upper - lower);
  const double sigma = theta / delta;
  const size_t m = (size_t)l->a.rows * (size_t)l->a.rb;
  if (zero_start)
    memset(l->q, 0, sizeof(double) * m);
  else
    piola__block_sparse_apply(&l->a, l->x, l->q, 0);
  over_rows(l, PASS_START, zero_start ? 0.0 : 1.0, 1.0 / theta);
  double rho_old = 1.0 / sigma;
  for (int k = 1; k < degree; ++k) {
    piola__block_sparse_apply(&l->a, l->d, l->q, 0);
    const double rho_new = 1.0 / (2.0 * sigma - rho_old);
    over_rows(l, PASS_CHEBYSHEV, rho_new * rho_old, 2.0 * rho_new / delta);
    rho_old = rho_new;
  }
}

/* A power iteration's two passes over rows r0 .. r1 - 1 (av = A v), each leaving its partial
 * sums in sums[0 .. 1]. */
typedef void power_rows(const piola__multigrid_level *l, const double *av, int32_t r0, int32_t r1,
                        double sums[2]);

/* The Rayleigh quotient's parts: sums[0] = v . A v, sums[1] = v . D v. */
static void quotient_rows(const piola__multigrid_level *l, const double *av, int32_t r0, int32_t r1,
                          double sums[2]) {
  const int b = l->a.rb;
  const double *v = l->mode;
  sums[0] = sums[1] = 0;
  for (int32_t r = r0; r < r1; ++r) {
    const double *vr = v + (size_t)b * r;
    const double *ar = av + (size_t)b * r;
    for (int i = 0; i < b; ++i) sums[0] += vr[i] * ar[i];
    const int32_t k = diagonal_entry(&l->a, r);
    if (k < 0) continue;
    const double *blk = l->a.values + (size_t)(b * b) * (size_t)k;
    for (int i = 0; i < b; ++i)
      for (int j = 0; j < b; ++j) sums[1] += vr[i] * blk[b * i + j] * vr[j];
  }
}

/* The next iterate before its scaling: v = D^-1 av, and sums[0] = its squared size. */
static void next_iterate_rows(const piola__multigrid_level *l, const double *av, int32_t r0,
                              int32_t r1, double sums[2]) {
  const int b = l->a.rb;
  double *v = l->mode;
  sums[0] = sums[1] = 0;
  for (int32_t r = r0; r < r1; ++r) {
    double *vr = v + (size_t)b * r;
    const double *ar = av + (size_t)b * r;
    const double *dinv = l->inverse_diagonal + (size_t)(b * b) * (size_t)r;
    double t[6];
    for (int i = 0; i < b; ++i) {
      t[i] = 0;
      for (int j = 0; j < b; ++j) t[i] += dinv[b * i + j] * ar[j];
    }
    for (int i = 0; i < b; ++i) vr[i] = t[i], sums[0] += t[i] * t[i];
  }
}

/* sums[0 .. 1] of one pass over the level's rows: the RANGES ranges' partial sums added in
 * range order, so the result does not depend on the thread count. */
static void power_pass(const piola__multigrid_level *l, const double *av, power_rows *rows,
                       double sums[2]) {
  const int32_t n = l->a.rows;
  double part[RANGES][2];
#pragma omp parallel for schedule(static) \
    num_threads(piola_thread_count()) if (n >= MULTIGRID_PARALLEL_MIN_ROWS)
  for (int k = 0; k < RANGES; ++k)
    rows(l, av, (int32_t)((int64_t)n * k / RANGES), (int32_t)((int64_t)n * (k + 1) / RANGES),
         part[k]);
  sums[0] = sums[1] = 0;
  for (int k = 0; k < RANGES; ++k) sums[0] += part[k][0], sums[1] += part[k][1];
}

/* The largest eigenvalue of D^-1 A by `iterations` power iterations from a fixed start
 * (warm: from the last iterate, l->mode), as the Rayleigh quotient (v . A v) / (v . D v)
 * (D^-1 A is self-adjoint in the D inner product: the quotient converges from below). The
 * sums in fixed ranges (power_pass), so any thread count gives the same bits. */
static double spectral_radius(const piola__multigrid_level *l, int iterations, int warm) {
  const int b = l->a.rb;
  const int64_t m = (int64_t)l->a.rows * b;
  if (m == 0) return 1.0;
  double *v = l->mode, *av = l->q;
  if (!warm)
    for (int64_t j = 0; j < m; ++j)
      v[j] = (double)((uint32_t)(j * 2654435761u) % 2001u) / 1000.0 - 1.0;
  double quotient = 0;
  for (int it = 0; it < iterations; ++it) {
    piola__block_sparse_apply(&l->a, v, av, 0);
    /* v . A v and v . D v */
    double sums[2];
    power_pass(l, av, quotient_rows, sums);
    if (!(sums[1] > 0)) break;
    quotient = sums[0] / sums[1];
    /* v = D^-1 A v, normalized */
    power_pass(l, av, next_iterate_rows, sums);
    const double size = sums[0];
    if (!(size > 0) || !isfinite(size)) break;
    const double scale = 1.0 / sqrt(size);
    for (int64_t j = 0; j < m; ++j) v[j] *= scale;
  }
  return quotient > 0 && isfinite(quotient) ? quotient : 1.0;
}

/* The diagonal inverses and rho of level l's operator. */
static void level_numbers(piola__multigrid_level *l) {
  over_rows(l, PASS_INVERT_DIAGONAL, 0, 0);
  l->rho = spectral_radius(l, POWER_ITERATIONS, 0);
}

/* ------------------------------------------------------------------ setup */

/* Level 0's values from the matrix and the constraints; fills s (per row) on the way. */
static void fill_level0(piola__multigrid *mg, const piola__stiffness_matrix *matrix,
                        const piola_elastic_body *body, piola__vertex_constraint *constraint,
                        const void *context, piola__vertex_projection *s) {
  const piola__damping_matrix *d = &body->damping;
  for (int32_t r = 0; r < mg->vertex_count; ++r)
    s[r] = piola__vertex_projection_of(constraint, context, d->order[r]);
  const fill_pass c = {mg, matrix, d, s};
  const int32_t n = mg->vertex_count;
#pragma omp parallel for schedule(static) \
    num_threads(piola_thread_count()) if (n >= MULTIGRID_PARALLEL_MIN_ROWS)
  for (int k = 0; k < RANGES; ++k)
    fill_rows(&c, (int32_t)((int64_t)n * k / RANGES), (int32_t)((int64_t)n * (k + 1) / RANGES));
}

/* Level 0's near null space: the rigid modes of each row's vertex about its aggregate's
 * centroid (rows of aggregate -1: zero), projected by the vertex's constraint; 3 x 6 per
 * row, row-major. */
static piola_status rigid_modes(const piola__multigrid *mg, const piola_elastic_body *body,
                                const int32_t *aggregate, int32_t aggregates,
                                const piola__vertex_projection *s, double *modes) {
  const piola__damping_matrix *d = &body->damping;
  double *centroid = calloc(4 * (size_t)(aggregates > 0 ? aggregates : 1), sizeof(double));
  if (!centroid) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "multigrid: out of memory");
  const int32_t n = mg->vertex_count;
  for (int32_t r = 0; r < n; ++r) {
    if (aggregate[r] < 0) continue;
    const double *x = body->positions + 3 * (size_t)d->order[r];
    double *c = centroid + 4 * (size_t)aggregate[r];
    c[0] += x[0], c[1] += x[1], c[2] += x[2], c[3] += 1;
  }
  for (int32_t g = 0; g < aggregates; ++g)
    for (int k = 0; k < 3; ++k) centroid[4 * g + k] /= centroid[4 * g + 3];
  for (int32_t r = 0; r < n; ++r) {
    double *b = modes + 18 * (size_t)r;
    memset(b, 0, 18 * sizeof(double));
    if (aggregate[r] < 0) continue;
    const double *x = body->positions + 3 * (size_t)d->order[r];
    const double *c = centroid + 4 * (size_t)aggregate[r];
    const double y[3] = {x[0] - c[0], x[1] - c[1], x[2] - c[2]};
    /* translations e_k; rotations e_k x y */
    for (int k = 0; k < 3; ++k) b[6 * k + k] = 1;
    b[6 * 1 + 3] = -y[2], b[6 * 2 + 3] = y[1];
    b[6 * 0 + 4] = y[2], b[6 * 2 + 4] = -y[0];
    b[6 * 0 + 5] = -y[1], b[6 * 1 + 5] = y[0];
    piola__project_rows(&s[r], b, 6);
  }
  free(centroid);
  return PIOLA_OK;
}

/* Rows r0 .. r1 - 1 of P = T - omega D^-1 (A T), in place of A T's blocks. */
static void smooth_rows(const piola__multigrid_level *l, const piola__block_sparse *t,
                        piola__block_sparse *at, double omega, int32_t r0, int32_t r1) {
  const int b = l->a.rb, nm = PIOLA_MULTIGRID_MODES;
  for (int32_t r = r0; r < r1; ++r) {
    const double *dinv = l->inverse_diagonal + (size_t)(b * b) * (size_t)r;
    for (int32_t k = at->row_start[r]; k < at->row_start[r + 1]; ++k) {
      double *blk = at->values + (size_t)(b * nm) * (size_t)k, w[36];
      for (int i = 0; i < b; ++i)
        for (int j = 0; j < nm; ++j) {
          double s = 0;
          for (int p = 0; p < b; ++p) s += dinv[b * i + p] * blk[nm * p + j];
          w[nm * i + j] = -omega * s;
        }
      /* T's block of row r, if it is in this column */
      if (t->row_start[r + 1] > t->row_start[r] && t->col[t->row_start[r]] == at->col[k]) {
        const double *tb = t->values + (size_t)(b * nm) * (size_t)t->row_start[r];
        for (int e = 0; e < b * nm; ++e) w[e] += tb[e];
      }
      memcpy(blk, w, sizeof(double) * (size_t)(b * nm));
    }
  }
}

/* P = (I - omega D^-1 A) T on level l (t: the tentative prolongator). */
static piola_status smooth_prolongator(piola__multigrid_level *l, const piola__block_sparse *t) {
  piola__block_sparse at;
  PIOLA_TRY(piola__block_sparse_product(&l->a, t, &at));
  const double omega = 4.0 / (3.0 * l->rho);
  const int32_t n = at.rows;
#pragma omp parallel for schedule(static) \
    num_threads(piola_thread_count()) if (n >= MULTIGRID_PARALLEL_MIN_ROWS)
  for (int k = 0; k < RANGES; ++k)
    smooth_rows(l, t, &at, omega, (int32_t)((int64_t)n * k / RANGES),
                (int32_t)((int64_t)n * (k + 1) / RANGES));
  l->p = at;
  return PIOLA_OK;
}

/* The next level's operator P^T A P: the blocks above the diagonal formed, those below
 * mirrored (A is symmetric), the diagonal blocks symmetrized; unknowns no mode reached (zero
 * rows and columns) get a unit diagonal. */
static piola_status galerkin(piola__multigrid_level *l, piola__block_sparse *coarse) {
  PIOLA_TRY(piola__block_sparse_transpose(&l->p, &l->pt));
  PIOLA_TRY(piola__block_sparse_galerkin_symmetric(&l->pt, &l->a, &l->p, coarse));
  piola__block_sparse_symmetrize(coarse);
  const int b = coarse->rb;
  for (int32_t r = 0; r < coarse->rows; ++r) {
    const int32_t k = diagonal_entry(coarse, r);
    if (k < 0) continue;
    double *blk = coarse->values + (size_t)(b * b) * (size_t)k;
    for (int i = 0; i < b; ++i)
      if (blk[b * i + i] == 0) blk[b * i + i] = 1;
  }
  return PIOLA_OK;
}

/* The dense Cholesky factor of the last level. */
static piola_status factor_coarse(piola__multigrid *mg, const piola__block_sparse *a) {
  const int32_t n = a->rows * a->rb;
  const int b = a->rb;
  mg->coarse_factor = calloc((size_t)n * (size_t)n > 0 ? (size_t)n * (size_t)n : 1, sizeof(double));
  if (!mg->coarse_factor) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "multigrid: out of memory");
  for (int32_t r = 0; r < a->rows; ++r)
    for (int32_t k = a->row_start[r]; k < a->row_start[r + 1]; ++k)
      for (int i = 0; i < b; ++i)
        for (int j = 0; j < b; ++j)
          mg->coarse_factor[(size_t)n * (size_t)(b * r + i) + (size_t)(b * a->col[k] + j)] =
              a->values[(size_t)(b * b) * (size_t)k + (size_t)(b * i + j)];
  cholesky_in_place(mg->coarse_factor, n);
  mg->coarse_size = n;
  return PIOLA_OK;
}

/* Levels from level 0 (filled, its numbers known) down. */
static piola_status build_levels(piola__multigrid *mg, const piola_elastic_body *body,
                                 const piola__vertex_projection *s) {
  double *modes = NULL;
  int32_t *aggregate = NULL;
  piola_status status = PIOLA_OK;
  double theta = PIOLA_MULTIGRID_STRENGTH;
  for (int k = 0;; ++k) {
    piola__multigrid_level *l = &mg->level[k];
    const int32_t dofs = l->a.rows * l->a.rb;
    if (dofs <= PIOLA_MULTIGRID_COARSE_DOFS) {
      status = factor_coarse(mg, &l->a);
      break;
    }
    if (k + 1 == PIOLA_MULTIGRID_MAX_LEVELS) break; /* smoothed only */
    aggregate = malloc(sizeof(int32_t) * (size_t)l->a.rows);
    if (!aggregate) {
      status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "multigrid: out of memory");
      break;
    }
    const int32_t aggregates = piola__multigrid_aggregate(&l->a, theta, aggregate);
    if (aggregates < 0) {
      status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "multigrid: out of memory");
      break;
    }
    /* no coarsening left: the last level (dense when small enough, else smoothed only) */
    if (aggregates == 0 || (int64_t)aggregates * PIOLA_MULTIGRID_MODES >= (int64_t)dofs * 9 / 10) {
      if (dofs <= 4 * PIOLA_MULTIGRID_COARSE_DOFS) status = factor_coarse(mg, &l->a);
      break;
    }
    double *coarse_modes = malloc(sizeof(double) * 36 * (size_t)aggregates);
    if (!coarse_modes) {
      status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "multigrid: out of memory");
      break;
    }
    if (k == 0) {
      free(modes);
      modes = malloc(sizeof(double) * 18 * (size_t)l->a.rows);
      status = modes ? rigid_modes(mg, body, aggregate, aggregates, s, modes)
                     : PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "multigrid: out of memory");
    }
    piola__block_sparse t = {0};
    if (status == PIOLA_OK)
      status = piola__multigrid_tentative(&l->a, aggregate, aggregates, modes, &t, coarse_modes);
    free(modes);
    modes = coarse_modes;
    free(aggregate);
    aggregate = NULL;
    if (status == PIOLA_OK) status = smooth_prolongator(l, &t);
    piola__block_sparse_free(&t);
    piola__multigrid_level *next = &mg->level[k + 1];
    if (status == PIOLA_OK) status = galerkin(l, &next->a);
    if (status == PIOLA_OK) status = level_vectors(next);
    if (status != PIOLA_OK) break;
    mg->level_count = k + 2;
    level_numbers(next);
    theta *= 0.5;
  }
  free(modes), free(aggregate);
  return status;
}

piola_status piola__multigrid_setup(piola__multigrid *mg, const piola__stiffness_matrix *matrix,
                                    const piola_elastic_body *body,
                                    piola__vertex_constraint *constraint, const void *context) {
  free_coarse_levels(mg);
  piola__vertex_projection *s = malloc(sizeof(piola__vertex_projection) *
                                       (size_t)(mg->vertex_count > 0 ? mg->vertex_count : 1));
  if (!s) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "multigrid: out of memory");
  fill_level0(mg, matrix, body, constraint, context, s);
  level_numbers(&mg->level[0]);
  piola_status status = build_levels(mg, body, s);
  free(s);
  if (status != PIOLA_OK) {
    free_coarse_levels(mg);
    return status;
  }
  mg->setups++;
  return PIOLA_OK;
}

void piola__multigrid_refresh(piola__multigrid *mg, const piola__stiffness_matrix *matrix,
                              const piola_elastic_body *body, piola__vertex_constraint *constraint,
                              const void *context) {
  piola__vertex_projection *s = malloc(sizeof(piola__vertex_projection) *
                                       (size_t)(mg->vertex_count > 0 ? mg->vertex_count : 1));
  if (!s) return; /* keeps the last numbers: still a valid preconditioner */
  fill_level0(mg, matrix, body, constraint, context, s);
  free(s);
  piola__multigrid_level *l0 = &mg->level[0];
  over_rows(l0, PASS_INVERT_DIAGONAL, 0, 0);
  l0->rho = fmax(l0->rho, spectral_radius(l0, REFRESH_POWER_ITERATIONS, 1));
  mg->refreshes++;
}

/* ------------------------------------------------------------------ the V-cycle */

/* x = V-cycle(f) on level k (its f given). */
static void cycle(piola__multigrid *mg, int k) {
  piola__multigrid_level *l = &mg->level[k];
  const size_t m = (size_t)l->a.rows * (size_t)l->a.rb;
  if (k == mg->level_count - 1) {
    if (mg->coarse_size > 0) {
      memcpy(l->x, l->f, sizeof(double) * m);
      cholesky_solve(mg->coarse_factor, mg->coarse_size, l->x);
    } else {
      chebyshev(l, LAST_LEVEL_SMOOTHING, 1);
    }
    return;
  }
  piola__multigrid_level *next = &mg->level[k + 1];
  chebyshev(l, PIOLA_MULTIGRID_SMOOTHING, 1);
  piola__block_sparse_apply(&l->a, l->x, l->q, 0);
  over_rows(l, PASS_RESIDUAL, 0, 0);
  piola__block_sparse_apply(&l->pt, l->r, next->f, 0);
  cycle(mg, k + 1);
  piola__block_sparse_apply(&l->p, next->x, l->x, 1);
  chebyshev(l, PIOLA_MULTIGRID_SMOOTHING, 0);
}

void piola__multigrid_apply(piola__multigrid *mg, const piola_elastic_body *body, const double *r,
                            double *z) {
  const piola__damping_matrix *d = &body->damping;
  piola__multigrid_level *l0 = &mg->level[0];
  const int32_t n = mg->vertex_count;
  for (int32_t row = 0; row < n; ++row)
    memcpy(l0->f + 3 * (size_t)row, r + 3 * (size_t)d->order[row], 3 * sizeof(double));
  cycle(mg, 0);
  for (int32_t row = 0; row < n; ++row)
    memcpy(z + 3 * (size_t)d->order[row], l0->x + 3 * (size_t)row, 3 * sizeof(double));
}
