/* The implicit step's system matrix on small bodies, for the preconditioner tests
 * (test_incomplete_cholesky.c, test_multigrid.c): a deformed neo-Hookean body and its
 * assembled Newton matrix, constraints (fixed and normal-held vertices) and the filtered
 * product S A S + (I - S), a preconditioned CG on the filtered system, and a nearly
 * incompressible block stepped by a world with a chosen preconditioner. Header-only: each
 * test executable includes it once. */
#ifndef PIOLA_TESTS_STIFFNESS_SYSTEMS_H
#define PIOLA_TESTS_STIFFNESS_SYSTEMS_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "block_scenes.h"
#include "force/elastic_body_internal.h"
#include "force/stiffness_matrix.h"
#include "piola/world.h"
#include "test_elastic_body_fixtures.h"

/* Constraints for the tests: kind[i] 0 free, 1 fixed, 2 held along normal + 3 i. */
typedef struct held {
  const int *kind;
  const double *normal;
} held;

static inline int held_constraint(const void *context, int32_t i, double normal[3]) {
  const held *h = context;
  if (!h) return 0;
  if (h->kind[i] == 2)
    for (int k = 0; k < 3; ++k) normal[k] = h->normal[3 * i + k];
  return h->kind[i];
}

/* r = S r */
static inline void project(const held *h, int32_t n, double *r) {
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

static inline void system_make(system_t *sys, piola_tet_mesh mesh, double e, double nu,
                               double weight, uint64_t seed) {
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

static inline void system_free(system_t *sys) {
  piola__stiffness_matrix_free(&sys->mx);
  piola_elastic_body_destroy(sys->body);
  fixture_mesh_free(&sys->mesh);
}

/* out = S A S p + (I - S) p: the filtered matrix */
static inline void filtered_apply(const system_t *sys, const held *h, const double *p,
                                  double *out) {
  const int32_t m = 3 * sys->n;
  double *sp = malloc(sizeof(double) * (size_t)m);
  memcpy(sp, p, sizeof(double) * (size_t)m);
  project(h, sys->n, sp);
  piola__stiffness_matrix_apply(&sys->mx, sys->body, sys->body->masses, 1.0, sp, out);
  project(h, sys->n, out);
  for (int32_t j = 0; j < m; ++j) out[j] += p[j] - sp[j];
  free(sp);
}

/* Constraints on a grid: the bottom layer fixed, the top layer held along a tilted normal. */
static inline void grid_constraints(const system_t *sys, int *kind, double *nrm) {
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

/* grid_constraints of sys in malloc'd arrays (held_grid_free frees them). */
static inline held held_grid_make(const system_t *sys) {
  int *kind = malloc(sizeof(int) * (size_t)sys->n);
  double *nrm = malloc(sizeof(double) * 3 * (size_t)sys->n);
  grid_constraints(sys, kind, nrm);
  return (held){kind, nrm};
}

static inline void held_grid_free(held *h) { free((void *)h->kind), free((void *)h->normal); }

/* A preconditioner for pcg: z = P^-1 r (pcg projects z by S afterwards). */
typedef void test_preconditioner(const void *context, const system_t *sys, const double *r,
                                 double *z);

/* Block Jacobi: z_i = A_ii^-1 r_i. */
static inline void block_jacobi(const void *context, const system_t *sys, const double *r,
                                double *z) {
  (void)context;
  for (int32_t i = 0; i < sys->n; ++i) {
    const double *bi = sys->mx.inverse_diagonal + 9 * (size_t)i;
    for (int k = 0; k < 3; ++k)
      z[3 * i + k] =
          bi[3 * k] * r[3 * i] + bi[3 * k + 1] * r[3 * i + 1] + bi[3 * k + 2] * r[3 * i + 2];
  }
}

/* Preconditioned CG on the filtered system S A S x = S b, z = S P^-1 r. Returns the
 * iterations; x gets the solution. */
static inline int pcg(const system_t *sys, const held *h, test_preconditioner *precondition,
                      const void *context, const double *b, double *x, double tol) {
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
    precondition(context, sys, r, z);
    project(h, sys->n, z);
    double rz_new = 0, rr = 0;
    for (int32_t j = 0; j < m; ++j) rz_new += r[j] * z[j], rr += r[j] * r[j];
    if (rr <= tol * tol * r0) break;
    /* the first direction is z itself: p is not yet set (0 times garbage can be NaN) */
    for (int32_t j = 0; j < m; ++j) p[j] = it > 0 ? z[j] + rz_new / rz * p[j] : z[j];
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

/* A nearly incompressible block (0.3 x 0.3 x 0.15 m, 2 cells x 2 cells x cells cubes, 2 cm
 * above the ground) dropped on the ground (backward Euler) or clamped at one end
 * (quasistatics, or backward Euler when clamped: a cantilever swinging down), 8 frames at
 * one step each; returns its final positions (malloc'd) and the CG iterations. */
static inline double *drop_block(piola_integrator_type type, piola_preconditioner_type pc,
                                 piola_linear_forcing forcing, int cells, int clamped, long *cg,
                                 int32_t *n) {
  piola_world_def wd = piola_default_world_def();
  wd.integrator = type;
  wd.implicit_dt = 1.0 / 30;
  wd.preconditioner = pc;
  wd.linear_forcing = forcing;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_tet_mesh mesh = block_mesh(2 * cells, 2 * cells, cells, 0.3, 0.3, 0.15);
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
  if (type == PIOLA_INTEGRATOR_QUASISTATIC || clamped)
    sd.constraints = &clamp, sd.constraint_count = 1;
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

/* drop_block with `pc` (named `pc_name` in the printed line) and with block Jacobi, both under
 * Eisenstat-Walker forcing, against block Jacobi with the fixed forcing 1e-3: Newton stops at
 * an RMS force per mass of 1e-5 g, so the final positions agree to well under a micrometre
 * whichever way each system was solved; nothing sinks below the ground; and `pc` takes fewer
 * CG iterations than block Jacobi. */
static inline void preconditioner_results_agree_with(piola_integrator_type type, piola_preconditioner_type pc,
                                                     const char *pc_name, int cells, int clamped) {
  long cg_ref, cg_bj, cg_pc;
  int32_t n;
  double *ref = drop_block(type, PIOLA_PRECONDITIONER_BLOCK_JACOBI, PIOLA_FORCING_FIXED, cells, clamped, &cg_ref, &n);
  double *bj = drop_block(type, PIOLA_PRECONDITIONER_BLOCK_JACOBI, PIOLA_FORCING_EISENSTAT_WALKER, cells, clamped,
                          &cg_bj, &n);
  double *x = drop_block(type, pc, PIOLA_FORCING_EISENSTAT_WALKER, cells, clamped, &cg_pc, &n);
  double d_bj = 0, d_pc = 0, zmin = INFINITY;
  for (int32_t j = 0; j < 3 * n; ++j) {
    d_bj = fmax(d_bj, fabs(bj[j] - ref[j]));
    d_pc = fmax(d_pc, fabs(x[j] - ref[j]));
    if (j % 3 == 2) zmin = fmin(zmin, x[j]);
  }
  printf("%s, 8 frames: CG iterations %ld (block Jacobi, fixed 1e-3), %ld (block "
         "Jacobi, Eisenstat-Walker), %ld (%s, Eisenstat-Walker); positions differ from the "
         "first by %.3g m and %.3g m\n", piola_integrator_type_name(type), cg_ref, cg_bj, cg_pc,
         pc_name, d_bj, d_pc);
  assert_true(d_bj < 1e-6 && d_pc < 1e-6);
  assert_true(zmin > -1e-9);
  assert_true(cg_pc < cg_bj);
  free(ref), free(bj), free(x);
}

/* The same under backward Euler and then under quasistatics. */
static inline void preconditioner_results_agree(piola_preconditioner_type pc, const char *pc_name, int cells,
                                                int clamped) {
  preconditioner_results_agree_with(PIOLA_INTEGRATOR_BACKWARD_EULER, pc, pc_name, cells, clamped);
  preconditioner_results_agree_with(PIOLA_INTEGRATOR_QUASISTATIC, pc, pc_name, cells, clamped);
}

#endif
