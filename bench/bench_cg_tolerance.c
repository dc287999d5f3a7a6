/* What the damping solves' tolerance costs in accuracy: the bench_step torus scene
 * (bench/support/bench_scenes.c) run for a number of steps of 1e-4 s at several
 * cg_tolerance values and compared with a run at 1e-12; the time-discretization error is the
 * difference a run with half the step (at 1e-12) makes. A tolerance is safe when its error is
 * well below that one.
 *
 *   build/<dir>/bench_cg_tolerance [steps] [sideways speed, m/s] [mesh]
 *
 * The sideways speed is added to the whole body's initial velocity (it falls at 1 m/s onto
 * the ground, friction 0.5): a stopping test that does not depend on the body's momentum
 * gives the same iterations with or without it. Prints, per tolerance, the CG iterations
 * per step and the largest velocity and position differences from the reference. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/mesh_io.h"
#include "piola/world.h"
#include "support/bench_scenes.h"

static int run(const piola_tet_mesh *mesh, double tolerance, double dt, int steps, double sideways,
               double *x, double *v, double *iterations) {
  piola_world *w = bench_torus_step_world(mesh, tolerance);
  if (!w) return 1;
  int32_t n = mesh->vertex_count;
  if (sideways != 0) {
    memcpy(v, piola_world_solid_velocities(w, 0), 3 * (size_t)n * sizeof(double));
    for (int32_t i = 0; i < n; ++i) v[3 * i] += sideways;
    if (piola_world_solid_set_state(w, 0, NULL, v) != PIOLA_OK) return 1;
  }
  int64_t cg = 0;
  for (int s = 0; s < steps; ++s) {
    piola_step_stats st;
    if (piola_world_step(w, dt, &st) != PIOLA_OK) {
      fprintf(stderr, "bench_cg_tolerance: %s\n", piola_last_error());
      piola_world_destroy(w);
      return 1;
    }
    cg += st.cg_iterations;
  }
  memcpy(x, piola_world_solid_positions(w, 0), 3 * (size_t)n * sizeof(double));
  memcpy(v, piola_world_solid_velocities(w, 0), 3 * (size_t)n * sizeof(double));
  *iterations = (double)cg / steps;
  piola_world_destroy(w);
  return 0;
}

static double max_difference(const double *a, const double *b, int64_t m) {
  double d = 0;
  for (int64_t i = 0; i < m; ++i) d = fmax(d, fabs(a[i] - b[i]));
  return d;
}

int main(int argc, char **argv) {
  int steps = argc > 1 ? atoi(argv[1]) : 20;
  if (steps < 1) steps = 1;
  double sideways = argc > 2 ? atof(argv[2]) : 0;
  const char *path = argc > 3 && argv[3][0] ? argv[3] : PIOLA_DATA_DIR "/vega/torus-easy.veg";
  piola_tet_mesh mesh;
  if (piola_tet_mesh_read(path, &mesh) != PIOLA_OK) {
    fprintf(stderr, "bench_cg_tolerance: %s\n", piola_last_error());
    return 1;
  }
  const int64_t m = 3 * (int64_t)mesh.vertex_count;
  double *xr = malloc((size_t)m * sizeof(double)), *vr = malloc((size_t)m * sizeof(double));
  double *x = malloc((size_t)m * sizeof(double)), *v = malloc((size_t)m * sizeof(double));
  const double dt = 1e-4, reference = 1e-12;
  double it;
  printf("bench_cg_tolerance: %s, %d vertices, %d steps of %g s, sideways %g m/s\n", path,
         (int)mesh.vertex_count, steps, dt, sideways);
  if (run(&mesh, reference, dt, steps, sideways, xr, vr, &it)) return 1;
  printf("%-22s %14s %14s %14s\n", "run", "CG iter/step", "max |dv| m/s", "max |dx| m");
  printf("%-22s %14.1f %14s %14s\n", "tolerance 1e-12 (ref)", it, "0", "0");
  if (run(&mesh, reference, dt / 2, 2 * steps, sideways, x, v, &it)) return 1;
  printf("%-22s %14.1f %14.3g %14.3g\n", "dt/2 at 1e-12", it, max_difference(v, vr, m),
         max_difference(x, xr, m));
  const double tolerances[] = {1e-8, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2};
  for (size_t k = 0; k < sizeof tolerances / sizeof *tolerances; ++k) {
    if (run(&mesh, tolerances[k], dt, steps, sideways, x, v, &it)) return 1;
    char name[32];
    snprintf(name, sizeof name, "tolerance %g", tolerances[k]);
    printf("%-22s %14.1f %14.3g %14.3g\n", name, it, max_difference(v, vr, m), max_difference(x, xr, m));
  }
  free(xr), free(vr), free(x), free(v);
  piola_tet_mesh_free(&mesh);
  return 0;
}
