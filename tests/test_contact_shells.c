/* Shells in the world's collision surface (docs/contact.md, "Shells"): cloth self-collision
 * and two-way contact between solids and shells.
 *
 * - The cloth_folds example (examples/cloth_folds.json, at a reduced resolution, with
 *   collisions after every step instead of its collision_interval) falls onto
 *   itself in folds; after every step no two cloth triangles without a shared vertex
 *   intersect (exact referee, src/contact/triangle_intersection.c, with a box sweep in front
 *   of it that only drops pairs whose closed boxes are disjoint). Without self_collision the
 *   same run does intersect, so the check has teeth.
 * - Two sheets stacked on the ground: the upper one stays above the lower one, at about the
 *   collision thickness, and never intersects it; without self_collision it sinks onto it.
 * - A block flies into a free cloth with no gravity and no obstacles: total linear momentum
 *   of the pair is conserved through the collision, both bodies change momentum (two-way),
 *   and no triangle of the block's boundary or of the cloth intersects another.
 * - The scene key and the def are checked on shells. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/scene.h"
#include "piola/world.h"
#include "piola/world_shells.h"
#include "scene/scene_desc.h"
#include "cloth_scenes.h"
#include "triangle_referee.h"

/* ------------------------------------------------------------------ referee */


/* The referee checks all pairs; the box sweep must not lose any. A crossing pair of
 * triangles (and a pair that only touches at a point) among far apart ones is found. */
static void referee_finds_crossings_among_many(void **state) {
  (void)state;
  double x[3 * 9] = {0, 0, 0,    1, 0, 0,   0, 1, 0,       /* in z = 0 */
                     0.2, 0.2, -1, 0.3, 0.2, 1, 0.2, 0.3, 1, /* pierces it */
                     5, 5, 5,    6, 5, 5,   5, 6, 5};      /* far away */
  int32_t tris[9] = {0, 1, 2, 3, 4, 5, 6, 7, 8};
  judged one = {x, tris, 3};
  assert_int_equal(referee_count_intersections(&one, 1), 1);
  x[9 + 2] = 0.0, x[12 + 2] = 1, x[15 + 2] = 1; /* now it touches z = 0 at one point */
  assert_int_equal(referee_count_intersections(&one, 1), 1);
  x[9 + 2] = 1e-12;
  assert_int_equal(referee_count_intersections(&one, 1), 0);
  /* the same triangles as two sets: no vertex is shared across sets */
  judged two[2] = {{x, tris, 1}, {x, tris, 1}};
  assert_int_equal(referee_count_intersections(two, 2), 1);
}

/* ------------------------------------------------------------------ cloth folds */


/* Runs the example at resolution cells x cells until t_end, checking every step; returns the
 * worst number of intersecting pairs seen and adds the contact statistics to total. */
static long run_cloth_folds(int self_collision, const char *cells, double t_end,
                            piola_step_stats *total, double *final_top) {
  char path[1024];
  snprintf(path, sizeof path, "%s/examples/cloth_folds.json", PIOLA_SOURCE_DIR);
  char *text = test_read_text(path);
  test_replace_first(text, "\"resolution\": [48, 48]", cells);
  /* collisions after every step, so that every step is judged (test_collision_step.c judges
   * the example's own collision steps) */
  test_replace_first(text, "\"collision_interval\": 0.0016666666666666668", "\"collision_interval\": 0");
  if (!self_collision) test_replace_first(text, "\"enabled\": true", "\"enabled\":false");
  piola_scene *scene = NULL;
  if (piola_scene_load_string(text, PIOLA_SOURCE_DIR, "cloth_folds", &scene) != PIOLA_OK)
    fail_msg("%s", piola_last_error());
  free(text);
  piola_world *w = piola_scene_world(scene);
  assert_int_equal(piola_world_shell_count(w), 1);
  judged cloth = referee_shell_set(w, 0);
  assert_int_equal(referee_count_intersections(&cloth, 1), 0);
  memset(total, 0, sizeof(*total));
  long worst = 0;
  int steps = 0;
  while (piola_world_time(w) < t_end) {
    piola_step_stats one;
    assert_int_equal(piola_world_step(w, 0, &one), PIOLA_OK);
    total->contacts += one.contacts, total->impacts += one.impacts;
    total->impact_zones += one.impact_zones;
    long bad = referee_count_intersections(&cloth, 1);
    if (bad > worst) worst = bad;
    if (self_collision && bad)
      fail_msg("step %d, t = %g s: %ld intersecting cloth triangle pairs", steps,
               piola_world_time(w), bad);
    ++steps;
  }
  const double *x = piola_world_shell_positions(w, 0);
  double top = -INFINITY;
  for (int32_t i = 0; i < piola_shell_body_vertex_count(piola_world_shell_body(w, 0)); ++i)
    top = fmax(top, x[3 * i + 2]);
  *final_top = top;
  piola_scene_destroy(scene);
  return worst;
}

static void cloth_folds_example_never_intersects(void **state) {
  (void)state;
  /* the cloth starts upright, 0.33 m up; by t_end its top has come down onto the pile */
  const double t_end = 0.1 + 0.5 * (double)test_samples(10, 2) / 10.0;
  piola_step_stats with, without;
  double top_with, top_without;
  long worst = run_cloth_folds(1, "\"resolution\": [20, 20]", t_end, &with, &top_with);
  assert_int_equal(worst, 0);
  print_message("cloth folds to t = %.2f s: %lld contacts, %lld impacts, %lld zones, top at %.3f m\n",
                t_end, (long long)with.contacts, (long long)with.impacts,
                (long long)with.impact_zones, top_with);
  assert_true(with.contacts + with.impacts > 0);
  if (t_end >= 0.5) assert_true(top_with < 0.2); /* it fell over onto itself */
  long worst_off = run_cloth_folds(0, "\"resolution\": [20, 20]", t_end, &without, &top_without);
  assert_true(without.contacts + without.impacts + without.impact_zones == 0);
  if (t_end >= 0.5) assert_true(worst_off > 0);
}

/* ------------------------------------------------------------------ stacked sheets */

/* Lowest vertex of the upper sheet minus the highest of the lower one, m. */
static double sheet_gap(const piola_world *w) {
  int32_t n0 = piola_shell_body_vertex_count(piola_world_shell_body(w, 0));
  int32_t n1 = piola_shell_body_vertex_count(piola_world_shell_body(w, 1));
  const double *x0 = piola_world_shell_positions(w, 0), *x1 = piola_world_shell_positions(w, 1);
  double top_of_lower = -INFINITY, bottom_of_upper = INFINITY;
  for (int32_t i = 0; i < n0; ++i) top_of_lower = fmax(top_of_lower, x0[3 * i + 2]);
  for (int32_t i = 0; i < n1; ++i) bottom_of_upper = fmin(bottom_of_upper, x1[3 * i + 2]);
  return bottom_of_upper - top_of_lower;
}

static double stack_sheets(int self_collision, double h, long *worst) {
  piola_world_def wd = piola_default_world_def();
  wd.max_dt = 1e-3;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_obstacle_def ground = piola_default_obstacle_def();
  ground.friction = 0.5;
  assert_int_equal(piola_world_add_obstacle(w, &ground, NULL), PIOLA_OK);
  /* the lower sheet lies on the ground; the upper one, offset so no vertex sits over a
   * vertex, falls onto it from 2 cm with 1 m/s */
  piola_tri_mesh lower = cloth_sheet(0.2, 12, 0.0, 0.0), upper = cloth_sheet(0.16, 10, 0.02, 0.0037);
  piola_shell_def a = cloth_shell_def(&lower, self_collision, h), b = cloth_shell_def(&upper, self_collision, h);
  b.velocity = (piola_vec3){0, 0, -1.0};
  assert_int_equal(piola_world_add_shell(w, &a, NULL), PIOLA_OK);
  assert_int_equal(piola_world_add_shell(w, &b, NULL), PIOLA_OK);
  piola_tri_mesh_free(&lower), piola_tri_mesh_free(&upper);
  judged sets[2] = {referee_shell_set(w, 0), referee_shell_set(w, 1)};
  double smallest_gap = INFINITY;
  *worst = 0;
  const double t_end = 0.05 + 0.15 * (double)test_samples(10, 2) / 10.0;
  while (piola_world_time(w) < t_end) {
    assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
    long bad = referee_count_intersections(sets, 2);
    if (bad > *worst) *worst = bad;
    smallest_gap = fmin(smallest_gap, sheet_gap(w));
  }
  piola_world_destroy(w);
  return smallest_gap;
}

static void stacked_sheets_stay_apart(void **state) {
  (void)state;
  const double h = 3e-3;
  long worst = 0;
  double gap = stack_sheets(1, h, &worst);
  print_message("stacked sheets: smallest gap %.3g m (thickness %g m)\n", gap, h);
  assert_int_equal(worst, 0);
  /* the repulsion holds the upper sheet near the thickness; CCD never lets it reach the
   * lower one, the ground projection at most pushes the lower one up a little */
  assert_true(gap > 0.3 * h);
  long worst_off = 0;
  double gap_off = stack_sheets(0, h, &worst_off);
  assert_true(gap_off < 1e-6); /* without it the upper sheet lands on the ground too */
  assert_true(worst_off > 0);
}

/* ------------------------------------------------------------------ two-way, momentum */

/* With self_collision on both sides, the one-way collide_with_solids stays out of the pair:
 * turning it on changes nothing, to the bit. */
static void one_way_coupling_defers_to_two_way_contact(void **state) {
  (void)state;
  double *runs[2] = {NULL, NULL};
  int32_t nc = 0;
  piola_step_stats totals[2] = {{0}, {0}};
  for (int one_way = 0; one_way < 2; ++one_way) {
    piola_world_def wd = piola_default_world_def();
    wd.max_dt = 5e-4;
    piola_world *w = NULL;
    assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
    piola_tet_mesh block;
    assert_int_equal(piola_tet_mesh_box_grid(3, 3, 2, (piola_vec3){0.02, 0.02, 0.02}, &block),
                     PIOLA_OK);
    for (int32_t i = 0; i < block.vertex_count; ++i)
      block.positions[3 * i] -= 0.03, block.positions[3 * i + 1] -= 0.03;
    piola_tet_mesh_orient(&block);
    piola_solid_def sd = piola_default_solid_def();
    sd.mesh = &block;
    sd.material.youngs_modulus = 1e5;
    sd.constraints = &(piola_constraint_def){.selector = {.type = PIOLA_SELECT_BOX,
                                                          .box_min = {-1, -1, -1},
                                                          .box_max = {1, 1, 1e-3}}};
    sd.constraint_count = 1;
    sd.self_collision.enabled = true;
    sd.self_collision.thickness = 2e-3;
    assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
    piola_tri_mesh cloth = cloth_sheet(0.12, 10, 0.05, 0.0);
    piola_shell_def cd = cloth_shell_def(&cloth, 1, 2e-3);
    cd.collide_with_solids = one_way != 0;
    cd.velocity = (piola_vec3){0, 0, -6.0}; /* 3 mm a step: x~ reaches into the block */
    assert_int_equal(piola_world_add_shell(w, &cd, NULL), PIOLA_OK);
    piola_tri_mesh_free(&cloth);
    assert_int_equal(piola_world_advance_to(w, 0.03, &totals[one_way]), PIOLA_OK);
    nc = piola_shell_body_vertex_count(piola_world_shell_body(w, 0));
    runs[one_way] = malloc(sizeof(double) * 3 * (size_t)nc);
    assert_non_null(runs[one_way]);
    memcpy(runs[one_way], piola_world_shell_positions(w, 0), sizeof(double) * 3 * (size_t)nc);
    piola_tet_mesh_free(&block);
    piola_world_destroy(w);
  }
  print_message("cloth onto block at 6 m/s: %lld contacts, %lld impacts, %lld zones\n",
                (long long)totals[0].contacts, (long long)totals[0].impacts,
                (long long)totals[0].impact_zones);
  assert_true(totals[0].contacts > 0); /* the cloth did reach the block */
  assert_memory_equal(runs[0], runs[1], sizeof(double) * 3 * (size_t)nc);
  free(runs[0]), free(runs[1]);
}

/* speed: m/s of the block, h: collision thickness, m (cloth_scenes.h). At 12 m/s the block
 * moves about 1.4 mm a step (the block's CFL step is about 0.12 ms), more than a thickness of
 * 0.5 mm, so continuous detection (impacts) has to act, not only the repulsion. Collisions are
 * processed and judged after every step (collision_interval 0). */

static void block_hits_free_cloth_conserving_momentum(void **state) {
  (void)state;
  block_hits_free_cloth(2.0, 2e-3, 0);
}

static void fast_block_hits_free_cloth_conserving_momentum(void **state) {
  (void)state;
  block_hits_free_cloth(12.0, 5e-4, 0);
}

/* ------------------------------------------------------------------ keys and defs */

static void shell_self_collision_key_and_def(void **state) {
  (void)state;
  scene_desc d;
  const char *json =
      "{\"shells\": [{\"mesh\": {\"generate\": \"rectangle\", \"size\": [1, 1], \"resolution\": [2, 2]},"
      " \"self_collision\": {\"thickness\": 0.004, \"friction\": 0.1}},"
      " {\"mesh\": {\"generate\": \"rectangle\", \"size\": [1, 1], \"resolution\": [2, 2]}}]}";
  if (piola__scene_parse(json, "/base", "t", &d) != PIOLA_OK) fail_msg("%s", piola_last_error());
  assert_true(d.shells[0].def.self_collision.enabled);
  assert_close(d.shells[0].def.self_collision.thickness, 0.004, 0);
  assert_close(d.shells[0].def.self_collision.friction, 0.1, 0);
  assert_false(d.shells[1].def.self_collision.enabled);
  piola__scene_desc_free(&d);
  const char *bad =
      "{\"shells\": [{\"mesh\": {\"generate\": \"rectangle\", \"size\": [1, 1], \"resolution\": [2, 2]},"
      " \"self_collision\": {\"thickness\": -1}}]}";
  assert_int_not_equal(piola__scene_parse(bad, "/base", "t", &d), PIOLA_OK);
  assert_non_null(strstr(piola_last_error(), "self_collision"));

  piola_world_def wd = piola_default_world_def();
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_tri_mesh m = cloth_sheet(0.1, 2, 0, 0);
  piola_shell_def sd = cloth_shell_def(&m, 1, 0.0);
  assert_int_equal(piola_world_add_shell(w, &sd, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  sd.self_collision.thickness = 1e-3, sd.self_collision.friction = -0.5;
  assert_int_equal(piola_world_add_shell(w, &sd, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  sd.self_collision.friction = 0.5;
  assert_int_equal(piola_world_add_shell(w, &sd, NULL), PIOLA_OK);
  piola_tri_mesh_free(&m);
  piola_world_destroy(w);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(referee_finds_crossings_among_many),
      cmocka_unit_test(shell_self_collision_key_and_def),
      cmocka_unit_test(block_hits_free_cloth_conserving_momentum),
      cmocka_unit_test(fast_block_hits_free_cloth_conserving_momentum),
      cmocka_unit_test(stacked_sheets_stay_apart),
      cmocka_unit_test(one_way_coupling_defers_to_two_way_contact),
      cmocka_unit_test(cloth_folds_example_never_intersects),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
