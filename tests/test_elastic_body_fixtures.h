/* Small meshes and materials built in code for the elastic body tests (the mesh readers are
 * tested elsewhere). Header-only: each test executable includes it once. */
#ifndef PIOLA_TESTS_ELASTIC_BODY_FIXTURES_H
#define PIOLA_TESTS_ELASTIC_BODY_FIXTURES_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "piola/elastic_body.h"
#include "test_support.h"

/* n x n x n unit-size cubes of edge h, each split into 6 tets around its main diagonal
 * (a conforming triangulation). Orientation is left to the body. */
static inline piola_tet_mesh fixture_grid(int n, double h) {
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(n, n, n, (piola_vec3){h, h, h}, &mesh), PIOLA_OK);
  return mesh;
}

/* The unit right tet (0,0,0), (1,0,0), (0,1,0), (0,0,1), scaled by h. */
static inline piola_tet_mesh fixture_single_tet(double h) {
  piola_tet_mesh mesh;
  memset(&mesh, 0, sizeof mesh);
  mesh.vertex_count = 4;
  mesh.tet_count = 1;
  mesh.positions = calloc(12, sizeof(double));
  mesh.tets = malloc(sizeof(int32_t) * 4);
  mesh.positions[3] = h;
  mesh.positions[7] = h;
  mesh.positions[11] = h;
  for (int c = 0; c < 4; ++c) mesh.tets[c] = c;
  return mesh;
}

static inline void fixture_mesh_free(piola_tet_mesh *mesh) {
  free(mesh->positions);
  free(mesh->tets);
  free(mesh->tet_regions);
  memset(mesh, 0, sizeof *mesh);
}

static inline piola_material fixture_material(piola_material_model model) {
  piola_material_def def = piola_default_material_def();
  def.model = model;
  def.youngs_modulus = 1e4;
  def.poisson_ratio = 0.3;
  piola_material material;
  assert_int_equal(piola_material_init(&def, &material), PIOLA_OK);
  return material;
}

static inline piola_elastic_body *fixture_body(const piola_tet_mesh *mesh,
                                               const piola_material *material) {
  piola_elastic_body_def def = piola_default_elastic_body_def();
  def.rest_mesh = mesh;
  def.materials = material;
  def.material_count = 1;
  def.density = 1000;
  piola_elastic_body *body = NULL;
  piola_status status = piola_elastic_body_create(&def, &body);
  if (status != PIOLA_OK) fail_msg("create failed: %s", piola_last_error());
  return body;
}

/* A body of count materials (tet_materials: each tet's index, NULL when count is 1) and
 * per-tet fibre directions (NULL: none). */
static inline piola_elastic_body *fixture_body_with_fibers(const piola_tet_mesh *mesh,
                                                           const piola_material *materials,
                                                           int32_t count,
                                                           const int32_t *tet_materials,
                                                           const double *fibers) {
  piola_elastic_body_def def = piola_default_elastic_body_def();
  def.rest_mesh = mesh;
  def.materials = materials;
  def.material_count = count;
  def.tet_materials = tet_materials;
  def.fiber_directions = fibers;
  piola_elastic_body *body;
  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_OK);
  return body;
}

/* A uniformly random rotation (row-major) from a random unit quaternion. */
static inline void fixture_random_rotation(test_rng *rng, double r[9]) {
  double q[4], n = 0;
  for (int i = 0; i < 4; ++i) {
    q[i] = test_rng_normal(rng);
    n += q[i] * q[i];
  }
  n = sqrt(n);
  double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
  double m[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                 2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                 2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
  memcpy(r, m, sizeof m);
}

static inline double fixture_max_abs(const double *a, int n) {
  double m = 0;
  for (int i = 0; i < n; ++i) m = fmax(m, fabs(a[i]));
  return m;
}

/* Fails unless f, the body's forces at x (n dofs), is minus the gradient of its elastic
 * energy: central differences of step h (m), every dof, within rel_tol of max |f|. x is
 * left as it was; `what` names the case in the message. */
static inline void fixture_check_energy_gradient(piola_elastic_body *body, double *x, int n,
                                                 const double *f, double h, double rel_tol,
                                                 const char *what) {
  double *scratch = malloc(sizeof(double) * (size_t)n);
  const double scale = fixture_max_abs(f, n);
  for (int i = 0; i < n; ++i) {
    const double xi = x[i];
    piola_elastic_stats ep, em;
    x[i] = xi + h;
    assert_int_equal(piola_elastic_body_update(body, x, 1.0, scratch, &ep), PIOLA_OK);
    x[i] = xi - h;
    assert_int_equal(piola_elastic_body_update(body, x, 1.0, scratch, &em), PIOLA_OK);
    x[i] = xi;
    const double d = -(ep.elastic_energy - em.elastic_energy) / (2 * h);
    if (!(fabs(d - f[i]) <= rel_tol * scale))
      fail_msg("%s dof %d: -dE/dx = %.10g, force %.10g", what, i, d, f[i]);
  }
  free(scratch);
}

/* Moves the apex of fixture_single_tet(1.0) below its base face z = 0 (at a random x, y in
 * [-0.3, 0.6) and depth in [0, 0.9)) and fails unless the body's forces there are finite and
 * push the apex back up; fiber names the tet's fibre in the message. Returns the depth (m)
 * and, in inverted, the update's count of inverted tets. */
static inline double fixture_check_apex_pushed_back(piola_elastic_body *body,
                                                    const piola_tet_mesh *mesh, test_rng *rng,
                                                    const double fiber[3], int32_t *inverted) {
  double x[12];
  memcpy(x, mesh->positions, sizeof x);
  const double depth = test_rng_uniform(rng, 0.0, 0.9);
  x[9] = test_rng_uniform(rng, -0.3, 0.6);
  x[10] = test_rng_uniform(rng, -0.3, 0.6);
  x[11] = -depth; /* apex below the face z = 0 */
  double f[12];
  piola_elastic_stats st;
  assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, &st), PIOLA_OK);
  for (int i = 0; i < 12; ++i) assert_true(isfinite(f[i]));
  if (!(f[11] > 0))
    fail_msg("apex at (%g %g %g), fibre (%g %g %g): force z %g does not push it back", x[9],
             x[10], x[11], fiber[0], fiber[1], fiber[2], f[11]);
  *inverted = st.inverted_count;
  return depth;
}

static inline double fixture_signed_volume(const double *x, const int32_t *tet) {
  const double *a = x + 3 * tet[0], *b = x + 3 * tet[1], *c = x + 3 * tet[2], *d = x + 3 * tet[3];
  double e1[3], e2[3], e3[3];
  for (int i = 0; i < 3; ++i) {
    e1[i] = b[i] - a[i];
    e2[i] = c[i] - a[i];
    e3[i] = d[i] - a[i];
  }
  return (e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0]) +
          e1[2] * (e2[0] * e3[1] - e2[1] * e3[0])) / 6.0;
}

#endif
