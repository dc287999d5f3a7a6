/* Benchmark of the damping operator, the kernel that each conjugate-gradient iteration of the
 * implicit step applies (a dozen or more times per elastic update), and of its assembly.
 *
 *   build/<dir>/bench_damping [repeats] [mesh]
 *
 * Mesh: Vega's torus-easy.veg (97,878 tets) unless another is given. The body is updated at
 * its rest positions plus a random perturbation of 2% of the mean edge length (a busy,
 * rotated-frame state), then, for 1 and 2 threads, each repeat updates once more and times
 * the first damping call after it (which assembles the damping matrix: "first") and then 20
 * applies ("apply", per call). Reports medians over `repeats` (default 7) of wall time and
 * of process CPU time (all threads together), and the least CPU time per apply seen: on a
 * loaded machine wall time mostly measures the other processes, and even CPU time grows
 * when another process shares the core's caches and memory bandwidth. For instruction counts, which do not depend on the load, run one
 * repeat under valgrind --tool=callgrind --toggle-collect=piola_elastic_body_damping_forces
 * (see docs/bench-notes/damping.md). Uses only the public API, so older versions build it. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "piola/elastic_body.h"
#include "piola/mesh_io.h"
#include "support/bench_support.h"

int main(int argc, char **argv) {
  int repeats = argc > 1 ? atoi(argv[1]) : 7;
  if (repeats < 1) repeats = 1;
  const char *path = argc > 2 ? argv[2] : PIOLA_DATA_DIR "/vega/torus-easy.veg";
  piola_tet_mesh mesh;
  if (piola_tet_mesh_read(path, &mesh) != PIOLA_OK) {
    fprintf(stderr, "bench_damping: %s\n", piola_last_error());
    return 1;
  }
  piola_material_def mdef = bench_rows_material_def(PIOLA_MODEL_NEOHOOKEAN);
  piola_material material;
  piola_elastic_body_def def = piola_default_elastic_body_def();
  def.rest_mesh = &mesh;
  def.materials = &material;
  def.material_count = 1;
  piola_elastic_body *body = NULL;
  if (piola_material_init(&mdef, &material) != PIOLA_OK || piola_elastic_body_create(&def, &body) != PIOLA_OK) {
    fprintf(stderr, "bench_damping: %s\n", piola_last_error());
    return 1;
  }
  int32_t nv = mesh.vertex_count, n = 3 * nv;
  double edge = 0;
  for (int32_t t = 0; t < mesh.tet_count; ++t) {
    const int32_t *tet = mesh.tets + 4 * t;
    double e2 = 0;
    for (int k = 0; k < 3; ++k) {
      double dk = mesh.positions[3 * tet[1] + k] - mesh.positions[3 * tet[0] + k];
      e2 += dk * dk;
    }
    edge += sqrt(e2);
  }
  edge /= mesh.tet_count;
  double *x = malloc(sizeof(double) * (size_t)n), *v = malloc(sizeof(double) * (size_t)n);
  double *f = malloc(sizeof(double) * (size_t)n);
  for (int32_t i = 0; i < n; ++i) {
    x[i] = mesh.positions[i] + 0.02 * edge * bench_uniform(-1, 1);
    v[i] = bench_uniform(-1, 1);
  }
  printf("bench_damping: %s, %d vertices, %d tets\n", path, (int)nv, (int)mesh.tet_count);
  printf("%8s %14s %14s %14s %16s %16s\n", "threads", "ms/apply", "CPU ms/apply", "min CPU ms",
         "ms/first call", "CPU ms/first");
  const int applies = 20;
  double *wall = malloc(sizeof(double) * (size_t)repeats), *cpu = malloc(sizeof(double) * (size_t)repeats);
  double *wall1 = malloc(sizeof(double) * (size_t)repeats), *cpu1 = malloc(sizeof(double) * (size_t)repeats);
  for (int threads = 1; threads <= 2; ++threads) {
    piola_set_thread_count(threads);
    for (int r = 0; r < repeats; ++r) {
      if (piola_elastic_body_update(body, x, 1.0, f, NULL) != PIOLA_OK) {
        fprintf(stderr, "bench_damping: %s\n", piola_last_error());
        return 1;
      }
      double w0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
      piola_elastic_body_damping_forces(body, v, 1.0, 0.5, f);
      wall1[r] = bench_wall_seconds() - w0;
      cpu1[r] = bench_cpu_seconds() - c0;
      w0 = bench_wall_seconds();
      c0 = bench_cpu_seconds();
      for (int k = 0; k < applies; ++k) piola_elastic_body_damping_forces(body, v, 1.0, 0.5, f);
      wall[r] = (bench_wall_seconds() - w0) / applies;
      cpu[r] = (bench_cpu_seconds() - c0) / applies;
    }
    double cpu_median = bench_median(cpu, repeats); /* sorts cpu: cpu[0] is the least */
    printf("%8d %14.3f %14.3f %14.3f %16.3f %16.3f\n", threads, 1e3 * bench_median(wall, repeats),
           1e3 * cpu_median, 1e3 * cpu[0], 1e3 * bench_median(wall1, repeats), 1e3 * bench_median(cpu1, repeats));
  }
  piola_set_thread_count(0);
  free(wall);
  free(cpu);
  free(wall1);
  free(cpu1);
  free(x);
  free(v);
  free(f);
  piola_elastic_body_destroy(body);
  piola_tet_mesh_free(&mesh);
  return 0;
}
