/* Benchmark of the elastic force loop (tets per second) and of the vectorized SVD kernel.
 *
 *   build/<dir>/bench_forces [repeats]
 *
 * Meshes: a generated structured grid of ~105K tets, and Vega's torus-easy.veg (97,878 tets)
 * when the mesh reader is available. Each is deformed by a small random perturbation plus
 * mirroring one corner of ~1% of the tets through the plane of the other three, so a few
 * percent of tets are inverted, as in a simulation recovering from collisions. Reports the
 * bench_median of `repeats` (default 7) timings of piola_elastic_body_update (forces, no stats:
 * the energy is computed only on request) with 1 and 2 threads, as wall time and as process
 * CPU time divided by the thread count (the machine is shared; see docs/bench-notes). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "force/elastic_body_internal.h"
#include "support/elastic_referees.h"
#include "force/svd_kernel.h"
#include "piola/elastic_body.h"
#include "piola/mesh_io.h"
#include "support/bench_deform.h"
#include "support/bench_support.h"

/* n^3 cubes, 6 tets each, edge h. */
static piola_tet_mesh grid_mesh(int n, double h) {
  piola_tet_mesh mesh;
  if (piola_tet_mesh_box_grid(n, n, n, (piola_vec3){h, h, h}, &mesh) != PIOLA_OK) {
    fprintf(stderr, "bench_forces: %s\n", piola_last_error());
    exit(1);
  }
  return mesh;
}

static void bench_mesh(const char *name, const piola_tet_mesh *mesh, int repeats) {
  static const piola_material_model models[] = {PIOLA_MODEL_NEOHOOKEAN, PIOLA_MODEL_COROTATED,
                                                PIOLA_MODEL_ROTATED_LINEAR, PIOLA_MODEL_STVK,
                                                PIOLA_MODEL_SPLINE};
  for (size_t m = 0; m < sizeof models / sizeof models[0]; ++m) {
    piola_material_def mdef = bench_rows_material_def(models[m]);
    piola_material material;
    if (piola_material_init(&mdef, &material) != PIOLA_OK) return;
    piola_elastic_body_def def = piola_default_elastic_body_def();
    def.rest_mesh = mesh;
    def.materials = &material;
    def.material_count = 1;
    piola_elastic_body *body;
    if (piola_elastic_body_create(&def, &body) != PIOLA_OK) {
      printf("%s: %s\n", name, piola_last_error());
      return;
    }
    double *x = bench_deformed_positions(body);
    double *f = malloc(sizeof(double) * 3 * (size_t)mesh->vertex_count);
    piola_elastic_stats stats;
    piola_elastic_body_update(body, x, 1.0, f, &stats);
    for (int threads = 1; threads <= 2; ++threads) {
      piola_set_thread_count(threads);
      double times[64], cpu[64];
      int n = repeats < 64 ? repeats : 64;
      piola_elastic_body_update(body, x, 1.0, f, NULL); /* warm up */
      for (int r = 0; r < n; ++r) {
        double t0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
        piola_elastic_body_update(body, x, 1.0, f, NULL);
        times[r] = bench_wall_seconds() - t0;
        cpu[r] = (bench_cpu_seconds() - c0) / threads;
      }
      double t = bench_median(times, n), c = bench_median(cpu, n);
      printf("| %-14s | %-14s | %7d | %5.2f%% | %d | %8.3f | %7.2f | %7.2f |\n", name,
             piola_material_model_name(models[m]), (int)mesh->tet_count,
             100.0 * stats.inverted_count / mesh->tet_count, threads, 1e3 * t,
             mesh->tet_count / t * 1e-6, mesh->tet_count / c * 1e-6);
    }
    /* the scalar reference loop (public piola_diagonalize3 + piola_material_stress per tet,
     * serial), for a speedup that does not depend on how loaded the machine is */
    {
      double times[64], cpu[64];
      int n = repeats < 64 ? repeats : 64;
      for (int r = 0; r < n; ++r) {
        double t0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
        piola__elastic_body_update_reference(body, x, 1.0, f, NULL);
        times[r] = bench_wall_seconds() - t0;
        cpu[r] = bench_cpu_seconds() - c0;
      }
      double t = bench_median(times, n), c = bench_median(cpu, n);
      printf("| %-14s | %-14s | %7d |        | 1 | %8.3f | %7.2f | %7.2f | (scalar reference)\n",
             name, piola_material_model_name(models[m]), (int)mesh->tet_count, 1e3 * t,
             mesh->tet_count / t * 1e-6, mesh->tet_count / c * 1e-6);
    }
    /* damping, 2 threads */
    double times[64];
    int n = repeats < 64 ? repeats : 64;
    for (int r = 0; r < n; ++r) {
      double t0 = bench_wall_seconds();
      piola_elastic_body_damping_forces(body, x, 1.0, 0.5, f);
      times[r] = bench_wall_seconds() - t0;
    }
    if (m == 0)
      printf("| %-14s | damping        | %7d |        | 2 | %8.3f | %7.2f |         |\n", name,
             (int)mesh->tet_count, 1e3 * bench_median(times, n), mesh->tet_count / bench_median(times, n) * 1e-6);
    piola_set_thread_count(0);
    free(x);
    free(f);
    piola_elastic_body_destroy(body);
  }
}

static void bench_svd(int repeats) {
  int n = 1 << 16;
  double *f = malloc(sizeof(double) * 9 * (size_t)n), *u = malloc(sizeof(double) * 9 * (size_t)n);
  double *v = malloc(sizeof(double) * 9 * (size_t)n), *s = malloc(sizeof(double) * 3 * (size_t)n);
  for (int i = 0; i < 9 * n; ++i) f[i] = (i % 4 == 0 ? 1.0 : 0.0) + bench_uniform(-0.3, 0.3);
  double times[64], cpu[64];
  int r_count = repeats < 64 ? repeats : 64;
  for (int r = 0; r < r_count; ++r) {
    double t0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
    piola__svd3_kernel_batch(n, f, u, s, v);
    times[r] = bench_wall_seconds() - t0;
    cpu[r] = bench_cpu_seconds() - c0;
  }
  printf("\nvectorized SVD kernel (8 lanes, %d sweeps), 1 thread: %.1f ns/matrix wall, %.1f ns/matrix "
         "CPU time (medians of %d; includes the AoS<->SoA copies of the batch)\n",
         PIOLA_SVD_JACOBI_SWEEPS, 1e9 * bench_median(times, r_count) / n, 1e9 * bench_median(cpu, r_count) / n,
         r_count);
  free(f);
  free(u);
  free(v);
  free(s);
}

int main(int argc, char **argv) {
  int repeats = argc > 1 ? atoi(argv[1]) : 7;
  if (repeats < 1) repeats = 1;
  printf("| mesh           | model          |    tets | inverted | threads | ms (wall) | M tets/s (wall) | M tets/s (CPU time) |\n");
  printf("|---|---|---|---|---|---|---|---|\n");
  piola_tet_mesh grid = grid_mesh(26, 0.01);
  bench_mesh("grid 26^3x6", &grid, repeats);
  free(grid.positions);
  free(grid.tets);
  piola_tet_mesh torus;
  if (piola_tet_mesh_read(PIOLA_DATA_DIR "/vega/torus-easy.veg", &torus) == PIOLA_OK) {
    bench_mesh("torus-easy.veg", &torus, repeats);
    piola_tet_mesh_free(&torus);
  } else {
    printf("torus-easy.veg: %s\n", piola_last_error());
  }
  bench_svd(repeats);
  return 0;
}
