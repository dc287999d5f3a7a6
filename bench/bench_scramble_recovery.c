/* How often a randomly scrambled body recovers, per model and inversion extension: the
 * measurements behind docs/materials.md "Tangled equilibria" and "Defaults that recover". Not
 * a timing benchmark: a robustness table, reproducible to the digit (fixed seeds, one thread).
 *
 * Protocol (tests/support/recovery_runs.c): the 3 x 3 x 3 grid of unit size (162 tets),
 * E = 10 kPa, nu = 0.3, 1000 kg/m^3 (models with their own moduli scaled to the same rest
 * shear modulus; fibres along x). Start: every node at a uniformly random point of the unit
 * cube, at rest. Then 12 s of elastic and damping forces (beta = 300, alpha = 100 Pa s), the
 * integrator and fixed step of tests/test_recovery.c (HGO: capped by half the state-aware
 * bound, see recovery_runs.h). Outcome per seed:
 *   recovered   max |fhat - 1| <= 1e-6 and nothing inverted (the test's criterion);
 *   slow        not within 1e-6 yet but the elastic energy is below 1e-3 J (on its way);
 *   stuck-model stuck with every Fhat entry at or above the threshold: an equilibrium of the
 *               constitutive model itself, which no inversion extension can change;
 *   stuck-ext   stuck with some entry below the threshold: the extension takes part;
 *   diverged    a position or force stopped being finite (the step was too long for
 *               the stiffness the body reached).
 *
 * usage: bench_scramble_recovery [seeds] [name]   (default 40; seeds 1..N; name keeps the rows
 *        of that model or inversion mode)
 *        bench_scramble_recovery seeds model mode|default threshold|default
 *                                one configuration ("default": the model's default) and the
 *                                seeds it does not recover, e.g. "... 160 ogden energy 0.5"
 *        bench_scramble_recovery seeds model mode threshold seconds high j_low j_high levels
 *                                the same, the threshold raised towards `high` as J falls
 *                                from j_high to j_low (recovery_threshold_by_volume: an
 *                                experiment, docs/materials.md "Defaults that recover") */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/bench_support.h"
#include "support/recovery_runs.h"
#include "piola/threads.h"

typedef struct outcome {
  int count[RECOVERY_RESULT_COUNT];
  int failed_count;
  int failed[1024]; /* the seeds not recovered (first 1024) */
} outcome;

static void run_config(const piola_tet_mesh *mesh, const piola_material_def *def, int first,
                       int seeds) {
  piola_material material;
  if (piola_material_init(def, &material) != PIOLA_OK) {
    fprintf(stderr, "bench_scramble_recovery: %s\n", piola_last_error());
    exit(1);
  }
  static outcome out;
  memset(&out, 0, sizeof out);
  const double t0 = bench_wall_seconds();
  for (int s = first; s <= seeds; ++s) {
    const recovery_result r = recovery_scramble_run(mesh, &material, s);
    ++out.count[r];
    if (r != RECOVERY_RECOVERED && out.failed_count < 1024) out.failed[out.failed_count++] = s;
  }
  printf("| %s | %s | %.2g | %d | %d | %d | %d | %d | %.1f |\n",
         piola_material_model_name(material.model), piola_inversion_mode_name(material.inversion_mode),
         material.threshold, out.count[RECOVERY_RECOVERED], out.count[RECOVERY_SLOW],
         out.count[RECOVERY_STUCK_MODEL], out.count[RECOVERY_STUCK_EXTENSION],
         out.count[RECOVERY_DIVERGED], bench_wall_seconds() - t0);
  printf("not recovered:");
  for (int k = 0; k < out.failed_count; ++k) printf(" %d", out.failed[k]);
  printf("\n");
  fflush(stdout);
}

int main(int argc, char **argv) {
  int first = 1, seeds = argc > 1 ? atoi(argv[1]) : 40;
  if (argc > 1 && strchr(argv[1], '-')) sscanf(argv[1], "%d-%d", &first, &seeds);
  if (first < 1) first = 1;
  if (seeds < first) seeds = first;
  piola_set_thread_count(1);
  piola_tet_mesh mesh;
  if (recovery_grid(&mesh) != 0) return 1;
  if (argc == 6 || argc == 10) recovery_scramble_seconds = atof(argv[5]);
  if (argc == 10)
    recovery_threshold_by_volume = (recovery_volume_threshold){atoi(argv[9]), atof(argv[6]),
                                                               atof(argv[7]), atof(argv[8])};
  printf("scrambled 3x3x3 grid (%d tets), seeds %d..%d, %g s each\n", (int)mesh.tet_count, first,
         seeds, recovery_scramble_seconds);
  printf("| model | extension | threshold | recovered | slow | stuck (model) | stuck (extension) | diverged | wall s |\n");
  printf("|---|---|---|---|---|---|---|---|---|\n");
  if (argc == 5 || argc == 6 || argc == 10) { /* one configuration from the command line */
    piola_material_model model;
    if (!piola_material_model_from_name(argv[2], &model)) {
      fprintf(stderr, "bench_scramble_recovery: unknown model '%s'\n", argv[2]);
      return 1;
    }
    piola_material_def def = recovery_material_def(model);
    if (strcmp(argv[3], "default") != 0 &&
        !piola_inversion_mode_from_name(argv[3], &def.inversion_mode)) {
      fprintf(stderr, "bench_scramble_recovery: unknown inversion mode '%s'\n", argv[3]);
      return 1;
    }
    if (strcmp(argv[4], "default") != 0) def.inversion_threshold = atof(argv[4]);
    run_config(&mesh, &def, first, seeds);
    piola_tet_mesh_free(&mesh);
    return 0;
  }
  typedef struct config {
    piola_material_model model;
    piola_inversion_mode mode;
    double threshold;
  } config;
  const config configs[] = {
      {PIOLA_MODEL_NEOHOOKEAN, PIOLA_INVERSION_LINEAR, 0.3},
      {PIOLA_MODEL_NEOHOOKEAN, PIOLA_INVERSION_CLAMP, 0.3},
      {PIOLA_MODEL_NEOHOOKEAN, PIOLA_INVERSION_LINEAR, 0.2},
      {PIOLA_MODEL_NEOHOOKEAN, PIOLA_INVERSION_LINEAR, 0.4},
      {PIOLA_MODEL_NEOHOOKEAN, PIOLA_INVERSION_LINEAR, 0.5},
      {PIOLA_MODEL_NEOHOOKEAN, PIOLA_INVERSION_CLAMP, 0.5},
      {PIOLA_MODEL_ROTATED_LINEAR, PIOLA_INVERSION_LINEAR, 0.3},
      {PIOLA_MODEL_ROTATED_LINEAR, PIOLA_INVERSION_CLAMP, 0.3},
      {PIOLA_MODEL_COROTATED, PIOLA_INVERSION_LINEAR, 0.3},
      {PIOLA_MODEL_COROTATED, PIOLA_INVERSION_CLAMP, 0.3},
      {PIOLA_MODEL_STVK, PIOLA_INVERSION_LINEAR, 0.3},
      {PIOLA_MODEL_STVK, PIOLA_INVERSION_CLAMP, 0.3},
      {PIOLA_MODEL_SPLINE, PIOLA_INVERSION_LINEAR, 0.3},
      {PIOLA_MODEL_SPLINE, PIOLA_INVERSION_CLAMP, 0.3},
      {PIOLA_MODEL_NEOHOOKEAN, PIOLA_INVERSION_ENERGY, 0.3},
      {PIOLA_MODEL_NEOHOOKEAN, PIOLA_INVERSION_ENERGY, 0.5},
      {PIOLA_MODEL_STABLE_NEOHOOKEAN, PIOLA_INVERSION_LINEAR, 0.3},
      {PIOLA_MODEL_STABLE_NEOHOOKEAN, PIOLA_INVERSION_CLAMP, 0.3},
      {PIOLA_MODEL_STABLE_NEOHOOKEAN, PIOLA_INVERSION_ENERGY, 0.3},
      {PIOLA_MODEL_ROTATED_LINEAR, PIOLA_INVERSION_ENERGY, 0.3},
      {PIOLA_MODEL_COROTATED, PIOLA_INVERSION_ENERGY, 0.3},
      {PIOLA_MODEL_STVK, PIOLA_INVERSION_ENERGY, 0.3},
      {PIOLA_MODEL_SPLINE, PIOLA_INVERSION_ENERGY, 0.3},
      {PIOLA_MODEL_HGO, PIOLA_INVERSION_LINEAR, 0.3}, /* measurable since its fibre stretch limit */
      {PIOLA_MODEL_HGO, PIOLA_INVERSION_CLAMP, 0.3},
  };
  /* An optional second argument keeps the rows whose model or inversion mode has that name. */
  const char *only = argc > 2 ? argv[2] : NULL;
  for (size_t k = 0; k < sizeof configs / sizeof configs[0]; ++k) {
    const config *c = &configs[k];
    if (only && strcmp(only, piola_material_model_name(c->model)) != 0 &&
        strcmp(only, piola_inversion_mode_name(c->mode)) != 0)
      continue;
    piola_material_def def = recovery_material_def(c->model);
    def.inversion_mode = c->mode;
    def.inversion_threshold = c->threshold;
    run_config(&mesh, &def, first, seeds);
  }
  piola_tet_mesh_free(&mesh);
  return 0;
}
