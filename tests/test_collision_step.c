/* The collision step of Bridson, Fedkiw and Anderson 2002 (piola_world_def.collision_interval,
 * docs/contact.md "Collision step"): self-collision processing once per interval of simulated
 * time instead of after every step.
 *
 * - The cloth_folds example (its own collision_interval, at a reduced resolution): at every
 *   interval end no two cloth triangles without a shared vertex intersect (exact referee,
 *   triangle_referee.h); driven by piola_world_advance_to to frame times, every frame is
 *   intersection-free too.
 * - A block flies into a free cloth with no gravity: the pair's linear momentum is conserved
 *   to rounding through collision steps that span many steps, both bodies change momentum,
 *   and every interval end is intersection-free.
 * - A cloth hanging from a driven line onto the ground: the driven nodes stay on their
 *   path, the ground holds, and interval ends are intersection-free.
 * - Without self-collision the interval changes nothing, to the bit; bad values are errors. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/scene.h"
#include "piola/world.h"
#include "piola/world_shells.h"
#include "cloth_scenes.h"
#include "triangle_referee.h"



/* The cloth_folds example at 20 x 20 cells; *interval receives its collision_interval. */
static piola_scene *cloth_folds(double *interval) {
  char path[1024];
  snprintf(path, sizeof path, "%s/examples/cloth_folds.json", PIOLA_SOURCE_DIR);
  char *text = test_read_text(path);
  test_replace_first(text, "\"resolution\": [48, 48]", "\"resolution\": [20, 20]");
  const char *key = strstr(text, "\"collision_interval\":");
  if (!key) fail_msg("the example has no integrator.collision_interval");
  *interval = strtod(key + strlen("\"collision_interval\":"), NULL);
  assert_true(*interval > 0);
  piola_scene *scene = NULL;
  if (piola_scene_load_string(text, PIOLA_SOURCE_DIR, "cloth_folds", &scene) != PIOLA_OK)
    fail_msg("%s", piola_last_error());
  free(text);
  return scene;
}

static double top_of(const piola_world *w) {
  const double *x = piola_world_shell_positions(w, 0);
  double top = -INFINITY;
  for (int32_t i = 0; i < piola_shell_body_vertex_count(piola_world_shell_body(w, 0)); ++i)
    top = fmax(top, x[3 * i + 2]);
  return top;
}

/* Step by step: the world ends an interval with the first step that reaches dt_c after the
 * previous end, and the referee finds nothing there. Steps inside an interval may leave
 * intersections (collisions are resolved at its end); they are counted, not judged. */
static void cloth_folds_interval_ends_are_collision_free(void **state) {
  (void)state;
  const double t_end = 0.1 + 0.5 * (double)test_samples(10, 2) / 10.0;
  double dtc;
  piola_scene *scene = cloth_folds(&dtc);
  piola_world *w = piola_scene_world(scene);
  judged cloth = referee_shell_set(w, 0);
  assert_int_equal(referee_count_intersections(&cloth, 1), 0);
  double next_end = dtc;
  long intervals = 0, steps = 0, inside_bad = 0;
  double longest = 0; /* step, s */
  piola_step_stats total = {0};
  while (piola_world_time(w) < t_end) {
    piola_step_stats one;
    assert_int_equal(piola_world_step(w, 0, &one), PIOLA_OK);
    total.contacts += one.contacts, total.impacts += one.impacts;
    ++steps;
    longest = fmax(longest, one.last_dt);
    const double t = piola_world_time(w);
    if (t >= next_end - 1e-12) {
      assert_int_equal(one.collision_steps, 1);
      assert_true(t < next_end + one.last_dt); /* the first step past the end */
      long bad = referee_count_intersections(&cloth, 1);
      if (bad) fail_msg("interval %ld ending at t = %g s: %ld intersecting pairs", intervals, t, bad);
      next_end = t + dtc;
      ++intervals;
    } else {
      /* no collision processing inside an interval */
      assert_int_equal(one.collision_steps, 0);
      assert_int_equal(one.contacts + one.impacts + one.impact_zones, 0);
      inside_bad += referee_count_intersections(&cloth, 1) > 0;
    }
  }
  print_message("cloth folds to t = %.2f s, interval %.4g s: %ld steps, %ld intervals, %lld contacts,"
                " %lld impacts, %ld steps inside intervals with crossings, top at %.3f m\n",
                t_end, dtc, steps, intervals, (long long)total.contacts, (long long)total.impacts,
                inside_bad, top_of(w));
  assert_true(intervals >= (long)(t_end / (dtc + longest))); /* each at most dt_c + a step */
  assert_true(steps > intervals); /* several steps per collision step */
  assert_true(total.contacts + total.impacts > 0);
  if (t_end >= 0.5) assert_true(top_of(w) < 0.2); /* it fell over onto itself */
  piola_scene_destroy(scene);
}

/* Driven to frame times (30 fps, as piola run does): every frame is intersection-free, and
 * frames land exactly on their times. */
static void cloth_folds_frames_are_collision_free(void **state) {
  (void)state;
  const int frames = (int)(3 + 15 * test_samples(10, 1) / 10);
  double dtc;
  piola_scene *scene = cloth_folds(&dtc);
  piola_world *w = piola_scene_world(scene);
  judged cloth = referee_shell_set(w, 0);
  piola_step_stats total = {0};
  const double frame = 1.0 / piola_scene_fps(scene);
  for (int f = 1; f <= frames; ++f) {
    /* steps a frame: as many as the stable dt needs (with a margin for a state that lowers
     * it), +1 for the split before the frame time; never a run of ever smaller steps
     * towards it */
    const double most = ceil(1.5 * frame / piola_world_stable_dt(w)) + 1;
    piola_step_stats one = {0};
    assert_int_equal(piola_world_advance_to(w, f * frame, &one), PIOLA_OK);
    assert_true(piola_world_time(w) == f * frame);
    assert_true(one.collision_steps >= 1); /* the frame time ended an interval */
    if ((double)one.substeps > most) fail_msg("frame %d: %d steps, at most %g expected", f, (int)one.substeps, most);
    total.contacts += one.contacts, total.impacts += one.impacts;
    total.impact_zones += one.impact_zones;
    long bad = referee_count_intersections(&cloth, 1);
    if (bad) fail_msg("frame %d: %ld intersecting pairs", f, bad);
  }
  print_message("cloth folds, %d frames: %lld contacts, %lld impacts, %lld zones\n", frames,
                (long long)total.contacts, (long long)total.impacts, (long long)total.impact_zones);
  if (frames >= 10) assert_true(total.contacts + total.impacts > 0);
  piola_scene_destroy(scene);
}

/* speed: m/s of the block, h: collision thickness, m; dtc: collision interval, s. An
 * interval of 2 ms spans several steps, in which the block moves 4 mm at 2 m/s and 24 mm at
 * 12 m/s (the cloth is 10 mm above it): the block would pass through the cloth inside one
 * interval, and the collision step has to stop it. */
static void block_hits_free_cloth_conserving_momentum(void **state) {
  (void)state;
  block_hits_free_cloth(2.0, 2e-3, 2e-3);
}

static void fast_block_hits_free_cloth_conserving_momentum(void **state) {
  (void)state;
  block_hits_free_cloth(12.0, 5e-4, 2e-3);
}

/* A 0.2 m cloth held along its middle line x = 0, 0.08 m up, which is driven sideways at
 * 0.2 m/s: both halves hang down from it against each other (self-contact along their
 * length), their lower parts pile on the ground. The driven nodes stay exactly on their
 * prescribed path (collision processing treats them as pinned), the ground holds, and every
 * interval end is intersection-free. */
static void driven_cloth_on_ground(void **state) {
  (void)state;
  piola_world_def wd = piola_default_world_def();
  wd.max_dt = 1e-3;
  wd.collision_interval = 1.0 / 120;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_obstacle_def ground = piola_default_obstacle_def();
  ground.friction = 0.5;
  assert_int_equal(piola_world_add_obstacle(w, &ground, NULL), PIOLA_OK);
  piola_tri_mesh cloth = cloth_sheet(0.2, 12, 0.08, 0.0);
  piola_shell_def cd = cloth_shell_def(&cloth, 1, 3e-3);
  piola_constraint_def line = {.selector = {.type = PIOLA_SELECT_BOX,
                                            .box_min = {-1e-6, -1, -1},
                                            .box_max = {1e-6, 1, 1}},
                               .driven = true};
  line.motion = piola_default_rigid_motion_def();
  line.motion.velocity[0] = piola_track_constant(0.2);
  cd.constraints = &line;
  cd.constraint_count = 1;
  assert_int_equal(piola_world_add_shell(w, &cd, NULL), PIOLA_OK);
  const int32_t n = cloth.vertex_count;
  const uint8_t *flags = piola_world_shell_constraint_flags(w, 0);
  int32_t driven = 0;
  for (int32_t i = 0; i < n; ++i) driven += flags[i] != 0;
  assert_int_equal(driven, 13);
  judged set = referee_shell_set(w, 0);
  piola_step_stats total = {0};
  const int intervals = (int)(12 + 36 * test_samples(10, 1) / 10);
  double lowest = INFINITY;
  for (int k = 1; k <= intervals; ++k) {
    assert_int_equal(piola_world_advance_to(w, k * wd.collision_interval, &total), PIOLA_OK);
    const double t = piola_world_time(w), *x = piola_world_shell_positions(w, 0);
    for (int32_t i = 0; i < n; ++i) {
      if (flags[i]) {
        assert_close(x[3 * i], cloth.positions[3 * i] + 0.2 * t, 1e-12);
        assert_close(x[3 * i + 1], cloth.positions[3 * i + 1], 1e-12);
        assert_close(x[3 * i + 2], cloth.positions[3 * i + 2], 1e-12);
      } else {
        lowest = fmin(lowest, x[3 * i + 2]);
      }
    }
    long bad = referee_count_intersections(&set, 1);
    if (bad) fail_msg("t = %g s: %ld intersecting pairs", t, bad);
  }
  print_message("driven cloth, %d intervals: %lld steps, %lld contacts, %lld impacts, lowest %.4g m\n",
                intervals, (long long)total.substeps, (long long)total.contacts,
                (long long)total.impacts, lowest);
  assert_true(lowest > -1e-3); /* the ground holds, within the obstacle's projection */
  if (intervals >= 40) {
    assert_true(total.contacts + total.impacts > 0); /* the halves did meet */
    assert_true(lowest < 0.01);                      /* and reached the ground */
  }
  piola_tri_mesh_free(&cloth);
  piola_world_destroy(w);
}

/* Without self-collision there is nothing for the interval to batch: the run is the same to
 * the bit (obstacles are handled inside every step either way). */
static void interval_without_self_collision_changes_nothing(void **state) {
  (void)state;
  double *runs[2] = {NULL, NULL};
  int32_t n = 0;
  for (int r = 0; r < 2; ++r) {
    piola_world_def wd = piola_default_world_def();
    wd.collision_interval = r ? 0.01 : 0.0;
    piola_world *w = NULL;
    assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
    piola_obstacle_def ground = piola_default_obstacle_def();
    assert_int_equal(piola_world_add_obstacle(w, &ground, NULL), PIOLA_OK);
    piola_tri_mesh cloth = cloth_sheet(0.1, 8, 0.01, 0.0);
    piola_shell_def cd = cloth_shell_def(&cloth, 0, 1e-3);
    assert_int_equal(piola_world_add_shell(w, &cd, NULL), PIOLA_OK);
    n = cloth.vertex_count;
    piola_tri_mesh_free(&cloth);
    assert_int_equal(piola_world_advance_to(w, 0.07, NULL), PIOLA_OK);
    runs[r] = malloc(sizeof(double) * 3 * (size_t)n);
    assert_non_null(runs[r]);
    memcpy(runs[r], piola_world_shell_positions(w, 0), sizeof(double) * 3 * (size_t)n);
    piola_world_destroy(w);
  }
  assert_true(runs[0][2] < 0.01 - 1e-4); /* it did fall */
  assert_memory_equal(runs[0], runs[1], sizeof(double) * 3 * (size_t)n);
  free(runs[0]), free(runs[1]);
}

static void collision_interval_def_and_key(void **state) {
  (void)state;
  piola_world_def wd = piola_default_world_def();
  assert_true(wd.collision_interval == 0.0);
  piola_world *w = NULL;
  wd.collision_interval = -1e-3;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "collision_interval"));
  wd.collision_interval = NAN;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_null(w);
  const char *scene_fmt =
      "{\"integrator\": {\"collision_interval\": %s},"
      " \"shells\": [{\"mesh\": {\"generate\": \"rectangle\", \"size\": [0.1, 0.1],"
      " \"resolution\": [2, 2]}}]}";
  char text[512];
  piola_scene *scene = NULL;
  snprintf(text, sizeof text, scene_fmt, "-0.01");
  assert_int_not_equal(piola_scene_load_string(text, ".", "bad", &scene), PIOLA_OK);
  assert_non_null(strstr(piola_last_error(), "collision_interval"));
  snprintf(text, sizeof text, scene_fmt, "\"x\"");
  assert_int_not_equal(piola_scene_load_string(text, ".", "bad", &scene), PIOLA_OK);
  snprintf(text, sizeof text, scene_fmt, "0.005");
  if (piola_scene_load_string(text, ".", "good", &scene) != PIOLA_OK) fail_msg("%s", piola_last_error());
  piola_scene_destroy(scene);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(collision_interval_def_and_key),
      cmocka_unit_test(interval_without_self_collision_changes_nothing),
      cmocka_unit_test(block_hits_free_cloth_conserving_momentum),
      cmocka_unit_test(fast_block_hits_free_cloth_conserving_momentum),
      cmocka_unit_test(driven_cloth_on_ground),
      cmocka_unit_test(cloth_folds_frames_are_collision_free),
      cmocka_unit_test(cloth_folds_interval_ends_are_collision_free),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
