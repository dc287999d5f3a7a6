/* Benchmark of one full time step of the world: elastic forces and diagonalization once,
 * two damping solves by conjugate gradient, collisions with a ground plane.
 *
 *   build/<dir>/bench_step [repeats] [mesh]
 *
 * Mesh: Vega's torus-easy.veg (97,878 tets) from ../shared/data unless another is given.
 * The torus starts slightly scrambled (so elastic forces and damping are busy), falls under
 * gravity onto a plane through its lowest point, with shear and bulk viscosities chosen so
 * the two solves of a step took about 20 CG iterations together under the old stopping test
 * (12 at the default cg_tolerance now; bench_step_phases takes a tolerance to force ~20).
 * Each timing is 10 steps of
 * fixed dt = 1e-4 s; the table gives the median over `repeats` (default 5) for 1 and 2
 * threads: wall and process CPU time per step (CPU time is less disturbed by a loaded
 * machine; with 2 threads it counts both), CG iterations per step, and the two kernels a
 * step is made of timed alone: one elastic update and one damping-force evaluation (a step
 * costs one update plus about one damping evaluation per CG iteration; the damping time
 * excludes the first call after the update, which also assembles the damping matrix once per
 * step). bench_damping times the damping operator alone, in CPU time too. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "piola/mesh_io.h"
#include "piola/threads.h"
#include "piola/world.h"
#include "support/bench_scenes.h"
#include "support/bench_support.h"

int main(int argc, char **argv) {
  int repeats = argc > 1 ? atoi(argv[1]) : 5;
  if (repeats < 1) repeats = 1;
  const char *path = argc > 2 ? argv[2] : PIOLA_DATA_DIR "/vega/torus-easy.veg";
  piola_tet_mesh mesh;
  if (piola_tet_mesh_read(path, &mesh) != PIOLA_OK) {
    fprintf(stderr, "bench_step: %s\n", piola_last_error());
    return 1;
  }
  double zmin = INFINITY, xmin = INFINITY, xmax = -INFINITY;
  for (int32_t i = 0; i < mesh.vertex_count; ++i) {
    zmin = fmin(zmin, mesh.positions[3 * i + 2]);
    xmin = fmin(xmin, mesh.positions[3 * i]);
    xmax = fmax(xmax, mesh.positions[3 * i]);
  }
  double size = xmax - xmin;
  printf("bench_step: %s, %d vertices, %d tets, size %.3g m\n", path, (int)mesh.vertex_count,
         (int)mesh.tet_count, size);
  printf("%8s %10s %14s %14s %12s %14s\n", "threads", "ms/step", "CPU ms/step", "CG iter/step",
         "ms/update", "ms/damping");
  for (int threads = 1; threads <= 2; ++threads) {
    piola_set_thread_count(threads);
    double *times = malloc((size_t)repeats * sizeof *times);
    double *cpu = malloc((size_t)repeats * sizeof *cpu);
    double *upd = malloc((size_t)repeats * sizeof *upd);
    double *damp = malloc((size_t)repeats * sizeof *damp);
    double cg_per_step = 0;
    for (int r = 0; r < repeats; ++r) {
      /* the shared issue-3 scene (bench/support/bench_scenes.h): fixed dt 1e-4 s */
      piola_world *world = bench_torus_step_world(&mesh, 0);
      if (!world) return 1;
      piola_step_stats st;
      for (int s = 0; s < 3; ++s) piola_world_step(world, 1e-4, &st); /* warm up */
      const int steps = 10;
      int cg = 0;
      double t0 = bench_wall_seconds();
      clock_t c0 = clock();
      for (int s = 0; s < steps; ++s) {
        if (piola_world_step(world, 1e-4, &st) != PIOLA_OK) {
          fprintf(stderr, "bench_step: %s\n", piola_last_error());
          return 1;
        }
        cg += st.cg_iterations;
      }
      times[r] = (bench_wall_seconds() - t0) / steps;
      cpu[r] = (double)(clock() - c0) / CLOCKS_PER_SEC / steps;
      cg_per_step = (double)cg / steps;
      /* the two kernels of a step alone, on this state: one elastic update, one damping apply */
      const piola_elastic_body *body = piola_world_solid_body(world, 0);
      int32_t n = piola_elastic_body_vertex_count(body);
      double *f = malloc(3 * (size_t)n * sizeof *f);
      double *x = malloc(3 * (size_t)n * sizeof *x);
      memcpy(x, piola_world_solid_positions(world, 0), 3 * (size_t)n * sizeof *x);
      piola_elastic_body *mut = (piola_elastic_body *)body; /* the world's own body, same state */
      double u0 = bench_wall_seconds();
      for (int k = 0; k < 3; ++k) piola_elastic_body_update(mut, x, 1.0, f, NULL);
      upd[r] = (bench_wall_seconds() - u0) / 3;
      /* the first call after an update assembles the damping matrix (once per step): not
       * part of the per-apply time, which is what each CG iteration pays */
      piola_elastic_body_damping_forces(body, piola_world_solid_velocities(world, 0), 1, 1, f);
      double d0 = bench_wall_seconds();
      for (int k = 0; k < 5; ++k)
        piola_elastic_body_damping_forces(body, piola_world_solid_velocities(world, 0), 1, 1, f);
      damp[r] = (bench_wall_seconds() - d0) / 5;
      free(f);
      free(x);
      piola_world_destroy(world);
    }
    qsort(times, (size_t)repeats, sizeof *times, bench_compare_doubles);
    qsort(cpu, (size_t)repeats, sizeof *cpu, bench_compare_doubles);
    qsort(upd, (size_t)repeats, sizeof *upd, bench_compare_doubles);
    qsort(damp, (size_t)repeats, sizeof *damp, bench_compare_doubles);
    printf("%8d %10.2f %14.2f %14.1f %12.2f %14.2f\n", threads, 1e3 * times[repeats / 2],
           1e3 * cpu[repeats / 2], cg_per_step, 1e3 * upd[repeats / 2], 1e3 * damp[repeats / 2]);
    free(times);
    free(cpu);
    free(upd);
    free(damp);
  }
  piola_tet_mesh_free(&mesh);
  return 0;
}
