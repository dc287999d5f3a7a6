/* The per-vertex projection S of the implicit step's constraints, for the preconditioners
 * that factor or coarsen the filtered matrix S A S + (I - S) (block IC(0), multigrid).
 *
 * A vertex is free (S_i = I), held in all directions (S_i = 0: fixed, driven, massless) or
 * held along a unit normal n (S_i = I - n n^T: an obstacle contact), as the filtered CG of
 * the implicit step holds it. The filtered matrix is symmetric positive definite when A is,
 * maps the free subspace to itself and is the identity on the held one, so a preconditioner
 * built from it needs no projection of its own beyond S on its output. */
#ifndef PIOLA_FORCE_VERTEX_PROJECTION_H
#define PIOLA_FORCE_VERTEX_PROJECTION_H

#include <stdint.h>
#include <string.h>

/* How vertex i is constrained: 0 free, 1 held in all directions, 2 held along normal[3]
 * (unit). */
typedef int piola__vertex_constraint(const void *context, int32_t vertex, double normal[3]);

/* The projection S of one vertex: kind 0 free (S = I), 1 held (S = 0), 2 held along n. */
typedef struct piola__vertex_projection {
  int kind;
  double n[3];
} piola__vertex_projection;

static inline piola__vertex_projection piola__vertex_projection_of(
    piola__vertex_constraint *constraint, const void *context, int32_t i) {
  piola__vertex_projection s = {0, {0, 0, 0}};
  if (constraint) s.kind = constraint(context, i, s.n);
  return s;
}

/* b = S b, b row-major 3x3 (or a 3-vector when columns is 1, or 3 rows of `columns`). */
static inline void piola__project_rows(const piola__vertex_projection *s, double *b, int columns) {
  if (s->kind == 0) return;
  if (s->kind == 1) {
    memset(b, 0, 3 * (size_t)columns * sizeof(double));
    return;
  }
  for (int c = 0; c < columns; ++c) {
    double dn = s->n[0] * b[c] + s->n[1] * b[columns + c] + s->n[2] * b[2 * columns + c];
    for (int r = 0; r < 3; ++r) b[columns * r + c] -= s->n[r] * dn;
  }
}

/* b = b S, b row-major 3x3. */
static inline void piola__project_columns(const piola__vertex_projection *s, double b[9]) {
  if (s->kind == 0) return;
  if (s->kind == 1) {
    memset(b, 0, 9 * sizeof(double));
    return;
  }
  for (int r = 0; r < 3; ++r) {
    double dn = b[3 * r] * s->n[0] + b[3 * r + 1] * s->n[1] + b[3 * r + 2] * s->n[2];
    for (int c = 0; c < 3; ++c) b[3 * r + c] -= dn * s->n[c];
  }
}

/* The filtered diagonal block S A_ii S + (I - S), symmetrized. */
static inline void piola__filtered_diagonal(const piola__vertex_projection *s, const double *a,
                                            double out[9]) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[3 * r + c] = 0.5 * (a[3 * r + c] + a[3 * c + r]);
  piola__project_rows(s, out, 3);
  piola__project_columns(s, out);
  if (s->kind == 1) {
    out[0] = out[4] = out[8] = 1;
  } else if (s->kind == 2) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) out[3 * r + c] += s->n[r] * s->n[c];
  }
}

#endif
