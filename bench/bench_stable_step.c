/* Cost of the state-aware step bound (src/force/stable_step.c) against the force loop it
 * must stay under 5% of (issue 21).
 *
 *   build/<dir>/bench_stable_step [repeats [model ...]]
 *
 * Vega's torus-easy.veg (97,878 tets) when the data folder is there, else a generated
 * 105,456-tet grid, deformed by a random stretch of up to 30% plus noise of 5% of an edge
 * (the same state for every model; PIOLA_BENCH_STATE=n draws the n-th other one), for the
 * models named (default: neohookean, corotated, stable_neohookean, ogden). Per model and thread
 * count (1, 2) the update (piola_elastic_body_update, forces only) and the bound pass are timed
 * interleaved, one of each per repeat; the medians (default 15 repeats) and their ratio are
 * printed. The bound reads the Fhat the update stored, so each pass follows an update as in a step,
 * and it finds the tet that sets the bound, as a step does (world_solids.c).
 * Medians of wall time and of process CPU time (the latter less disturbed on a loaded machine). A
 * second bound pass follows the first at once ("warm"): its Fhat and weights are then in cache, so
 * warm against cold tells whether the pass waits on memory or on its arithmetic. HGO also
 * runs with fibres (one direction, across hgo.axis), with the force loop's cache of their
 * term and without it (the term computed again tet by tet). The models whose force loop
 * forms the bound's k (stable_step_modulus.h: every model, HGO without fibres) run
 * one body two ways, with that cache and with it detached (the force loop forms no k, the pass
 * computes every one: the cost before the cache; one body, so that both read the same memory;
 * the Ogden models' per-tet cache of their parts is detached with it; the two swap places
 * every other repeat, so that each runs after the same work as often as the other: in a fixed
 * order HGO's update with k always followed its fibre bodies' heavy passes and read 8-15% for
 * neo-Hookean's arithmetic), and
 * a line "added" with what the bound adds to a step, the medians of (update with k + pass) /
 * (update without k) - 1 over the interleaved repeats, wall and process CPU.
 * PIOLA_BENCH_VARIANT=i (0: with the cache, 1: without) runs body i alone, for instruction
 * counts (valgrind --tool=callgrind; the inclusive counts of piola_elastic_body_update and of
 * the bound's piola__elastic_body_state_rate2 per call). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "force/elastic_body_internal.h"
#include "force/stable_step.h"
#include "piola/elastic_body.h"
#include "piola/mesh_io.h"
#include "support/bench_support.h"

/* A body of the mesh and material; HGO's second and third have fibres FIBERS (3 per tet;
 * NULL: none), with and without their cache. */
static piola_elastic_body *make_body(const piola_tet_mesh *mesh, const piola_material *material,
                                     const double *fibers) {
  piola_elastic_body *body = NULL;
  piola_elastic_body_def def = piola_default_elastic_body_def();
  def.rest_mesh = mesh;
  def.materials = material;
  def.material_count = 1;
  def.fiber_directions = fibers;
  if (piola_elastic_body_create(&def, &body) != PIOLA_OK) {
    fprintf(stderr, "bench_stable_step: %s\n", piola_last_error());
    exit(1);
  }
  return body;
}

static void bench_model(const char *name, const piola_tet_mesh *mesh, piola_material_model model,
                        int repeats) {
  piola_material_def md = bench_rows_material_def(model);
  piola_material material;
  if (piola_material_init(&md, &material) != PIOLA_OK) {
    fprintf(stderr, "bench_stable_step: %s\n", piola_last_error());
    exit(1);
  }
  enum { MAX_VARIANTS = 4 };
  piola_elastic_body *bodies[MAX_VARIANTS] = {make_body(mesh, &material, NULL), NULL, NULL, NULL};
  const char *labels[MAX_VARIANTS] = {"", "", "", ""};
  double *fibers = NULL;
  int variants = 1;
  /* the k cache's two variants are one body, its cache detached for the second: the same
   * memory, so that the difference is the cache's and not where each body's arrays lie */
  double *detached = NULL, *detached_ogden = NULL;
  if (bodies[0]->step_cache) {
    bodies[1] = bodies[0];
    detached = bodies[0]->step_cache;
    /* the Ogden models' per-tet cache goes too: an update without the bound writes neither */
    detached_ogden = bodies[0]->ogden_cache;
    labels[0] = " (k cache)", labels[1] = " (no k cache)", variants = 2;
  }
  if (model == PIOLA_MODEL_HGO) { /* the first two without fibres */
    fibers = malloc(sizeof(double) * 3 * (size_t)mesh->tet_count);
    for (int32_t e = 0; e < mesh->tet_count; ++e) fibers[3 * e] = 1.0, fibers[3 * e + 1] = 0.3, fibers[3 * e + 2] = 0.2;
    bodies[variants] = make_body(mesh, &material, fibers);
    bodies[variants + 1] = make_body(mesh, &material, fibers);
    free(bodies[variants + 1]->hgo_cache);
    bodies[variants + 1]->hgo_cache = NULL;
    labels[variants] = " fibres, cache", labels[variants + 1] = " fibres, none";
    variants += 2;
  }
  const char *only = getenv("PIOLA_BENCH_VARIANT");
  const int alone = only && *only ? atoi(only) : -1;
  const int32_t nv = mesh->vertex_count;
  double *x = malloc(sizeof(double) * 3 * (size_t)nv), *f = malloc(sizeof(double) * 3 * (size_t)nv);
  const char *state = getenv("PIOLA_BENCH_STATE");
  bench_seed(state && *state ? (uint64_t)strtoull(state, NULL, 10) : 0);
  double a[3] = {1 + bench_uniform(-0.3, 0.3), 1 + bench_uniform(-0.3, 0.3), 1 + bench_uniform(-0.3, 0.3)};
  const double noise = 0.05 * piola_elastic_body_min_rest_altitude(bodies[0]) * 3;
  for (int32_t i = 0; i < nv; ++i)
    for (int k = 0; k < 3; ++k) x[3 * i + k] = a[k] * mesh->positions[3 * i + k] + noise * bench_uniform(-1, 1);
  /* per variant: update wall, bound wall, update CPU, bound CPU, then the second bound pass
   * run at once after the first (its Fhat and weights warm in cache): wall, CPU */
  double *t[MAX_VARIANTS][6];
  for (int b = 0; b < MAX_VARIANTS; ++b)
    for (int k = 0; k < 6; ++k) t[b][k] = malloc(sizeof(double) * (size_t)repeats);
  for (int threads = 1; threads <= 2; ++threads) {
    piola_set_thread_count(threads);
    double sink = 0;
    for (int r = -1; r < repeats; ++r) /* r = -1 warms up (and builds the weights) */
      for (int i = 0; i < variants; ++i) {
        /* the pair swaps places every other repeat (the head of this file says why) */
        const int b = detached && i < 2 && (r & 1) ? 1 - i : i;
        if (alone >= 0 && b != alone) continue;
        if (detached) {
          bodies[0]->step_cache = b == 1 ? NULL : detached;
          bodies[0]->ogden_cache = b == 1 ? NULL : detached_ogden;
        }
        double c0 = bench_cpu_seconds(), t0 = bench_wall_seconds();
        piola_elastic_body_update(bodies[b], x, 1.0, f, NULL);
        double c1 = bench_cpu_seconds(), t1 = bench_wall_seconds();
        int32_t worst; /* asked for, as a step asks (world_solids.c: the small-step warning names it) */
        sink += piola__elastic_body_state_rate2(bodies[b], &worst);
        double c2 = bench_cpu_seconds(), t2 = bench_wall_seconds();
        sink += piola__elastic_body_state_rate2(bodies[b], &worst);
        double c3 = bench_cpu_seconds(), t3 = bench_wall_seconds();
        if (r >= 0) {
          t[b][0][r] = t1 - t0, t[b][1][r] = t2 - t1, t[b][2][r] = c1 - c0, t[b][3][r] = c2 - c1;
          t[b][4][r] = t3 - t2, t[b][5][r] = c3 - c2;
        }
      }
    /* per repeat, before the medians sort the timings: (update + pass with the cache) over
     * the update without it, wall then CPU */
    if (detached) bodies[0]->step_cache = detached, bodies[0]->ogden_cache = detached_ogden;
    double added_wall = 0, added_cpu = 0;
    if (bodies[0]->step_cache && alone < 0) {
      double added[2][repeats];
      for (int r = 0; r < repeats; ++r)
        for (int k = 0; k < 2; ++k)
          added[k][r] = (t[0][2 * k][r] + t[0][2 * k + 1][r]) / t[1][2 * k][r] - 1.0;
      added_wall = bench_median(added[0], repeats), added_cpu = bench_median(added[1], repeats);
    }
    for (int b = 0; b < variants; ++b) {
      if (alone >= 0 && b != alone) continue;
      double m[6];
      for (int k = 0; k < 6; ++k) m[k] = bench_median(t[b][k], repeats);
      printf("| %-16s | %-17s%s | %7d | %d | %8.3f | %8.3f | %5.1f%% | %5.1f%% | %8.3f | %5.1f%% | (%g)\n",
             name, piola_material_model_name(model), labels[b], (int)mesh->tet_count, threads,
             1e3 * m[0], 1e3 * m[1], 100 * m[1] / m[0], 100 * m[3] / m[2], 1e3 * m[4],
             100 * m[5] / m[2], sink > 0 ? 1.0 : 0.0);
    }
    if (bodies[0]->step_cache && alone < 0)
      printf("| %-16s | %-17s added | %7d | %d | added by the bound to the update without k: %5.1f%% (wall), %5.1f%% (process CPU) |\n",
             name, piola_material_model_name(model), (int)mesh->tet_count, threads, 100 * added_wall,
             100 * added_cpu);
  }
  piola_set_thread_count(0);
  for (int b = 0; b < MAX_VARIANTS; ++b)
    for (int k = 0; k < 6; ++k) free(t[b][k]);
  free(x), free(f), free(fibers);
  for (int b = 0; b < variants; ++b)
    if (b == 0 || bodies[b] != bodies[0]) piola_elastic_body_destroy(bodies[b]);
}

int main(int argc, char **argv) {
  int repeats = argc > 1 ? atoi(argv[1]) : 15;
  if (repeats < 1) repeats = 1;
  piola_tet_mesh mesh;
  const char *name = "torus-easy.veg";
  if (piola_tet_mesh_read(PIOLA_DATA_DIR "/vega/torus-easy.veg", &mesh) != PIOLA_OK) {
    name = "grid 26^3x6";
    if (piola_tet_mesh_box_grid(26, 26, 26, (piola_vec3){0.01, 0.01, 0.01}, &mesh) != PIOLA_OK) {
      fprintf(stderr, "bench_stable_step: %s\n", piola_last_error());
      return 1;
    }
  }
  printf("| mesh             | model             |    tets | threads | update ms | bound ms | bound/update (wall) | (process CPU) | warm bound ms | warm/update (CPU) |\n");
  static const char *const defaults[] = {"neohookean", "corotated", "stable_neohookean", "ogden"};
  const int named = argc > 2 ? argc - 2 : 4;
  for (int k = 0; k < named; ++k) {
    const char *model_name = argc > 2 ? argv[2 + k] : defaults[k];
    piola_material_model model;
    if (!piola_material_model_from_name(model_name, &model)) {
      fprintf(stderr, "bench_stable_step: unknown model \"%s\"\n", model_name);
      return 1;
    }
    bench_model(name, &mesh, model, repeats);
  }
  piola_tet_mesh_free(&mesh);
  return 0;
}
