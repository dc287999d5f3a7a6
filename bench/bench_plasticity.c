/* Benchmark: the cost of a plastic update next to the cost of a force evaluation.
 *
 *   build/<dir>/bench_plasticity [repeats]
 *
 * Mesh: Vega's torus-easy.veg (97,878 tets), neo-Hookean. Scenarios, each timed as the bench_median
 * of `repeats` (default 7) runs with 1 and 2 threads, as CPU time / threads (the machine is
 * shared; see docs/bench-notes/plasticity.md):
 *   quiet    small random motion (1% of an edge): almost no tet yields; the common step.
 *   flowing  a 30% stretch plus noise on a fresh state: every tet yields (return mapping,
 *            new Fp^-1, cheap limit bounds, new effective Dm^-1).
 *   limited  a 4x stretch on a fresh state: every tet yields and hits the limit (exact SVD
 *            and clamp): the worst case, met only while Fp saturates.
 *   control  "flowing" with control toward a goal map (two eigen-decompositions per tet).
 * The force evaluation is piola_elastic_body_update at the same positions, no stats. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "piola/elastic_body.h"
#include "piola/mesh_io.h"
#include "piola/plasticity.h"
#include "support/bench_support.h"

enum { QUIET, FLOWING, LIMITED, CONTROL, SCENARIO_COUNT };
static const char *const names[] = {"quiet", "flowing", "limited", "control"};

static void positions(const piola_elastic_body *body, int scenario, double *x) {
  int32_t nv = piola_elastic_body_vertex_count(body);
  const double *rest = piola_elastic_body_rest_positions(body);
  double stretch = scenario == QUIET ? 1.0 : (scenario == LIMITED ? 4.0 : 1.3);
  for (int32_t i = 0; i < nv; ++i) {
    x[3 * i] = stretch * rest[3 * i] + 0.002 * bench_uniform(-1, 1);
    x[3 * i + 1] = rest[3 * i + 1] + 0.002 * bench_uniform(-1, 1);
    x[3 * i + 2] = rest[3 * i + 2] + 0.002 * bench_uniform(-1, 1);
  }
}

int main(int argc, char **argv) {
  int repeats = argc > 1 ? atoi(argv[1]) : 7;
  if (repeats < 1) repeats = 1;
  const char *path = PIOLA_DATA_DIR "/vega/torus-easy.veg";
  piola_tet_mesh mesh;
  if (piola_tet_mesh_read(path, &mesh) != PIOLA_OK) {
    fprintf(stderr, "bench_plasticity: %s\n", piola_last_error());
    return 1;
  }
  piola_material_def mdef = bench_rows_material_def(PIOLA_MODEL_NEOHOOKEAN);
  piola_material mat;
  piola_material_init(&mdef, &mat);
  piola_elastic_body_def bdef = piola_default_elastic_body_def();
  bdef.rest_mesh = &mesh;
  bdef.materials = &mat;
  bdef.material_count = 1;
  piola_elastic_body *body;
  if (piola_elastic_body_create(&bdef, &body) != PIOLA_OK) {
    fprintf(stderr, "bench_plasticity: %s\n", piola_last_error());
    return 1;
  }
  int32_t nv = piola_elastic_body_vertex_count(body), nt = piola_elastic_body_tet_count(body);
  double *x = malloc(sizeof(double) * 3 * (size_t)nv), *f = malloc(sizeof(double) * 3 * (size_t)nv);
  double *force_t = malloc(sizeof(double) * (size_t)repeats), *plastic_t = malloc(sizeof(double) * (size_t)repeats);
  printf("torus-easy.veg: %d tets; bench_median of %d, CPU time / threads\n", (int)nt, repeats);
  printf("%-8s %7s %12s %12s %9s %8s %8s\n", "scenario", "threads", "force (ms)", "plastic (ms)", "ratio", "yielded", "limited");
  for (int threads = 1; threads <= 2; ++threads) {
    piola_set_thread_count(threads);
    for (int sc = 0; sc < SCENARIO_COUNT; ++sc) {
      piola_plasticity_def def = piola_default_plasticity_def();
      def.yield = 0.05;
      def.limit = 1.0;
      if (sc == CONTROL) {
        def.control.goal = PIOLA_PLASTIC_GOAL_MAP;
        def.control.goal_map = (piola_mat3){{{1.5, 0, 0}, {0, 1.5, 0}, {0, 0, 0.4}}};
      }
      positions(body, sc, x);
      piola_plastic_stats st = {0, 0, 1};
      for (int r = 0; r < repeats; ++r) {
        piola_plastic_state *p;
        if (piola_plastic_state_create(body, &def, &p) != PIOLA_OK) {
          fprintf(stderr, "bench_plasticity: %s\n", piola_last_error());
          return 1;
        }
        double c0 = bench_cpu_seconds();
        piola_elastic_body_update(body, x, 1.0, f, NULL);
        double c1 = bench_cpu_seconds();
        piola_plastic_state_update(p, 1e-3, &st);
        double c2 = bench_cpu_seconds();
        force_t[r] = (c1 - c0) / threads;
        plastic_t[r] = (c2 - c1) / threads;
        piola_plastic_state_destroy(p);
      }
      double fm = bench_median(force_t, repeats), pm = bench_median(plastic_t, repeats);
      printf("%-8s %7d %12.2f %12.2f %8.1f%% %8d %8d\n", names[sc], threads, 1e3 * fm, 1e3 * pm, 100 * pm / fm,
             (int)st.yielded_count, (int)st.limited_count);
    }
  }
  free(x), free(f), free(force_t), free(plastic_t);
  piola_elastic_body_destroy(body);
  piola_tet_mesh_free(&mesh);
  return 0;
}
