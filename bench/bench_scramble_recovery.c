/* How often a randomly scrambled body recovers, per model and inversion extension: the
 * measurements behind docs/materials.md "Tangled equilibria". Not a timing benchmark: a
 * robustness table, reproducible to the digit (fixed seeds, one thread).
 *
 * Body: the 3 x 3 x 3 grid of unit size (162 tets), E = 10 kPa, nu = 0.3, 1000 kg/m^3. Start:
 * every node at a uniformly random point of the unit cube, at rest. Then 12 s of elastic and
 * damping forces (beta = 300, alpha = 100 Pa s), the integrator and step of
 * tests/test_recovery.c. Outcome per seed:
 *   recovered   max |fhat - 1| <= 1e-6 and nothing inverted (the test's criterion);
 *   slow        not within 1e-6 yet but the elastic energy is below 1e-3 J (on its way);
 *   stuck-model stuck with every Fhat entry at or above the threshold: an equilibrium of the
 *               constitutive model itself, which no inversion extension can change;
 *   stuck-ext   stuck with some entry below the threshold: the extension takes part.
 *
 * usage: bench_scramble_recovery [seeds] [name]   (default 40; seeds 1..N; name keeps the rows
 *        of that model or inversion mode) */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <stdlib.h>

#include "support/bench_support.h"
#include "piola/elastic_body.h"
#include "piola/material.h"
#include "piola/mesh.h"
#include "piola/threads.h"

typedef struct outcome {
  int recovered, slow, stuck_model, stuck_extension;
} outcome;

static uint64_t xorshift(uint64_t *s) {
  uint64_t x = *s;
  x ^= x << 13;
  x ^= x >> 7;
  x ^= x << 17;
  return *s = x;
}

static outcome run_config(const piola_tet_mesh *mesh, piola_material_model model,
                          piola_inversion_mode mode, double threshold, int seeds) {
  outcome out = {0, 0, 0, 0};
  piola_material_def def = piola_default_material_def();
  def.model = model;
  def.youngs_modulus = 1e4;
  def.poisson_ratio = 0.3;
  def.inversion_mode = mode;
  def.inversion_threshold = threshold;
  piola_material material;
  piola_elastic_body_def bd = piola_default_elastic_body_def();
  bd.rest_mesh = mesh;
  bd.materials = &material;
  bd.material_count = 1;
  bd.density = 1000;
  piola_elastic_body *body = NULL;
  if (piola_material_init(&def, &material) != PIOLA_OK ||
      piola_elastic_body_create(&bd, &body) != PIOLA_OK) {
    fprintf(stderr, "bench_scramble_recovery: %s\n", piola_last_error());
    exit(1);
  }
  const int32_t nv = piola_elastic_body_vertex_count(body), nt = piola_elastic_body_tet_count(body);
  const double *mass = piola_elastic_body_masses(body);
  const double beta = 300.0, alpha = 100.0, h = piola_elastic_body_min_rest_altitude(body);
  const double dt = fmin(0.5 * h / (piola_elastic_body_max_wave_speed(body) * sqrt(12.0)),
                         0.25 * 1000.0 * h * h / (beta + alpha));
  const int steps = (int)(12.0 / dt);
  double *x = malloc(sizeof(double) * 3 * (size_t)nv), *v = malloc(sizeof(double) * 3 * (size_t)nv);
  double *fe = malloc(sizeof(double) * 3 * (size_t)nv), *fd = malloc(sizeof(double) * 3 * (size_t)nv);
  if (!x || !v || !fe || !fd) exit(1);
  for (int s = 1; s <= seeds; ++s) {
    uint64_t state = 0x9E3779B97F4A7C15ull * (uint64_t)(s + 1);
    for (int k = 0; k < 10; ++k) xorshift(&state);
    for (int32_t i = 0; i < 3 * nv; ++i) {
      x[i] = (double)(xorshift(&state) >> 11) * (1.0 / 9007199254740992.0);
      v[i] = 0.0;
    }
    for (int k = 0; k < steps; ++k) {
      piola_elastic_body_update(body, x, 1.0, fe, NULL);
      piola_elastic_body_damping_forces(body, v, beta, alpha, fd);
      for (int32_t i = 0; i < 3 * nv; ++i) {
        v[i] += dt * (fe[i] + fd[i]) / mass[i / 3];
        x[i] += dt * v[i];
      }
    }
    piola_elastic_stats stats;
    piola_elastic_body_update(body, x, 1.0, fe, &stats);
    const double *fhat = piola_elastic_body_fhat(body);
    double worst = 0.0, smallest = INFINITY;
    for (int32_t t = 0; t < 3 * nt; ++t) {
      worst = fmax(worst, fabs(fhat[t] - 1.0));
      smallest = fmin(smallest, fhat[t]);
    }
    if (worst <= 1e-6 && stats.inverted_count == 0) ++out.recovered;
    else if (stats.elastic_energy < 1e-3) ++out.slow;
    else if (smallest >= threshold) ++out.stuck_model;
    else ++out.stuck_extension;
  }
  free(x);
  free(v);
  free(fe);
  free(fd);
  piola_elastic_body_destroy(body);
  return out;
}

int main(int argc, char **argv) {
  int seeds = argc > 1 ? atoi(argv[1]) : 40;
  if (seeds < 1) seeds = 1;
  piola_set_thread_count(1);
  piola_tet_mesh mesh;
  if (piola_tet_mesh_box_grid(3, 3, 3, (piola_vec3){1.0 / 3, 1.0 / 3, 1.0 / 3}, &mesh) != PIOLA_OK)
    return 1;
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
  };
  /* An optional second argument keeps the rows whose model or inversion mode has that name. */
  const char *only = argc > 2 ? argv[2] : NULL;
  printf("scrambled 3x3x3 grid (%d tets), seeds 1..%d, 12 s each\n", (int)mesh.tet_count, seeds);
  printf("| model | extension | threshold | recovered | slow | stuck (model) | stuck (extension) | wall s |\n");
  printf("|---|---|---|---|---|---|---|---|\n");
  for (size_t k = 0; k < sizeof configs / sizeof configs[0]; ++k) {
    const config *c = &configs[k];
    if (only && strcmp(only, piola_material_model_name(c->model)) != 0 &&
        strcmp(only, piola_inversion_mode_name(c->mode)) != 0)
      continue;
    double t0 = bench_wall_seconds();
    outcome o = run_config(&mesh, c->model, c->mode, c->threshold, seeds);
    printf("| %s | %s | %.1f | %d | %d | %d | %d | %.1f |\n", piola_material_model_name(c->model),
           piola_inversion_mode_name(c->mode), c->threshold, o.recovered, o.slow, o.stuck_model,
           o.stuck_extension, bench_wall_seconds() - t0);
    fflush(stdout);
  }
  piola_tet_mesh_free(&mesh);
  return 0;
}
