/* Where a full time step's time goes: the bench_step scene with the world's per-phase
 * timers on (src/sim/step_profile.h).
 *
 *   build/<dir>/bench_step_phases [repeats] [mesh] [cg_tolerance] [threads]
 *
 * ("" for mesh keeps the default; cg_tolerance 0 keeps the world's default.)
 * Each repeat builds the torus scene (bench/support/bench_scenes.c), takes 3 warm-up steps
 * and times 10 steps of 1e-4 s, for 1 and then 2 threads (or only `threads`), the thread
 * counts interleaved so that a change of machine load hits both alike. Per phase it prints
 * the median over repeats of the ms per step: wall time, the main thread's CPU time
 * (steadier on a loaded machine: it leaves out time other processes hold the core) and the
 * process CPU time (all threads). "applies" are the damping operator applies inside the two
 * solves, already counted in their solve's row. */
#include <stdio.h>
#include <stdlib.h>

#include "piola/mesh_io.h"
#include "piola/threads.h"
#include "sim/world_internal.h"
#include "support/bench_scenes.h"
#include "support/bench_support.h"

enum { ROWS = STEP_PHASE_COUNT + 3, MAX_REPEATS = 64 }; /* phases, applies, total, CG iterations */

int main(int argc, char **argv) {
  int repeats = argc > 1 ? atoi(argv[1]) : 5;
  if (repeats < 1) repeats = 1;
  if (repeats > MAX_REPEATS) repeats = MAX_REPEATS;
  const char *path = argc > 2 && argv[2][0] ? argv[2] : PIOLA_DATA_DIR "/vega/torus-easy.veg";
  double tolerance = argc > 3 ? atof(argv[3]) : 0;
  int only = argc > 4 ? atoi(argv[4]) : 0;
  piola_tet_mesh mesh;
  if (piola_tet_mesh_read(path, &mesh) != PIOLA_OK) {
    fprintf(stderr, "bench_step_phases: %s\n", piola_last_error());
    return 1;
  }
  printf("bench_step_phases: %s, %d vertices, %d tets, cg_tolerance %g, %d repeats x 10 steps\n", path,
         (int)mesh.vertex_count, (int)mesh.tet_count,
         tolerance > 0 ? tolerance : piola_default_world_def().cg_tolerance, repeats);
  /* samples[threads - 1][row][kind][repeat], kind: wall, thread CPU, process CPU */
  static double samples[2][ROWS][3][MAX_REPEATS];
  const int steps = 10;
  for (int r = 0; r < repeats; ++r) {
    for (int threads = 1; threads <= 2; ++threads) {
      if (only && threads != only) continue;
      piola_set_thread_count(threads);
      piola_world *world = bench_torus_step_world(&mesh, tolerance);
      if (!world) return 1;
      piola_step_stats st;
      for (int s = 0; s < 3; ++s) piola_world_step(world, 1e-4, &st); /* warm up */
      piola__step_profile_reset(&world->profile, 1);
      int64_t cg = 0;
      double w0 = bench_wall_seconds(), t0 = bench_thread_cpu_seconds(), c0 = bench_cpu_seconds();
      for (int s = 0; s < steps; ++s) {
        if (piola_world_step(world, 1e-4, &st) != PIOLA_OK) {
          fprintf(stderr, "bench_step_phases: %s\n", piola_last_error());
          return 1;
        }
        cg += st.cg_iterations;
      }
      double tot[3] = {bench_wall_seconds() - w0, bench_thread_cpu_seconds() - t0, bench_cpu_seconds() - c0};
      const step_profile *p = &world->profile;
      double(*row)[3][MAX_REPEATS] = samples[threads - 1];
      for (int ph = 0; ph < STEP_PHASE_COUNT; ++ph) {
        row[ph][0][r] = 1e3 * p->wall[ph] / steps;
        row[ph][1][r] = 1e3 * p->thread_cpu[ph] / steps;
        row[ph][2][r] = 1e3 * p->cpu[ph] / steps;
      }
      row[STEP_PHASE_COUNT][0][r] = 1e3 * p->apply_wall / steps;
      row[STEP_PHASE_COUNT][1][r] = 1e3 * p->apply_thread_cpu / steps;
      row[STEP_PHASE_COUNT][2][r] = 1e3 * p->apply_cpu / steps;
      for (int k = 0; k < 3; ++k) row[STEP_PHASE_COUNT + 1][k][r] = 1e3 * tot[k] / steps;
      row[STEP_PHASE_COUNT + 2][0][r] = (double)cg / steps;
      row[STEP_PHASE_COUNT + 2][1][r] = (double)p->applies / steps;
      row[STEP_PHASE_COUNT + 2][2][r] = 0;
      piola_world_destroy(world);
    }
  }
  for (int threads = 1; threads <= 2; ++threads) {
    if (only && threads != only) continue;
    double(*row)[3][MAX_REPEATS] = samples[threads - 1];
    printf("\n%d thread%s: ms per step, median of %d\n", threads, threads > 1 ? "s" : "", repeats);
    printf("%-18s %10s %12s %12s\n", "phase", "wall", "thread CPU", "process CPU");
    for (int ph = 0; ph < STEP_PHASE_COUNT + 2; ++ph) {
      const char *name = ph < STEP_PHASE_COUNT ? piola__step_phase_names[ph]
                         : ph == STEP_PHASE_COUNT ? "(applies in solves)"
                                                  : "total";
      printf("%-18s %10.2f %12.2f %12.2f\n", name, bench_median(row[ph][0], repeats),
             bench_median(row[ph][1], repeats), bench_median(row[ph][2], repeats));
    }
    double applies = bench_median(row[STEP_PHASE_COUNT + 2][1], repeats);
    printf("CG iterations/step %.1f, damping applies in solves/step %.1f\n",
           bench_median(row[STEP_PHASE_COUNT + 2][0], repeats), applies);
  }
  piola_set_thread_count(0);
  piola_tet_mesh_free(&mesh);
  return 0;
}
