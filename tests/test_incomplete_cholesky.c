/* The block IC(0) preconditioner of the implicit integrators
 * (src/force/stiffness_incomplete_cholesky.c):
 *  - on a single tet the edge pattern is complete, so IC(0) has no dropped fill and is the
 *    exact factorization: P^-1 A = I, also for the filtered matrix with fixed and
 *    normal-held vertices;
 *  - on a deformed, stiff grid P^-1 is symmetric positive definite and keeps constrained
 *    components at zero;
 *  - a CG preconditioned by it solves the filtered system to tolerance, in fewer iterations
 *    than block Jacobi;
 *  - backward Euler and quasistatic steps with either preconditioner, and with
 *    Eisenstat-Walker or fixed forcing, agree to the Newton tolerance on a nearly incompressible block landing on the
 *    ground (contacts: normal-held nodes), in fewer CG iterations with IC(0);
 *  - the scene keys integrator.preconditioner and integrator.linear_forcing, bad values
 *    refused by their key paths. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "force/elastic_body_internal.h"
#include "force/stiffness_incomplete_cholesky.h"
#include "force/stiffness_matrix.h"
#include "block_scenes.h"
#include "piola/scene.h"
#include "piola/world.h"
#include "test_elastic_body_fixtures.h"

/* Constraints for the tests: kind[i] 0 free, 1 fixed, 2 held along normal + 3 i. */
typedef struct held {
  const int *kind;
  const double *normal;
} held;

static int held_constraint(const void *context, int32_t i, double normal[3]) {
  const held *h = context;
  if (!h) return 0;
  if (h->kind[i] == 2)
    for (int k = 0; k < 3; ++k) normal[k] = h->normal[3 * i + k];
  return h->kind[i];
}

/* r = S r */
static void project(const held *h, int32_t n, double *r) {
  for (int32_t i = 0; i < n && h; ++i) {
    double *ri = r + 3 * i;
    if (h->kind[i] == 1) {
      ri[0] = ri[1] = ri[2] = 0;
    } else if (h->kind[i] == 2) {
      const double *nn = h->normal + 3 * i;
      double dn = ri[0] * nn[0] + ri[1] * nn[1] + ri[2] * nn[2];
      for (int k = 0; k < 3; ++k) ri[k] -= dn * nn[k];
    }
  }
}

/* A body of mesh, neo-Hookean with E and nu, deformed by a stretch, a squash and noise, its
 * Newton matrix M + weight K assembled. */
typedef struct system {
  piola_tet_mesh mesh;
  piola_material material;
  piola_elastic_body *body;
  piola__stiffness_matrix mx;
  int32_t n;
} system_t;

static void system_make(system_t *sys, piola_tet_mesh mesh, double e, double nu, double weight,
                        uint64_t seed) {
  sys->mesh = mesh;
  piola_material_def md = piola_default_material_def();
  md.model = PIOLA_MODEL_NEOHOOKEAN;
  md.youngs_modulus = e;
  md.poisson_ratio = nu;
  assert_int_equal(piola_material_init(&md, &sys->material), PIOLA_OK);
  sys->body = fixture_body(&sys->mesh, &sys->material);
  const int32_t n = sys->n = sys->body->vertex_count;
  test_rng rng = test_rng_seeded(seed);
  double *x = malloc(sizeof(double) * 3 * (size_t)n), *f = malloc(sizeof(double) * 3 * (size_t)n);
  for (int32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k)
      x[3 * i + k] = sys->body->rest_positions[3 * i + k] * (k == 2 ? 0.7 : 1.1) +
                     test_rng_uniform(&rng, -0.02, 0.02);
  assert_int_equal(piola_elastic_body_update(sys->body, x, 1.0, f, NULL), PIOLA_OK);
  assert_int_equal(piola__stiffness_matrix_init(&sys->mx, sys->body), PIOLA_OK);
  piola__stiffness_matrix_assemble(&sys->mx, sys->body, weight, 0.0, sys->body->masses, 1.0);
  free(x), free(f);
}

static void system_free(system_t *sys) {
  piola__stiffness_matrix_free(&sys->mx);
  piola_elastic_body_destroy(sys->body);
  fixture_mesh_free(&sys->mesh);
}

/* out = S A S p + (I - S) p: the filtered matrix */
static void filtered_apply(const system_t *sys, const held *h, const double *p, double *out) {
  const int32_t m = 3 * sys->n;
  double *sp = malloc(sizeof(double) * (size_t)m);
  memcpy(sp, p, sizeof(double) * (size_t)m);
  project(h, sys->n, sp);
  piola__stiffness_matrix_apply(&sys->mx, sys->body, sys->body->masses, 1.0, sp, out);
  project(h, sys->n, out);
  for (int32_t j = 0; j < m; ++j) out[j] += p[j] - sp[j];
  free(sp);
}

/* Dense columns of P^-1 (the preconditioner) and of the filtered matrix. */
static void dense_columns(const system_t *sys, const held *h, const piola__incomplete_cholesky *f,
                          double *pinv, double *a) {
  const int32_t m = 3 * sys->n;
  double *e = calloc((size_t)m, sizeof(double)), *col = malloc(sizeof(double) * (size_t)m);
  for (int32_t c = 0; c < m; ++c) {
    e[c] = 1;
    piola__incomplete_cholesky_apply(f, sys->body, e, col);
    for (int32_t r = 0; r < m; ++r) pinv[(size_t)r * (size_t)m + (size_t)c] = col[r];
    filtered_apply(sys, h, e, col);
    for (int32_t r = 0; r < m; ++r) a[(size_t)r * (size_t)m + (size_t)c] = col[r];
    e[c] = 0;
  }
  free(e), free(col);
}

/* max |P^-1 A - I| over the entries */
static double exactness_error(const system_t *sys, const held *h) {
  piola__incomplete_cholesky f;
  assert_int_equal(piola__incomplete_cholesky_init(&f, sys->body), PIOLA_OK);
  piola__incomplete_cholesky_factor(&f, &sys->mx, sys->body, h ? held_constraint : NULL, h);
  assert_int_equal(f.fallback_rows, 0);
  const int32_t m = 3 * sys->n;
  double *pinv = malloc(sizeof(double) * (size_t)m * (size_t)m);
  double *a = malloc(sizeof(double) * (size_t)m * (size_t)m);
  dense_columns(sys, h, &f, pinv, a);
  double worst = 0;
  for (int32_t r = 0; r < m; ++r)
    for (int32_t c = 0; c < m; ++c) {
      double s = 0;
      for (int32_t k = 0; k < m; ++k) s += pinv[(size_t)r * (size_t)m + (size_t)k] * a[(size_t)k * (size_t)m + (size_t)c];
      worst = fmax(worst, fabs(s - (r == c ? 1.0 : 0.0)));
    }
  free(pinv), free(a);
  piola__incomplete_cholesky_free(&f);
  return worst;
}

static void test_single_tet_is_exact(void **state) {
  (void)state;
  system_t sys;
  /* stiffness far above the mass: the factor is mostly the elastic coupling */
  system_make(&sys, fixture_single_tet(0.1), 1e6, 0.45, 1e-3, 5);
  double free_error = exactness_error(&sys, NULL);
  printf("single tet, free: max |P^-1 A - I| = %.3g\n", free_error);
  assert_true(free_error < 1e-9);
  const int kind[4] = {0, 1, 2, 0};
  const double nrm[12] = {0, 0, 0, 0, 0, 0, 0.6, 0.0, 0.8, 0, 0, 0};
  held h = {kind, nrm};
  double held_error = exactness_error(&sys, &h);
  printf("single tet, one fixed and one normal-held vertex: max |P^-1 A - I| = %.3g\n", held_error);
  assert_true(held_error < 1e-9);
  system_free(&sys);
}

/* Constraints on a grid: the bottom layer fixed, the top layer held along a tilted normal. */
static void grid_constraints(const system_t *sys, int *kind, double *nrm) {
  double top = -INFINITY, bottom = INFINITY;
  for (int32_t i = 0; i < sys->n; ++i) {
    top = fmax(top, sys->body->rest_positions[3 * i + 2]);
    bottom = fmin(bottom, sys->body->rest_positions[3 * i + 2]);
  }
  const double len = sqrt(0.1 * 0.1 + 1.0);
  for (int32_t i = 0; i < sys->n; ++i) {
    const double z = sys->body->rest_positions[3 * i + 2];
    kind[i] = z == bottom ? 1 : z == top ? 2 : 0;
    nrm[3 * i] = 0.1 / len, nrm[3 * i + 1] = 0, nrm[3 * i + 2] = 1.0 / len;
  }
}

static void test_grid_preconditioner_is_spd(void **state) {
  (void)state;
  system_t sys;
  system_make(&sys, fixture_grid(3, 0.1), 1e7, 0.49, 1e-3, 7);
  int *kind = malloc(sizeof(int) * (size_t)sys.n);
  double *nrm = malloc(sizeof(double) * 3 * (size_t)sys.n);
  grid_constraints(&sys, kind, nrm);
  held h = {kind, nrm};
  piola__incomplete_cholesky f;
  assert_int_equal(piola__incomplete_cholesky_init(&f, sys.body), PIOLA_OK);
  piola__incomplete_cholesky_factor(&f, &sys.mx, sys.body, held_constraint, &h);
  const int32_t m = 3 * sys.n;
  double *pinv = malloc(sizeof(double) * (size_t)m * (size_t)m);
  double *a = malloc(sizeof(double) * (size_t)m * (size_t)m);
  dense_columns(&sys, &h, &f, pinv, a);
  double asym = 0, size = 0;
  for (int32_t r = 0; r < m; ++r)
    for (int32_t c = 0; c < m; ++c) {
      asym = fmax(asym, fabs(pinv[(size_t)r * m + c] - pinv[(size_t)c * m + r]));
      size = fmax(size, fabs(pinv[(size_t)r * m + c]));
    }
  printf("grid %d vertices: P^-1 asymmetry %.3g of %.3g, %d fallback rows\n", (int)sys.n, asym,
         size, (int)f.fallback_rows);
  assert_true(asym <= 1e-10 * size);
  double *lambda = malloc(sizeof(double) * (size_t)m);
  test_symmetric_eigenvalues(pinv, m, lambda);
  double lo = INFINITY, hi = 0;
  for (int32_t k = 0; k < m; ++k) lo = fmin(lo, lambda[k]), hi = fmax(hi, lambda[k]);
  printf("P^-1 eigenvalues in [%.3g, %.3g]\n", lo, hi);
  assert_true(lo > 0);
  /* constrained components of P^-1 r are zero for a filtered r */
  test_rng rng = test_rng_seeded(3);
  double *r = malloc(sizeof(double) * (size_t)m), *z = malloc(sizeof(double) * (size_t)m);
  for (int32_t j = 0; j < m; ++j) r[j] = test_rng_uniform(&rng, -1, 1);
  project(&h, sys.n, r);
  piola__incomplete_cholesky_apply(&f, sys.body, r, z);
  double zmax = fixture_max_abs(z, m), leak = 0;
  for (int32_t i = 0; i < sys.n; ++i) {
    const double *zi = z + 3 * i;
    if (kind[i] == 1) leak = fmax(leak, fixture_max_abs(zi, 3));
    if (kind[i] == 2) leak = fmax(leak, fabs(zi[0] * nrm[3 * i] + zi[1] * nrm[3 * i + 1] + zi[2] * nrm[3 * i + 2]));
  }
  printf("constrained components of P^-1 S r: %.3g of %.3g\n", leak, zmax);
  assert_true(leak <= 1e-10 * zmax);
  free(lambda), free(r), free(z), free(pinv), free(a), free(kind), free(nrm);
  piola__incomplete_cholesky_free(&f);
  system_free(&sys);
}

/* Preconditioned CG on the filtered system S A S x = S b; precondition: IC(0) when f, else
 * block Jacobi (S P_ii^-1). Returns the iterations; x gets the solution. */
static int pcg(const system_t *sys, const held *h, const piola__incomplete_cholesky *f,
               const double *b, double *x, double tol) {
  const int32_t m = 3 * sys->n;
  double *r = malloc(sizeof(double) * (size_t)m), *z = malloc(sizeof(double) * (size_t)m);
  double *p = malloc(sizeof(double) * (size_t)m), *q = malloc(sizeof(double) * (size_t)m);
  memset(x, 0, sizeof(double) * (size_t)m);
  memcpy(r, b, sizeof(double) * (size_t)m);
  project(h, sys->n, r);
  double r0 = 0;
  for (int32_t j = 0; j < m; ++j) r0 += r[j] * r[j];
  int it = 0;
  double rz = 0;
  for (; it < 5000; ++it) {
    if (f) {
      piola__incomplete_cholesky_apply(f, sys->body, r, z);
    } else {
      for (int32_t i = 0; i < sys->n; ++i) {
        const double *bi = sys->mx.inverse_diagonal + 9 * (size_t)i;
        for (int k = 0; k < 3; ++k) z[3 * i + k] = bi[3 * k] * r[3 * i] + bi[3 * k + 1] * r[3 * i + 1] + bi[3 * k + 2] * r[3 * i + 2];
      }
    }
    project(h, sys->n, z);
    double rz_new = 0, rr = 0;
    for (int32_t j = 0; j < m; ++j) rz_new += r[j] * z[j], rr += r[j] * r[j];
    if (rr <= tol * tol * r0) break;
    for (int32_t j = 0; j < m; ++j) p[j] = z[j] + (it > 0 ? rz_new / rz : 0.0) * p[j];
    rz = rz_new;
    filtered_apply(sys, h, p, q);
    double pq = 0;
    for (int32_t j = 0; j < m; ++j) pq += p[j] * q[j];
    const double alpha = rz / pq;
    for (int32_t j = 0; j < m; ++j) x[j] += alpha * p[j], r[j] -= alpha * q[j];
  }
  free(r), free(z), free(p), free(q);
  return it;
}

static void test_cg_solves_to_tolerance(void **state) {
  (void)state;
  system_t sys;
  system_make(&sys, fixture_grid(6, 0.05), 1e7, 0.49, 1e-3, 11);
  int *kind = malloc(sizeof(int) * (size_t)sys.n);
  double *nrm = malloc(sizeof(double) * 3 * (size_t)sys.n);
  grid_constraints(&sys, kind, nrm);
  held h = {kind, nrm};
  piola__incomplete_cholesky f;
  assert_int_equal(piola__incomplete_cholesky_init(&f, sys.body), PIOLA_OK);
  piola__incomplete_cholesky_factor(&f, &sys.mx, sys.body, held_constraint, &h);
  const int32_t m = 3 * sys.n;
  double *b = malloc(sizeof(double) * (size_t)m), *x = malloc(sizeof(double) * (size_t)m);
  double *xj = malloc(sizeof(double) * (size_t)m), *ax = malloc(sizeof(double) * (size_t)m);
  test_rng rng = test_rng_seeded(21);
  for (int32_t j = 0; j < m; ++j) b[j] = test_rng_uniform(&rng, -1, 1);
  project(&h, sys.n, b);
  const double tol = 1e-8;
  int it_ic = pcg(&sys, &h, &f, b, x, tol);
  int it_bj = pcg(&sys, &h, NULL, b, xj, tol);
  filtered_apply(&sys, &h, x, ax);
  double res = 0, bn = 0, diff = 0, xn = 0;
  for (int32_t j = 0; j < m; ++j) {
    res += (ax[j] - b[j]) * (ax[j] - b[j]), bn += b[j] * b[j];
    diff = fmax(diff, fabs(x[j] - xj[j])), xn = fmax(xn, fabs(xj[j]));
  }
  printf("grid %d vertices, E = 10 MPa, nu = 0.49: CG to 1e-8 in %d iterations with IC(0), %d "
         "with block Jacobi; |Ax - b|/|b| = %.3g; solutions differ by %.3g of %.3g\n",
         (int)sys.n, it_ic, it_bj, sqrt(res / bn), diff, xn);
  assert_true(sqrt(res / bn) < 1e-6);
  assert_true(it_ic < it_bj);
  assert_true(diff < 1e-5 * xn);
  free(b), free(x), free(xj), free(ax), free(kind), free(nrm);
  piola__incomplete_cholesky_free(&f);
  system_free(&sys);
}

/* A nearly incompressible block dropped on the ground (backward Euler) or clamped at one end
 * (quasistatics), 8 frames at one step each; returns its final positions (malloc'd) and the
 * CG iterations. */
static double *drop_block(piola_integrator_type type, piola_preconditioner_type pc,
                          piola_linear_forcing forcing, long *cg, int32_t *n) {
  piola_world_def wd = piola_default_world_def();
  wd.integrator = type;
  wd.implicit_dt = 1.0 / 30;
  wd.preconditioner = pc;
  wd.linear_forcing = forcing;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_tet_mesh mesh = block_mesh(6, 6, 3, 0.3, 0.3, 0.15);
  for (int32_t i = 0; i < mesh.vertex_count; ++i) mesh.positions[3 * i + 2] += 0.02;
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  sd.material.model = PIOLA_MODEL_NEOHOOKEAN;
  sd.material.youngs_modulus = 1e6;
  sd.material.poisson_ratio = 0.49;
  sd.shear_viscosity = piola_track_constant(1);
  /* quasistatics: a cantilever clamped at x = 0 (a free block has no equilibrium in the air) */
  piola_constraint_def clamp;
  memset(&clamp, 0, sizeof clamp);
  clamp.selector.type = PIOLA_SELECT_BOX;
  clamp.selector.box_min = (piola_vec3){-1, -1, -1};
  clamp.selector.box_max = (piola_vec3){1e-9, 1, 1};
  if (type == PIOLA_INTEGRATOR_QUASISTATIC) sd.constraints = &clamp, sd.constraint_count = 1;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  piola_obstacle_def g = piola_default_obstacle_def();
  g.type = PIOLA_OBSTACLE_PLANE;
  g.axis = (piola_vec3){0, 0, 1};
  g.friction = 0.5;
  assert_int_equal(piola_world_add_obstacle(w, &g, NULL), PIOLA_OK);
  *cg = 0;
  for (int f = 1; f <= 8; ++f) {
    piola_step_stats st;
    memset(&st, 0, sizeof st);
    assert_int_equal(piola_world_advance_to(w, f / 30.0, &st), PIOLA_OK);
    assert_int_equal(st.newton_failures, 0);
    *cg += st.linear_iterations;
  }
  *n = piola_elastic_body_vertex_count(piola_world_solid_body(w, 0));
  double *x = malloc(sizeof(double) * 3 * (size_t)*n);
  memcpy(x, piola_world_solid_positions(w, 0), sizeof(double) * 3 * (size_t)*n);
  block_mesh_free(&mesh);
  piola_world_destroy(w);
  return x;
}

static void newton_results_agree(piola_integrator_type type) {
  long cg_ref, cg_bj, cg_ic;
  int32_t n;
  double *ref = drop_block(type, PIOLA_PRECONDITIONER_BLOCK_JACOBI, PIOLA_FORCING_FIXED, &cg_ref, &n);
  double *bj = drop_block(type, PIOLA_PRECONDITIONER_BLOCK_JACOBI, PIOLA_FORCING_EISENSTAT_WALKER, &cg_bj, &n);
  double *ic = drop_block(type, PIOLA_PRECONDITIONER_INCOMPLETE_CHOLESKY, PIOLA_FORCING_EISENSTAT_WALKER, &cg_ic, &n);
  double d_bj = 0, d_ic = 0, zmin = INFINITY;
  for (int32_t j = 0; j < 3 * n; ++j) {
    d_bj = fmax(d_bj, fabs(bj[j] - ref[j]));
    d_ic = fmax(d_ic, fabs(ic[j] - ref[j]));
    if (j % 3 == 2) zmin = fmin(zmin, ic[j]);
  }
  printf("%s, 8 frames: CG iterations %ld (block Jacobi, fixed 1e-3), %ld (block "
         "Jacobi, Eisenstat-Walker), %ld (IC(0), Eisenstat-Walker); positions differ from the "
         "first by %.3g m and %.3g m\n", piola_integrator_type_name(type), cg_ref, cg_bj, cg_ic,
         d_bj, d_ic);
  /* Newton stops at an RMS force per mass of 1e-5 g: positions of a 0.3 m block agree to
   * well under a micrometre whichever way each system was solved */
  assert_true(d_bj < 1e-6 && d_ic < 1e-6);
  assert_true(zmin > -1e-9);
  assert_true(cg_ic < cg_bj);
  free(ref), free(bj), free(ic);
}

static void test_newton_results_agree(void **state) {
  (void)state;
  newton_results_agree(PIOLA_INTEGRATOR_BACKWARD_EULER);
  newton_results_agree(PIOLA_INTEGRATOR_QUASISTATIC);
}

static void test_scene_keys(void **state) {
  (void)state;
  const char *good = "{\"integrator\": {\"type\": \"backward_euler\", \"preconditioner\": "
                     "\"incomplete_cholesky\", \"linear_forcing\": \"fixed\"}, \"solids\": "
                     "[{\"mesh\": {\"generate\": \"box\", \"half_extents\": [0.1, 0.1, 0.1], "
                     "\"cell_size\": 0.05}}]}";
  piola_scene *scene = NULL;
  if (piola_scene_load_string(good, NULL, NULL, &scene) != PIOLA_OK) fail_msg("%s", piola_last_error());
  piola_step_stats st;
  memset(&st, 0, sizeof st);
  assert_int_equal(piola_world_advance_to(piola_scene_world(scene), 1.0 / 30, &st), PIOLA_OK);
  piola_scene_destroy(scene);
  const char *bad_pc = "{\"integrator\": {\"preconditioner\": \"ilu\"}, \"solids\": []}";
  assert_int_equal(piola_scene_load_string(bad_pc, NULL, NULL, &scene), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "integrator.preconditioner"));
  const char *bad_forcing = "{\"integrator\": {\"linear_forcing\": 1}, \"solids\": []}";
  assert_int_equal(piola_scene_load_string(bad_forcing, NULL, NULL, &scene), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "integrator.linear_forcing"));
  piola_world_def wd = piola_default_world_def();
  assert_int_equal(wd.preconditioner, PIOLA_PRECONDITIONER_BLOCK_JACOBI);
  assert_int_equal(wd.linear_forcing, PIOLA_FORCING_EISENSTAT_WALKER);
  wd.preconditioner = PIOLA_PRECONDITIONER_COUNT;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_ERROR_INVALID_ARGUMENT);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_single_tet_is_exact),
      cmocka_unit_test(test_grid_preconditioner_is_spd),
      cmocka_unit_test(test_cg_solves_to_tolerance),
      cmocka_unit_test(test_newton_results_agree),
      cmocka_unit_test(test_scene_keys),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
