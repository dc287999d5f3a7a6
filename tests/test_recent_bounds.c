/* The explicit step never exceeds the smallest CFL bound of the last 16 steps' start states
 * (docs/time-stepping.md, "The recent bounds"; src/sim/integrator.c).
 *
 * The case that needed it: Ogden's default parameters (docs/materials.md) on
 * medit/unit_ball.mesh as the file has it (a 3.46 m diagonal), scrambled by two diagonals,
 * no gravity, shear and bulk viscosity 5 Pa s, the explicit integrator at its default cfl.
 * With the current state's bound alone the step rose and fell with the oscillation of the
 * stiffest (stretched) tets and pumped energy into them: the total energy rose from the
 * first frame on and the state blew up at 0.071 s (kinetic energy 1e196 J), for every seed
 * tried. Here the run must keep a finite state and lose energy every frame (damping is all
 * that acts). Then the window goes through a checkpoint: a world built the same way reads
 * it and runs on bit for bit like the writer, and the same file rewritten as format 6 (no
 * window) still reads. */
#include "test_support.h"
#include "checkpoint_files.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "piola/checkpoint.h"
#include "piola/elastic_body.h"
#include "piola/mesh_io.h"
#include "piola/world.h"
#include "real_mesh_scenes.h"

static piola_world *scrambled_ogden_ball(const piola_tet_mesh *mesh) {
  real_mesh_scramble scene = {piola_default_solid_def().material, 5, 2 * real_mesh_diagonal(mesh),
                              PIOLA_INTEGRATOR_NEWMARK, NULL, NULL};
  /* Ogden's default terms, as a scene naming only the model (E is not used by Ogden) */
  scene.material.model = PIOLA_MODEL_OGDEN;
  scene.material.youngs_modulus = 1e5;
  scene.material.poisson_ratio = 0.3;
  piola_world *w = real_mesh_scramble_world(mesh, &scene);
  if (!w) fail_msg("%s", piola_last_error());
  return w;
}

/* Rewrites the checkpoint at path as format 6 wrote it (docs/file-formats.md): the same, less
 * the three arrays of the recent step bounds after the time. */
static void rewrite_as_format_6(const char *path) {
  size_t length;
  unsigned char *data = checkpoint_file_read(path, &length);
  size_t pos = CHECKPOINT_HEADER_BYTES;
  checkpoint_skip_array(data, &pos, 8); /* time */
  const size_t bounds_at = pos;
  assert_int_equal(checkpoint_skip_array(data, &pos, 4), 1);  /* count */
  assert_int_equal(checkpoint_skip_array(data, &pos, 4), 1);  /* next */
  assert_int_equal(checkpoint_skip_array(data, &pos, 8), 16); /* the values */
  memmove(data + bounds_at, data + pos, length - 8 - pos);
  checkpoint_file_write(path, data, bounds_at + length - 8 - pos, 6);
  free(data);
}

static void stretched_ogden_ball_loses_energy(void **state) {
  (void)state;
  piola_tet_mesh mesh = real_mesh_read("medit/unit_ball.mesh");
  piola_world *a = scrambled_ogden_ball(&mesh);
  double last = real_mesh_total_energy(a);
  long steps = 0;
  for (int frame = 1; frame <= 3; ++frame) {
    piola_step_stats st = {0};
    if (piola_world_advance_to(a, frame / 30.0, &st) != PIOLA_OK || !real_mesh_solid_finite(a))
      fail_msg("frame %d: %s", frame, piola_last_error());
    const double e = real_mesh_total_energy(a);
    if (getenv("PIOLA_TEST_VERBOSE"))
      print_message("frame %d: %d steps, %d energy redos, total energy %.6g J\n", frame,
                    (int)st.substeps, (int)st.energy_redos, e);
    if (!(e < last)) fail_msg("frame %d: the total energy rose from %g J to %g J", frame, last, e);
    last = e, steps += st.substeps;
  }
  /* the scramble is stiff: the state's bound is far below the rest one */
  assert_true(steps > 1000);

  /* the window through a checkpoint: b, built the same way, runs on like a */
  char file[4096];
  checkpoint_temp_file(file, sizeof file, "piola_recent_bounds");
  piola_world *b = scrambled_ogden_ball(&mesh);
  const uint64_t key = piola_world_scene_key(b, NULL, 0);
  assert_int_equal(piola_world_checkpoint_write(a, file, key, 3), PIOLA_OK);
  int32_t frame = -1;
  assert_int_equal(piola_world_checkpoint_read(b, file, key, &frame), PIOLA_OK);
  assert_int_equal(frame, 3);
  checkpoint_same_solid_state(a, b);
  assert_true(piola_world_stable_dt(a) == piola_world_stable_dt(b));
  /* format 6, no window: read, and the next step follows the current state's bound alone */
  piola_world *c = scrambled_ogden_ball(&mesh);
  rewrite_as_format_6(file);
  assert_int_equal(piola_world_checkpoint_read(c, file, key, &frame), PIOLA_OK);
  checkpoint_same_solid_state(a, c);
  assert_true(piola_world_stable_dt(c) >= piola_world_stable_dt(a));
  unlink(file);
  assert_int_equal(piola_world_advance_to(a, 0.1 + 1.0 / 300, NULL), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(b, 0.1 + 1.0 / 300, NULL), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(c, 0.1 + 1.0 / 300, NULL), PIOLA_OK);
  checkpoint_same_solid_state(a, b);
  assert_true(real_mesh_solid_finite(c));
  piola_world_destroy(a), piola_world_destroy(b), piola_world_destroy(c);
  piola_tet_mesh_free(&mesh);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(stretched_ogden_ball_loses_energy),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
