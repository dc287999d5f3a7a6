/* Block compressed sparse rows: the operators of the multigrid hierarchy
 * (force/stiffness_multigrid.h).
 *
 * A matrix of rows x cols blocks, each rb x cb (3 for a vertex, 6 for a coarse node's rigid
 * modes), stored by rows: the entries of block row r are [row_start[r], row_start[r + 1]),
 * their block columns col[k] increasing, their blocks values[rb cb k ..] row-major. Both
 * triangles of a symmetric matrix are stored, so a product row needs no transposed access
 * and every row is summed by one thread in a fixed order: products are bit-identical for
 * any thread count. The sparse products (A T, Galerkin's P^T A P) are for the hierarchy's
 * setup; their numbers are formed in parallel ranges of rows (of c for the Galerkin product),
 * each entry summed in the same order whatever the ranges, and so are their patterns (each
 * range with its own marker arrays, each row's columns found in the same order whatever the
 * range; only the running sums of the row lengths on one thread). */
#ifndef PIOLA_MATH_BLOCK_SPARSE_H
#define PIOLA_MATH_BLOCK_SPARSE_H

#include <stdint.h>

#include "piola/status.h"

typedef struct piola__block_sparse {
  int32_t rows, cols; /* in blocks */
  int rb, cb;         /* block size: rows and columns */
  int32_t *row_start; /* rows + 1 */
  int32_t *col;       /* per entry */
  double *values;     /* rb * cb per entry */
} piola__block_sparse;

/* Allocates a matrix of `entries` blocks (row_start, col and values uninitialised). */
piola_status piola__block_sparse_alloc(piola__block_sparse *m, int32_t rows, int32_t cols, int rb,
                                       int cb, int64_t entries);
void piola__block_sparse_free(piola__block_sparse *m);

static inline int64_t piola__block_sparse_entries(const piola__block_sparse *m) {
  return m->row_start ? m->row_start[m->rows] : 0;
}

/* y = A x (y = A x + y when accumulate), rows in parallel over fixed ranges. */
void piola__block_sparse_apply(const piola__block_sparse *a, const double *x, double *y,
                               int accumulate);

/* c = a b (a->cols == b->rows, a->cb == b->rb); c's columns increasing in each row. */
piola_status piola__block_sparse_product(const piola__block_sparse *a, const piola__block_sparse *b,
                                         piola__block_sparse *c);

/* c = pt (a p), pt = p^T as piola__block_sparse_transpose gives it: the Galerkin product,
 * bit-identical to piola__block_sparse_product(pt, a p) but without forming a p (on the
 * Figure 2 torus a 48 MB matrix written, and its pages faulted in, at every setup): each row
 * of a p is formed once in a row buffer and scattered into the rows of c that need it (with
 * several threads, once per range of c's rows that needs it: the ranges split c's rows so
 * that few rows of a p feed two). */
piola_status piola__block_sparse_galerkin(const piola__block_sparse *pt,
                                          const piola__block_sparse *a,
                                          const piola__block_sparse *p, piola__block_sparse *c);

/* The Galerkin product of a symmetric a: c's blocks on and above the diagonal as
 * piola__block_sparse_galerkin forms them (bit-identical), those below the transposes of
 * their mirror blocks, so c is symmetric but for its diagonal blocks. The scatter of the
 * product's terms, most of its work, is halved: the level-0 product of the Figure 2 torus's
 * multigrid setup takes 57-70 ms instead of 73-86 ms (BENCHMARKS.md, "Implicit
 * integrators"). */
piola_status piola__block_sparse_galerkin_symmetric(const piola__block_sparse *pt,
                                                    const piola__block_sparse *a,
                                                    const piola__block_sparse *p,
                                                    piola__block_sparse *c);

/* t = a^T: its pattern on one thread, its numbers in parallel ranges of t's rows. */
piola_status piola__block_sparse_transpose(const piola__block_sparse *a, piola__block_sparse *t);

/* a = (a + a^T) / 2 for a square matrix with a symmetric pattern (columns increasing):
 * the Galerkin products are symmetric only to rounding. In parallel ranges of rows. */
void piola__block_sparse_symmetrize(piola__block_sparse *a);

#endif
