/* Cost of muscle fibres in the elastic force loop.
 *
 *   build/<dir>/bench_muscle [repeats]
 *
 * A structured grid of ~105K tets, muscle material, positions stretched 5% along x plus a
 * small random perturbation. Times piola_elastic_body_update (forces, no stats) on one
 * thread for: no fibres (the isotropic part alone, which is the neo-Hookean loop), random
 * per-tet fibres with activation 0.5, and the same with stats (fibre energy included).
 * Median of `repeats` (default 7) runs, wall and thread CPU time. */
#include <stdio.h>
#include <stdlib.h>

#include "piola/elastic_body.h"
#include "support/bench_support.h"

static void row(const char *label, piola_elastic_body *body, const double *x, double *f,
                int stats, int32_t tets, int repeats, double *cpu_out) {
  double wall[64], cpu[64];
  const int n = repeats < 64 ? repeats : 64;
  piola_elastic_stats st;
  piola_elastic_body_update(body, x, 1.0, f, stats ? &st : NULL); /* warm up */
  for (int r = 0; r < n; ++r) {
    const double t0 = bench_wall_seconds(), c0 = bench_thread_cpu_seconds();
    piola_elastic_body_update(body, x, 1.0, f, stats ? &st : NULL);
    wall[r] = bench_wall_seconds() - t0;
    cpu[r] = bench_thread_cpu_seconds() - c0;
  }
  const double w = bench_median(wall, n), c = bench_median(cpu, n);
  printf("| %-34s | %7d | %8.3f | %8.3f | %6.1f |\n", label, (int)tets, 1e3 * w, 1e3 * c,
         1e9 * c / tets);
  if (cpu_out) *cpu_out = c;
}

int main(int argc, char **argv) {
  const int repeats = argc > 1 ? atoi(argv[1]) : 7;
  piola_tet_mesh mesh;
  if (piola_tet_mesh_box_grid(26, 26, 26, (piola_vec3){0.01, 0.01, 0.01}, &mesh) != PIOLA_OK) {
    fprintf(stderr, "bench_muscle: %s\n", piola_last_error());
    return 1;
  }
  piola_set_thread_count(1);
  piola_material_def mdef = bench_rows_material_def(PIOLA_MODEL_MUSCLE);
  mdef.poisson_ratio = 0.45;
  piola_material material;
  if (piola_material_init(&mdef, &material) != PIOLA_OK) return 1;
  double *fibers = malloc(sizeof(double) * 3 * (size_t)mesh.tet_count);
  for (int32_t i = 0; i < 3 * mesh.tet_count; ++i) fibers[i] = bench_uniform(-1, 1) + (i % 3 == 0 ? 2 : 0);
  double *x = malloc(sizeof(double) * 3 * (size_t)mesh.vertex_count);
  double *f = malloc(sizeof(double) * 3 * (size_t)mesh.vertex_count);
  for (int32_t i = 0; i < 3 * mesh.vertex_count; ++i)
    x[i] = mesh.positions[i] * (i % 3 == 0 ? 1.05 : 1.0) + 1e-4 * bench_uniform(-1, 1);
  printf("| case (1 thread) | tets | wall ms | cpu ms | cpu ns/tet |\n|---|---|---|---|---|\n");
  piola_elastic_body_def def = piola_default_elastic_body_def();
  def.rest_mesh = &mesh;
  def.materials = &material;
  def.material_count = 1;
  piola_elastic_body *plain, *muscle;
  if (piola_elastic_body_create(&def, &plain) != PIOLA_OK) return 1;
  def.fiber_directions = fibers;
  if (piola_elastic_body_create(&def, &muscle) != PIOLA_OK) return 1;
  piola_elastic_body_set_activation(muscle, 0.5);
  double c0, c1;
  row("muscle, no fibres (isotropic only)", plain, x, f, 0, mesh.tet_count, repeats, &c0);
  row("muscle, fibres, activation 0.5", muscle, x, f, 0, mesh.tet_count, repeats, &c1);
  row("muscle, fibres, with stats (energy)", muscle, x, f, 1, mesh.tet_count, repeats, NULL);
  printf("fibre overhead (cpu): %.1f%%\n", 100 * (c1 / c0 - 1));
  piola_elastic_body_destroy(plain);
  piola_elastic_body_destroy(muscle);
  free(fibers);
  free(x);
  free(f);
  piola_tet_mesh_free(&mesh);
  return 0;
}
