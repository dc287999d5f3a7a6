/* How long recovery takes with piola's own integrator: the measurements behind
 * docs/time-stepping.md "Recovery". Not a timing benchmark: a table of settling times.
 *
 *   bench_recovery_time MESH MODEL START E VISCOSITY [SECONDS] [DENSITY] [INTEGRATOR] [DIAGONAL]
 *
 * MESH a tet mesh file; MODEL a model name (corotated, neohookean, ...); START one of point,
 * line, plane, mirror or scramble:R (R in multiples of the bounding-box diagonal); E Young's
 * modulus (Pa, nu = 0.3); VISCOSITY the shear and bulk viscosity (Pa s); SECONDS of
 * simulated time (default 5); DENSITY kg/m^3 (default 1000); INTEGRATOR newmark (default)
 * or backward_euler (at its default step); DIAGONAL m: the mesh is scaled about its box's
 * centre to that bounding-box diagonal (default: as read). Zero gravity. Prints every 0.1 s the shape error (largest distance of a vertex from the rest
 * shape after the best rigid motion, Procrustes, in % of the diagonal), the kinetic and
 * elastic energy (J), the inverted tets and the steps, then the first times the shape error
 * fell below 10% and 1% and stayed there, next to the settling time piola_settling_time
 * predicts for 1% from the initial shape error (piola/settling.h: the lowest vibration mode
 * of this mesh at rest and its damping). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/diagonalize.h"
#include "piola/mesh_io.h"
#include "piola/settling.h"
#include "piola/threads.h"
#include "piola/world.h"

static double shape_error(const double *x, const double *rest, const double *mass, int32_t nv) {
  double cx[3] = {0}, cr[3] = {0}, mt = 0;
  for (int32_t v = 0; v < nv; ++v) {
    mt += mass[v];
    for (int i = 0; i < 3; ++i) cx[i] += mass[v] * x[3 * v + i], cr[i] += mass[v] * rest[3 * v + i];
  }
  for (int i = 0; i < 3; ++i) cx[i] /= mt, cr[i] /= mt;
  piola_mat3 h, u, w;
  memset(&h, 0, sizeof h);
  for (int32_t v = 0; v < nv; ++v)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) h.m[i][j] += mass[v] * (rest[3 * v + i] - cr[i]) * (x[3 * v + j] - cx[j]);
  piola_vec3 s;
  if (piola_diagonalize3(&h, &u, &s, &w) != PIOLA_OK) return INFINITY;
  double worst = 0;
  for (int32_t v = 0; v < nv; ++v) {
    if (!(mass[v] > 0)) continue; /* a vertex in no tet is held where it started */
    double d2 = 0;
    for (int i = 0; i < 3; ++i) {
      double y = cr[i];
      for (int j = 0; j < 3; ++j) {
        const double r = u.m[i][0] * w.m[j][0] + u.m[i][1] * w.m[j][1] + u.m[i][2] * w.m[j][2];
        y += r * (x[3 * v + j] - cx[j]);
      }
      d2 += (y - rest[3 * v + i]) * (y - rest[3 * v + i]);
    }
    worst = fmax(worst, sqrt(d2));
  }
  return worst;
}

int main(int argc, char **argv) {
  if (argc < 6) {
    fprintf(stderr, "usage: bench_recovery_time MESH MODEL START E VISCOSITY [SECONDS] [DENSITY] [INTEGRATOR] [DIAGONAL]\n");
    return 2;
  }
  /* one thread: on a loaded machine a small body's parallel regions mostly wait */
  piola_set_thread_count(1);
  piola_tet_mesh mesh;
  if (piola_tet_mesh_read(argv[1], &mesh) != PIOLA_OK) return fprintf(stderr, "%s\n", piola_last_error()), 1;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int32_t v = 0; v < mesh.vertex_count; ++v)
    for (int i = 0; i < 3; ++i) lo[i] = fmin(lo[i], mesh.positions[3 * v + i]), hi[i] = fmax(hi[i], mesh.positions[3 * v + i]);
  double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
  if (argc > 9) {
    const double scale = atof(argv[9]) / diag;
    for (int32_t v = 0; v < mesh.vertex_count; ++v)
      for (int i = 0; i < 3; ++i) mesh.positions[3 * v + i] = (mesh.positions[3 * v + i] - 0.5 * (lo[i] + hi[i])) * scale;
    diag = atof(argv[9]);
  }
  piola_world_def wd = piola_default_world_def();
  if (argc > 8 && !piola_integrator_type_from_name(argv[8], &wd.integrator))
    return fprintf(stderr, "unknown integrator %s\n", argv[8]), 2;
  for (int k = 0; k < 3; ++k) wd.gravity[k] = piola_track_constant(0);
  piola_world *world = NULL;
  if (piola_world_create(&wd, &world) != PIOLA_OK) return fprintf(stderr, "%s\n", piola_last_error()), 1;
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  if (!piola_material_model_from_name(argv[2], &sd.material.model))
    return fprintf(stderr, "unknown model %s\n", argv[2]), 2;
  sd.material.youngs_modulus = atof(argv[4]);
  sd.material.poisson_ratio = 0.3;
  sd.density = argc > 7 ? atof(argv[7]) : 1000;
  sd.shear_viscosity = sd.bulk_viscosity = piola_track_constant(atof(argv[5]));
  const char *start = argv[3];
  double m[3] = {1, 1, 1};
  if (!strcmp(start, "point")) m[0] = m[1] = m[2] = 0;
  else if (!strcmp(start, "line")) m[1] = m[2] = 0;
  else if (!strcmp(start, "plane")) m[2] = 0;
  else if (!strcmp(start, "mirror")) m[0] = -1;
  else if (!strncmp(start, "scramble:", 9)) sd.scramble_radius = atof(start + 9) * diag;
  else return fprintf(stderr, "unknown start '%s'\n", start), 2;
  sd.initial_matrix = (piola_mat3){{{m[0], 0, 0}, {0, m[1], 0}, {0, 0, m[2]}}};
  if (piola_world_add_solid(world, &sd, NULL) != PIOLA_OK) return fprintf(stderr, "%s\n", piola_last_error()), 1;
  const char *warning = piola_world_warning(world, PIOLA_WARNING_SLIVER);
  if (warning) printf("# %s\n", warning);
  const piola_elastic_body *body = piola_world_solid_body(world, 0);
  const double *rest = piola_elastic_body_rest_positions(body), *mass = piola_elastic_body_masses(body);
  const double seconds = argc > 6 ? atof(argv[6]) : 5;
  piola_settling_estimate est;
  if (piola_elastic_body_settling_estimate(body, atof(argv[5]), atof(argv[5]), &est) != PIOLA_OK)
    return fprintf(stderr, "%s\n", piola_last_error()), 1;
  const double e0 = shape_error(piola_world_solid_positions(world, 0), rest, mass, mesh.vertex_count);
  const double predicted = piola_settling_time(&est, e0, 0.01 * diag);
  printf("# lowest mode %.4g rad/s (pi c_s / D = %.4g), its damping %.4g /s, decay %.4g /s, "
         "relaxation %.4g /s, D / c_p %.3g s (%d inverse iterations): predicted %.3g s to 1%%\n",
         est.lowest_frequency, M_PI * sqrt(sd.material.youngs_modulus / 2.6 / sd.density) / diag,
         est.lowest_damping, est.lowest_decay_rate, est.relaxation_rate, est.crossing_time,
         est.iterations, predicted);
  double below10 = NAN, below1 = NAN;
  long steps = 0, retries = 0;
  printf("# %s %s %s E %g Pa, viscosity %g Pa s, density %g, diagonal %g m\n", argv[1], argv[2], start,
         sd.material.youngs_modulus, atof(argv[5]), sd.density, diag);
  printf("# t (s)  shape error (%% of diagonal)  kinetic (J)  elastic (J)  inverted  steps\n");
  for (int frame = 0; frame <= (int)lround(seconds * 10); ++frame) {
    if (frame > 0) {
      piola_step_stats st = {0};
      if (piola_world_advance_to(world, 0.1 * frame, &st) != PIOLA_OK) {
        printf("# stopped: %s\n", piola_last_error());
        return 1;
      }
      steps += st.substeps, retries += st.step_retries;
    }
    const double e = 100 * shape_error(piola_world_solid_positions(world, 0), rest, mass, mesh.vertex_count) / diag;
    piola_solid_stats ss = piola_world_solid_stats(world, 0);
    printf("%.1f %.4g %.4g %.4g %d %ld\n", 0.1 * frame, e, ss.kinetic_energy, ss.elastic_energy,
           (int)ss.inverted_count, steps);
    if (e < 10 && isnan(below10)) below10 = 0.1 * frame;
    if (e >= 10) below10 = NAN;
    if (e < 1 && isnan(below1)) below1 = 0.1 * frame;
    if (e >= 1) below1 = NAN;
    fflush(stdout);
  }
  printf("# below 10%%: %g s, below 1%%: %g s (predicted %.3g s), steps %ld, retries %ld\n", below10,
         below1, predicted, steps, retries);
  for (int k = 0; k < PIOLA_WARNING_KIND_COUNT; ++k)
    if (k != PIOLA_WARNING_SLIVER && piola_world_warning(world, (piola_warning_kind)k))
      printf("# %s\n", piola_world_warning(world, (piola_warning_kind)k));
  piola_world_destroy(world);
  piola_tet_mesh_free(&mesh);
  return 0;
}
