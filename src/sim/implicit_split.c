/* The Newton systems of a solid split among processes (piola/work_split.h, docs/mpi.md,
 * "Implicit integrators on several processes"), handed to the split's solver.
 *
 * Each process assembles the system matrix (stiffness_matrix.h) from the tets it holds: in
 * the local mode its own and its ghost blocks, every tet on a node it owns, so the rows of
 * its nodes are complete and summed in the single process's order (the other rows are
 * partial and never read); in the replicated mode every tet. The solver reads the owned
 * rows through row_of, filtered as the single process's conjugate gradient filters its
 * vectors: with S_i the filter of node i (0 for a fixed, driven or massless node, I - n n^T
 * for one held along n, I otherwise) the system is
 *   (S A S + I - S) d = -S g,
 * whose solution has (I - S) d = 0 and S A S d = -S g: the filtered CG's. */
#include <math.h>
#include <string.h>

#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "sim/implicit_split.h"

/* The filter of node i as a 3x3 matrix. */
static void node_filter(const world_body *s, int32_t i, double f[9]) {
  memset(f, 0, 9 * sizeof(double));
  if (s->flags[i] != NODE_FREE || s->inverse_mass[i] == 0) return;
  for (int k = 0; k < 3; ++k) f[4 * k] = 1;
  if (!s->colliding[i]) return;
  const double *n = s->normals + 3 * i;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) f[3 * a + b] -= n[a] * n[b];
}

/* out = fi b fj (b transposed first when transpose). */
static void filter_block(const double fi[9], const double *b, int transpose, const double fj[9],
                         double out[9]) {
  double bt[9], t[9];
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c < 3; ++c) bt[3 * a + c] = transpose ? b[3 * c + a] : b[3 * a + c];
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c < 3; ++c)
      t[3 * a + c] = fi[3 * a] * bt[c] + fi[3 * a + 1] * bt[3 + c] + fi[3 * a + 2] * bt[6 + c];
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c < 3; ++c)
      out[3 * a + c] = t[3 * a] * fj[c] + t[3 * a + 1] * fj[3 + c] + t[3 * a + 2] * fj[6 + c];
}

typedef struct split_rows {
  const world_body *s;
  const piola__stiffness_matrix *matrix;
} split_rows;

/* Row `node` of the filtered system matrix: the diagonal block, then one per mesh edge
 * (A_ij = -S_ij, stiffness_matrix.h). */
static int32_t row_of(const void *owner, int32_t node, int32_t *columns, double *blocks) {
  const split_rows *c = owner;
  const world_body *s = c->s;
  const piola__damping_matrix *d = &s->solid->damping;
  const double *edge = c->matrix->blocks;
  const int32_t r = d->rank[node];
  double fi[9], fj[9], neg[9];
  node_filter(s, node, fi);
  filter_block(fi, c->matrix->diagonal + 9 * (size_t)node, 0, fi, blocks);
  for (int k = 0; k < 3; ++k) blocks[4 * k] += 1.0;
  for (int k = 0; k < 9; ++k) blocks[k] -= fi[k]; /* + (I - S_i) */
  columns[0] = node;
  int32_t count = 1;
  for (int32_t k = d->row_start[r]; k < d->row_start[r + 1]; ++k, ++count) {
    for (int e = 0; e < 9; ++e) neg[e] = -edge[9 * (size_t)k + e];
    node_filter(s, d->col[k], fj);
    filter_block(fi, neg, 0, fj, blocks + 9 * (size_t)count);
    columns[count] = d->col[k];
  }
  for (int32_t k = d->lower_start[r]; k < d->lower_start[r + 1]; ++k, ++count) {
    for (int e = 0; e < 9; ++e) neg[e] = -edge[9 * (size_t)d->lower_edge[k] + e];
    node_filter(s, d->lower_col[k], fj);
    filter_block(fi, neg, 1, fj, blocks + 9 * (size_t)count);
    columns[count] = d->lower_col[k];
  }
  return count;
}

const piola_work_split *piola__implicit_split_of(const world_body *s) {
  if (s->kind != PIOLA_BODY_SOLID || !s->solid->split) return NULL;
  const piola_work_split *split = s->solid->split;
  return split->part_count > 1 && split->solve_newton ? split : NULL;
}

int32_t piola__implicit_split_solve(const world_body *s, const piola__stiffness_matrix *matrix,
                                    const double *residual, double tolerance,
                                    const piola_world_def *def, int32_t step_system, double *rhs,
                                    double *step) {
  const piola_work_split *split = piola__implicit_split_of(s);
  const piola__damping_matrix *d = &s->solid->damping;
  for (int32_t i = 0; i < s->n; ++i) {
    double f[9];
    node_filter(s, i, f);
    const double *g = residual + 3 * i;
    for (int a = 0; a < 3; ++a)
      rhs[3 * i + a] = -(f[3 * a] * g[0] + f[3 * a + 1] * g[1] + f[3 * a + 2] * g[2]);
  }
  int32_t widest = 0;
  for (int32_t r = 0; r < d->vertex_count; ++r) {
    const int32_t w = d->row_start[r + 1] - d->row_start[r] + d->lower_start[r + 1] - d->lower_start[r];
    if (w > widest) widest = w;
  }
  const split_rows rows = {s, matrix};
  const piola_split_newton_system system = {.node_count = s->n,
                                            .positions = s->x,
                                            .rhs = rhs,
                                            .max_row_blocks = widest + 1,
                                            .row = row_of,
                                            .owner = &rows,
                                            .tolerance = tolerance,
                                            .max_iterations = def->linear_max_iterations,
                                            .preconditioner = def->mpi_preconditioner,
                                            .step_system = step_system};
  const int32_t iterations = split->solve_newton(split->context, &system, step);
  /* an iterative solve leaves the filtered components near zero, not at it (with GAMG
   * they were ~1e-5 of the step): filtered to zero, as the serial CG's are, so that held
   * nodes do not move during the iterations */
  for (int32_t i = 0; i < s->n; ++i) {
    double f[9], *di = step + 3 * i;
    node_filter(s, i, f);
    const double d0 = di[0], d1 = di[1], d2 = di[2];
    for (int a = 0; a < 3; ++a) di[a] = f[3 * a] * d0 + f[3 * a + 1] * d1 + f[3 * a + 2] * d2;
  }
  return iterations;
}

double piola__implicit_matrix_trace(const world_body *s, const piola__stiffness_matrix *matrix) {
  const piola_work_split *split = piola__implicit_split_of(s);
  const int owned_only = split && split->reduce;
  double trace = 0;
  for (int32_t i = 0; i < s->n; ++i) {
    if (owned_only && split->node_part[i] != split->part) continue;
    const double *b = matrix->diagonal + 9 * (size_t)i;
    trace += b[0] + b[4] + b[8];
  }
  /* the owned rows' sums, added in process order: the same bits on every process */
  if (owned_only) split->reduce(split->context, &trace, 1, PIOLA_WORK_SPLIT_SUM);
  return trace;
}
