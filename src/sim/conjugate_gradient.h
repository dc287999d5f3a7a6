/* A filtered, diagonally preconditioned conjugate gradient.
 *
 * The damping solves of the step loop are (M - h D) v = b with M the lumped mass and D the
 * linear damping operator: symmetric, and positive definite because damping only removes
 * energy. The operator is applied through a callback (for a solid, a product with the
 * damping matrix the body assembles once per update), so the solver needs no matrix.
 * Constrained nodes and the normal velocity of colliding nodes are held at the values of
 * the initial guess by a filter S that projects those components out of every residual and
 * search direction (Baraff and Witkin's modified conjugate gradient). The preconditioner is
 * the inverse lumped mass, which commutes with the per-node filter. Dot products are summed
 * over fixed node ranges in index order and the ranges in order, so results do not depend on
 * the thread count.
 *
 * The stopping test is relative to the residual of the initial guess, ||r|| <= tol ||b - A x0||
 * (filtered, M^-1 norm), not to ||b||. The callers' b is M v plus a step's worth of forces, so
 * ||b|| is a body's momentum, and a test relative to it lets a body moving at 3 m/s stop
 * with an error in its velocity change far larger, relative to that change, than the same
 * body at rest; at loose tolerances the guess (the old velocity) passed it before any
 * iteration. The
 * residual of a guess that carries the old velocity (A x0 = M x0 - h D x0, and D ignores
 * rigid motion) measures only the step's velocity change still to be made, so tol is the
 * fraction of that change left unresolved, whatever the body's speed.
 *
 * The solver also returns A x (unfiltered) at the solution, kept up to date alongside x
 * (A x += alpha A p with the A p it has anyway), so a caller that needs it (the friction
 * pass after the final solve) does not pay one more operator apply: the operator is the
 * expensive part of every iteration. */
#ifndef PIOLA_SIM_CONJUGATE_GRADIENT_H
#define PIOLA_SIM_CONJUGATE_GRADIENT_H

#include <stdint.h>

typedef struct cg_problem {
  int32_t n;                                  /* nodes; vectors are 3n */
  void (*apply)(void *ctx, const double *p, double *out); /* out = A p */
  /* projects the constrained components of nodes [begin, end) of r to zero; called on
   * disjoint node ranges from several threads at once */
  void (*filter)(void *ctx, double *r, int32_t begin, int32_t end);
  void *ctx;
  const double *inverse_mass;                 /* n, the preconditioner */
  double tolerance;                           /* residual / initial residual, M^-1 norm */
  int32_t max_iterations;
  double *initial_ax; /* 3n or NULL: receives A x at the guess, unfiltered */
  const double *given_ax; /* 3n or NULL: A x at the guess, known already (no apply for it) */
} cg_problem;

/* Solves A x = b starting from x (whose filtered components are kept). work holds 3 * 3n
 * doubles. ax (3n, may be NULL) receives A x at the returned x, unfiltered, to rounding.
 * Returns the iterations used. */
int32_t piola__cg_solve(const cg_problem *problem, const double *b, double *x, double *work,
                        double *ax);

#endif
