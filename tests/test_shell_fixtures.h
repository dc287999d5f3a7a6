/* Sheets, materials and shell bodies built in code for the shell tests. Header-only: each
 * test executable includes it once. */
#ifndef PIOLA_TESTS_SHELL_FIXTURES_H
#define PIOLA_TESTS_SHELL_FIXTURES_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "piola/shell_body.h"
#include "piola/world.h"
#include "piola/world_shells.h"
#include "test_support.h"

static const piola_material_model shell_all_models[] = {
    PIOLA_MODEL_ROTATED_LINEAR, PIOLA_MODEL_COROTATED, PIOLA_MODEL_STVK, PIOLA_MODEL_NEOHOOKEAN,
    PIOLA_MODEL_SPLINE};
#define SHELL_MODEL_COUNT 5

static inline piola_material shell_material(piola_material_model model, double youngs) {
  piola_material_def def = piola_default_material_def();
  def.model = model;
  def.youngs_modulus = youngs;
  def.poisson_ratio = 0.3;
  piola_material material;
  assert_int_equal(piola_material_init(&def, &material), PIOLA_OK);
  return material;
}

/* A width x height sheet with nx x ny cells. */
static inline piola_tri_mesh shell_sheet(double width, double height, int nx, int ny) {
  piola_tri_mesh mesh;
  assert_int_equal(piola_tri_mesh_rectangle(width, height, nx, ny, &mesh), PIOLA_OK);
  return mesh;
}

/* A world without gravity (max_dt 1 s, the given cfl) holding one 1 x 1 m sheet of 12 x 12
 * cells, 1 mm thick, E = 100 kPa, nu = 0.3, with the given bending stiffness (N m) and
 * constraints. */
static inline piola_world *shell_sheet_world(piola_material_model model, double cfl, double bending,
                                             const piola_constraint_def *constraints,
                                             int32_t constraint_count) {
  piola_world_def wdef = piola_default_world_def();
  wdef.max_dt = 1.0;
  wdef.cfl = cfl;
  for (int k = 0; k < 3; ++k) wdef.gravity[k] = piola_track_constant(0.0);
  piola_world *world;
  assert_int_equal(piola_world_create(&wdef, &world), PIOLA_OK);
  piola_tri_mesh mesh = shell_sheet(1.0, 1.0, 12, 12);
  piola_shell_def def = piola_default_shell_def();
  def.mesh = &mesh;
  def.material.model = model;
  def.material.youngs_modulus = 1e5;
  def.material.poisson_ratio = 0.3;
  def.thickness = 1e-3;
  def.bending.stiffness = bending;
  def.constraints = constraints;
  def.constraint_count = constraint_count;
  assert_int_equal(piola_world_add_shell(world, &def, NULL), PIOLA_OK);
  piola_tri_mesh_free(&mesh);
  return world;
}

/* A single triangle (0,0,0), (1,0,0), (0.3,0.8,0) scaled by h. */
static inline piola_tri_mesh shell_single_triangle(double h) {
  piola_tri_mesh mesh;
  memset(&mesh, 0, sizeof mesh);
  mesh.vertex_count = 3;
  mesh.triangle_count = 1;
  mesh.positions = calloc(9, sizeof(double));
  mesh.triangles = malloc(3 * sizeof(int32_t));
  mesh.positions[3] = h;
  mesh.positions[6] = 0.3 * h;
  mesh.positions[7] = 0.8 * h;
  for (int c = 0; c < 3; ++c) mesh.triangles[c] = c;
  return mesh;
}

/* The default shell body definition of `mesh` in the one material `material`. */
static inline piola_shell_body_def shell_def_of(const piola_tri_mesh *mesh, const piola_material *material) {
  piola_shell_body_def def = piola_default_shell_body_def();
  def.rest_mesh = mesh;
  def.materials = material;
  def.material_count = 1;
  return def;
}

static inline piola_shell_body *shell_body_from(const piola_tri_mesh *mesh,
                                                const piola_material *material,
                                                double bending_stiffness) {
  piola_shell_body_def def = shell_def_of(mesh, material);
  def.thickness = 0.01;
  def.density = 500;
  def.bending.stiffness = bending_stiffness;
  piola_shell_body *body = NULL;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_OK);
  return body;
}

/* Total elastic energy (membrane + bending) at x. */
static inline double shell_energy(piola_shell_body *body, const double *x) {
  int32_t n = piola_shell_body_vertex_count(body);
  double *f = malloc(sizeof(double) * 3 * (size_t)n);
  piola_shell_stats stats;
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, &stats), PIOLA_OK);
  free(f);
  return stats.membrane_energy + stats.bending_energy;
}

/* Random rotation matrix (row-major 3x3) from a random unit quaternion. */
static inline void shell_random_rotation(test_rng *rng, double r[9]) {
  double q[4], n = 0;
  for (int i = 0; i < 4; ++i) {
    q[i] = test_rng_normal(rng);
    n += q[i] * q[i];
  }
  n = sqrt(n);
  for (int i = 0; i < 4; ++i) q[i] /= n;
  double w = q[0], x = q[1], y = q[2], z = q[3];
  double m[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                 2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                 2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
  memcpy(r, m, sizeof m);
}

/* Sum of forces and of torques x_i x f_i over all vertices. */
static inline void shell_net_force_torque(int32_t n, const double *x, const double *f,
                                          double net[3], double torque[3]) {
  for (int k = 0; k < 3; ++k) net[k] = torque[k] = 0;
  for (int32_t i = 0; i < n; ++i) {
    const double *p = x + 3 * i, *g = f + 3 * i;
    for (int k = 0; k < 3; ++k) net[k] += g[k];
    torque[0] += p[1] * g[2] - p[2] * g[1];
    torque[1] += p[2] * g[0] - p[0] * g[2];
    torque[2] += p[0] * g[1] - p[1] * g[0];
  }
}

static inline double shell_max_abs(const double *a, size_t n) {
  double m = 0;
  for (size_t i = 0; i < n; ++i) m = fmax(m, fabs(a[i]));
  return m;
}

#endif
