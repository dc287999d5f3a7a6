/* Blocks of tets shared by the world dynamics tests (block_scenes.h). */
#include "test_support.h"

#include <stdlib.h>

#include "block_scenes.h"
#include "piola/elastic_body.h"

piola_tet_mesh block_mesh(int nx, int ny, int nz, double a, double b, double c) {
  piola_tet_mesh m;
  assert_int_equal(piola_tet_mesh_box_grid(nx, ny, nz, (piola_vec3){a / nx, b / ny, c / nz}, &m),
                   PIOLA_OK);
  return m;
}

void block_mesh_free(piola_tet_mesh *m) {
  free(m->positions);
  free(m->tets);
}

piola_world *weightless_world(double max_dt) {
  piola_world_def wd = piola_default_world_def();
  for (int k = 0; k < 3; ++k) wd.gravity[k] = piola_track_constant(0);
  wd.max_dt = max_dt;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  return w;
}

piola_world *deformed_block_world(piola_material_model model, int n, piola_mat3 initial,
                                  double viscosity, double cfl, int32_t cg_max_iterations) {
  return deformed_block_world_inverting(model, PIOLA_INVERSION_MODEL_DEFAULT, 0, n, initial,
                                        viscosity, cfl, cg_max_iterations);
}

piola_world *deformed_block_world_inverting(piola_material_model model, piola_inversion_mode mode,
                                            double threshold, int n, piola_mat3 initial,
                                            double viscosity, double cfl,
                                            int32_t cg_max_iterations) {
  piola_world_def wd = piola_default_world_def();
  for (int k = 0; k < 3; ++k) wd.gravity[k] = piola_track_constant(0);
  wd.max_dt = 1;
  wd.cfl = cfl;
  if (cg_max_iterations > 0) wd.cg_max_iterations = cg_max_iterations;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(n, n, n, (piola_vec3){0.1, 0.1, 0.1}, &mesh), PIOLA_OK);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  sd.material.model = model;
  sd.material.youngs_modulus = 1e4;
  sd.material.poisson_ratio = 0.3;
  sd.material.inversion_mode = mode;
  sd.material.inversion_threshold = threshold;
  sd.density = 1000;
  sd.shear_viscosity = piola_track_constant(viscosity);
  sd.bulk_viscosity = piola_track_constant(viscosity);
  sd.initial_matrix = initial;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  piola_tet_mesh_free(&mesh);
  return w;
}

void solid_momenta(const piola_world *w, double p[3], double l[3], double *kinetic) {
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const double *m = piola_elastic_body_masses(b);
  const double *x = piola_world_solid_positions(w, 0), *v = piola_world_solid_velocities(w, 0);
  double e = 0;
  p[0] = p[1] = p[2] = l[0] = l[1] = l[2] = 0;
  for (int32_t i = 0; i < piola_elastic_body_vertex_count(b); ++i) {
    const double *xi = x + 3 * i, *vi = v + 3 * i;
    for (int k = 0; k < 3; ++k) p[k] += m[i] * vi[k];
    l[0] += m[i] * (xi[1] * vi[2] - xi[2] * vi[1]);
    l[1] += m[i] * (xi[2] * vi[0] - xi[0] * vi[2]);
    l[2] += m[i] * (xi[0] * vi[1] - xi[1] * vi[0]);
    e += 0.5 * m[i] * (vi[0] * vi[0] + vi[1] * vi[1] + vi[2] * vi[2]);
  }
  if (kinetic) *kinetic = e;
}

void spin_block(piola_world *w, double vz, double vz_per_y) {
  const int32_t n = piola_elastic_body_vertex_count(piola_world_solid_body(w, 0));
  double *v = malloc(3 * (size_t)n * sizeof(double));
  assert_non_null(v);
  const double *x = piola_world_solid_positions(w, 0);
  for (int32_t i = 0; i < n; ++i) {
    const double *xi = x + 3 * i;
    v[3 * i] = 0.5 - 3.0 * (xi[1] - 0.1);
    v[3 * i + 1] = -0.2 + 3.0 * (xi[0] - 0.15);
    v[3 * i + 2] = vz + vz_per_y * (xi[1] - 0.1);
  }
  assert_int_equal(piola_world_solid_set_state(w, 0, NULL, v), PIOLA_OK);
  free(v);
}
