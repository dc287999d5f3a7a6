/* Recovery with backward Euler at one step per 1/30 s frame, on a real mesh (the Medit unit
 * ball of ../shared/data, 1110 tets, scaled to 0.2 m): collapsed to a point, to a line, to a
 * plane, or scrambled (every node moved by up to 40% of the radius), for every model (the
 * muscle with passive fibres along x), in zero gravity with light damping. After 2 s
 * (60 frames; with PIOLA_TEST_SCALE < 1, the sanitizer pass, only 5 frames, checked for
 * finiteness, and each model from one start, rotating through the four) no tet is
 * inverted and the elastic energy is below 1e-4 of its value at the start: the shape is back up to a rigid motion. Every frame
 * is one step unless Newton failed (then stats.csv says so); the state is finite throughout.
 * And a harder start on a bigger real mesh: tetgen/armadillo_4k.node scrambled by two of its
 * diagonals (scrambled_armadillo_recovers); and Gmsh's bunny collapsed to a point, which
 * froze while failed tries stopped at dt / 8 (collapsed_bunny_moves). */
#include "test_support.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/mesh_io.h"
#include "piola/world.h"
#include "real_mesh_scenes.h"

typedef enum { POINT, LINE, PLANE, SCRAMBLE } start_kind;
static const char *start_name[] = {"point", "line", "plane", "scramble"};

static void recover(const piola_tet_mesh *mesh, piola_material_model model, start_kind kind) {
  piola_world_def wd = piola_default_world_def();
  wd.gravity[2] = piola_track_constant(0);
  wd.integrator = PIOLA_INTEGRATOR_BACKWARD_EULER;
  wd.implicit_dt = 1.0 / 30;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material.model = model;
  sd.material.youngs_modulus = 5e4;
  sd.material.poisson_ratio = 0.3;
  sd.shear_viscosity = piola_track_constant(2);
  sd.bulk_viscosity = piola_track_constant(2);
  sd.initial_matrix = (piola_mat3){{{kind != POINT, 0, 0}, {0, kind == PLANE || kind == SCRAMBLE, 0},
                                    {0, 0, kind == SCRAMBLE}}};
  if (kind == SCRAMBLE) sd.scramble_radius = 0.04, sd.scramble_seed = 3;
  double *fibers = NULL;
  if (model == PIOLA_MODEL_MUSCLE) {
    fibers = malloc(sizeof(double) * 3 * (size_t)mesh->tet_count);
    for (int32_t t = 0; t < mesh->tet_count; ++t) fibers[3 * t] = 1, fibers[3 * t + 1] = 0, fibers[3 * t + 2] = 0;
    sd.fiber_directions = fibers;
    sd.activation = piola_track_constant(0); /* passive: the rest shape is the equilibrium */
  }
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  piola_solid_stats s0 = piola_world_solid_stats(w, 0);
  const int frames = test_scale() >= 1.0 ? 60 : 5;
  int32_t failures = 0;
  for (int f = 1; f <= frames; ++f) {
    piola_step_stats st;
    memset(&st, 0, sizeof st);
    if (piola_world_advance_to(w, f / 30.0, &st) != PIOLA_OK)
      fail_msg("%s from %s, frame %d: %s", piola_material_model_name(model), start_name[kind], f,
               piola_last_error());
    failures += st.newton_failures;
    if (st.newton_failures == 0) assert_int_equal(st.substeps, 1);
    const double *x = piola_world_solid_positions(w, 0);
    for (int32_t i = 0; i < 3 * mesh->vertex_count; ++i) assert_true(isfinite(x[i]));
  }
  piola_solid_stats s1 = piola_world_solid_stats(w, 0);
  print_message("%-14s %-8s: energy %.3g -> %.3g J, %d inverted, %d Newton failures\n",
                piola_material_model_name(model), start_name[kind], s0.elastic_energy,
                s1.elastic_energy, (int)s1.inverted_count, (int)failures);
  if (frames >= 60) {
    if (s1.inverted_count != 0 || !(s1.elastic_energy <= 1e-4 * s0.elastic_energy))
      fail_msg("%s from %s did not recover: energy %g of %g, %d inverted",
               piola_material_model_name(model), start_name[kind], s1.elastic_energy,
               s0.elastic_energy, (int)s1.inverted_count);
  }
  free(fibers);
  piola_world_destroy(w);
}

static void every_model_every_start(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  memset(&mesh, 0, sizeof mesh);
  const char *path = test_data_path("medit/unit_ball.mesh");
  if (piola_tet_mesh_read(path, &mesh) != PIOLA_OK) fail_msg("%s: %s", path, piola_last_error());
  for (int32_t i = 0; i < 3 * mesh.vertex_count; ++i) mesh.positions[i] *= 0.2;
  const int every_start = test_scale() >= 1.0;
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    for (int kind = POINT; kind <= SCRAMBLE; ++kind)
      if (every_start || kind == model % (SCRAMBLE + 1))
        recover(&mesh, (piola_material_model)model, (start_kind)kind);
  free(mesh.positions);
  free(mesh.tets);
  free(mesh.tet_regions);
}

/* A hard start on a real mesh (docs/time-stepping.md, "Failure", "Halving only while it
 * helps"): tetgen/armadillo_4k.node as its file has it, scrambled by two bounding-box
 * diagonals, corotated, E = 100 kPa, nu = 0.3, shear and bulk viscosity 5 Pa s, no gravity,
 * one step per 1/30 s frame. After 2 s no tet is inverted and the energy is below 1e-9 of the
 * start's (measured: none inverted from frame 53 on with the AVX-512, AVX2 and baseline
 * kernels, about 3e3 of 2.75e15 J left; while every failed step was halved three times, 16
 * were still inverted at 2 s). Under the sanitizers, 3 frames, checked for finiteness. */
/* Advances w to frame f (1/30 s frames), failing the test, named by `what`, unless the step
 * succeeds with solid 0's state finite. */
static piola_step_stats advance_frame(piola_world *w, int f, const char *what) {
  piola_step_stats st;
  memset(&st, 0, sizeof st);
  if (piola_world_advance_to(w, f / 30.0, &st) != PIOLA_OK)
    fail_msg("%s, frame %d: %s", what, f, piola_last_error());
  assert_true(real_mesh_solid_finite(w));
  return st;
}

static void scrambled_armadillo_recovers(void **state) {
  (void)state;
  piola_tet_mesh mesh = real_mesh_read("tetgen/armadillo_4k.node");
  const real_mesh_scramble scene = {real_mesh_material_def(PIOLA_MODEL_COROTATED, 1e5, 0.3), 5,
                                    2 * real_mesh_diagonal(&mesh), PIOLA_INTEGRATOR_BACKWARD_EULER,
                                    NULL, NULL};
  piola_world *w = real_mesh_scramble_world(&mesh, &scene);
  if (!w) fail_msg("%s", piola_last_error());
  const double start = real_mesh_total_energy(w);
  const int frames = test_scale() >= 1.0 ? 60 : 3;
  int32_t failures = 0;
  for (int f = 1; f <= frames; ++f)
    failures += advance_frame(w, f, "scrambled armadillo").newton_failures;
  const piola_solid_stats end = piola_world_solid_stats(w, 0);
  print_message(
      "scrambled corotated armadillo: energy %.3g -> %.3g J, %d inverted, %d Newton "
      "failures\n",
      start, real_mesh_total_energy(w), (int)end.inverted_count, (int)failures);
  if (frames >= 60) {
    assert_int_equal(end.inverted_count, 0);
    assert_true(real_mesh_total_energy(w) < 1e-9 * start);
  }
  piola_world_destroy(w);
  piola_tet_mesh_free(&mesh);
}

/* A body whose tries would keep only their start (docs/time-stepping.md, "Failure", "Halved
 * past the last try"): gmsh/bunny.msh (19,379 tets, slivers of 0.23 degrees) collapsed to a
 * point, Stable Neo-Hookean, E = 100 kPa, nu = 0.3, shear and bulk viscosity 5 Pa s, no
 * gravity, one step per 1/30 s frame. While failed tries stopped at dt / 8 it froze in its
 * third frame: every try of every step failed and kept its start, 8,567 tets inverted in
 * every frame after. Tries halved on past dt / 8 move it: measured 8,553 inverted at frame 2
 * and 6,139 at frame 4 with the AVX-512 kernels, 8,541 and 7,824 with the AVX2 ones. Skipped
 * under the sanitizers (a frame of this tangle takes 10-30 s in Release). */
static void collapsed_bunny_moves(void **state) {
  (void)state;
  if (test_scale() < 1.0) skip();
  piola_tet_mesh mesh = real_mesh_read("gmsh/bunny.msh");
  const piola_mat3 point = {{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}};
  const real_mesh_scramble scene = {real_mesh_material_def(PIOLA_MODEL_STABLE_NEOHOOKEAN, 1e5, 0.3),
                                    5, 0, PIOLA_INTEGRATOR_BACKWARD_EULER, NULL, &point};
  piola_world *w = real_mesh_scramble_world(&mesh, &scene);
  if (!w) fail_msg("%s", piola_last_error());
  int32_t inverted[5] = {0};
  for (int f = 1; f <= 4; ++f) {
    advance_frame(w, f, "collapsed bunny");
    inverted[f] = (int32_t)piola_world_solid_stats(w, 0).inverted_count;
  }
  print_message("collapsed Stable Neo-Hookean bunny: %d, %d, %d, %d tets inverted at frames 1-4\n",
                (int)inverted[1], (int)inverted[2], (int)inverted[3], (int)inverted[4]);
  /* frozen, frames 3 and 4 were the same; moving, the count falls every frame */
  assert_true(inverted[3] < inverted[2] && inverted[4] < inverted[3]);
  assert_true(inverted[4] < 0.95 * inverted[2]);
  piola_world_destroy(w);
  piola_tet_mesh_free(&mesh);
}

int main(void) {
  piola_set_thread_count(1);
  omp_set_num_threads(1);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(every_model_every_start),
      cmocka_unit_test(scrambled_armadillo_recovers),
      cmocka_unit_test(collapsed_bunny_moves),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
