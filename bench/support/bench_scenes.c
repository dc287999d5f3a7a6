#include "support/bench_scenes.h"

#include <math.h>
#include <stdio.h>

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
