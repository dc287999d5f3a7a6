/* examples/gears.json, the scene of issue 3 (after paper Figure 6), run as a user runs it:
 * a soft neo-Hookean ball falls onto two interlocking gears turning toward each other.
 *
 * - Turning, the gears pull the ball through their nip: its centre of mass goes from above
 *   the gears to below them, and at some frame every node is below the nip (the lens where
 *   the tip circles overlap). In the nip many tets invert; some time after the ball has come
 *   out, none is inverted and it is round again (its extents near the rest diameter).
 * - The control: the same scene with the gears standing still holds the ball on top of the
 *   teeth. So it is the turning gears that pull it through, not gravity.
 *
 * - After every frame no node is inside a gear: the collision processing keeps the ball out
 *   of the teeth. (With gear faces just outside the walls, e.g. half_length 0.16 m against
 *   walls at 0.15 m, nodes pressed into a tooth next to a wall were found 0.01 m inside: the
 *   nearest gear surface is then the face, whose normal points through the wall, and the
 *   wall, processed last, puts them back; docs/obstacles.md.)
 *
 * The scene is the example file itself; the control differs from it only in the two gear
 * motions (replaced in the text, and the test fails if the text to replace is gone). The
 * penetration check builds the two gears again from the example's numbers. */
#include "test_support.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/elastic_body.h"
#include "piola/obstacle.h"
#include "piola/scene.h"
#include "piola/world.h"

/* Geometry of the example (checked against the loaded scene's behaviour, not re-read). */
#define GEAR_TIP_RADIUS 0.2   /* m */
#define GEAR_CENTER_X 0.18    /* m, the gears sit at x = -+ this, z = 0 */
#define BALL_DIAMETER 0.24    /* m */

/* One of the example's gears: tips 0.2 m, depth 0.05 m, 10 teeth, half length 0.25 m, axis y,
 * turned about its axle from angle0 (rad) at `rate` rad/s. */
static piola_obstacle *example_gear(double center_x, double angle0, double rate) {
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_GEAR;
  d.center = (piola_vec3){center_x, 0, 0};
  d.axis = (piola_vec3){0, 1, 0};
  d.radius = GEAR_TIP_RADIUS;
  d.tooth_depth = 0.05;
  d.tooth_count = 10;
  d.half_length = 0.25;
  d.motion.kind = PIOLA_MOTION_POSE;
  d.motion.axis = d.axis;
  d.motion.pivot = d.center;
  const double times[2] = {0, 10}, angles[2] = {angle0, angle0 + 10 * rate};
  assert_int_equal(piola_track_from_keys(times, angles, 2, &d.motion.angle), PIOLA_OK);
  piola_obstacle *o = NULL;
  if (piola_obstacle_create(&d, &o) != PIOLA_OK) fail_msg("%s", piola_last_error());
  return o;
}

/* Deepest penetration (m, <= 0) of any node of the ball into the gears at the world's time. */
static double deepest_in_gears(const piola_world *w, piola_obstacle *const gears[2]) {
  const double *x = piola_world_solid_positions(w, 0);
  int32_t n = piola_elastic_body_vertex_count(piola_world_solid_body(w, 0));
  double t = piola_world_time(w), deepest = 0;
  for (int32_t i = 0; i < n; ++i)
    for (int g = 0; g < 2; ++g) {
      piola_vec3 p = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
      deepest = fmin(deepest, piola_obstacle_signed_distance(gears[g], t, p, NULL, NULL));
    }
  return deepest;
}

/* Half height of the lens where the two tip circles overlap: the nip spans |z| below it. */
static double nip_half_height(void) {
  return sqrt(GEAR_TIP_RADIUS * GEAR_TIP_RADIUS - GEAR_CENTER_X * GEAR_CENTER_X);
}

/* Replaces the one occurrence of `from` in *text by `to` (fails the test if absent). */
static void replace_once(char **text, const char *from, const char *to) {
  char *at = strstr(*text, from);
  if (!at) fail_msg("examples/gears.json no longer contains %s", from);
  size_t head = (size_t)(at - *text), nf = strlen(from), nt = strlen(to), nt_all = strlen(*text);
  char *out = malloc(nt_all - nf + nt + 1);
  assert_non_null(out);
  memcpy(out, *text, head);
  memcpy(out + head, to, nt);
  memcpy(out + head + nt, at + nf, nt_all - head - nf + 1);
  free(*text);
  *text = out;
}

typedef struct ball_state {
  double com[3];     /* m, mean of the node positions (equal masses aside, a fine proxy) */
  double lo[3], hi[3];
  int32_t inverted;
} ball_state;

static ball_state measure(const piola_world *w) {
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const double *x = piola_world_solid_positions(w, 0);
  const double *m = piola_elastic_body_masses(b);
  int32_t n = piola_elastic_body_vertex_count(b);
  ball_state s;
  double mass = 0;
  for (int k = 0; k < 3; ++k) s.com[k] = 0, s.lo[k] = INFINITY, s.hi[k] = -INFINITY;
  for (int32_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      double v = x[3 * i + k];
      assert_true(isfinite(v));
      s.com[k] += m[i] * v;
      s.lo[k] = fmin(s.lo[k], v);
      s.hi[k] = fmax(s.hi[k], v);
    }
    mass += m[i];
  }
  for (int k = 0; k < 3; ++k) s.com[k] /= mass;
  s.inverted = piola_world_solid_stats(w, 0).inverted_count;
  return s;
}

static piola_scene *load_example(const char *replace_a, const char *by_a, const char *replace_b,
                                 const char *by_b) {
  char path[1024];
  snprintf(path, sizeof path, "%s/examples/gears.json", PIOLA_SOURCE_DIR);
  char *text = test_read_text(path);
  if (replace_a) replace_once(&text, replace_a, by_a);
  if (replace_b) replace_once(&text, replace_b, by_b);
  piola_scene *scene = NULL;
  if (piola_scene_load_string(text, PIOLA_SOURCE_DIR "/examples", "gears.json", &scene) !=
      PIOLA_OK)
    fail_msg("%s", piola_last_error());
  free(text);
  return scene;
}

static void turning_gears_pull_the_ball_through(void **state) {
  (void)state;
  piola_scene *scene = load_example(NULL, NULL, NULL, NULL);
  piola_world *w = piola_scene_world(scene);
  const double fps = piola_scene_fps(scene), nip = nip_half_height();
  const int32_t tets = piola_elastic_body_tet_count(piola_world_solid_body(w, 0));

  piola_obstacle *gears[2] = {example_gear(-GEAR_CENTER_X, 0, 2), example_gear(GEAR_CENTER_X, 0.31416, -2)};
  double deepest = 0;
  ball_state s = measure(w);
  assert_true(s.lo[2] > GEAR_TIP_RADIUS); /* starts wholly above the gears */
  int32_t most_inverted = 0;
  double most_inverted_com_z = 0, out_time = -1;
  /* 2.4 s: the ball reaches the nip at about 0.7 s, is through by about 1.6 s. */
  const int frames = (int)ceil(2.4 * fps);
  ball_state last = s;
  for (int f = 1; f <= frames; ++f) {
    if (piola_world_advance_to(w, f / fps, NULL) != PIOLA_OK)
      fail_msg("frame %d: %s", f, piola_last_error());
    s = measure(w);
    deepest = fmin(deepest, deepest_in_gears(w, gears));
    if (s.inverted > most_inverted) most_inverted = s.inverted, most_inverted_com_z = s.com[2];
    if (out_time < 0 && s.hi[2] < -nip) out_time = f / fps;
    /* Once out, at least 0.3 s later: nothing inverted. */
    if (out_time >= 0 && f / fps > out_time + 0.3 && s.inverted != 0)
      fail_msg("t = %g s: %d tets still inverted (the ball came out at %g s)", f / fps,
               s.inverted, out_time);
    last = s;
  }
  print_message("gears: %d tets, at most %d inverted (centre of mass at z = %.3f m then), wholly "
                "below the nip at t = %.3f s, at the end centre (%.3f, %.3f) m, extents %.3f "
                "%.3f %.3f m, deepest node in a gear %.3g m\n",
                tets, most_inverted, most_inverted_com_z, out_time, last.com[0], last.com[2],
                last.hi[0] - last.lo[0], last.hi[1] - last.lo[1], last.hi[2] - last.lo[2], deepest);
  /* Frames land on step ends, where collision processing has just put every node outside. */
  assert_true(deepest > -1e-9);
  piola_obstacle_destroy(gears[0]);
  piola_obstacle_destroy(gears[1]);
  if (out_time < 0) fail_msg("the ball never came out below the nip (z < %g m)", -nip);
  /* Squashed in the nip: a good share of the tets inverted while the centre is in it (the
   * example's cylinder pushes the ball in early, so fewer invert at once than with the gears
   * alone: 48 of 1080 against 69). */
  assert_true(most_inverted >= tets / 40);
  assert_true(fabs(most_inverted_com_z) < GEAR_TIP_RADIUS);
  /* Out on the other side, below the gears, and round again. */
  assert_true(last.com[2] < -GEAR_TIP_RADIUS);
  assert_int_equal(last.inverted, 0);
  for (int k = 0; k < 3; ++k) {
    double extent = last.hi[k] - last.lo[k];
    assert_true(extent > 0.85 * BALL_DIAMETER && extent < 1.15 * BALL_DIAMETER);
  }
  piola_scene_destroy(scene);
}

static void standing_gears_hold_the_ball(void **state) {
  (void)state;
  piola_scene *scene = load_example("{\"keys\": [[0, 0], [10, 20]]}", "0",
                                    "{\"keys\": [[0, 0.31416], [10, -19.68584]]}", "0.31416");
  piola_world *w = piola_scene_world(scene);
  const double fps = piola_scene_fps(scene);
  /* By 1.2 s the turning gears have the ball's centre below the gear centres' height. */
  const int frames = (int)ceil(1.2 * fps);
  ball_state s = measure(w);
  for (int f = 1; f <= frames; ++f) {
    if (piola_world_advance_to(w, f / fps, NULL) != PIOLA_OK)
      fail_msg("frame %d: %s", f, piola_last_error());
    s = measure(w);
  }
  print_message("standing gears: centre of mass at z = %.3f m, lowest node %.3f m\n", s.com[2],
                s.lo[2]);
  /* Resting on the teeth (centre at about 0.22 m): well above the nip, its bottom too. */
  assert_true(s.com[2] > 0.75 * GEAR_TIP_RADIUS);
  assert_true(s.lo[2] > nip_half_height() * 0.5);
  assert_int_equal(s.inverted, 0);
  piola_scene_destroy(scene);
}

int main(void) {
  /* one thread: the machine running the tests is shared and the mesh is small */
  piola_set_thread_count(1);
  omp_set_num_threads(1);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(turning_gears_pull_the_ball_through),
      cmocka_unit_test(standing_gears_hold_the_ball),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
