/* The filtered conjugate gradient of the damping solves (src/sim/conjugate_gradient.c), on
 * small dense systems of the same shape: A = M + K with M a positive diagonal (per node) and
 * K symmetric positive semi-definite, some nodes held entirely and some with one direction
 * held. Checked against a direct solve of the reduced system: the held components keep the
 * guess, the free ones satisfy the equations, and the A x the solver hands back is A at its
 * x. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sim/conjugate_gradient.h"
#include "test_support.h"

enum { NODES = 7, DOF = 3 * NODES };

typedef struct dense_system {
  double a[DOF][DOF];
  double inverse_mass[NODES];
  int held[NODES];          /* 1: the whole node */
  double normal[NODES][3];  /* nonzero: this direction of the node is held */
  int applies;
} dense_system;

static void dense_apply(void *ctx, const double *p, double *out) {
  dense_system *d = ctx;
  d->applies++;
  for (int i = 0; i < DOF; ++i) {
    double s = 0;
    for (int j = 0; j < DOF; ++j) s += d->a[i][j] * p[j];
    out[i] = s;
  }
}

static void dense_filter(void *ctx, double *r, int32_t begin, int32_t end) {
  const dense_system *d = ctx;
  for (int i = begin; i < end; ++i) {
    double *ri = r + 3 * i;
    const double *n = d->normal[i];
    if (d->held[i]) {
      ri[0] = ri[1] = ri[2] = 0;
    } else {
      double dn = ri[0] * n[0] + ri[1] * n[1] + ri[2] * n[2];
      for (int k = 0; k < 3; ++k) ri[k] -= dn * n[k];
    }
  }
}

/* M (1..3 kg per node) + G^T G scaled by stiffness: SPD, condition set by stiffness. */
static void random_system(test_rng *rng, dense_system *d, double stiffness) {
  memset(d, 0, sizeof *d);
  double g[DOF][DOF];
  for (int i = 0; i < DOF; ++i)
    for (int j = 0; j < DOF; ++j) g[i][j] = test_rng_uniform(rng, -1, 1);
  for (int i = 0; i < DOF; ++i)
    for (int j = 0; j < DOF; ++j) {
      double s = 0;
      for (int k = 0; k < DOF; ++k) s += g[k][i] * g[k][j];
      d->a[i][j] = stiffness * s / DOF;
    }
  for (int i = 0; i < NODES; ++i) {
    double m = test_rng_uniform(rng, 1, 3);
    d->inverse_mass[i] = 1 / m;
    for (int k = 0; k < 3; ++k) d->a[3 * i + k][3 * i + k] += m;
  }
  d->held[1] = 1;
  double n[3] = {test_rng_normal(rng), test_rng_normal(rng), test_rng_normal(rng)};
  double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int k = 0; k < 3; ++k) d->normal[4][k] = n[k] / len;
}

/* Gaussian elimination with partial pivoting on an m x m system (a and b overwritten). */
static void dense_solve(int m, double *a, double *b) {
  for (int c = 0; c < m; ++c) {
    int piv = c;
    for (int r = c + 1; r < m; ++r)
      if (fabs(a[r * m + c]) > fabs(a[piv * m + c])) piv = r;
    for (int k = 0; k < m; ++k) {
      double t = a[c * m + k];
      a[c * m + k] = a[piv * m + k], a[piv * m + k] = t;
    }
    double t = b[c];
    b[c] = b[piv], b[piv] = t;
    for (int r = c + 1; r < m; ++r) {
      double f = a[r * m + c] / a[c * m + c];
      for (int k = c; k < m; ++k) a[r * m + k] -= f * a[c * m + k];
      b[r] -= f * b[c];
    }
  }
  for (int c = m - 1; c >= 0; --c) {
    for (int k = c + 1; k < m; ++k) b[c] -= a[c * m + k] * b[k];
    b[c] /= a[c * m + c];
  }
}

/* The exact filtered solution: x = x0 + B y, B an orthonormal basis of the free space,
 * (B^T A B) y = B^T (b - A x0). */
static void reference_solution(const dense_system *d, const double *b, const double *x0, double *x) {
  static double basis[DOF][DOF];
  int cols = 0;
  for (int i = 0; i < NODES; ++i) {
    if (d->held[i]) continue;
    for (int k = 0; k < 3; ++k) {
      double e[DOF] = {0};
      e[3 * i + k] = 1;
      dense_filter((void *)d, e, 0, NODES);
      /* Gram-Schmidt against the node's earlier columns */
      for (int c = 0; c < cols; ++c) {
        double s = 0;
        for (int j = 0; j < DOF; ++j) s += basis[c][j] * e[j];
        for (int j = 0; j < DOF; ++j) e[j] -= s * basis[c][j];
      }
      double len = 0;
      for (int j = 0; j < DOF; ++j) len += e[j] * e[j];
      if (len < 1e-20) continue;
      for (int j = 0; j < DOF; ++j) basis[cols][j] = e[j] / sqrt(len);
      cols++;
    }
  }
  double r[DOF], ax0[DOF];
  dense_apply((void *)d, x0, ax0);
  for (int i = 0; i < DOF; ++i) r[i] = b[i] - ax0[i];
  double *red = calloc((size_t)cols * (size_t)cols, sizeof *red), rhs[DOF];
  for (int p = 0; p < cols; ++p) {
    double ab[DOF];
    dense_apply((void *)d, basis[p], ab);
    for (int q = 0; q < cols; ++q) {
      double s = 0;
      for (int j = 0; j < DOF; ++j) s += basis[q][j] * ab[j];
      red[q * cols + p] = s;
    }
    double s = 0;
    for (int j = 0; j < DOF; ++j) s += basis[p][j] * r[j];
    rhs[p] = s;
  }
  dense_solve(cols, red, rhs);
  for (int i = 0; i < DOF; ++i) {
    x[i] = x0[i];
    for (int p = 0; p < cols; ++p) x[i] += basis[p][i] * rhs[p];
  }
  free(red);
}

static void solves_the_filtered_system_and_returns_its_product(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(31);
  const double stiffness[] = {0.01, 1, 30};
  for (int trial = 0; trial < 3 * (int)test_samples(10, 2); ++trial) {
    dense_system d;
    random_system(&rng, &d, stiffness[trial % 3]);
    double b[DOF], x0[DOF], x[DOF], ref[DOF], ax[DOF], direct[DOF], work[3 * DOF];
    for (int i = 0; i < DOF; ++i) b[i] = test_rng_uniform(&rng, -1, 1), x0[i] = test_rng_uniform(&rng, -1, 1);
    memcpy(x, x0, sizeof x);
    cg_problem pb = {NODES, dense_apply, dense_filter, &d, d.inverse_mass, 1e-12, 200, NULL, NULL};
    int32_t it = piola__cg_solve(&pb, b, x, work, ax);
    assert_true(it > 0 && it < 200);
    reference_solution(&d, b, x0, ref);
    double scale = 0;
    for (int i = 0; i < DOF; ++i) scale = fmax(scale, fabs(ref[i]));
    for (int i = 0; i < DOF; ++i) assert_close(x[i], ref[i], 1e-9 * scale);
    /* held components keep the guess */
    for (int k = 0; k < 3; ++k) assert_close(x[3 + k], x0[3 + k], 0);
    double dn = 0;
    for (int k = 0; k < 3; ++k) dn += (x[12 + k] - x0[12 + k]) * d.normal[4][k];
    assert_close(dn, 0, 1e-12);
    /* the product handed back is A at the returned x (held rows included) */
    dense_apply(&d, x, direct);
    double amax = 0;
    for (int i = 0; i < DOF; ++i) amax = fmax(amax, fabs(direct[i]));
    for (int i = 0; i < DOF; ++i) assert_close(ax[i], direct[i], 1e-12 * amax);
  }
}

static void a_converged_guess_costs_one_apply(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(5);
  dense_system d;
  random_system(&rng, &d, 1);
  double x[DOF], b[DOF], ax[DOF], work[3 * DOF];
  for (int i = 0; i < DOF; ++i) x[i] = test_rng_uniform(&rng, -1, 1);
  dense_apply(&d, x, b); /* x already solves it */
  d.applies = 0;
  cg_problem pb = {NODES, dense_apply, dense_filter, &d, d.inverse_mass, 1e-8, 200, NULL, NULL};
  assert_int_equal(piola__cg_solve(&pb, b, x, work, ax), 0);
  assert_int_equal(d.applies, 1);
  for (int i = 0; i < DOF; ++i) assert_close(ax[i], b[i], 0);
}

/* M^-1-norm of the filtered residual b - A x. */
static double residual_norm(dense_system *d, const double *b, const double *x) {
  double ax[DOF], r[DOF];
  dense_apply(d, x, ax);
  for (int i = 0; i < DOF; ++i) r[i] = b[i] - ax[i];
  dense_filter(d, r, 0, NODES);
  double s = 0;
  for (int i = 0; i < DOF; ++i) s += r[i] * r[i] * d->inverse_mass[i / 3];
  return sqrt(s);
}

/* The stopping test is relative to the residual of the guess, not to b: it stops once the
 * residual is below tol times the initial one, and moving guess and right-hand side together
 * by a large y (x0 + y, b + A y: the same correction to make, as for a fast body whose old
 * velocity is the guess) leaves the iterations as they were. */
static void stops_relative_to_the_initial_residual(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(9);
  for (int trial = 0; trial < (int)test_samples(10, 2); ++trial) {
    dense_system d;
    random_system(&rng, &d, 30);
    double b[DOF], x0[DOF], y[DOF], ay[DOF], b2[DOF], x2[DOF], x[DOF], work[3 * DOF];
    for (int i = 0; i < DOF; ++i) {
      b[i] = test_rng_uniform(&rng, -1, 1), x0[i] = test_rng_uniform(&rng, -1, 1);
      y[i] = 1e4 * test_rng_uniform(&rng, -1, 1);
    }
    dense_apply(&d, y, ay);
    for (int i = 0; i < DOF; ++i) b2[i] = b[i] + ay[i], x2[i] = x0[i] + y[i];
    const double tol = 1e-3;
    cg_problem pb = {NODES, dense_apply, dense_filter, &d, d.inverse_mass, tol, 200, NULL, NULL};
    memcpy(x, x0, sizeof x);
    int32_t it = piola__cg_solve(&pb, b, x, work, NULL);
    int32_t it2 = piola__cg_solve(&pb, b2, x2, work, NULL);
    assert_true(it > 0);
    assert_int_equal(it, it2);
    double r0 = residual_norm(&d, b, x0), r = residual_norm(&d, b, x);
    assert_true(r <= tol * r0 * (1 + 1e-9));
    /* and it stopped there, short of what a tight tolerance takes */
    cg_problem tight = pb;
    tight.tolerance = 1e-12;
    memcpy(x, x0, sizeof x);
    assert_true(piola__cg_solve(&tight, b, x, work, NULL) > it);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(solves_the_filtered_system_and_returns_its_product),
      cmocka_unit_test(a_converged_guess_costs_one_apply),
      cmocka_unit_test(stops_relative_to_the_initial_residual),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
