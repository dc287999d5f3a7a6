/* The invertible diagonalization F = U Fhat V^T (include/piola/diagonalize.h).
 *
 * Every sampled F is checked against the whole contract: reconstruction to 1e-12 |F|, U and V
 * orthonormal and proper to 1e-12, entries sorted by magnitude, at most one negative entry and
 * only the last, its sign equal to the sign of det F wherever that sign is numerically
 * determined, finite outputs. The singular values are checked by an independent route: the
 * three symmetric functions of the squared singular values are |F|^2, |cof F|^2 and det F^2,
 * and the signed product of Fhat must equal det F; for well separated Gaussian samples the
 * eigenvalues of F^T F from the closed-form cubic are compared entry by entry as well. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "test_support.h"

#include "math/mat3.h"
#include "piola/diagonalize.h"

/* ------------------------------------------------------------------------ checking */

typedef struct worst_seen {
  long count;
  double reconstruction; /* |U Fhat V^T - F| / |F| */
  double orthonormality; /* max |U^T U - I|, |V^T V - I| */
  double determinant;    /* max |det U - 1|, |det V - 1| */
  double invariants;     /* scaled error of |F|^2, |cof F|^2, det F */
  double cubic;          /* error of fhat^2 against the cubic's roots, over |F|^2 */
} worst_seen;

static void report(const char *name, const worst_seen *w) {
  char cubic[32] = "-";
  if (w->cubic > 0) snprintf(cubic, sizeof cubic, "%.2e", w->cubic);
  print_message("%-30s %9ld matrices  recon %.2e  orth %.2e  det %.2e  invariants %.2e  cubic %s\n",
                name, w->count, w->reconstruction, w->orthonormality, w->determinant,
                w->invariants, cubic);
}

static double max_abs3(const mat3 *f) { return mat3_max_abs(*f); }

/* Exponent e with max|F| = f 2^e, f in [0.5, 1): the tests compare F 2^-e and Fhat 2^-e, so
 * squares neither overflow nor vanish (ldexp, since 2^-e itself may not be a double). */
static int scale_exponent(double max_abs) {
  int e = 0;
  if (max_abs > 0) (void)frexp(max_abs, &e);
  return e;
}

static void print_matrix3(const mat3 *f) {
  for (int i = 0; i < 3; ++i)
    print_error("  [%.17g, %.17g, %.17g]\n", f->m[i][0], f->m[i][1], f->m[i][2]);
}

/* Eigenvalues of a symmetric 3x3 matrix, descending, by the trigonometric solution of its
 * characteristic cubic: a route that shares nothing with the code under test. */
static void symmetric_eigenvalues_cubic(const mat3 *c, double lambda[3]) {
  double q = mat3_trace(*c) / 3.0;
  double p1 = c->m[0][1] * c->m[0][1] + c->m[0][2] * c->m[0][2] + c->m[1][2] * c->m[1][2];
  double d0 = c->m[0][0] - q, d1 = c->m[1][1] - q, d2 = c->m[2][2] - q;
  double p2 = d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * p1;
  double p = sqrt(p2 / 6.0);
  if (p == 0) {
    lambda[0] = lambda[1] = lambda[2] = q;
    return;
  }
  mat3 b = mat3_scale(mat3_sub(*c, mat3_scale(mat3_identity(), q)), 1.0 / p);
  double r = fmax(-1.0, fmin(1.0, mat3_det(b) / 2.0));
  double phi = acos(r) / 3.0;
  lambda[0] = q + 2.0 * p * cos(phi);
  lambda[2] = q + 2.0 * p * cos(phi + 2.0 * M_PI / 3.0);
  lambda[1] = 3.0 * q - lambda[0] - lambda[2];
}

/* Runs piola_diagonalize3 on f and checks the full contract. compare_cubic: also compare with
 * the closed-form eigenvalues of F^T F where they are well separated. */
static void check3(const mat3 *f, worst_seen *w, const char *what, long index, int compare_cubic) {
  mat3 u, v;
  piola_vec3 fh;
  piola_status s = piola_diagonalize3(f, &u, &fh, &v);
  double d[3] = {fh.x, fh.y, fh.z};
  const char *problem = NULL;
  char detail[256] = "";
  double m = max_abs3(f);
  int ex = scale_exponent(m);
  mat3 fs;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) fs.m[i][j] = ldexp(f->m[i][j], -ex);
  double ds[3] = {ldexp(d[0], -ex), ldexp(d[1], -ex), ldexp(d[2], -ex)};
  double nf = mat3_norm(fs);
  /* Outputs cannot be finer than the smallest subnormal: for F near the bottom of the double
   * range (beyond the contract's 1e-150) that spacing, not the algorithm, limits accuracy. */
  double quantum = nf > 0 ? 8.0 * ldexp(DBL_TRUE_MIN, -ex) / nf : 0.0;

  if (s != PIOLA_OK) problem = "status is not PIOLA_OK";
  if (!problem && (!mat3_is_finite(u) || !mat3_is_finite(v) || !isfinite(d[0]) ||
                   !isfinite(d[1]) || !isfinite(d[2])))
    problem = "non-finite output";
  if (!problem) {
    double orth = fmax(mat3_max_abs(mat3_sub(mat3_mul_transpose_a(u, u), mat3_identity())),
                       mat3_max_abs(mat3_sub(mat3_mul_transpose_a(v, v), mat3_identity())));
    double det = fmax(fabs(mat3_det(u) - 1.0), fabs(mat3_det(v) - 1.0));
    w->orthonormality = fmax(w->orthonormality, orth);
    w->determinant = fmax(w->determinant, det);
    if (orth > 1e-12) problem = "U or V not orthonormal to 1e-12";
    if (det > 1e-12) problem = "det U or det V differs from +1 by more than 1e-12";
  }
  if (!problem) {
    mat3 rec = mat3_mul_diag_transpose(u, (vec3){ds[0], ds[1], ds[2]}, v);
    double err = mat3_norm(mat3_sub(rec, fs));
    double rel = nf > 0 ? err / nf : err;
    w->reconstruction = fmax(w->reconstruction, rel);
    if (rel > 1e-12 + quantum) {
      problem = "|U Fhat V^T - F| > 1e-12 |F|";
      snprintf(detail, sizeof detail, "relative error %.3e", rel);
    }
  }
  if (!problem && !(fabs(d[0]) >= fabs(d[1]) && fabs(d[1]) >= fabs(d[2])))
    problem = "|fhat| not sorted in decreasing order";
  if (!problem && (d[0] < 0 || d[1] < 0)) problem = "a negative entry other than the last";
  if (!problem) {
    /* Sign of det F: trusted only where it exceeds the rounding of its own evaluation. */
    double det = mat3_det(fs);
    if (fabs(det) > 1e-12 * nf * nf * nf) {
      if (det > 0 && !(d[2] > 0)) problem = "det F > 0 but the last entry is not positive";
      if (det < 0 && !(d[2] < 0)) problem = "det F < 0 but the last entry is not negative";
    }
    if (m == 0 && (d[0] != 0 || d[1] != 0 || d[2] != 0)) problem = "F = 0 but Fhat != 0";
  }
  if (!problem) {
    /* Symmetric functions: sum s_i^2 = |F|^2, sum (s_i s_j)^2 = |cof F|^2, prod fhat = det F. */
    double n2 = nf * nf;
    double e1 = fabs(ds[0] * ds[0] + ds[1] * ds[1] + ds[2] * ds[2] - n2) / (n2 > 0 ? n2 : 1);
    double c2 = mat3_ddot(mat3_cofactor(fs), mat3_cofactor(fs));
    double p01 = ds[0] * ds[1], p02 = ds[0] * ds[2], p12 = ds[1] * ds[2];
    double e2 = fabs(p01 * p01 + p02 * p02 + p12 * p12 - c2) / (n2 > 0 ? n2 * n2 : 1);
    double e3 = fabs(ds[0] * ds[1] * ds[2] - mat3_det(fs)) / (n2 > 0 ? n2 * nf : 1);
    double e = fmax(e1, fmax(e2, e3));
    w->invariants = fmax(w->invariants, e);
    if (e > 1e-13 + 4.0 * quantum) {
      problem = "Fhat does not match |F|^2, |cof F|^2 or det F";
      snprintf(detail, sizeof detail, "errors %.3e %.3e %.3e", e1, e2, e3);
    }
  }
  if (!problem && compare_cubic && nf > 0) {
    double lambda[3];
    mat3 c = mat3_mul_transpose_a(fs, fs);
    symmetric_eigenvalues_cubic(&c, lambda);
    double n2 = nf * nf;
    int separated = lambda[0] - lambda[1] > 1e-3 * n2 && lambda[1] - lambda[2] > 1e-3 * n2;
    if (separated)
      for (int k = 0; k < 3; ++k) {
        double e = fabs(ds[k] * ds[k] - lambda[k]) / n2;
        w->cubic = fmax(w->cubic, e);
        if (e > 1e-11) {
          problem = "fhat^2 differs from the eigenvalues of F^T F (characteristic cubic)";
          snprintf(detail, sizeof detail, "entry %d: %.17g vs %.17g", k, ds[k] * ds[k], lambda[k]);
        }
      }
  }
  w->count++;
  if (problem) {
    print_error("%s sample %ld: %s %s\nF =\n", what, index, problem, detail);
    print_matrix3(f);
    print_error("fhat = [%.17g, %.17g, %.17g]\nU =\n", d[0], d[1], d[2]);
    print_matrix3(&u);
    print_error("V =\n");
    print_matrix3(&v);
    fail_msg("diagonalize3 contract violated (%s)", what);
  }
}

static void check3x2(const mat3x2 *f, worst_seen *w, const char *what, long index);
static mat3x2 first_two_columns(mat3 a);

/* ------------------------------------------------------------------------ generators */

static double gauss(test_rng *r) { return test_rng_normal(r); }

static mat3 gaussian3(test_rng *r) {
  mat3 a;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a.m[i][j] = gauss(r);
  return a;
}

/* Uniformly random rotation from a random unit quaternion. */
static mat3 random_rotation(test_rng *r) {
  double q[4], n = 0;
  do {
    n = 0;
    for (int k = 0; k < 4; ++k) {
      q[k] = gauss(r);
      n += q[k] * q[k];
    }
  } while (n < 1e-6);
  n = 1.0 / sqrt(n);
  double w = q[0] * n, x = q[1] * n, y = q[2] * n, z = q[3] * n;
  return (mat3){{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                 {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                 {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
}

static double random_sign(test_rng *r) { return (test_rng_next(r) & 1) ? -1.0 : 1.0; }

static double log_uniform(test_rng *r, double lo_exp10, double hi_exp10) {
  return pow(10.0, test_rng_uniform(r, lo_exp10, hi_exp10));
}

static mat3 rotated_diagonal(test_rng *r, double a, double b, double c) {
  return mat3_mul(mat3_mul(random_rotation(r), mat3_diag(a, b, c)),
                  mat3_transpose(random_rotation(r)));
}

static mat3 permutation3(int which) {
  static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  mat3 p = mat3_zero();
  for (int i = 0; i < 3; ++i) p.m[i][perms[which][i]] = 1.0;
  return p;
}

static double small_int(test_rng *r, double zero_probability) {
  if (test_rng_uniform(r, 0, 1) < zero_probability) return 0.0;
  return (double)((long)(test_rng_next(r) % 9) - 4);
}

/* ------------------------------------------------------------------------ 3x3 properties */

static void gaussian_matrices(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(101);
  worst_seen w = {0};
  long n = test_samples(2000000, 2000);
  for (long i = 0; i < n; ++i) {
    mat3 f = gaussian3(&r);
    check3(&f, &w, "gaussian", i, 1);
  }
  report("gaussian", &w);
}

static void rotations_times_signed_diagonals(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(202);
  worst_seen w = {0};
  long n = test_samples(1000000, 1000);
  for (long i = 0; i < n; ++i) {
    double a = random_sign(&r) * log_uniform(&r, -3, 3), b = random_sign(&r) * log_uniform(&r, -3, 3),
           c = random_sign(&r) * log_uniform(&r, -3, 3);
    mat3 f = rotated_diagonal(&r, a, b, c);
    check3(&f, &w, "rotation diag rotation", i, 1);
  }
  report("rotation*diag*rotation", &w);
}

static void reflections(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(303);
  worst_seen w = {0};
  long n = test_samples(500000, 500);
  for (long i = 0; i < n; ++i) {
    mat3 f;
    if (i % 2 == 0) { /* a Householder reflection I - 2 n n^T, det -1, all singular values 1 */
      vec3 nv = vec3_make(gauss(&r), gauss(&r), gauss(&r));
      nv = vec3_scale(nv, 1.0 / vec3_norm(nv));
      f = mat3_identity();
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) f.m[a][b] -= 2.0 * vec3_get(nv, a) * vec3_get(nv, b);
    } else { /* stretched reflection: rotation diag(a, b, -c) rotation, det < 0 */
      f = rotated_diagonal(&r, log_uniform(&r, -2, 2), log_uniform(&r, -2, 2),
                           -log_uniform(&r, -2, 2));
    }
    assert_true(mat3_det(f) < 0);
    check3(&f, &w, "reflection", i, 0);
  }
  report("reflections", &w);
}

static void near_rank_deficient(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(404);
  worst_seen w = {0};
  long n = test_samples(1000000, 1000);
  for (long i = 0; i < n; ++i) {
    double s1 = random_sign(&r) * log_uniform(&r, -300, -8);
    double s2 = (i % 3 == 0) ? random_sign(&r) * log_uniform(&r, -300, -8)
                             : random_sign(&r) * log_uniform(&r, -1, 0);
    mat3 f;
    if (i % 4 == 3) { /* graded: tiny singular values carried by tiny columns */
      f = mat3_mul(gaussian3(&r), mat3_diag(1.0, fabs(s1), fabs(s2)));
    } else {
      f = mat3_mul(rotated_diagonal(&r, 1.0, s1, s2), permutation3((int)(i % 6)));
    }
    check3(&f, &w, "near rank deficient", i, 0);
  }
  report("near rank deficient", &w);
}

static void exact_low_rank(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(505);
  worst_seen w = {0};
  long n = test_samples(500000, 500);
  for (long i = 0; i < n; ++i) {
    mat3 f = mat3_zero();
    vec3 a = vec3_make(small_int(&r, 0.3), small_int(&r, 0.3), small_int(&r, 0.3));
    vec3 b = vec3_make(small_int(&r, 0.3), small_int(&r, 0.3), small_int(&r, 0.3));
    switch (i % 4) {
      case 0: /* rank 0, with signed zeros */
        for (int k = 0; k < 9; ++k) f.m[k / 3][k % 3] = random_sign(&r) * 0.0;
        break;
      case 1: /* rank 1: an integer outer product a b^T (exact) */
        for (int p = 0; p < 3; ++p)
          for (int q = 0; q < 3; ++q) f.m[p][q] = vec3_get(a, p) * vec3_get(b, q);
        break;
      case 2: { /* rank 2: third column an integer combination of the first two (exact) */
        double al = small_int(&r, 0.2), be = small_int(&r, 0.2);
        mat3_set_column(&f, 0, a);
        mat3_set_column(&f, 1, b);
        mat3_set_column(&f, 2, vec3_add(vec3_scale(a, al), vec3_scale(b, be)));
        f = mat3_mul(f, permutation3((int)(test_rng_next(&r) % 6)));
        break;
      }
      default: { /* rank 1 from real vectors: rank 1 up to rounding */
        vec3 x = vec3_make(gauss(&r), gauss(&r), gauss(&r));
        vec3 y = vec3_make(gauss(&r), gauss(&r), gauss(&r));
        for (int p = 0; p < 3; ++p)
          for (int q = 0; q < 3; ++q) f.m[p][q] = vec3_get(x, p) * vec3_get(y, q);
      }
    }
    check3(&f, &w, "exact low rank", i, 0);
  }
  report("exact rank 0/1/2", &w);
}

static void repeated_singular_values(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(606);
  worst_seen w = {0};
  long n = test_samples(500000, 500);
  for (long i = 0; i < n; ++i) {
    double a = log_uniform(&r, -2, 2), b = log_uniform(&r, -2, 2);
    double d[3] = {a, a, b};
    if (i % 5 == 0) d[2] = a;     /* all three equal: a scaled rotation or reflection */
    if (i % 7 == 0) d[2] = 0.0;   /* a repeated pair and a zero */
    for (int k = 0; k < 3; ++k) d[k] *= random_sign(&r);
    mat3 p = permutation3((int)(test_rng_next(&r) % 6));
    mat3 core = mat3_mul(mat3_mul(p, mat3_diag(d[0], d[1], d[2])), mat3_transpose(p));
    mat3 f = (i % 2 == 0) ? core
                          : mat3_mul(mat3_mul(random_rotation(&r), core),
                                     mat3_transpose(random_rotation(&r)));
    check3(&f, &w, "repeated singular values", i, 0);
  }
  report("repeated singular values", &w);
}

static void perturbed_identity_and_reflections(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(707);
  worst_seen w = {0};
  long n = test_samples(500000, 500);
  const mat3 bases[3] = {mat3_identity(), mat3_diag(-1, -1, -1), mat3_diag(1, 1, -1)};
  for (long i = 0; i < n; ++i) {
    double eps = log_uniform(&r, -17, -3);
    mat3 f = mat3_add(bases[i % 3], mat3_scale(gaussian3(&r), eps));
    check3(&f, &w, "perturbed I / -I / diag(1,1,-1)", i, 0);
  }
  report("perturbed I, -I, diag(1,1,-1)", &w);
}

static void extreme_scales(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(808);
  worst_seen w = {0}, wb = {0}; /* within the contract's range, and beyond it */
  long n = test_samples(500000, 500);
  for (long i = 0; i < n; ++i) {
    mat3 f;
    switch (i % 3) {
      case 0: f = gaussian3(&r); break;
      case 1: f = rotated_diagonal(&r, 1.0, random_sign(&r) * log_uniform(&r, -12, 0), -1e-9); break;
      default: f = rotated_diagonal(&r, 1.0, 1.0, random_sign(&r) * log_uniform(&r, -150, -8));
    }
    /* The contract's range 1e-150..1e150, and one sample in ten beyond it: down into the
     * subnormals and up to 1e300 (the algorithm scales by exact powers of two, so it should
     * not care). */
    int beyond = i % 10 == 9;
    double scale = beyond ? log_uniform(&r, -318, 300) : log_uniform(&r, -150, 150);
    f = mat3_scale(f, scale);
    check3(&f, beyond ? &wb : &w, "extreme scale", i, 0);
  }
  report("scales 1e-150..1e150", &w);
  report("scales 1e-318..1e300", &wb);
}

static void integer_matrices_with_zeros(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(909);
  worst_seen w = {0};
  long n = test_samples(1000000, 1000);
  for (long i = 0; i < n; ++i) {
    mat3 f;
    double pz = (i % 3 == 0) ? 0.8 : 0.5;
    for (int k = 0; k < 9; ++k) f.m[k / 3][k % 3] = small_int(&r, pz);
    check3(&f, &w, "integer", i, 0);
  }
  report("integers with zeros", &w);
}

/* Beyond the contract, a property of one-sided Jacobi worth keeping: for F = G D with G well
 * conditioned and D a column scaling down to 1e-40, even the tiny singular values come out to
 * high relative accuracy. Their product must equal |det G| d1 d2 d3 relatively, which an
 * absolutely accurate method (error ~1e-16 |F|) would miss by many orders of magnitude. */
static void column_graded_matrices_keep_relative_accuracy(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(1414);
  long n = test_samples(200000, 200), tested = 0;
  double worst = 0;
  for (long i = 0; i < n; ++i) {
    mat3 g = gaussian3(&r);
    double dg = mat3_det(g);
    if (fabs(dg) < 0.1) continue; /* keeps cond(G) below about 1e3 */
    double dd[3] = {1.0, log_uniform(&r, -40, 0), log_uniform(&r, -40, 0)};
    mat3 f = mat3_mul(g, mat3_diag(dd[0], dd[1], dd[2])), u, v;
    piola_vec3 d;
    assert_int_equal(piola_diagonalize3(&f, &u, &d, &v), PIOLA_OK);
    double e = fabs(d.x * d.y * d.z / (dg * dd[1] * dd[2]) - 1.0);
    worst = fmax(worst, e);
    ++tested;
    if (!(e <= 1e-11))
      fail_msg("graded sample %ld: product of Fhat off by %.3e relative (d = %g, %g)", i, e,
               dd[1], dd[2]);
  }
  print_message("column-graded: %ld matrices, worst relative error of prod(fhat) %.2e\n", tested,
                worst);
}

/* Adversarial: entries of wildly different magnitudes in one matrix (1e-320..1e300, special
 * values, zeros), so the columns and singular values span the whole double range. */
static void wild_dynamic_range(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(1313);
  worst_seen w = {0}, wsub = {0};
  const double special[] = {0.0, DBL_TRUE_MIN, DBL_MIN, 1.0, 1e-300, 1e300, DBL_MAX / 8};
  long n = test_samples(300000, 300);
  for (long i = 0; i < n; ++i) {
    mat3 f;
    for (int k = 0; k < 9; ++k) {
      double x;
      uint64_t pick = test_rng_next(&r) % 4;
      if (pick == 0)
        x = special[test_rng_next(&r) % (sizeof special / sizeof special[0])];
      else if (pick == 1)
        x = 0.0;
      else
        x = log_uniform(&r, -320, 300);
      f.m[k / 3][k % 3] = random_sign(&r) * x;
    }
    /* Where all of F is below 1e-290, Fhat lands in the subnormals and its spacing, not the
     * algorithm, bounds the error (check3 allows for it): keep those apart in the report. */
    mat3x2 g = first_two_columns(f);
    double m3 = mat3_max_abs(f), m2 = 0;
    for (int k = 0; k < 6; ++k) m2 = fmax(m2, fabs(g.m[k / 2][k % 2]));
    check3(&f, m3 >= 1e-290 ? &w : &wsub, "wild dynamic range", i, 0);
    check3x2(&g, m2 >= 1e-290 ? &w : &wsub, "wild dynamic range 3x2", i);
  }
  report("wild range 3x3+3x2", &w);
  report("wild range, all F < 1e-290", &wsub);
}

/* Physics: Fhat depends only on the shape, not on rotations of world or material space, and
 * mirroring the world (-F) flips exactly the sign of the smallest entry. */
static void fhat_is_invariant_under_rotations(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(1010);
  long n = test_samples(200000, 200);
  double worst = 0;
  for (long i = 0; i < n; ++i) {
    mat3 f = (i % 2) ? gaussian3(&r)
                     : rotated_diagonal(&r, 1.0, log_uniform(&r, -6, 0),
                                        random_sign(&r) * log_uniform(&r, -12, 0));
    mat3 g = mat3_mul(mat3_mul(random_rotation(&r), f), mat3_transpose(random_rotation(&r)));
    mat3 h = mat3_scale(f, -1.0);
    mat3 u, v;
    piola_vec3 df, dg, dh;
    assert_int_equal(piola_diagonalize3(&f, &u, &df, &v), PIOLA_OK);
    assert_int_equal(piola_diagonalize3(&g, &u, &dg, &v), PIOLA_OK);
    assert_int_equal(piola_diagonalize3(&h, &u, &dh, &v), PIOLA_OK);
    double nf = mat3_norm(f);
    double a[3] = {df.x, df.y, df.z}, b[3] = {dg.x, dg.y, dg.z}, c[3] = {dh.x, dh.y, dh.z};
    int sign_known = fabs(mat3_det(f)) > 1e-12 * nf * nf * nf;
    for (int k = 0; k < 3; ++k) {
      double e = fmax(fabs(fabs(a[k]) - fabs(b[k])), fabs(fabs(a[k]) - fabs(c[k]))) / nf;
      worst = fmax(worst, e);
      assert_true(e <= 1e-13);
    }
    if (sign_known) {
      assert_true((a[2] > 0) == (b[2] > 0));
      assert_true((a[2] > 0) == (c[2] < 0));
    }
  }
  print_message("rotation invariance: %ld triples, worst |fhat| change %.2e |F|\n", n, worst);
}

/* ------------------------------------------------------------------------ 3x3 explicit */

static void zero_gives_identity_frames(void **state) {
  (void)state;
  mat3 f = mat3_zero(), u, v;
  f.m[1][2] = -0.0;
  piola_vec3 d;
  assert_int_equal(piola_diagonalize3(&f, &u, &d, &v), PIOLA_OK);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      assert_true(u.m[i][j] == (i == j ? 1.0 : 0.0));
      assert_true(v.m[i][j] == (i == j ? 1.0 : 0.0));
    }
  assert_true(d.x == 0 && d.y == 0 && d.z == 0);
  assert_false(signbit(d.x) || signbit(d.y) || signbit(d.z));
}

static void single_nonzero_entry(void **state) {
  (void)state;
  worst_seen w = {0};
  const double values[] = {1.0, -2.5, 1e-300, -1e300, 4.9e-324, DBL_MAX / 4, -DBL_MIN};
  for (int k = 0; k < 9; ++k)
    for (size_t t = 0; t < sizeof values / sizeof values[0]; ++t) {
      mat3 f = mat3_zero(), u, v;
      f.m[k / 3][k % 3] = values[t];
      check3(&f, &w, "single entry", k, 0);
      piola_vec3 d;
      assert_int_equal(piola_diagonalize3(&f, &u, &d, &v), PIOLA_OK);
      assert_close(d.x, fabs(values[t]), 4 * DBL_EPSILON * fabs(values[t]));
      assert_true(d.y == 0 && d.z == 0);
    }
}

static void analytic_cases(void **state) {
  (void)state;
  struct {
    mat3 f;
    double expected[3];
  } cases[] = {
      {mat3_identity(), {1, 1, 1}},
      {mat3_diag(-1, -1, -1), {1, 1, -1}},
      {mat3_diag(1, 1, -1), {1, 1, -1}},
      {mat3_diag(3, -2, 1), {3, 2, -1}},
      {mat3_diag(-3, -2, 1), {3, 2, 1}},
      {mat3_diag(0.5, -4, 0), {4, 0.5, 0}},
      {mat3_diag(-1e-200, 7, 7), {7, 7, -1e-200}},
      {(mat3){{{0, 2, 0}, {0, 0, 3}, {1, 0, 0}}}, {3, 2, 1}},  /* permutation, det +6 */
      {(mat3){{{0, 2, 0}, {3, 0, 0}, {0, 0, 1}}}, {3, 2, -1}}, /* odd permutation, det -6 */
  };
  worst_seen w = {0};
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
    mat3 u, v;
    piola_vec3 d;
    check3(&cases[c].f, &w, "analytic", (long)c, 0);
    assert_int_equal(piola_diagonalize3(&cases[c].f, &u, &d, &v), PIOLA_OK);
    double got[3] = {d.x, d.y, d.z};
    for (int k = 0; k < 3; ++k)
      assert_close(got[k], cases[c].expected[k], 4 * DBL_EPSILON * fabs(cases[c].expected[k]));
  }
  /* A pure rotation: Fhat = I and U V^T is the rotation itself. */
  test_rng r = test_rng_seeded(11);
  for (int t = 0; t < 100; ++t) {
    mat3 q = random_rotation(&r), u, v;
    piola_vec3 d;
    assert_int_equal(piola_diagonalize3(&q, &u, &d, &v), PIOLA_OK);
    assert_close(d.x, 1, 1e-14);
    assert_close(d.y, 1, 1e-14);
    assert_close(d.z, 1, 1e-14);
    assert_true(mat3_max_abs(mat3_sub(mat3_mul_transpose_b(u, v), q)) < 1e-14);
  }
}

static void non_finite_input_is_rejected(void **state) {
  (void)state;
  const double bad[] = {NAN, INFINITY, -INFINITY};
  for (int k = 0; k < 9; ++k)
    for (int t = 0; t < 3; ++t) {
      mat3 f = mat3_identity(), u = mat3_zero(), v = mat3_zero();
      f.m[k / 3][k % 3] = bad[t];
      piola_vec3 d = {5, 5, 5};
      piola_clear_error();
      assert_int_equal(piola_diagonalize3(&f, &u, &d, &v), PIOLA_ERROR_NOT_FINITE);
      assert_non_null(strstr(piola_last_error(), "not finite"));
      char where[16];
      snprintf(where, sizeof where, "F[%d][%d]", k / 3, k % 3);
      assert_non_null(strstr(piola_last_error(), where));
      assert_true(mat3_max_abs(mat3_sub(u, mat3_identity())) == 0);
      assert_true(mat3_max_abs(mat3_sub(v, mat3_identity())) == 0);
      assert_true(d.x == 0 && d.y == 0 && d.z == 0);
    }
}

static void singular_values_beyond_double_range_are_reported(void **state) {
  (void)state;
  mat3 f, u, v;
  for (int k = 0; k < 9; ++k) f.m[k / 3][k % 3] = DBL_MAX; /* rank 1, sigma = 3 DBL_MAX */
  piola_vec3 d;
  assert_int_equal(piola_diagonalize3(&f, &u, &d, &v), PIOLA_ERROR_NOT_FINITE);
  assert_true(mat3_max_abs(mat3_sub(u, mat3_identity())) == 0);
  assert_true(d.x == 0 && d.y == 0 && d.z == 0);
  /* Just inside the range it works. */
  for (int k = 0; k < 9; ++k) f.m[k / 3][k % 3] = DBL_MAX / 4;
  worst_seen w = {0};
  check3(&f, &w, "near DBL_MAX", 0, 0);
}

/* ------------------------------------------------------------------------ 3x2 */

static void print_matrix3x2(const mat3x2 *f) {
  for (int i = 0; i < 3; ++i) print_error("  [%.17g, %.17g]\n", f->m[i][0], f->m[i][1]);
}

static void check3x2(const mat3x2 *f, worst_seen *w, const char *what, long index) {
  mat3x2 u;
  mat2 v;
  double d[2];
  piola_status s = piola_diagonalize3x2(f, &u, d, &v);
  const char *problem = NULL;
  char detail[256] = "";
  double m = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) m = fmax(m, fabs(f->m[i][j]));
  int ex = scale_exponent(m);
  mat3x2 fs;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) fs.m[i][j] = ldexp(f->m[i][j], -ex);
  double ds[2] = {ldexp(d[0], -ex), ldexp(d[1], -ex)};
  double nf = mat3x2_norm(fs);
  double quantum = nf > 0 ? 8.0 * ldexp(DBL_TRUE_MIN, -ex) / nf : 0.0; /* as in check3 */
  int finite = isfinite(d[0]) && isfinite(d[1]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) finite = finite && isfinite(u.m[i][j]);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) finite = finite && isfinite(v.m[i][j]);

  if (s != PIOLA_OK) problem = "status is not PIOLA_OK";
  if (!problem && !finite) problem = "non-finite output";
  if (!problem) {
    double orth = 0;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        double uu = 0, vv = 0;
        for (int k = 0; k < 3; ++k) uu += u.m[k][a] * u.m[k][b];
        for (int k = 0; k < 2; ++k) vv += v.m[k][a] * v.m[k][b];
        orth = fmax(orth, fmax(fabs(uu - (a == b)), fabs(vv - (a == b))));
      }
    double det = fabs(mat2_det(v) - 1.0);
    w->orthonormality = fmax(w->orthonormality, orth);
    w->determinant = fmax(w->determinant, det);
    if (orth > 1e-12) problem = "U or V columns not orthonormal to 1e-12";
    if (det > 1e-12) problem = "det V differs from +1 by more than 1e-12";
  }
  if (!problem) {
    mat3x2 rec = mat3x2_mul_diag_transpose(u, ds, v);
    double err2 = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 2; ++j) err2 += pow(rec.m[i][j] - fs.m[i][j], 2);
    double rel = nf > 0 ? sqrt(err2) / nf : sqrt(err2);
    w->reconstruction = fmax(w->reconstruction, rel);
    if (rel > 1e-12 + quantum) {
      problem = "|U Fhat V^T - F| > 1e-12 |F|";
      snprintf(detail, sizeof detail, "relative error %.3e", rel);
    }
  }
  if (!problem && !(d[0] >= d[1] && d[1] >= 0)) problem = "fhat not sorted and nonnegative";
  if (!problem) {
    /* s0^2 + s1^2 = |F|^2 and s0 s1 = |c0 x c1| (the area ratio of the triangle). */
    double n2 = nf * nf;
    vec3 c0 = mat3x2_column(fs, 0), c1 = mat3x2_column(fs, 1);
    double e1 = fabs(ds[0] * ds[0] + ds[1] * ds[1] - n2) / (n2 > 0 ? n2 : 1);
    double e2 = fabs(ds[0] * ds[1] - vec3_norm(vec3_cross(c0, c1))) / (n2 > 0 ? n2 : 1);
    double e = fmax(e1, e2);
    w->invariants = fmax(w->invariants, e);
    if (e > 1e-13 + 4.0 * quantum) {
      problem = "fhat does not match |F|^2 or the area ratio";
      snprintf(detail, sizeof detail, "errors %.3e %.3e", e1, e2);
    }
  }
  w->count++;
  if (problem) {
    print_error("%s sample %ld: %s %s\nF =\n", what, index, problem, detail);
    print_matrix3x2(f);
    print_error("fhat = [%.17g, %.17g]\nU =\n", d[0], d[1]);
    print_matrix3x2(&u);
    print_error("V = [%.17g, %.17g; %.17g, %.17g]\n", v.m[0][0], v.m[0][1], v.m[1][0], v.m[1][1]);
    fail_msg("diagonalize3x2 contract violated (%s)", what);
  }
}

static mat2 rotation2(double angle) {
  return (mat2){{{cos(angle), -sin(angle)}, {sin(angle), cos(angle)}}};
}

static mat3x2 first_two_columns(mat3 a) {
  return mat3x2_from_columns(mat3_column(a, 0), mat3_column(a, 1));
}

static void shells_property(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(1111);
  worst_seen w = {0}, wb = {0}; /* within the contract's range, and beyond it */
  long n = test_samples(2000000, 2000);
  for (long i = 0; i < n; ++i) {
    mat3x2 f;
    int beyond = i % 80 == 79;
    switch (i % 8) {
      case 0:
      case 1:
        for (int k = 0; k < 6; ++k) f.m[k / 2][k % 2] = gauss(&r);
        break;
      case 2: { /* orthonormal pair times diag times rotation, wide range of stretches */
        double dd[2] = {log_uniform(&r, -3, 3), log_uniform(&r, -3, 3)};
        f = mat3x2_mul_mat2(mat3x2_mul_diag_transpose(first_two_columns(random_rotation(&r)), dd,
                                                      mat2_identity()),
                            mat2_transpose(rotation2(test_rng_uniform(&r, -4, 4))));
        break;
      }
      case 3: { /* nearly collapsed to a line */
        double dd[2] = {1.0, log_uniform(&r, -300, -8)};
        f = mat3x2_mul_mat2(mat3x2_mul_diag_transpose(first_two_columns(random_rotation(&r)), dd,
                                                      mat2_identity()),
                            rotation2(test_rng_uniform(&r, -4, 4)));
        break;
      }
      case 4: { /* exactly collapsed to a line: parallel integer columns, or one zero column */
        vec3 a = vec3_make(small_int(&r, 0.3), small_int(&r, 0.3), small_int(&r, 0.3));
        double al = small_int(&r, 0.3);
        f = (test_rng_next(&r) & 1) ? mat3x2_from_columns(a, vec3_scale(a, al))
                                    : mat3x2_from_columns(vec3_scale(a, al), a);
        break;
      }
      case 5: /* integers with many zeros (includes the point, F = 0) */
        for (int k = 0; k < 6; ++k) f.m[k / 2][k % 2] = small_int(&r, 0.6);
        break;
      case 6: { /* equal stretches: a scaled isometry */
        double dd[2] = {2.0, 2.0};
        f = mat3x2_mul_mat2(mat3x2_mul_diag_transpose(first_two_columns(random_rotation(&r)), dd,
                                                      mat2_identity()),
                            rotation2(test_rng_uniform(&r, -4, 4)));
        break;
      }
      default: { /* extreme scales */
        double scale = beyond ? log_uniform(&r, -318, 300) : log_uniform(&r, -150, 150);
        for (int k = 0; k < 6; ++k) f.m[k / 2][k % 2] = gauss(&r) * scale;
        if (test_rng_next(&r) & 1)
          for (int k = 0; k < 3; ++k) f.m[k][1] = f.m[k][0] * 3.0; /* and collapsed */
      }
    }
    check3x2(&f, beyond ? &wb : &w, "shell", i);
  }
  report("3x2 mixed", &w);
  report("3x2 scales 1e-318..1e300", &wb);
}

static void shell_fhat_is_invariant_under_rotations(void **state) {
  (void)state;
  test_rng r = test_rng_seeded(1212);
  long n = test_samples(200000, 200);
  double worst = 0;
  for (long i = 0; i < n; ++i) {
    mat3x2 f, g, u;
    mat2 v;
    for (int k = 0; k < 6; ++k) f.m[k / 2][k % 2] = gauss(&r);
    mat3 q = random_rotation(&r);
    mat2 p = rotation2(test_rng_uniform(&r, -4, 4));
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 2; ++b) {
        double x = 0;
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 2; ++l) x += q.m[a][k] * f.m[k][l] * p.m[b][l];
        g.m[a][b] = x;
      }
    double df[2], dg[2];
    assert_int_equal(piola_diagonalize3x2(&f, &u, df, &v), PIOLA_OK);
    assert_int_equal(piola_diagonalize3x2(&g, &u, dg, &v), PIOLA_OK);
    double nf = mat3x2_norm(f);
    for (int k = 0; k < 2; ++k) {
      double e = fabs(df[k] - dg[k]) / nf;
      worst = fmax(worst, e);
      assert_true(e <= 1e-13);
    }
  }
  print_message("3x2 rotation invariance: %ld pairs, worst fhat change %.2e |F|\n", n, worst);
}

static void shells_explicit(void **state) {
  (void)state;
  mat3x2 f = {{{0, 0}, {0, 0}, {0, 0}}}, u;
  mat2 v;
  double d[2] = {7, 7};
  assert_int_equal(piola_diagonalize3x2(&f, &u, d, &v), PIOLA_OK);
  assert_true(d[0] == 0 && d[1] == 0);
  assert_true(u.m[0][0] == 1 && u.m[1][1] == 1 && u.m[0][1] == 0 && u.m[1][0] == 0 &&
              u.m[2][0] == 0 && u.m[2][1] == 0);
  assert_true(v.m[0][0] == 1 && v.m[1][1] == 1 && v.m[0][1] == 0 && v.m[1][0] == 0);

  worst_seen w = {0};
  for (int k = 0; k < 6; ++k) { /* a single nonzero entry: a line */
    mat3x2 g = {{{0, 0}, {0, 0}, {0, 0}}};
    g.m[k / 2][k % 2] = -3.0;
    check3x2(&g, &w, "single entry", k);
    assert_int_equal(piola_diagonalize3x2(&g, &u, d, &v), PIOLA_OK);
    assert_close(d[0], 3.0, 1e-15);
    assert_true(d[1] == 0);
  }
  /* In-plane identity and an in-plane mirror: a mirrored triangle is not inverted here. */
  mat3x2 id = {{{1, 0}, {0, 1}, {0, 0}}}, mirror = {{{1, 0}, {0, -1}, {0, 0}}};
  assert_int_equal(piola_diagonalize3x2(&id, &u, d, &v), PIOLA_OK);
  assert_close(d[0], 1, 1e-15);
  assert_close(d[1], 1, 1e-15);
  assert_int_equal(piola_diagonalize3x2(&mirror, &u, d, &v), PIOLA_OK);
  assert_close(d[0], 1, 1e-15);
  assert_close(d[1], 1, 1e-15);
  check3x2(&mirror, &w, "mirror", 0);

  const double bad[] = {NAN, INFINITY, -INFINITY};
  for (int k = 0; k < 6; ++k)
    for (int t = 0; t < 3; ++t) {
      mat3x2 g = {{{1, 0}, {0, 1}, {0, 0}}};
      g.m[k / 2][k % 2] = bad[t];
      piola_clear_error();
      assert_int_equal(piola_diagonalize3x2(&g, &u, d, &v), PIOLA_ERROR_NOT_FINITE);
      assert_non_null(strstr(piola_last_error(), "not finite"));
      assert_true(d[0] == 0 && d[1] == 0);
      assert_true(u.m[0][0] == 1 && u.m[1][1] == 1 && u.m[2][0] == 0 && u.m[2][1] == 0 &&
                  u.m[0][1] == 0 && u.m[1][0] == 0);
      assert_true(v.m[0][0] == 1 && v.m[1][1] == 1 && v.m[0][1] == 0 && v.m[1][0] == 0);
    }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(zero_gives_identity_frames),
      cmocka_unit_test(single_nonzero_entry),
      cmocka_unit_test(analytic_cases),
      cmocka_unit_test(non_finite_input_is_rejected),
      cmocka_unit_test(singular_values_beyond_double_range_are_reported),
      cmocka_unit_test(gaussian_matrices),
      cmocka_unit_test(rotations_times_signed_diagonals),
      cmocka_unit_test(reflections),
      cmocka_unit_test(near_rank_deficient),
      cmocka_unit_test(exact_low_rank),
      cmocka_unit_test(repeated_singular_values),
      cmocka_unit_test(perturbed_identity_and_reflections),
      cmocka_unit_test(extreme_scales),
      cmocka_unit_test(integer_matrices_with_zeros),
      cmocka_unit_test(fhat_is_invariant_under_rotations),
      cmocka_unit_test(wild_dynamic_range),
      cmocka_unit_test(column_graded_matrices_keep_relative_accuracy),
      cmocka_unit_test(shells_explicit),
      cmocka_unit_test(shells_property),
      cmocka_unit_test(shell_fhat_is_invariant_under_rotations),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
