/* The derivatives of the shell forces for the implicit integrators (shell/shell_stiffness.h):
 *  - the membrane stiffness of a triangle, unprojected, against central differences of the
 *    forces for every model on random, stretched, compressed, nearly collapsed and inverted
 *    (reference normal) triangles, away from the models' kinks; its projection symmetric
 *    and negative semi-definite everywhere, and equal to the exact one where nothing clamps
 *    (biaxial tension);
 *  - the bending Gauss-Newton stiffness on flat, bent, folded and negatively bent hinges:
 *    equal to the differences of the forces when the rest angle is the current one, and off
 *    by exactly D w Phi'(theta) hess theta otherwise (hess theta from differences of the
 *    angle's gradient), symmetric, semi-definite;
 *  - the damping derivatives against differences of the damping forces;
 *  - the assembled system matrix of a sheet: symmetric, positive definite, and its product
 *    equal to M p - kw K p - dw D p summed from the element matrices. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "force/stiffness_matrix.h"
#include "shell/shell_body_internal.h"
#include "shell/shell_stiffness.h"
#include "test_shell_fixtures.h"

static double max_abs(const double *a, int n) { return shell_max_abs(a, (size_t)n); }

/* Checks that a (n x n) is symmetric and negative semi-definite, relative to its size. */
static void assert_symmetric_nsd(const double *a, int n, const char *what) {
  const double scale = max_abs(a, n * n);
  double copy[144], lambda[12];
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (!(fabs(a[n * i + j] - a[n * j + i]) <= 1e-12 * scale))
        fail_msg("%s: not symmetric at (%d, %d): %g vs %g", what, i, j, a[n * i + j], a[n * j + i]);
  memcpy(copy, a, sizeof(double) * (size_t)(n * n));
  test_symmetric_eigenvalues(copy, n, lambda);
  for (int i = 0; i < n; ++i)
    if (!(lambda[i] <= 1e-10 * scale)) fail_msg("%s: eigenvalue %g > 0 (scale %g)", what, lambda[i], scale);
}

/* Central differences of the forces of body at x (n vertices) into out (3n x 3n). */
static void force_differences(piola_shell_body *body, const double *x, int n, double *out) {
  double *xp = malloc(sizeof(double) * 3 * (size_t)n), *fp = malloc(sizeof(double) * 3 * (size_t)n);
  double *fm = malloc(sizeof(double) * 3 * (size_t)n);
  const double h = 1e-6;
  for (int c = 0; c < 3 * n; ++c) {
    memcpy(xp, x, sizeof(double) * 3 * (size_t)n);
    xp[c] = x[c] + h;
    assert_int_equal(piola_shell_body_update(body, xp, 1.0, fp, NULL), PIOLA_OK);
    xp[c] = x[c] - h;
    assert_int_equal(piola_shell_body_update(body, xp, 1.0, fm, NULL), PIOLA_OK);
    for (int r = 0; r < 3 * n; ++r) out[3 * n * r + c] = (fp[r] - fm[r]) / (2 * h);
  }
  double *f = fp;
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  free(xp), free(fp), free(fm);
}

static piola_shell_body *triangle_body(const piola_tri_mesh *mesh, const piola_material *material,
                                       int reference_normals) {
  piola_shell_body_def def = piola_default_shell_body_def();
  def.rest_mesh = mesh;
  def.materials = material;
  def.material_count = 1;
  def.thickness = 0.01;
  def.use_reference_normals = reference_normals;
  piola_shell_body *body = NULL;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_OK);
  return body;
}

/* Positions of the fixture triangle (rest in the xy plane, so its rest frame is x, y)
 * deformed by F = Q [diag(f0, f1); 0] R(phi)^T: a signed f1 < 0 mirrors it. */
static void deformed_triangle(const piola_tri_mesh *mesh, double f0, double f1, double phi,
                              const double q[9], double x[9]) {
  const double c = cos(phi), s = sin(phi);
  for (int a = 0; a < 3; ++a) {
    const double *p = mesh->positions + 3 * a;
    /* R^T X, then the stretches, then Q */
    const double r0 = c * p[0] + s * p[1], r1 = -s * p[0] + c * p[1];
    const double y[3] = {f0 * r0, f1 * r1, 0};
    for (int i = 0; i < 3; ++i) x[3 * a + i] = q[3 * i] * y[0] + q[3 * i + 1] * y[1] + q[3 * i + 2] * y[2];
  }
}

typedef struct triangle_case {
  const char *name;
  double f0, f1;
  int reference_normals;
} triangle_case;

static const triangle_case TRIANGLE_CASES[] = {
    {"near rest", 1.07, 0.93, 0},       {"stretched", 1.45, 1.31, 0},
    {"compressed", 0.7, 0.55, 0},       {"nearly collapsed", 1.1, 0.1, 0},
    {"collapsed to a point", 0.2, 0.1, 0}, {"inverted", 1.1, -0.5, 1},
    {"inverted and thin", 0.9, -0.1, 1}, {"sheared", 1.4, 0.6, 0},
};

static void membrane_matches_differences(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(14);
  piola_tri_mesh mesh = shell_single_triangle(1.0);
  const int cases = (int)(sizeof TRIANGLE_CASES / sizeof TRIANGLE_CASES[0]);
  for (int m = 0; m < SHELL_MODEL_COUNT; ++m)
    for (int k = 0; k < cases; ++k)
      for (int trial = 0; trial < (int)test_samples(3, 1); ++trial) {
        const triangle_case *tc = &TRIANGLE_CASES[k];
        piola_material material = shell_material(shell_all_models[m], 1e5);
        piola_shell_body *body = triangle_body(&mesh, &material, tc->reference_normals);
        double q[9], x[9], fd[81], exact[81], f[9];
        shell_random_rotation(&rng, q);
        if (tc->reference_normals) {
          /* inversion is against the world-space reference normal (+z): turn about z only */
          const double a = test_rng_uniform(&rng, 0, 2 * M_PI);
          const double qz[9] = {cos(a), -sin(a), 0, sin(a), cos(a), 0, 0, 0, 1};
          memcpy(q, qz, sizeof qz);
        }
        deformed_triangle(&mesh, tc->f0, tc->f1, test_rng_uniform(&rng, 0, 2 * M_PI), q, x);
        force_differences(body, x, 3, fd);
        assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
        assert_close(piola_shell_body_fhat(body)[1], tc->f1, 1e-9);
        piola__shell_triangle_stiffness(body, 0, 0, exact);
        const double scale = max_abs(exact, 81);
        for (int e = 0; e < 81; ++e)
          if (!(fabs(exact[e] - fd[e]) <= 2e-6 * scale))
            fail_msg("model %d, %s: entry (%d, %d) is %.9g, differences give %.9g (scale %g)",
                     (int)shell_all_models[m], tc->name, e / 9, e % 9, exact[e], fd[e], scale);
        double projected[81];
        piola__shell_triangle_stiffness(body, 0, 1, projected);
        char what[96];
        snprintf(what, sizeof what, "model %d, %s, projected", (int)shell_all_models[m], tc->name);
        assert_symmetric_nsd(projected, 9, what);
        /* rows sum to zero: no net force from a translation */
        for (int r = 0; r < 9; ++r)
          for (int j = 0; j < 3; ++j)
            assert_close(projected[9 * r + j] + projected[9 * r + 3 + j] + projected[9 * r + 6 + j],
                         0.0, 1e-12 * max_abs(projected, 81));
        piola_shell_body_destroy(body);
      }
  piola_tri_mesh_free(&mesh);
}

/* In biaxial tension every quotient and the diagonal block are already non-negative for the
 * models that stiffen under stretch: the projection changes nothing. */
static void projection_is_exact_in_tension(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(15);
  piola_tri_mesh mesh = shell_single_triangle(1.0);
  const piola_material_model models[] = {PIOLA_MODEL_COROTATED, PIOLA_MODEL_STVK,
                                         PIOLA_MODEL_NEOHOOKEAN};
  for (int m = 0; m < 3; ++m) {
    piola_material material = shell_material(models[m], 1e5);
    piola_shell_body *body = triangle_body(&mesh, &material, 0);
    double q[9], x[9], f[9], exact[81], projected[81];
    shell_random_rotation(&rng, q);
    deformed_triangle(&mesh, 1.3, 1.1, 0.4, q, x);
    assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
    piola__shell_triangle_stiffness(body, 0, 0, exact);
    piola__shell_triangle_stiffness(body, 0, 1, projected);
    for (int e = 0; e < 81; ++e) assert_close(projected[e], exact[e], 1e-10 * max_abs(exact, 81));
    piola_shell_body_destroy(body);
  }
  piola_tri_mesh_free(&mesh);
}

/* Two triangles on the edge x3 = (0,0,0) -> x4 = (1,0,0), x1 above it, x2 below; x2 folded
 * about the edge by angle fold, then a random rigid motion and a small random jiggle. */
static piola_tri_mesh hinge_mesh(void) {
  piola_tri_mesh mesh;
  memset(&mesh, 0, sizeof mesh);
  mesh.vertex_count = 4;
  mesh.triangle_count = 2;
  mesh.positions = calloc(12, sizeof(double));
  mesh.triangles = malloc(6 * sizeof(int32_t));
  const double p[12] = {0, 0, 0, 1, 0, 0, 0.4, 0.8, 0, 0.6, -0.7, 0};
  memcpy(mesh.positions, p, sizeof p);
  const int32_t t[6] = {0, 1, 2, 1, 0, 3};
  memcpy(mesh.triangles, t, sizeof t);
  return mesh;
}

static void folded_positions(test_rng *rng, double fold, double x[12]) {
  const double y[12] = {0, 0, 0, 1, 0, 0, 0.4, 0.8, 0, 0.6, -0.7 * cos(fold), -0.7 * sin(fold)};
  double q[9];
  shell_random_rotation(rng, q);
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i)
      x[3 * a + i] = q[3 * i] * y[3 * a] + q[3 * i + 1] * y[3 * a + 1] + q[3 * i + 2] * y[3 * a + 2] +
                     0.5 + 0.03 * test_rng_uniform(rng, -1, 1);
}

/* The element matrices of every triangle (exact membrane) and hinge (Gauss-Newton) summed
 * into a dense 3n x 3n. */
static void dense_stiffness(const piola_shell_body *body, int project, double *k) {
  const int n = body->vertex_count, w = 3 * n;
  memset(k, 0, sizeof(double) * (size_t)(w * w));
  double e[144];
  for (int32_t t = 0; t < body->triangle_count; ++t) {
    piola__shell_triangle_stiffness(body, t, project, e);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            k[w * (3 * body->triangles[t].v[a] + i) + 3 * body->triangles[t].v[b] + j] +=
                e[9 * (3 * a + i) + 3 * b + j];
  }
  for (int32_t h = 0; h < body->hinge_count; ++h) {
    piola__shell_hinge_stiffness(body, h, e);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            k[w * (3 * body->hinges[h].v[a] + i) + 3 * body->hinges[h].v[b] + j] +=
                e[12 * (3 * a + i) + 3 * b + j];
  }
}

static void bending_gauss_newton(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(16);
  piola_tri_mesh mesh = hinge_mesh();
  piola_material material = shell_material(PIOLA_MODEL_COROTATED, 1e3);
  const double folds[] = {0.0, 0.4, 1.2, 2.6, -0.9, -2.4};
  const double stiffness = 2.0;
  for (int k = 0; k < 6; ++k) {
    piola_shell_body *body = shell_body_from(&mesh, &material, stiffness);
    assert_int_equal(piola_shell_body_hinge_count(body), 1);
    double x[12], f[12], fd[144], exact[144];
    folded_positions(&rng, folds[k], x);
    assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
    const double theta = piola_shell_body_angles(body)[0];
    /* the hinge alone: symmetric, negative semi-definite */
    double gn[144];
    piola__shell_hinge_stiffness(body, 0, gn);
    assert_symmetric_nsd(gn, 12, "hinge");
    assert_true(max_abs(gn, 144) > 0);
    /* at its rest angle the Gauss-Newton form is the whole Hessian */
    assert_int_equal(piola_shell_body_set_rest_angles(body, &theta), PIOLA_OK);
    force_differences(body, x, 4, fd);
    dense_stiffness(body, 0, exact);
    double scale = max_abs(exact, 144);
    for (int e = 0; e < 144; ++e)
      if (!(fabs(exact[e] - fd[e]) <= 2e-6 * scale))
        fail_msg("fold %g at rest: entry (%d, %d) is %.9g, differences give %.9g", folds[k], e / 12,
                 e % 12, exact[e], fd[e]);
    /* away from it the rest is D w Phi'(theta) hess theta, with hess theta from differences
     * of the angle's gradient */
    const double theta0 = theta - 0.7;
    assert_int_equal(piola_shell_body_set_rest_angles(body, &theta0), PIOLA_OK);
    force_differences(body, x, 4, fd);
    dense_stiffness(body, 0, exact);
    const int32_t *hv = piola_shell_body_hinges(body);
    const double w = body->hinges[0].weight;
    const double slope = sin(0.5 * theta) - sin(0.5 * theta0);
    double xp[12], gp[12], gm[12], hess[144];
    const double h = 1e-6;
    for (int c = 0; c < 12; ++c) {
      memcpy(xp, x, sizeof xp);
      /* column c is coordinate c % 3 of vertex hv[c / 3] (vertex-order of the hinge) */
      const int j = 3 * hv[c / 3] + c % 3;
      xp[j] = x[j] + h;
      piola__hinge_angle(xp + 3 * hv[0], xp + 3 * hv[1], xp + 3 * hv[2], xp + 3 * hv[3], gp);
      xp[j] = x[j] - h;
      piola__hinge_angle(xp + 3 * hv[0], xp + 3 * hv[1], xp + 3 * hv[2], xp + 3 * hv[3], gm);
      for (int r = 0; r < 12; ++r) hess[12 * r + c] = (gp[r] - gm[r]) / (2 * h);
    }
    scale = fmax(max_abs(exact, 144), max_abs(fd, 144));
    for (int r = 0; r < 12; ++r)
      for (int c = 0; c < 12; ++c) {
        const int gr = 3 * hv[r / 3] + r % 3, gc = 3 * hv[c / 3] + c % 3;
        const double expected = exact[12 * gr + gc] - stiffness * w * slope * hess[12 * r + c];
        if (!(fabs(expected - fd[12 * gr + gc]) <= 1e-5 * scale))
          fail_msg("fold %g off rest: entry (%d, %d): %.9g expected, differences give %.9g",
                   folds[k], gr, gc, expected, fd[12 * gr + gc]);
      }
    piola_shell_body_destroy(body);
  }
  piola_tri_mesh_free(&mesh);
}

/* Damping is linear in v: its derivative is exact, checked column by column. */
static void damping_derivatives(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(17);
  piola_tri_mesh mesh = hinge_mesh();
  piola_material material = shell_material(PIOLA_MODEL_NEOHOOKEAN, 1e4);
  piola_shell_body_def def = shell_def_of(&mesh, &material);
  def.thickness = 0.01;
  def.bending.stiffness = 1.0;
  def.bending.damping = 0.3;
  piola_shell_body *body = NULL;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_OK);
  double x[12], f[12], v[12], dv[12], dense[144], e[144];
  folded_positions(&rng, 0.8, x);
  for (int i = 0; i < 12; ++i) x[i] += 0.1 * test_rng_uniform(&rng, -1, 1); /* stretch, shear */
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  const double beta = 2.0, alpha = 5.0;
  memset(dense, 0, sizeof dense);
  for (int t = 0; t < 2; ++t) {
    piola__shell_triangle_damping(body, t, beta, alpha, e);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            dense[12 * (3 * body->triangles[t].v[a] + i) + 3 * body->triangles[t].v[b] + j] +=
                e[9 * (3 * a + i) + 3 * b + j];
  }
  piola__shell_hinge_damping(body, 0, e);
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          dense[12 * (3 * body->hinges[0].v[a] + i) + 3 * body->hinges[0].v[b] + j] +=
              e[12 * (3 * a + i) + 3 * b + j];
  assert_symmetric_nsd(dense, 12, "damping");
  for (int c = 0; c < 12; ++c) {
    memset(v, 0, sizeof v);
    v[c] = 1.0;
    piola_shell_body_damping_forces(body, v, beta, alpha, dv);
    for (int r = 0; r < 12; ++r) assert_close(dense[12 * r + c], dv[r], 1e-12 * max_abs(dense, 144));
  }
  piola_shell_body_destroy(body);
  piola_tri_mesh_free(&mesh);
}

/* The assembled matrix of a bent, stretched sheet: its product is M p - kw K p - dw D p
 * with K the projected element matrices, it is symmetric and positive definite. */
static void assembled_matrix(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(18);
  piola_tri_mesh mesh = shell_sheet(1.0, 0.8, 4, 3);
  piola_material material = shell_material(PIOLA_MODEL_STVK, 1e4);
  piola_shell_body_def def = shell_def_of(&mesh, &material);
  def.thickness = 0.01;
  def.bending.stiffness = 0.5;
  def.bending.damping = 0.05;
  piola_shell_body *body = NULL;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_OK);
  const int n = piola_shell_body_vertex_count(body), w = 3 * n;
  double *x = malloc(sizeof(double) * (size_t)w), *f = malloc(sizeof(double) * (size_t)w);
  for (int i = 0; i < n; ++i) {
    const double *p = mesh.positions + 3 * i;
    /* rolled up around the y axis and jiggled: compressed and stretched triangles */
    x[3 * i] = sin(1.5 * p[0]) / 1.5 + 0.03 * test_rng_uniform(&rng, -1, 1);
    x[3 * i + 1] = p[1] * (1 + 0.2 * p[0]);
    x[3 * i + 2] = (1 - cos(1.5 * p[0])) / 1.5;
  }
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  piola__stiffness_matrix m;
  assert_int_equal(piola__shell_stiffness_matrix_init(&m, body), PIOLA_OK);
  const double kw = 1e-3, dw = 0.03, beta = 3.0, alpha = 1.0, mw = 1.0;
  const double *mass = piola_shell_body_masses(body);
  piola__shell_stiffness_matrix_assemble(&m, body, kw, dw, beta, alpha, mass, mw);
  double *k = calloc((size_t)(w * w), sizeof(double)), *d = calloc((size_t)(w * w), sizeof(double));
  dense_stiffness(body, 1, k);
  double e[144];
  for (int32_t t = 0; t < body->triangle_count; ++t) {
    piola__shell_triangle_damping(body, t, beta, alpha, e);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            d[w * (3 * body->triangles[t].v[a] + i) + 3 * body->triangles[t].v[b] + j] +=
                e[9 * (3 * a + i) + 3 * b + j];
  }
  for (int32_t h = 0; h < body->hinge_count; ++h) {
    piola__shell_hinge_damping(body, h, e);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            d[w * (3 * body->hinges[h].v[a] + i) + 3 * body->hinges[h].v[b] + j] +=
                e[12 * (3 * a + i) + 3 * b + j];
  }
  double *p = malloc(sizeof(double) * (size_t)w), *q = malloc(sizeof(double) * (size_t)w);
  double *ap = malloc(sizeof(double) * (size_t)w), *aq = malloc(sizeof(double) * (size_t)w);
  for (int trial = 0; trial < 5; ++trial) {
    for (int i = 0; i < w; ++i) p[i] = test_rng_normal(&rng), q[i] = test_rng_normal(&rng);
    piola__shell_stiffness_matrix_apply(&m, body, mass, mw, p, ap);
    piola__shell_stiffness_matrix_apply(&m, body, mass, mw, q, aq);
    double pap = 0, paq = 0, qap = 0, scale = 0;
    for (int r = 0; r < w; ++r) {
      double expected = mw * mass[r / 3] * p[r];
      for (int c = 0; c < w; ++c) expected -= (kw * k[w * r + c] + dw * d[w * r + c]) * p[c];
      scale = fmax(scale, fabs(expected));
      assert_close(ap[r], expected, 1e-10 * (fabs(expected) + 1e-3));
      pap += p[r] * ap[r], paq += p[r] * aq[r], qap += q[r] * ap[r];
    }
    assert_true(pap > 0);
    assert_close(paq, qap, 1e-12 * (fabs(paq) + scale));
  }
  /* the diagonal blocks are the dense matrix's */
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        const int r = 3 * i + a, c = 3 * i + b;
        const double expected = (a == b ? mw * mass[i] : 0.0) - kw * k[w * r + c] - dw * d[w * r + c];
        assert_close(m.diagonal[9 * i + 3 * a + b], expected, 1e-10 * fabs(m.diagonal[9 * i + 4 * a]));
      }
  free(p), free(q), free(ap), free(aq), free(k), free(d), free(x), free(f);
  piola__stiffness_matrix_free(&m);
  piola_shell_body_destroy(body);
  piola_tri_mesh_free(&mesh);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(membrane_matches_differences),
      cmocka_unit_test(projection_is_exact_in_tension),
      cmocka_unit_test(bending_gauss_newton),
      cmocka_unit_test(damping_derivatives),
      cmocka_unit_test(assembled_matrix),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
