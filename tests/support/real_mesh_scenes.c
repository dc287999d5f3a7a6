/* Real meshes as the issue 21 acceptance tests use them (real_mesh_scenes.h). */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "piola/elastic_body.h"
#include "piola/mesh_io.h"
#include "real_mesh_scenes.h"

/* The mesh's bounding box, lo and hi; returns its diagonal. */
static double bounds(const piola_tet_mesh *mesh, double lo[3], double hi[3]) {
  for (int i = 0; i < 3; ++i) lo[i] = INFINITY, hi[i] = -INFINITY;
  for (int32_t v = 0; v < mesh->vertex_count; ++v)
    for (int i = 0; i < 3; ++i)
      lo[i] = fmin(lo[i], mesh->positions[3 * v + i]),
      hi[i] = fmax(hi[i], mesh->positions[3 * v + i]);
  return sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
              (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

double real_mesh_diagonal(const piola_tet_mesh *mesh) {
  double lo[3], hi[3];
  return bounds(mesh, lo, hi);
}

piola_tet_mesh real_mesh_read(const char *relative) {
  piola_tet_mesh mesh;
  memset(&mesh, 0, sizeof mesh);
  const char *path = test_data_path(relative);
  if (piola_tet_mesh_read(path, &mesh) != PIOLA_OK) fail_msg("%s: %s", path, piola_last_error());
  return mesh;
}

piola_tet_mesh real_mesh_scaled(const char *relative, double diagonal) {
  piola_tet_mesh mesh = real_mesh_read(relative);
  double lo[3], hi[3];
  const double d = bounds(&mesh, lo, hi);
  for (int32_t v = 0; v < mesh.vertex_count; ++v)
    for (int i = 0; i < 3; ++i)
      mesh.positions[3 * v + i] =
          (mesh.positions[3 * v + i] - 0.5 * (lo[i] + hi[i])) * diagonal / d;
  return mesh;
}

piola_material_def real_mesh_material_def(piola_material_model model, double youngs,
                                          double poisson) {
  piola_material_def def = piola_default_material_def();
  const double mu = youngs / (2 * (1 + poisson));
  def.model = model;
  def.youngs_modulus = youngs;
  def.poisson_ratio = poisson;
  double ogden_mu = 0;
  for (int p = 0; p < def.ogden.term_count; ++p)
    ogden_mu += 0.5 * def.ogden.mu[p] * def.ogden.alpha[p];
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

double real_mesh_total_energy(const piola_world *w) {
  const piola_solid_stats s = piola_world_solid_stats(w, 0);
  return s.kinetic_energy + s.elastic_energy;
}

piola_world *real_mesh_scramble_world(const piola_tet_mesh *mesh, const real_mesh_scramble *scene) {
  piola_world_def wd = piola_default_world_def();
  for (int i = 0; i < 3; ++i) wd.gravity[i] = piola_track_constant(0);
  wd.integrator = scene->integrator;
  if (scene->integrator != PIOLA_INTEGRATOR_NEWMARK) wd.implicit_dt = 1.0 / 30;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material = scene->material;
  sd.density = 1000;
  sd.shear_viscosity = sd.bulk_viscosity = piola_track_constant(scene->viscosity);
  sd.scramble_radius = scene->radius;
  sd.fiber_directions = scene->fibers;
  if (scene->start_matrix) sd.initial_matrix = *scene->start_matrix;
  if (piola_world_add_solid(w, &sd, NULL) != PIOLA_OK) {
    piola_world_destroy(w);
    return NULL;
  }
  return w;
}

void real_mesh_scramble_run(const piola_tet_mesh *mesh, const char *name,
                            piola_material_model model, double radius, double seconds,
                            const double *fibers) {
  const real_mesh_scramble scene = {real_mesh_material_def(model, 2e4, 0.3), 1000, radius,
                                    PIOLA_INTEGRATOR_NEWMARK,
                                    model == PIOLA_MODEL_HGO ? fibers : NULL, NULL};
  piola_world *w = real_mesh_scramble_world(mesh, &scene);
  if (!w) fail_msg("%s %s: %s", name, piola_material_model_name(model), piola_last_error());
  const double e0 = real_mesh_total_energy(w);
  double highest = e0;
  piola_step_stats st = {0};
  const clock_t c0 = clock();
  for (int frame = 1; frame <= 20; ++frame) {
    piola_step_stats fs = {0};
    if (piola_world_advance_to(w, seconds * frame / 20, &fs) != PIOLA_OK ||
        !real_mesh_solid_finite(w))
      fail_msg("%s, %s, scramble %g m, at %g s: %s", name, piola_material_model_name(model), radius,
               seconds * frame / 20, piola_last_error());
    st.substeps += fs.substeps, st.energy_redos += fs.energy_redos,
        st.step_retries += fs.step_retries;
    highest = fmax(highest, real_mesh_total_energy(w));
  }
  if (getenv("PIOLA_TEST_VERBOSE"))
    print_message(
        "%-22s %-17s %4.2f m, %4.2f s: %8d steps, %3d redos, %d retries, energy %.3g -> %.3g J "
        "(highest %.3g), %.2f s CPU\n",
        name, piola_material_model_name(model), radius, seconds, (int)st.substeps,
        (int)st.energy_redos, (int)st.step_retries, e0, real_mesh_total_energy(w), highest,
        (double)(clock() - c0) / CLOCKS_PER_SEC);
  if (!(highest <= 1.05 * e0))
    fail_msg("%s, %s, scramble %g m: total energy rose from %g J to %g J", name,
             piola_material_model_name(model), radius, e0, highest);
  piola_world_destroy(w);
}

void real_mesh_scramble_models(const char *relative, double diagonal,
                               const piola_material_model *models, int count, double radius) {
  const double seconds = fmax(0.02, 2.0 * fmin(test_scale(), 1.0));
  const char *only = getenv("PIOLA_TEST_MODEL");
  piola_tet_mesh mesh = real_mesh_scaled(relative, diagonal);
  for (int k = 0; k < count; ++k) {
    if (only && strcmp(only, piola_material_model_name(models[k]))) continue;
    real_mesh_scramble_run(&mesh, relative, models[k], radius, seconds, NULL);
  }
  piola_tet_mesh_free(&mesh);
}
