/* Block compressed sparse rows; see block_sparse.h. */
#include "math/block_sparse.h"

#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "piola/threads.h"

/* below this many values a product with a vector runs on one thread (the parallel region
 * costs more), and so does a sparse product below this many values of its left factor. By
 * values, not rows: a coarse level's row of 6x6 blocks is 16 times a 3x3 row's work, and
 * counted by rows the Figure 2 torus's second level (1,290 rows, 13 MB of blocks) and its
 * restriction ran on one thread, a quarter of a V-cycle (BENCHMARKS.md, "Implicit
 * integrators"). */
#define BLOCK_SPARSE_PARALLEL_MIN_VALUES (1 << 19)
enum { RANGES = 16 };

piola_status piola__block_sparse_alloc(piola__block_sparse *m, int32_t rows, int32_t cols, int rb,
                                       int cb, int64_t entries) {
  memset(m, 0, sizeof *m);
  m->rows = rows, m->cols = cols, m->rb = rb, m->cb = cb;
  if (entries > INT32_MAX)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "sparse matrix: %lld blocks are too many",
                      (long long)entries);
  m->row_start = malloc(sizeof(int32_t) * ((size_t)rows + 1));
  m->col = malloc(sizeof(int32_t) * (size_t)(entries > 0 ? entries : 1));
  m->values = malloc(sizeof(double) * (size_t)(rb * cb) * (size_t)(entries > 0 ? entries : 1));
  if (!m->row_start || !m->col || !m->values) {
    piola__block_sparse_free(m);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "sparse matrix: out of memory");
  }
  m->row_start[0] = 0;
  return PIOLA_OK;
}

void piola__block_sparse_free(piola__block_sparse *m) {
  free(m->row_start), free(m->col), free(m->values);
  memset(m, 0, sizeof *m);
}

/* Whether a product of a with a vector, or a sparse product with left factor a, runs in
 * parallel (BLOCK_SPARSE_PARALLEL_MIN_VALUES). */
static int parallel_product(const piola__block_sparse *a) {
  return (int64_t)a->row_start[a->rows] * a->rb * a->cb >= BLOCK_SPARSE_PARALLEL_MIN_VALUES;
}

typedef struct apply_pass {
  const piola__block_sparse *a;
  const double *x;
  double *y;
  int accumulate;
} apply_pass;

/* Two doubles in one register (SSE2, every x86-64 target; other targets split it): the
 * level operators' products in pairs of adjacent numbers, which halves their arithmetic
 * instructions. Loaded and stored through memcpy, so unaligned addresses are fine. */
typedef double pair __attribute__((vector_size(16)));

static inline pair load_pair(const double *p) {
  pair v;
  memcpy(&v, p, sizeof v);
  return v;
}

/* 3x3 blocks (level 0): row r's sums in lane pairs over its blocks, b and x taken two by two
 * (b0 b1 | b2 b3 | b4 b5 | b6 b7 against x0 x1 | x2 x0 | x1 x2 | x0 x1, b8 x2 alone), the
 * lanes of each output added at the row's end. */
static void apply_rows_3x3(const apply_pass *c, int32_t r0, int32_t r1) {
  const piola__block_sparse *a = c->a;
  for (int32_t r = r0; r < r1; ++r) {
    pair s01 = {0, 0}, s23 = {0, 0}, s45 = {0, 0}, s67 = {0, 0};
    double s8 = 0;
    for (int32_t k = a->row_start[r]; k < a->row_start[r + 1]; ++k) {
      const double *b = a->values + 9 * (size_t)k, *x = c->x + 3 * (size_t)a->col[k];
      const pair x01 = load_pair(x), x12 = load_pair(x + 1);
      const pair x20 = {x[2], x[0]};
      s01 += load_pair(b) * x01;
      s23 += load_pair(b + 2) * x20;
      s45 += load_pair(b + 4) * x12;
      s67 += load_pair(b + 6) * x01;
      s8 += b[8] * x[2];
    }
    /* y0 = b0 x0 + b1 x1 + b2 x2, y1 = b3 x0 + b4 x1 + b5 x2, y2 = b6 x0 + b7 x1 + b8 x2 */
    const double y[3] = {s01[0] + s01[1] + s23[0], s23[1] + s45[0] + s45[1],
                         s67[0] + s67[1] + s8};
    double *yr = c->y + 3 * (size_t)r;
    for (int i = 0; i < 3; ++i) yr[i] = c->accumulate ? yr[i] + y[i] : y[i];
  }
}

/* 6x3 blocks (the restriction P^T): as 3x3, the 18 numbers of a block in nine pairs
 * against x0 x1 | x2 x0 | x1 x2 repeated, each output the sum of its three numbers' lanes. */
static void apply_rows_6x3(const apply_pass *c, int32_t r0, int32_t r1) {
  const piola__block_sparse *a = c->a;
  for (int32_t r = r0; r < r1; ++r) {
    pair s[9] = {{0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}};
    for (int32_t k = a->row_start[r]; k < a->row_start[r + 1]; ++k) {
      const double *b = a->values + 18 * (size_t)k, *x = c->x + 3 * (size_t)a->col[k];
      const pair x01 = load_pair(x), x12 = load_pair(x + 1);
      const pair x20 = {x[2], x[0]};
      for (int h = 0; h < 3; ++h) {
        s[3 * h] += load_pair(b + 6 * h) * x01;
        s[3 * h + 1] += load_pair(b + 6 * h + 2) * x20;
        s[3 * h + 2] += load_pair(b + 6 * h + 4) * x12;
      }
    }
    double *yr = c->y + 6 * (size_t)r;
    for (int h = 0; h < 3; ++h) {
      /* rows 2h and 2h + 1: numbers 6h .. 6h + 2 and 6h + 3 .. 6h + 5 */
      const double y0 = s[3 * h][0] + s[3 * h][1] + s[3 * h + 1][0];
      const double y1 = s[3 * h + 1][1] + s[3 * h + 2][0] + s[3 * h + 2][1];
      yr[2 * h] = c->accumulate ? yr[2 * h] + y0 : y0;
      yr[2 * h + 1] = c->accumulate ? yr[2 * h + 1] + y1 : y1;
    }
  }
}

/* RBx6 blocks (the coarse levels' 6x6, the prolongator's 3x6): each output row's sum in a
 * lane pair, x taken two by two. */
static inline __attribute__((always_inline)) void rows_of_six(const apply_pass *c, int32_t r0,
                                                              int32_t r1, const int rb) {
  const piola__block_sparse *a = c->a;
  for (int32_t r = r0; r < r1; ++r) {
    pair s[6] = {{0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}};
    for (int32_t k = a->row_start[r]; k < a->row_start[r + 1]; ++k) {
      const double *b = a->values + (size_t)(6 * rb) * (size_t)k, *x = c->x + 6 * (size_t)a->col[k];
      const pair x01 = load_pair(x), x23 = load_pair(x + 2), x45 = load_pair(x + 4);
      for (int i = 0; i < rb; ++i)
        s[i] += load_pair(b + 6 * i) * x01 + load_pair(b + 6 * i + 2) * x23 +
                load_pair(b + 6 * i + 4) * x45;
    }
    double *yr = c->y + (size_t)rb * (size_t)r;
    for (int i = 0; i < rb; ++i) {
      const double y = s[i][0] + s[i][1];
      yr[i] = c->accumulate ? yr[i] + y : y;
    }
  }
}

static void apply_rows_6x6(const apply_pass *c, int32_t r0, int32_t r1) {
  rows_of_six(c, r0, r1, 6);
}

static void apply_rows_3x6(const apply_pass *c, int32_t r0, int32_t r1) {
  rows_of_six(c, r0, r1, 3);
}

/* Any other block size (up to 6 rows). */
static void apply_rows(const apply_pass *c, int32_t r0, int32_t r1) {
  const piola__block_sparse *a = c->a;
  const int rb = a->rb, cb = a->cb, bs = rb * cb;
  if (rb == 3 && cb == 3) {
    apply_rows_3x3(c, r0, r1);
    return;
  }
  if (rb == 3 && cb == 6) {
    apply_rows_3x6(c, r0, r1);
    return;
  }
  if (rb == 6 && cb == 3) {
    apply_rows_6x3(c, r0, r1);
    return;
  }
  if (rb == 6 && cb == 6) {
    apply_rows_6x6(c, r0, r1);
    return;
  }
  for (int32_t r = r0; r < r1; ++r) {
    double sum[6] = {0, 0, 0, 0, 0, 0};
    for (int32_t k = a->row_start[r]; k < a->row_start[r + 1]; ++k) {
      const double *b = a->values + (size_t)bs * (size_t)k,
                   *xk = c->x + (size_t)cb * (size_t)a->col[k];
      for (int i = 0; i < rb; ++i) {
        double s = 0;
        for (int j = 0; j < cb; ++j) s += b[cb * i + j] * xk[j];
        sum[i] += s;
      }
    }
    double *yr = c->y + (size_t)rb * (size_t)r;
    for (int i = 0; i < rb; ++i) yr[i] = c->accumulate ? yr[i] + sum[i] : sum[i];
  }
}

void piola__block_sparse_apply(const piola__block_sparse *a, const double *x, double *y,
                               int accumulate) {
  const apply_pass c = {a, x, y, accumulate};
  const int32_t n = a->rows;
#pragma omp parallel for schedule(static) \
    num_threads(piola_thread_count()) if (parallel_product(a))
  for (int r = 0; r < RANGES; ++r)
    apply_rows(&c, (int32_t)((int64_t)n * r / RANGES), (int32_t)((int64_t)n * (r + 1) / RANGES));
}

static int compare_int32(const void *a, const void *b) {
  const int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
  return (x > y) - (x < y);
}

/* The distinct columns of row r of a b into list (marker[c] == r marks them), sorted when
 * `sorted` (the counting pass needs no order); returns how many. */
static int32_t product_row_columns(const piola__block_sparse *a, const piola__block_sparse *b,
                                   int32_t r, int32_t *marker, int32_t *list, int sorted) {
  int32_t count = 0;
  for (int32_t k = a->row_start[r]; k < a->row_start[r + 1]; ++k) {
    const int32_t m = a->col[k];
    for (int32_t l = b->row_start[m]; l < b->row_start[m + 1]; ++l)
      if (marker[b->col[l]] != r) marker[b->col[l]] = r, list[count++] = b->col[l];
  }
  if (sorted) qsort(list, (size_t)count, sizeof(int32_t), compare_int32);
  return count;
}

/* lengths[r] = the number of distinct columns of row r of a b for every row of a, over
 * `ranges` ranges of rows, each with its own marker and list (width each). */
static void product_row_lengths(const piola__block_sparse *a, const piola__block_sparse *b,
                                int32_t *lengths, int ranges, int32_t *marker, int32_t *list,
                                int32_t width) {
  const int32_t rows = a->rows;
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) if (ranges > 1)
  for (int k = 0; k < ranges; ++k) {
    int32_t *mk = marker + (size_t)width * (size_t)k, *lk = list + (size_t)width * (size_t)k;
    for (int32_t j = 0; j < width; ++j) mk[j] = -1;
    for (int32_t r = (int32_t)((int64_t)rows * k / ranges);
         r < (int32_t)((int64_t)rows * (k + 1) / ranges); ++r)
      lengths[r] = product_row_columns(a, b, r, mk, lk, 0);
  }
}

/* c += a b for blocks R x K and K x C, fixed sizes for the products the multigrid setup
 * forms (A T and A P: 3x3 by 3x6; P^T (A P): 6x3 by 3x6; the coarse levels: 6x6 by 6x6). */
typedef void block_multiply_add(const double *a, const double *b, double *c, int r, int k, int cc);

#define BLOCK_MULTIPLY_ADD(NAME, R, K, C)                                               \
  static void NAME(const double *a, const double *b, double *c, int r, int k, int cc) { \
    (void)r, (void)k, (void)cc;                                                         \
    for (int i = 0; i < R; ++i)                                                         \
      for (int j = 0; j < C; ++j) {                                                     \
        double s = 0;                                                                   \
        for (int p = 0; p < K; ++p) s += a[K * i + p] * b[C * p + j];                   \
        c[C * i + j] += s;                                                              \
      }                                                                                 \
  }

/* The same sums with two adjacent numbers of a row of c at a time (C even): each lane does
 * exactly the operations of BLOCK_MULTIPLY_ADD in its order, so the bits are the same, in
 * half the arithmetic instructions (the Galerkin product's numbers are most of a multigrid
 * setup, BENCHMARKS.md). */
#define BLOCK_MULTIPLY_ADD_PAIRS(NAME, R, K, C)                                         \
  static void NAME(const double *a, const double *b, double *c, int r, int k, int cc) { \
    (void)r, (void)k, (void)cc;                                                         \
    for (int i = 0; i < R; ++i)                                                         \
      for (int j = 0; j < C; j += 2) {                                                  \
        pair s = {0, 0};                                                                \
        for (int p = 0; p < K; ++p) {                                                   \
          const pair ap = {a[K * i + p], a[K * i + p]};                                 \
          s += ap * load_pair(b + C * p + j);                                           \
        }                                                                               \
        const pair sum = load_pair(c + C * i + j) + s;                                  \
        memcpy(c + C * i + j, &sum, sizeof sum);                                        \
      }                                                                                 \
  }

BLOCK_MULTIPLY_ADD_PAIRS(multiply_add_3x3x6, 3, 3, 6)
BLOCK_MULTIPLY_ADD_PAIRS(multiply_add_6x3x6, 6, 3, 6)
BLOCK_MULTIPLY_ADD_PAIRS(multiply_add_6x6x6, 6, 6, 6)

static void multiply_add_any(const double *a, const double *b, double *c, int r, int k, int cc) {
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < cc; ++j) {
      double s = 0;
      for (int p = 0; p < k; ++p) s += a[k * i + p] * b[cc * p + j];
      c[cc * i + j] += s;
    }
}

static block_multiply_add *multiply_add_for(int r, int k, int c) {
  if (r == 3 && k == 3 && c == 6) return multiply_add_3x3x6;
  if (r == 6 && k == 3 && c == 6) return multiply_add_6x3x6;
  if (r == 6 && k == 6 && c == 6) return multiply_add_6x6x6;
  return multiply_add_any;
}

/* Adds row r of a b into out: the block of column j at out + (a->rb b->cb) position[j],
 * summed over a's row in order. */
static void add_product_row(const piola__block_sparse *a, const piola__block_sparse *b,
                            int32_t r, const int32_t *position, double *out,
                            block_multiply_add *multiply_add) {
  const int ra = a->rb, inner = a->cb, cb = b->cb;
  const size_t abs = (size_t)(ra * inner), bbs = (size_t)(inner * cb), obs = (size_t)(ra * cb);
  for (int32_t k = a->row_start[r]; k < a->row_start[r + 1]; ++k) {
    const double *ak = a->values + abs * (size_t)k;
    const int32_t m = a->col[k];
    for (int32_t l = b->row_start[m]; l < b->row_start[m + 1]; ++l)
      multiply_add(ak, b->values + bbs * (size_t)l, out + obs * (size_t)position[b->col[l]], ra,
                   inner, cb);
  }
}

/* Rows r0 .. r1 - 1 of c = a b, its row_start known: each row's columns sorted, its blocks
 * summed over a's row in order (marker, list and position: this range's own, marker[j] not
 * a row of the range on entry). */
static void product_rows(const piola__block_sparse *a, const piola__block_sparse *b,
                         piola__block_sparse *c, int32_t r0, int32_t r1, int32_t *marker,
                         int32_t *list, int32_t *position) {
  const int ra = a->rb, inner = a->cb, cb = b->cb;
  const size_t cbs = (size_t)(ra * cb);
  block_multiply_add *multiply_add = multiply_add_for(ra, inner, cb);
  for (int32_t r = r0; r < r1; ++r) {
    const int64_t at = c->row_start[r];
    const int32_t count = product_row_columns(a, b, r, marker, list, 1);
    for (int32_t q = 0; q < count; ++q) position[list[q]] = (int32_t)(at + q);
    memcpy(c->col + at, list, sizeof(int32_t) * (size_t)count);
    memset(c->values + cbs * (size_t)at, 0, sizeof(double) * cbs * (size_t)count);
    add_product_row(a, b, r, position, c->values, multiply_add);
  }
}

piola_status piola__block_sparse_product(const piola__block_sparse *a, const piola__block_sparse *b,
                                         piola__block_sparse *c) {
  memset(c, 0, sizeof *c);
  const int32_t rows = a->rows, cols = b->cols > 0 ? b->cols : 1;
  /* row ranges in parallel (parallel_product), each with its own work arrays */
  const int ranges = parallel_product(a) ? RANGES : 1;
  const size_t work = (size_t)cols * (size_t)ranges;
  int32_t *marker = malloc(sizeof(int32_t) * work);
  int32_t *list = malloc(sizeof(int32_t) * work);
  int32_t *position = malloc(sizeof(int32_t) * work);
  int32_t *counts = malloc(sizeof(int32_t) * ((size_t)rows + 1));
  piola_status status = PIOLA_OK;
  if (!marker || !list || !position || !counts) {
    status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "sparse product: out of memory");
    goto done;
  }
  product_row_lengths(a, b, counts, ranges, marker, list, cols);
  int64_t entries = 0;
  for (int32_t r = 0; r < rows; ++r) entries += counts[r];
  status = piola__block_sparse_alloc(c, rows, b->cols, a->rb, b->cb, entries);
  if (status != PIOLA_OK) goto done;
  for (int32_t r = 0; r < rows; ++r) c->row_start[r + 1] = c->row_start[r] + counts[r];
  for (size_t j = 0; j < work; ++j) marker[j] = -1;
#pragma omp parallel for schedule(static) \
    num_threads(piola_thread_count()) if (ranges > 1)
  for (int k = 0; k < ranges; ++k) {
    const size_t w = (size_t)cols * (size_t)k;
    product_rows(a, b, c, (int32_t)((int64_t)rows * k / ranges),
                 (int32_t)((int64_t)rows * (k + 1) / ranges), marker + w, list + w, position + w);
  }
done:
  free(marker), free(list), free(position), free(counts);
  return status;
}

/* The entry of column col in row r of c (present: c's pattern was built to hold it). */
static int32_t entry_of(const piola__block_sparse *c, int32_t r, int32_t col) {
  int32_t lo = c->row_start[r], hi = c->row_start[r + 1];
  while (lo < hi) {
    const int32_t mid = lo + (hi - lo) / 2;
    if (c->col[mid] < col)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

/* The operands of the Galerkin product's numbers, shared by its ranges. */
typedef struct galerkin_pass {
  const piola__block_sparse *pt, *a, *p;
  piola__block_sparse *c;
  const int32_t *ap_start, *ap_col;
  int32_t *cursor; /* per row g of c: its next entry of pt (rows of one range only) */
  int upper;       /* form only the blocks (g, h) with h >= g */
} galerkin_pass;

/* The numbers of the rows [g0, g1) of c (pattern built, values zeroed): row r of a p into
 * `row`, then its terms pt(g, r) (a p)(r, h) into every row g of c in the range that names r
 * (with gp->upper, only the blocks with h >= g). Rows r in increasing order, as pt's rows
 * list them, so every entry of c sums its terms in the order the two separate products
 * would, whichever range it falls in; a row r whose p row names rows of two ranges is formed
 * by both. */
static void galerkin_rows(const galerkin_pass *gp, int32_t g0, int32_t g1, int32_t *position,
                          double *row) {
  const piola__block_sparse *pt = gp->pt, *a = gp->a, *p = gp->p;
  piola__block_sparse *c = gp->c;
  const int ra = a->rb, inner = a->cb, cb = p->cb, rc = pt->rb;
  const size_t apbs = (size_t)(ra * cb), ptbs = (size_t)(rc * ra), cbs = (size_t)(rc * cb);
  block_multiply_add *ap_multiply_add = multiply_add_for(ra, inner, cb);
  block_multiply_add *c_multiply_add = multiply_add_for(rc, ra, cb);
  for (int32_t r = 0; r < a->rows; ++r) {
    int names = 0;
    for (int32_t j = p->row_start[r]; j < p->row_start[r + 1]; ++j)
      names |= p->col[j] >= g0 && p->col[j] < g1;
    if (!names) continue;
    const int32_t first = gp->ap_start[r], count = gp->ap_start[r + 1] - first;
    for (int32_t q = 0; q < count; ++q) position[gp->ap_col[first + q]] = q;
    memset(row, 0, sizeof(double) * apbs * (size_t)count);
    add_product_row(a, p, r, position, row, ap_multiply_add);
    for (int32_t j = p->row_start[r]; j < p->row_start[r + 1]; ++j) {
      const int32_t g = p->col[j];
      if (g < g0 || g >= g1) continue;
      const double *ptb = pt->values + ptbs * (size_t)gp->cursor[g]++;
      for (int32_t q = 0; q < count; ++q) {
        const int32_t h = gp->ap_col[first + q];
        if (gp->upper && h < g) continue;
        c_multiply_add(ptb, row + apbs * (size_t)q, c->values + cbs * (size_t)entry_of(c, g, h),
                       rc, ra, cb);
      }
    }
  }
}

/* The first row of range k of `ranges` over pt's rows: the ranges split pt's entries (the
 * rows of a p each range forms) evenly. */
static int32_t range_row(const piola__block_sparse *pt, int k, int ranges) {
  if (k >= ranges) return pt->rows;
  const int64_t share = (int64_t)pt->row_start[pt->rows] * k;
  int32_t g = 0;
  while (g < pt->rows && (int64_t)pt->row_start[g] * ranges < share) ++g;
  return g;
}

/* Rows r0 .. r1 - 1 of c's blocks below the diagonal: the transposes of their mirror
 * blocks above it. */
static void mirror_rows(piola__block_sparse *c, int32_t r0, int32_t r1) {
  const int b = c->rb;
  const size_t bs = (size_t)(b * b);
  for (int32_t g = r0; g < r1; ++g)
    for (int32_t k = c->row_start[g]; k < c->row_start[g + 1] && c->col[k] < g; ++k) {
      const double *upper = c->values + bs * (size_t)entry_of(c, c->col[k], g);
      double *lower = c->values + bs * (size_t)k;
      for (int i = 0; i < b; ++i)
        for (int j = 0; j < b; ++j) lower[b * i + j] = upper[b * j + i];
    }
}

/* What the Galerkin product's numbers need of its patterns besides c's: those of a p (row r's
 * columns ap_col[ap_start[r] ..), unsorted). */
typedef struct galerkin_plan {
  int32_t *ap_start, *ap_col;
  int32_t longest; /* the longest row of a p */
} galerkin_plan;

static void galerkin_plan_free(galerkin_plan *plan) {
  free(plan->ap_start), free(plan->ap_col);
  memset(plan, 0, sizeof *plan);
}

/* The columns of row g of c = pt (a p) into list (marker[h] == g marks them): the union of
 * the rows of a p that row g of pt names; returns how many. */
static int32_t galerkin_row_columns(const piola__block_sparse *pt, const galerkin_plan *plan,
                                    int32_t g, int32_t *marker, int32_t *list) {
  int32_t count = 0;
  for (int32_t k = pt->row_start[g]; k < pt->row_start[g + 1]; ++k) {
    const int32_t r = pt->col[k];
    for (int32_t q = plan->ap_start[r]; q < plan->ap_start[r + 1]; ++q) {
      const int32_t h = plan->ap_col[q];
      if (marker[h] != g) marker[h] = g, list[count++] = h;
    }
  }
  return count;
}

/* The plan's pattern passes after a p's row lengths (product_row_lengths), each over `ranges`
 * ranges of rows with their own marker and list (width each): a p's columns, c's row lengths,
 * c's columns sorted. Each row's columns are found in the same
 * order whatever the range, so the pattern does not depend on the ranges. */
enum { PASS_AP_COLUMNS, PASS_C_COUNT, PASS_C_COLUMNS };

static void plan_pass(const piola__block_sparse *pt, const piola__block_sparse *a,
                      const piola__block_sparse *p, galerkin_plan *plan, piola__block_sparse *c,
                      int pass, int ranges, int32_t *marker, int32_t *list, int32_t width) {
  const int over_ap = pass == PASS_AP_COLUMNS;
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) if (ranges > 1)
  for (int k = 0; k < ranges; ++k) {
    int32_t *mk = marker + (size_t)width * (size_t)k, *lk = list + (size_t)width * (size_t)k;
    for (int32_t j = 0; j < width; ++j) mk[j] = -1;
    const int32_t rows = over_ap ? a->rows : pt->rows;
    const int32_t r0 = over_ap ? (int32_t)((int64_t)rows * k / ranges) : range_row(pt, k, ranges);
    const int32_t r1 =
        over_ap ? (int32_t)((int64_t)rows * (k + 1) / ranges) : range_row(pt, k + 1, ranges);
    for (int32_t r = r0; r < r1; ++r) switch (pass) {
        case PASS_AP_COLUMNS:
          product_row_columns(a, p, r, mk, plan->ap_col + plan->ap_start[r], 0);
          break;
        case PASS_C_COUNT:
          c->row_start[r + 1] = galerkin_row_columns(pt, plan, r, mk, lk);
          break;
        default: {
          const int32_t count = galerkin_row_columns(pt, plan, r, mk, lk);
          qsort(lk, (size_t)count, sizeof(int32_t), compare_int32);
          memcpy(c->col + c->row_start[r], lk, sizeof(int32_t) * (size_t)count);
        }
      }
  }
}

/* start[0 .. n] from the lengths in start[1 .. n]: their running sums; returns the total
 * and the longest length in *longest. */
static int64_t running_sums(int32_t *start, int32_t n, int32_t *longest) {
  int64_t sum = 0;
  start[0] = 0;
  for (int32_t r = 0; r < n; ++r) {
    if (start[r + 1] > *longest) *longest = start[r + 1];
    sum += start[r + 1];
    start[r + 1] = (int32_t)(sum <= INT32_MAX ? sum : INT32_MAX);
  }
  return sum;
}

/* The plan and c's pattern (c allocated, its values not formed) for c = pt (a p), its
 * pattern passes in parallel ranges (plan_pass). */
static piola_status make_galerkin_plan(const piola__block_sparse *pt, const piola__block_sparse *a,
                                       const piola__block_sparse *p, galerkin_plan *plan,
                                       piola__block_sparse *c) {
  memset(c, 0, sizeof *c), memset(plan, 0, sizeof *plan);
  const int32_t n = a->rows, width = p->cols > 0 ? p->cols : 1;
  const int ranges = parallel_product(a) ? RANGES : 1;
  int32_t *marker = malloc(sizeof(int32_t) * (size_t)width * (size_t)ranges);
  int32_t *list = malloc(sizeof(int32_t) * (size_t)width * (size_t)ranges);
  int32_t *lengths = malloc(sizeof(int32_t) * ((size_t)pt->rows + 1));
  plan->ap_start = malloc(sizeof(int32_t) * ((size_t)n + 1));
  piola_status status = PIOLA_OK;
  if (!marker || !list || !lengths || !plan->ap_start) goto out_of_memory;
  /* the pattern of a p, row by row (unsorted: each (g, h) of c gets one term per row r) */
  product_row_lengths(a, p, plan->ap_start + 1, ranges, marker, list, width);
  plan->longest = 1;
  const int64_t ap_entries = running_sums(plan->ap_start, n, &plan->longest);
  if (ap_entries > INT32_MAX) {
    status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "sparse product: %lld blocks are too many",
                        (long long)ap_entries);
    goto done;
  }
  plan->ap_col = malloc(sizeof(int32_t) * (size_t)(ap_entries > 0 ? ap_entries : 1));
  if (!plan->ap_col) goto out_of_memory;
  plan_pass(pt, a, p, plan, c, PASS_AP_COLUMNS, ranges, marker, list, width);
  /* c: row g the union of the rows of a p that row g of pt names, sorted */
  piola__block_sparse counting = {.rows = pt->rows, .row_start = lengths};
  plan_pass(pt, a, p, plan, &counting, PASS_C_COUNT, ranges, marker, list, width);
  int32_t longest = 0;
  const int64_t entries = running_sums(lengths, pt->rows, &longest);
  status = piola__block_sparse_alloc(c, pt->rows, p->cols, pt->rb, p->cb, entries);
  if (status == PIOLA_OK) {
    memcpy(c->row_start, lengths, sizeof(int32_t) * ((size_t)pt->rows + 1));
    plan_pass(pt, a, p, plan, c, PASS_C_COLUMNS, ranges, marker, list, width);
  }
  goto done;
out_of_memory:
  status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "sparse product: out of memory");
done:
  if (status != PIOLA_OK) piola__block_sparse_free(c), galerkin_plan_free(plan);
  free(marker), free(list), free(lengths);
  return status;
}

/* c's numbers from the plan: all blocks (upper = 0) or those on and above the diagonal and
 * the others mirrored (upper = 1). */
static piola_status galerkin_numbers(const piola__block_sparse *pt, const piola__block_sparse *a,
                                     const piola__block_sparse *p, const galerkin_plan *plan,
                                     piola__block_sparse *c, int upper) {
  const int32_t cols = p->cols > 0 ? p->cols : 1;
  /* one range of c's rows per thread (each thread forms the rows of a p its range needs) */
  const int ranges = parallel_product(a) ? piola_thread_count() : 1;
  const size_t apbs = (size_t)(a->rb * p->cb), cbs = (size_t)(pt->rb * p->cb);
  int32_t *position = malloc(sizeof(int32_t) * (size_t)cols * (size_t)ranges);
  int32_t *cursor = malloc(sizeof(int32_t) * (size_t)(pt->rows > 0 ? pt->rows : 1));
  double *row = malloc(sizeof(double) * apbs * (size_t)plan->longest * (size_t)ranges);
  if (!position || !cursor || !row) {
    free(position), free(cursor), free(row);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "sparse product: out of memory");
  }
  memset(c->values, 0,
         sizeof(double) * cbs * (size_t)(c->row_start[c->rows] > 0 ? c->row_start[c->rows] : 1));
  for (int32_t g = 0; g < pt->rows; ++g) cursor[g] = pt->row_start[g];
  const galerkin_pass gp = {pt, a, p, c, plan->ap_start, plan->ap_col, cursor, upper};
#pragma omp parallel num_threads(ranges) if (ranges > 1)
  {
#pragma omp for schedule(static, 1)
    for (int k = 0; k < ranges; ++k)
      galerkin_rows(&gp, range_row(pt, k, ranges), range_row(pt, k + 1, ranges),
                    position + (size_t)cols * (size_t)k,
                    row + apbs * (size_t)plan->longest * (size_t)k);
    if (upper) {
#pragma omp for schedule(static)
      for (int k = 0; k < RANGES; ++k)
        mirror_rows(c, (int32_t)((int64_t)c->rows * k / RANGES),
                    (int32_t)((int64_t)c->rows * (k + 1) / RANGES));
    }
  }
  free(position), free(cursor), free(row);
  return PIOLA_OK;
}

/* c = pt (a p), all blocks formed (upper = 0) or those on and above the diagonal only and
 * the others mirrored (upper = 1, for a symmetric a; c square with a symmetric pattern). */
static piola_status galerkin_product(const piola__block_sparse *pt, const piola__block_sparse *a,
                                     const piola__block_sparse *p, piola__block_sparse *c,
                                     int upper) {
  galerkin_plan plan;
  PIOLA_TRY(make_galerkin_plan(pt, a, p, &plan, c));
  const piola_status status = galerkin_numbers(pt, a, p, &plan, c, upper);
  if (status != PIOLA_OK) piola__block_sparse_free(c);
  galerkin_plan_free(&plan);
  return status;
}

piola_status piola__block_sparse_galerkin(const piola__block_sparse *pt,
                                          const piola__block_sparse *a,
                                          const piola__block_sparse *p, piola__block_sparse *c) {
  return galerkin_product(pt, a, p, c, 0);
}

piola_status piola__block_sparse_galerkin_symmetric(const piola__block_sparse *pt,
                                                    const piola__block_sparse *a,
                                                    const piola__block_sparse *p,
                                                    piola__block_sparse *c) {
  return galerkin_product(pt, a, p, c, 1);
}

/* Rows r0 .. r1 - 1 of the transpose's numbers: each block of t found in a's row by a binary
 * search, a's rows sorted. */
static void transpose_numbers_rows(const piola__block_sparse *a, piola__block_sparse *t, int32_t r0,
                                   int32_t r1) {
  const int rb = a->rb, cb = a->cb;
  const size_t bs = (size_t)(rb * cb);
  for (int32_t g = r0; g < r1; ++g)
    for (int32_t k = t->row_start[g]; k < t->row_start[g + 1]; ++k) {
      const double *src = a->values + bs * (size_t)entry_of(a, t->col[k], g);
      double *dst = t->values + bs * (size_t)k;
      for (int i = 0; i < rb; ++i)
        for (int j = 0; j < cb; ++j) dst[rb * j + i] = src[cb * i + j];
    }
}

/* t's numbers from a's, t's pattern that of a^T, in parallel ranges of t's rows. */
static void transpose_numbers(const piola__block_sparse *a, piola__block_sparse *t) {
  const int32_t n = t->rows;
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) if (parallel_product(a))
  for (int k = 0; k < RANGES; ++k)
    transpose_numbers_rows(a, t, (int32_t)((int64_t)n * k / RANGES),
                           (int32_t)((int64_t)n * (k + 1) / RANGES));
}

piola_status piola__block_sparse_transpose(const piola__block_sparse *a, piola__block_sparse *t) {
  const int64_t entries = piola__block_sparse_entries(a);
  PIOLA_TRY(piola__block_sparse_alloc(t, a->cols, a->rows, a->cb, a->rb, entries));
  memset(t->row_start, 0, sizeof(int32_t) * ((size_t)a->cols + 1));
  for (int64_t k = 0; k < entries; ++k) t->row_start[a->col[k] + 1]++;
  for (int32_t c = 0; c < a->cols; ++c) t->row_start[c + 1] += t->row_start[c];
  int32_t *next = malloc(sizeof(int32_t) * (size_t)(a->cols > 0 ? a->cols : 1));
  if (!next) {
    piola__block_sparse_free(t);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "sparse transpose: out of memory");
  }
  memcpy(next, t->row_start, sizeof(int32_t) * (size_t)a->cols);
  /* rows in order: each transposed row gets its columns increasing */
  for (int32_t r = 0; r < a->rows; ++r)
    for (int32_t k = a->row_start[r]; k < a->row_start[r + 1]; ++k) t->col[next[a->col[k]]++] = r;
  transpose_numbers(a, t);
  free(next);
  return PIOLA_OK;
}

/* Rows r0 .. r1 - 1: each pair of blocks (r, c), (c, r) with c >= r by the row r; the pairs
 * of different rows share no block, so ranges run in parallel. */
static void symmetrize_rows(piola__block_sparse *a, int32_t r0, int32_t r1) {
  const int b = a->rb;
  const size_t bs = (size_t)(b * b);
  for (int32_t r = r0; r < r1; ++r)
    for (int32_t k = a->row_start[r]; k < a->row_start[r + 1]; ++k) {
      const int32_t c = a->col[k];
      if (c < r) continue;
      double *x = a->values + bs * (size_t)k, *y = a->values + bs * (size_t)entry_of(a, c, r);
      for (int i = 0; i < b; ++i)
        for (int j = 0; j < b; ++j) {
          if (c == r && j <= i) continue;
          const double mean = 0.5 * (x[b * i + j] + y[b * j + i]);
          x[b * i + j] = y[b * j + i] = mean;
        }
    }
}

void piola__block_sparse_symmetrize(piola__block_sparse *a) {
  const int32_t n = a->rows;
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) if (parallel_product(a))
  for (int k = 0; k < RANGES; ++k)
    symmetrize_rows(a, (int32_t)((int64_t)n * k / RANGES),
                    (int32_t)((int64_t)n * (k + 1) / RANGES));
}
