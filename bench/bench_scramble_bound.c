/* How tight the state-aware step bound is on a scrambled real mesh: at a few times of the run
 * of tests/test_scrambles_every_model.c (the mesh scaled to a 2 m diagonal, E = 20 kPa,
 * nu = 0.3, 1000 kg/m^3, 1000 Pa s, no gravity, one thread), the bound's step dt (cfl as the
 * world's, default 0.5) against the linearized stability limit 2 / omega_max of the frozen
 * state, omega_max^2 the largest eigenvalue of M^-1 K by power iteration (K u by central
 * differences of the elastic force; damping left out: it only lowers the growth). The ratio
 * (2 / omega_max) / dt is the factor a step could grow and stay stable: 2 / cfl = 4 for an
 * exact bound at the default cfl. docs/time-stepping.md, "What the test affords".
 * Not a timing benchmark.
 *
 * usage: bench_scramble_bound mesh model radius_m t1 [t2 ...]   (mesh relative to ../shared/data) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "piola/elastic_body.h"
#include "piola/threads.h"
#include "piola/world.h"
#include "support/bench_scenes.h"
#include "support/stability_rate.h"

/* largest eigenvalue of M^-1 K at x (largest_stability_rate2: 4000 power iterations from
 * uniform draws of rand(), seed 7); leaves the body updated at x, the state as the run left it */
static double largest_rate2(piola_elastic_body *body, const double *x) {
  const int32_t n = 3 * piola_elastic_body_vertex_count(body);
  const double *mass = piola_elastic_body_masses(body);
  double *u = malloc(sizeof *u * (size_t)n);
  srand(7);
  for (int32_t j = 0; j < n; ++j) u[j] = mass[j / 3] > 0 ? (double)rand() / RAND_MAX - 0.5 : 0;
  double lambda = 0;
  (void)largest_stability_rate2(body, x, u, 4000, &lambda); /* a failed update shows as a wild rate */
  free(u);
  return lambda;
}

int main(int argc, char **argv) {
  if (argc < 5) {
    fprintf(stderr, "usage: bench_scramble_bound mesh model radius_m t1 [t2 ...]\n");
    return 2;
  }
  piola_set_thread_count(1);
  piola_material_model model;
  if (!piola_material_model_from_name(argv[2], &model)) {
    fprintf(stderr, "bench_scramble_bound: unknown model '%s'\n", argv[2]);
    return 1;
  }
  piola_tet_mesh mesh;
  if (bench_read_mesh_with_diagonal(argv[1], 2.0, &mesh) != 0) {
    fprintf(stderr, "bench_scramble_bound: %s: %s\n", argv[1], piola_last_error());
    return 1;
  }
  piola_world_def wd = piola_default_world_def();
  for (int i = 0; i < 3; ++i) wd.gravity[i] = piola_track_constant(0);
  piola_world *w = NULL;
  if (piola_world_create(&wd, &w) != PIOLA_OK) {
    fprintf(stderr, "bench_scramble_bound: %s\n", piola_last_error());
    return 1;
  }
  piola_solid_def sd = bench_scramble_solid_def(&mesh, model, atof(argv[3]));
  if (piola_world_add_solid(w, &sd, NULL) != PIOLA_OK) {
    fprintf(stderr, "bench_scramble_bound: %s\n", piola_last_error());
    return 1;
  }
  printf("| t s | steps | bound dt s | 2 / omega_max s | ratio | inverted |\n|---|---|---|---|---|---|\n");
  long steps = 0;
  for (int k = 4; k < argc; ++k) {
    piola_step_stats st = {0};
    if (piola_world_advance_to(w, atof(argv[k]), &st) != PIOLA_OK) {
      printf("failed: %s\n", piola_last_error());
      break;
    }
    steps += st.substeps;
    const double dt = piola_world_stable_dt(w);
    piola_elastic_body *body = (piola_elastic_body *)piola_world_solid_body(w, 0);
    const double limit = 2 / sqrt(largest_rate2(body, piola_world_solid_positions(w, 0)));
    printf("| %g | %ld | %.3g | %.3g | %.1f | %d |\n", atof(argv[k]), steps, dt, limit, limit / dt,
           (int)piola_world_solid_stats(w, 0).inverted_count);
    fflush(stdout);
  }
  piola_world_destroy(w);
  piola_tet_mesh_free(&mesh);
  return 0;
}
