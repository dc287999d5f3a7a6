/* Weak scaling of the split Newmark step (docs/scaling.md): a box of generated tets, the
 * same number per process, stepped on every process of MPI_COMM_WORLD.
 *
 *   mpirun -np 1 build/test/bench_mpi_weak [TETS_PER_PROCESS] [STEPS] [REPEATS]
 *   mpirun -np 2 build/test/bench_mpi_weak [TETS_PER_PROCESS] [STEPS] [REPEATS]
 *
 * The box is n x n x (P n) cubes of 6 tets (P processes), a neo-Hookean jelly (E = 100 kPa,
 * nu = 0.4) with shear and bulk viscosity, starting stretched by 10% along x and swinging
 * back under gravity; steps of 1e-4 s. Each repeat times STEPS steps (median over repeats),
 * and process 0 prints: tets, steps, wall s/step, each process's time in the halo sums and
 * in the replication gathers per step, and their bytes per step, and its peak resident
 * memory (the largest over the run: setup, partition and steps) per tet of the box, and
 * its thread's CPU time per step, less what the exchanges took of it (their polling
 * included): the process's own work, which on a loaded machine scales where the wall time,
 * waiting for the other process's time slice, does not; and its thread CPU time per step
 * by phase of the step (the world's step profile, src/sim/step_profile.h, the exchanges'
 * CPU included, since they are timed as a whole): where one process works more than another.
 * Efficiency of weak scaling is the 1-process s/step over the P-process one. The box is
 * generated in memory (piola_tet_mesh_box_grid), no mesh file, and each process builds only
 * its part of it (piola_mpi_split_planner): the peak memory is the split's. Only built with
 * PIOLA_MPI. */
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "piola/threads.h"

#include "support/bench_support.h"
#include "piola/mpi.h"
#include "piola/world.h"
#include "sim/world_internal.h"

static piola_world *jelly_box(int n, int stack, const piola_work_split_planner *planner) {
  piola_tet_mesh mesh;
  const double h = 0.01;
  if (piola_tet_mesh_box_grid(n, n, stack * n, (piola_vec3){h, h, h}, &mesh) != PIOLA_OK) return NULL;
  piola_world_def wd = piola_default_world_def();
  wd.max_dt = 1e-4;
  wd.cfl = 2; /* every step max_dt long */
  piola_world *w = NULL;
  if (piola_world_create(&wd, &w) != PIOLA_OK) return NULL;
  piola_world_set_work_split_planner(w, planner); /* no process builds the whole box */
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  sd.material.model = PIOLA_MODEL_NEOHOOKEAN;
  sd.material.youngs_modulus = 1e5;
  sd.material.poisson_ratio = 0.4;
  sd.shear_viscosity = piola_track_constant(2.0);
  sd.bulk_viscosity = piola_track_constant(2.0);
  sd.initial_matrix = (piola_mat3){{{1.1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  piola_status st = piola_world_add_solid(w, &sd, NULL);
  piola_tet_mesh_free(&mesh);
  if (st != PIOLA_OK) {
    piola_world_destroy(w);
    return NULL;
  }
  return w;
}

static double thread_cpu_seconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  piola_set_thread_count(1); /* one thread per process */
  int rank, size;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const long per_process = argc > 1 ? atol(argv[1]) : 48000;
  const int steps = argc > 2 ? atoi(argv[2]) : 20, repeats = argc > 3 ? atoi(argv[3]) : 3;
  const int n = (int)fmax(2, round(cbrt(per_process / 6.0)));
  piola_mpi_split *split = NULL;
  piola_world *w = NULL;
  if (piola_mpi_split_create(&split) == PIOLA_OK) {
    piola_work_split_planner planner = piola_mpi_split_planner(split);
    w = jelly_box(n, size, &planner);
  }
  if (!w || piola_mpi_split_finish(split, w) != PIOLA_OK) {
    fprintf(stderr, "bench_mpi_weak: %s\n", piola_last_error());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  double *per_step = malloc(sizeof(double) * (size_t)repeats);
  piola_mpi_split_stats before = piola_mpi_split_stats_of(split);
  (void)piola_world_step(w, 0, NULL); /* warm-up */
  before = piola_mpi_split_stats_of(split);
  piola__step_profile_reset(&w->profile, 1); /* where each process's CPU time goes */
  double cpu = 0; /* the steps' CPU time, not the barriers' */
  for (int r = 0; r < repeats; ++r) {
    MPI_Barrier(MPI_COMM_WORLD);
    double t0 = bench_wall_seconds(), c0 = thread_cpu_seconds();
    for (int s = 0; s < steps; ++s)
      if (piola_world_step(w, 0, NULL) != PIOLA_OK) MPI_Abort(MPI_COMM_WORLD, 1);
    cpu += thread_cpu_seconds() - c0;
    MPI_Barrier(MPI_COMM_WORLD);
    per_step[r] = (bench_wall_seconds() - t0) / steps;
  }
  piola_mpi_split_stats after = piola_mpi_split_stats_of(split);
  const double total_steps = (double)steps * repeats;
  struct rusage usage;
  getrusage(RUSAGE_SELF, &usage); /* ru_maxrss: KiB on Linux */
  double resident = 0; /* now, after the steps: /proc/self/statm's second field, in pages */
  FILE *statm = fopen("/proc/self/statm", "r");
  if (statm) {
    long pages_total = 0, pages_resident = 0;
    if (fscanf(statm, "%ld %ld", &pages_total, &pages_resident) == 2)
      resident = (double)pages_resident * (double)sysconf(_SC_PAGESIZE);
    fclose(statm);
  }
  double mine[9] = {(after.halo_seconds - before.halo_seconds) / total_steps,
                    (after.gather_seconds - before.gather_seconds) / total_steps,
                    (double)(after.halo_bytes - before.halo_bytes) / total_steps,
                    (double)(after.gather_bytes - before.gather_bytes) / total_steps,
                    (double)after.shared_nodes, 1024.0 * (double)usage.ru_maxrss, resident,
                    cpu / total_steps,
                    (after.exchange_cpu_seconds - before.exchange_cpu_seconds) / total_steps};
  double *all = malloc(sizeof mine * (size_t)size);
  MPI_Gather(mine, 9, MPI_DOUBLE, all, 9, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  /* per phase: the thread CPU time per step (exchanges included), then the applies' */
  enum { PHASES = STEP_PHASE_COUNT + 1 };
  double phases[PHASES], *all_phases = malloc(sizeof phases * (size_t)size);
  for (int ph = 0; ph < STEP_PHASE_COUNT; ++ph) phases[ph] = w->profile.thread_cpu[ph] / total_steps;
  phases[STEP_PHASE_COUNT] = w->profile.apply_thread_cpu / total_steps;
  MPI_Gather(phases, PHASES, MPI_DOUBLE, all_phases, PHASES, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  if (rank == 0) {
    const piola_elastic_body *b = piola_world_solid_body(w, 0);
    printf("bench_mpi_weak: %d processes, %d tets (%ld per process asked), %d nodes, %d steps x %d\n",
           size, (int)piola_elastic_body_tet_count(b), per_process,
           (int)piola_elastic_body_vertex_count(b), steps, repeats);
    printf("  wall per step (median): %.4f s\n", bench_median(per_step, repeats));
    const double tets = (double)piola_elastic_body_tet_count(b);
    for (int q = 0; q < size; ++q) {
      const double *a = all + 9 * q;
      printf("  rank %d: halo %.5f s/step (%.0f B sent/step), gathers %.5f s/step (%.0f B "
             "received/step), %.0f shared nodes, peak RSS %.1f MB (%.0f B per tet of the box, "
             "%.0f B per tet of its share), resident after the steps %.1f MB (%.0f B per tet)\n",
             q, a[0], a[2], a[1], a[3], a[4], a[5] / 1e6, a[5] / tets, a[5] * size / tets,
             a[6] / 1e6, a[6] / tets);
      printf("  rank %d: CPU %.5f s/step, of which exchanges %.5f: own work %.5f s/step\n", q,
             a[7], a[8], a[7] - a[8]);
      printf("  rank %d: CPU ms/step by phase (exchanges included):", q);
      for (int ph = 0; ph < STEP_PHASE_COUNT; ++ph)
        if (all_phases[PHASES * q + ph] > 0)
          printf(" %s %.2f", piola__step_phase_names[ph], 1e3 * all_phases[PHASES * q + ph]);
      printf(" (applies in solves %.2f)\n", 1e3 * all_phases[PHASES * q + STEP_PHASE_COUNT]);
    }
  }
  free(all);
  free(all_phases);
  free(per_step);
  piola_mpi_split_destroy(split, w);
  piola_world_destroy(w);
  MPI_Finalize();
  return 0;
}
