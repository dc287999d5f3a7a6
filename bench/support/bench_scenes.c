#include "support/bench_scenes.h"

#include <math.h>
#include <stdio.h>

#include "support/recovery_runs.h"

piola_world *bench_torus_step_world(const piola_tet_mesh *mesh, double cg_tolerance) {
  double zmin = INFINITY, xmin = INFINITY, xmax = -INFINITY;
  for (int32_t i = 0; i < mesh->vertex_count; ++i) {
    zmin = fmin(zmin, mesh->positions[3 * i + 2]);
    xmin = fmin(xmin, mesh->positions[3 * i]);
    xmax = fmax(xmax, mesh->positions[3 * i]);
  }
  double size = xmax - xmin;
  piola_world_def wd = piola_default_world_def();
  wd.max_dt = 1e-4;
  wd.cfl = 2; /* fixed dt: this measures the cost of a step, not the step size */
  if (cg_tolerance > 0) wd.cg_tolerance = cg_tolerance;
  piola_world *world = NULL;
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material.model = PIOLA_MODEL_NEOHOOKEAN;
  sd.material.youngs_modulus = 1e5;
  sd.material.poisson_ratio = 0.4;
  sd.shear_viscosity = piola_track_constant(2e-5 * 1000 * size * size / 1e-4);
  sd.bulk_viscosity = piola_track_constant(2e-5 * 1000 * size * size / 1e-4);
  sd.scramble_radius = 1e-3 * size;
  sd.velocity = (piola_vec3){0, 0, -1};
  piola_obstacle_def ground = piola_default_obstacle_def();
  ground.type = PIOLA_OBSTACLE_PLANE;
  ground.center = (piola_vec3){0, 0, zmin};
  ground.axis = (piola_vec3){0, 0, 1};
  ground.friction = 0.5;
  if (piola_world_create(&wd, &world) != PIOLA_OK || piola_world_add_solid(world, &sd, NULL) != PIOLA_OK ||
      piola_world_add_obstacle(world, &ground, NULL) != PIOLA_OK) {
    fprintf(stderr, "bench: %s\n", piola_last_error());
    piola_world_destroy(world);
    return NULL;
  }
  return world;
}

int bench_read_mesh_with_diagonal(const char *relative, double diagonal, piola_tet_mesh *mesh) {
  if (recovery_read_unit_mesh(PIOLA_DATA_DIR, relative, mesh) != 0) return -1;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int32_t v = 0; v < 3 * mesh->vertex_count; ++v)
    lo[v % 3] = fmin(lo[v % 3], mesh->positions[v]), hi[v % 3] = fmax(hi[v % 3], mesh->positions[v]);
  const double d = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                        (hi[2] - lo[2]) * (hi[2] - lo[2]));
  for (int32_t v = 0; v < 3 * mesh->vertex_count; ++v) mesh->positions[v] *= diagonal / d;
  return 0;
}

piola_solid_def bench_scramble_solid_def(const piola_tet_mesh *mesh, piola_material_model model,
                                         double radius) {
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material.model = model;
  sd.material.youngs_modulus = 2e4;
  sd.material.poisson_ratio = 0.3;
  sd.density = 1000;
  sd.shear_viscosity = sd.bulk_viscosity = piola_track_constant(1000);
  sd.scramble_radius = radius;
  return sd;
}
