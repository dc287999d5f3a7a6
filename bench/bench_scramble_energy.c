/* Total energy (kinetic + elastic) of a scrambled real mesh under piola's own explicit
 * integrator, at ten times over a run: where a scramble gains energy, and whether the gain
 * follows the step size (an unstable step) or not (work of a stress extension without a
 * potential). docs/time-stepping.md "What the test affords" has the measurements. Not a
 * timing benchmark (the CPU time is printed for planning only).
 *
 * The body of tests/test_scrambles_every_model.c: the mesh scaled to a 2 m bounding-box
 * diagonal, E = 20 kPa, nu = 0.3, 1000 kg/m^3, shear and bulk viscosity 1000 Pa s, no gravity,
 * one thread.
 *
 * usage: bench_scramble_energy mesh model radius_m seconds [mode|default [threshold|default [cfl]]]
 *        (mesh relative to ../shared/data) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "piola/threads.h"
#include "piola/world.h"
#include "support/bench_scenes.h"

int main(int argc, char **argv) {
  if (argc < 5) {
    fprintf(stderr, "usage: bench_scramble_energy mesh model radius_m seconds [mode|default [threshold|default [cfl]]]\n");
    return 2;
  }
  piola_set_thread_count(1);
  piola_material_model model;
  if (!piola_material_model_from_name(argv[2], &model)) {
    fprintf(stderr, "bench_scramble_energy: unknown model '%s'\n", argv[2]);
    return 1;
  }
  const double radius = atof(argv[3]), seconds = atof(argv[4]);
  piola_tet_mesh mesh;
  if (bench_read_mesh_with_diagonal(argv[1], 2.0, &mesh) != 0) {
    fprintf(stderr, "bench_scramble_energy: %s: %s\n", argv[1], piola_last_error());
    return 1;
  }
  piola_world_def wd = piola_default_world_def();
  for (int i = 0; i < 3; ++i) wd.gravity[i] = piola_track_constant(0);
  if (argc > 7) wd.cfl = atof(argv[7]);
  piola_world *w = NULL;
  if (piola_world_create(&wd, &w) != PIOLA_OK) {
    fprintf(stderr, "bench_scramble_energy: %s\n", piola_last_error());
    return 1;
  }
  piola_solid_def sd = bench_scramble_solid_def(&mesh, model, radius);
  if (argc > 5 && strcmp(argv[5], "default") && !piola_inversion_mode_from_name(argv[5], &sd.material.inversion_mode)) {
    fprintf(stderr, "bench_scramble_energy: unknown inversion mode '%s'\n", argv[5]);
    return 1;
  }
  if (argc > 6 && strcmp(argv[6], "default")) sd.material.inversion_threshold = atof(argv[6]);
  if (piola_world_add_solid(w, &sd, NULL) != PIOLA_OK) {
    fprintf(stderr, "bench_scramble_energy: %s\n", piola_last_error());
    return 1;
  }
  const piola_solid_stats s0 = piola_world_solid_stats(w, 0);
  printf("| t s | steps | energy redos | last dt s | kinetic J | elastic J | total J | inverted | CPU s |\n");
  printf("|---|---|---|---|---|---|---|---|---|\n");
  printf("| 0 | 0 | 0 | | %.4g | %.4g | %.4g | %d | 0 |\n", s0.kinetic_energy, s0.elastic_energy,
         s0.kinetic_energy + s0.elastic_energy, (int)s0.inverted_count);
  long steps = 0, redos = 0;
  const clock_t c0 = clock();
  for (int k = 1; k <= 10; ++k) {
    piola_step_stats st = {0};
    const piola_status status = piola_world_advance_to(w, seconds * k / 10, &st);
    steps += st.substeps, redos += st.energy_redos;
    if (status != PIOLA_OK) {
      printf("failed: %s\n", piola_last_error());
      break;
    }
    const piola_solid_stats s = piola_world_solid_stats(w, 0);
    printf("| %.3g | %ld | %ld | %.3g | %.4g | %.4g | %.4g | %d | %.1f |\n", seconds * k / 10, steps, redos,
           st.last_dt, s.kinetic_energy, s.elastic_energy, s.kinetic_energy + s.elastic_energy,
           (int)s.inverted_count, (double)(clock() - c0) / CLOCKS_PER_SEC);
    fflush(stdout);
  }
  piola_world_destroy(w);
  piola_tet_mesh_free(&mesh);
  return 0;
}
