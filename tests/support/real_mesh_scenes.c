/* Real meshes as the issue 21 acceptance tests use them (real_mesh_scenes.h). */
#include "test_support.h"

#include <math.h>
#include <string.h>

#include "piola/elastic_body.h"
#include "piola/mesh_io.h"
#include "real_mesh_scenes.h"

piola_tet_mesh real_mesh_scaled(const char *relative, double diagonal) {
  piola_tet_mesh mesh;
  memset(&mesh, 0, sizeof mesh);
  const char *path = test_data_path(relative);
  if (piola_tet_mesh_read(path, &mesh) != PIOLA_OK) fail_msg("%s: %s", path, piola_last_error());
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int32_t v = 0; v < mesh.vertex_count; ++v)
    for (int i = 0; i < 3; ++i)
      lo[i] = fmin(lo[i], mesh.positions[3 * v + i]), hi[i] = fmax(hi[i], mesh.positions[3 * v + i]);
  const double d = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                        (hi[2] - lo[2]) * (hi[2] - lo[2]));
  for (int32_t v = 0; v < mesh.vertex_count; ++v)
    for (int i = 0; i < 3; ++i)
      mesh.positions[3 * v + i] = (mesh.positions[3 * v + i] - 0.5 * (lo[i] + hi[i])) * diagonal / d;
  return mesh;
}

piola_material_def real_mesh_material_def(piola_material_model model, double youngs, double poisson) {
  piola_material_def def = piola_default_material_def();
  const double mu = youngs / (2 * (1 + poisson));
  def.model = model;
  def.youngs_modulus = youngs;
  def.poisson_ratio = poisson;
  double ogden_mu = 0;
  for (int p = 0; p < def.ogden.term_count; ++p) ogden_mu += 0.5 * def.ogden.mu[p] * def.ogden.alpha[p];
  for (int p = 0; p < def.ogden.term_count; ++p) def.ogden.mu[p] *= mu / ogden_mu;
  def.mooney_rivlin.c10 = 0.375 * mu, def.mooney_rivlin.c01 = 0.125 * mu;
  def.hgo.mu = mu;
  return def;
}

int real_mesh_solid_finite(const piola_world *w) {
  const int32_t n = piola_elastic_body_vertex_count(piola_world_solid_body(w, 0));
  const double *x = piola_world_solid_positions(w, 0), *v = piola_world_solid_velocities(w, 0);
  for (int64_t j = 0; j < 3 * (int64_t)n; ++j)
    if (!isfinite(x[j]) || !isfinite(v[j])) return 0;
  return 1;
}
