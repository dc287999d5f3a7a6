/* What a freshly built elastic body costs before it runs at speed (BENCHMARKS.md, "Fracture"):
 * a cut rebuilds the whole body (piola__body_rebuild), and its first force update and damping
 * assembly then touch new memory.
 *
 *   build/<dir>/bench_fresh_body [cubes along x] [rounds] [--default-allocator]
 *
 * The body is the fracture benchmarks' grid (nx x nx/3 x nx/3 cubes, 6 tets each, 1 cm),
 * deformed a little. Each round creates it anew, then destroys the previous round's body (as a
 * rebuild builds the new body before it frees the old one), then updates its forces and
 * applies its damping twice (thread CPU time, 1 thread); per phase the median over the rounds
 * after the first is printed. With
 * `--default-allocator` the C library keeps its defaults; otherwise freed memory is kept as
 * `piola run` keeps it (src/cli/allocator_policy.h). */
#include <stdio.h>
#include <stdlib.h>

#include "piola/elastic_body.h"
#include "piola/material.h"
#include "piola/mesh.h"
#include "piola/threads.h"
#include "support/bench_fracture_body.h"
#include "support/bench_support.h"

enum { CREATE, FIRST_UPDATE, FIRST_DAMPING, UPDATE, DAMPING, PHASES };

int main(int argc, char **argv) {
  bench_allocator(&argc, argv);
  const int nx = argc > 1 ? atoi(argv[1]) : 30;
  const int rounds = argc > 2 ? atoi(argv[2]) : 7;
  if (nx < 3 || rounds < 2) {
    fprintf(stderr, "usage: bench_fresh_body [cubes along x >= 3] [rounds >= 2] [--default-allocator]\n");
    return 2;
  }
  piola_set_thread_count(1);
  piola_tet_mesh mesh;
  if (piola_tet_mesh_box_grid(nx, nx / 3, nx / 3, (piola_vec3){0.01, 0.01, 0.01}, &mesh) != PIOLA_OK) return 1;
  piola_material_def md = piola_default_material_def();
  piola_material material;
  if (piola_material_init(&md, &material) != PIOLA_OK) return 1;
  const int32_t n = mesh.vertex_count;
  double *x = malloc(3 * sizeof(double) * (size_t)n), *v = malloc(3 * sizeof(double) * (size_t)n);
  double *f = malloc(3 * sizeof(double) * (size_t)n);
  double *seconds = malloc(sizeof(double) * PHASES * (size_t)rounds);
  if (!x || !v || !f || !seconds) return 1;
  for (int32_t i = 0; i < 3 * n; ++i)
    x[i] = mesh.positions[i] * (1 + 0.01 * (i % 3)), v[i] = 0.01 * (i % 7);
  printf("grid %d x %d x %d cubes: %d tets, %d nodes, 1 thread, %d rounds\n", nx, nx / 3, nx / 3,
         (int)mesh.tet_count, (int)n, rounds);
  piola_elastic_body *previous = NULL;
  for (int r = 0; r < rounds; ++r) {
    piola_elastic_body_def def = piola_default_elastic_body_def();
    def.rest_mesh = &mesh, def.materials = &material, def.material_count = 1, def.density = 1000;
    piola_elastic_body *body = NULL;
    double t[PHASES + 1];
    t[0] = bench_thread_cpu_seconds();
    if (piola_elastic_body_create(&def, &body) != PIOLA_OK) {
      fprintf(stderr, "bench_fresh_body: %s\n", piola_last_error());
      return 1;
    }
    piola_elastic_body_destroy(previous);
    previous = body;
    t[1] = bench_thread_cpu_seconds();
    for (int phase = FIRST_UPDATE; phase < PHASES; ++phase) {
      if (phase == FIRST_UPDATE || phase == UPDATE) piola_elastic_body_update(body, x, 1, f, NULL);
      else piola_elastic_body_damping_forces(body, v, 1, phase == DAMPING ? 1.5 : 1, f);
      t[phase + 1] = bench_thread_cpu_seconds();
    }
    for (int phase = 0; phase < PHASES; ++phase) seconds[phase * rounds + r] = t[phase + 1] - t[phase];
  }
  piola_elastic_body_destroy(previous);
  static const char *names[PHASES] = {"create", "first force update", "first damping (assembly)",
                                      "second force update", "second damping (assembly)"};
  for (int phase = 0; phase < PHASES; ++phase)
    printf("%-26s %.2f ms (first round %.2f ms)\n", names[phase],
           1e3 * bench_median(seconds + phase * rounds + 1, rounds - 1), 1e3 * seconds[phase * rounds]);
  free(x), free(v), free(f), free(seconds), free(mesh.positions), free(mesh.tets);
  return 0;
}
