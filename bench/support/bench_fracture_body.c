#include "support/bench_fracture_body.h"

#include <stdio.h>
#include <stdlib.h>

#include "support/bench_support.h"

piola_world *bench_fracture_world(const piola_tet_mesh *mesh, piola_vec3 velocity) {
  piola_world_def wd = piola_default_world_def();
  for (int k = 0; k < 3; ++k) wd.gravity[k] = piola_track_constant(0);
  piola_world *w = NULL;
  if (piola_world_create(&wd, &w) != PIOLA_OK) {
    fprintf(stderr, "bench: %s\n", piola_last_error());
    return NULL;
  }
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material.youngs_modulus = 1e5;
  sd.material.poisson_ratio = 0.3;
  sd.shear_viscosity = piola_track_constant(1);
  sd.bulk_viscosity = piola_track_constant(1);
  sd.initial_matrix = (piola_mat3){{{1.1, 0.05, 0}, {0, 0.95, 0.02}, {0.03, 0, 1.05}}};
  sd.velocity = velocity;
  if (piola_world_add_solid(w, &sd, NULL) != PIOLA_OK) {
    fprintf(stderr, "bench: %s\n", piola_last_error());
    piola_world_destroy(w);
    return NULL;
  }
  return w;
}

double bench_fracture_time_steps(piola_world *w, int steps, double dt) {
  double t0 = bench_thread_cpu_seconds();
  for (int s = 0; s < steps; ++s)
    if (piola_world_step(w, dt, NULL) != PIOLA_OK) {
      fprintf(stderr, "bench: %s\n", piola_last_error());
      exit(1);
    }
  return (bench_thread_cpu_seconds() - t0) / steps;
}

