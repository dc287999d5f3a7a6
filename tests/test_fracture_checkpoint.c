/* Checkpoints of cut solids (src/sim/fracture_restore.c, the fracture section of
 * src/sim/world_checkpoint.c; docs/file-formats.md): a plastic, damped solid cut at t = 0
 * (as a scene with a cut at time 0 is built) and twice more during the run is checkpointed;
 * a world built the same way, so cut only once, reads the checkpoint and then runs on bit for
 * bit like the world that wrote it, through a further scripted cut, and a world reading an
 * older checkpoint of its own goes back to that cut state; a checkpoint whose cut state does
 * not fit the mesh, or that fits no further than its cut state, is refused and leaves the
 * world as it was (it runs on like the writer). */
#include "test_support.h"
#include "fracture_checks.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "piola/checkpoint.h"
#include "piola/elastic_body.h"
#include "piola/mesh.h"
#include "piola/plasticity.h"
#include "piola/world.h"
#include "piola/world_fracture.h"

static const piola_fracture_cut cuts[4] = {
    {.time = 0, .point = {0.12, 0.1, 0.1}, .normal = {1, 0.2, 0.1}},
    {.time = 0.01, .point = {0.1, 0.07, 0.1}, .normal = {0.1, 1, -0.3}},
    {.time = 0.02, .point = {0.1, 0.1, 0.13}, .normal = {0.2, 0.1, 1}},
    {.time = 0.04, .point = {0.05, 0.1, 0.1}, .normal = {1, -0.3, 0.2}}};

static piola_world *build_with(const piola_tet_mesh *mesh, const piola_plasticity_def *plasticity,
                               double max_dt) {
  piola_world_def wd = piola_default_world_def();
  wd.gravity[2] = piola_track_constant(-9.81);
  wd.max_dt = max_dt;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material.youngs_modulus = 5e4;
  sd.material.poisson_ratio = 0.3;
  sd.shear_viscosity = piola_track_constant(1);
  sd.bulk_viscosity = piola_track_constant(1);
  sd.initial_matrix = (piola_mat3){{{1.2, 0.1, 0}, {0, 1, 0}, {0, 0, 0.85}}};
  sd.plasticity = plasticity;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  piola_fracture_def def = piola_default_fracture_def();
  def.cuts = cuts, def.cut_count = 4, def.max_cuts_per_step = 1;
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_OK);
  return w;
}

static piola_world *build(const piola_tet_mesh *mesh, const piola_plasticity_def *plasticity) {
  return build_with(mesh, plasticity, 5e-4);
}

static void resumed_cut_solid_runs_on_bit_for_bit(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(5, 5, 5, (piola_vec3){0.05, 0.05, 0.05}, &mesh), PIOLA_OK);
  piola_plasticity_def plasticity = piola_default_plasticity_def();
  plasticity.yield = 0.02;
  piola_world *a = build(&mesh, &plasticity), *b = build(&mesh, &plasticity);
  const int32_t once = piola_world_solid_cut_tet_count(b, 0);
  assert_true(once > 0);
  assert_int_equal(piola_world_advance_to(a, 0.03, NULL), PIOLA_OK);
  assert_true(piola_world_solid_cut_tet_count(a, 0) > once); /* cut three times by now */
  char path[] = "/tmp/piola_fracture_checkpoint_XXXXXX";
  int fd = mkstemp(path);
  assert_true(fd >= 0);
  close(fd);
  const uint64_t key = piola_world_scene_key(b, NULL, 0); /* piola run takes it when built */
  fracture_checkpoint_round_trip(a, b, path, 7);
  int32_t frame = -1;
  fracture_same_state(a, b);
  /* on through the fourth cut (at 0.04 s) */
  assert_int_equal(piola_world_advance_to(a, 0.05, NULL), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(b, 0.05, NULL), PIOLA_OK);
  fracture_same_state(a, b);
  const int32_t four = piola_world_solid_cut_tet_count(a, 0);
  /* a world reading its own older checkpoint goes back to that cut state (frame may be
   * NULL; a missing file is reported as missing with it too) */
  assert_int_not_equal(piola_world_checkpoint_read(a, "/nonexistent/checkpoint.bin", key, NULL),
                       PIOLA_OK);
  assert_non_null(strstr(piola_last_error(), "/nonexistent/checkpoint.bin"));
  assert_int_equal(piola_world_checkpoint_read(a, path, key, NULL), PIOLA_OK);
  assert_int_equal(piola_world_checkpoint_read(a, path, key, &frame), PIOLA_OK);
  assert_int_equal(frame, 7);
  assert_true(piola_world_solid_cut_tet_count(a, 0) < four);
  assert_int_equal(piola_world_advance_to(a, 0.05, NULL), PIOLA_OK);
  fracture_same_state(a, b);
  /* the checkpoint of a solid cut from another mesh does not fit (passed with this key, so
   * the cut state itself is checked), and changes nothing */
  piola_tet_mesh other;
  assert_int_equal(piola_tet_mesh_box_grid(4, 4, 4, (piola_vec3){0.0625, 0.0625, 0.0625}, &other), PIOLA_OK);
  piola_world *c = build(&other, &plasticity);
  assert_int_equal(piola_world_advance_to(c, 0.03, NULL), PIOLA_OK);
  assert_int_equal(piola_world_checkpoint_write(c, path, key, 8), PIOLA_OK);
  assert_int_equal(piola_world_checkpoint_read(b, path, key, &frame), PIOLA_ERROR_PARSE);
  assert_int_equal(frame, 7);
  /* the checkpoint of the same mesh cut as far as a's was but without plasticity: its cut
   * state fits (b takes it while the file is checked), the plastic state does not, and b is
   * put back as it was */
  piola_world *d = build(&mesh, NULL);
  assert_int_equal(piola_world_advance_to(d, 0.03, NULL), PIOLA_OK);
  assert_int_equal(piola_world_checkpoint_write(d, path, key, 9), PIOLA_OK);
  assert_int_equal(piola_world_checkpoint_read(b, path, key, &frame), PIOLA_ERROR_PARSE);
  assert_non_null(strstr(piola_last_error(), "plasticity"));
  piola_world_destroy(d);
  assert_int_equal(frame, 7);
  assert_int_equal(piola_world_advance_to(a, 0.055, NULL), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(b, 0.055, NULL), PIOLA_OK);
  fracture_same_state(a, b);
  piola_world_destroy(c);
  piola_tet_mesh_free(&other);
  unlink(path);
  piola_world_destroy(a);
  piola_world_destroy(b);
  piola_tet_mesh_free(&mesh);
}

/* A plastic solid whose steps the stable step bound sets (max_dt far above it): the cuts at
 * 0.01 and 0.02 s rebuild it after it has yielded, so the bound's weights, built at its first
 * step after a cut from the effective Dm^-1 of then, are state the checkpoint carries
 * (format 6): the reader takes the writer's step sizes and runs on bit for bit through the
 * cut at 0.04 s. Without them it steps by another dt from its first step on. */
static void resumed_yielded_cut_solid_takes_the_writers_steps(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(5, 5, 5, (piola_vec3){0.05, 0.05, 0.05}, &mesh), PIOLA_OK);
  piola_plasticity_def plasticity = piola_default_plasticity_def();
  plasticity.yield = 0.02;
  piola_world *a = build_with(&mesh, &plasticity, 1.0), *b = build_with(&mesh, &plasticity, 1.0);
  assert_int_equal(piola_world_advance_to(a, 0.03, NULL), PIOLA_OK);
  assert_true(piola_world_solid_plastic_stats(a, 0).max_fp_stretch > 1); /* it has yielded */
  fracture_checkpoint_round_trip_via_temp_file(a, b, 3);
  fracture_same_state(a, b);
  const int32_t cut = piola_world_solid_cut_tet_count(a, 0);
  piola_step_stats sa, sb;
  assert_int_equal(piola_world_step(a, 0, &sa), PIOLA_OK);
  assert_int_equal(piola_world_step(b, 0, &sb), PIOLA_OK);
  assert_true(sa.last_dt < 1e-2); /* the bound sets it */
  assert_true(sa.last_dt == sb.last_dt);
  assert_int_equal(piola_world_advance_to(a, 0.045, NULL), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(b, 0.045, NULL), PIOLA_OK);
  assert_true(piola_world_solid_cut_tet_count(a, 0) > cut); /* through the fourth cut */
  fracture_same_state(a, b);
  piola_world_destroy(a);
  piola_world_destroy(b);
  piola_tet_mesh_free(&mesh);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(resumed_cut_solid_runs_on_bit_for_bit),
      cmocka_unit_test(resumed_yielded_cut_solid_takes_the_writers_steps),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
