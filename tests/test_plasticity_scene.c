/* Scene keys of plasticity: a plastic solid loads with its state, a goal mesh equal to the
 * rest mesh gives a zero goal distance, and every bad key fails naming its path. */
#include "test_support.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>

#include "piola/plasticity.h"
#include "piola/scene.h"

static const char *scene_with(const char *plasticity) {
  static char buf[4096];
  snprintf(buf, sizeof buf,
           "{\"frames\": 1, \"solids\": [{\"mesh\": {\"generate\": \"box\", \"half_extents\": [0.1, 0.1, 0.1], "
           "\"cell_size\": 0.1}, \"plasticity\": %s}]}",
           plasticity);
  return buf;
}

static void expect_error(const char *plasticity, const char *path_part) {
  piola_scene *scene = NULL;
  piola_status st = piola_scene_load_string(scene_with(plasticity), NULL, "s.json", &scene);
  if (st == PIOLA_OK) fail_msg("%s loaded", plasticity);
  if (!strstr(piola_last_error(), path_part))
    fail_msg("error '%s' does not name '%s'", piola_last_error(), path_part);
  assert_null(scene);
}

static void plastic_solid_loads_with_its_settings(void **state) {
  (void)state;
  piola_scene *scene = NULL;
  const char *text = scene_with("{\"yield\": 0.1, \"limit\": 0.9, \"hardening\": 2, "
                                "\"control\": {\"goal\": {\"map\": [[1.2, 0, 0], [0, 1, 0], [0, 0, 0.8]]}, \"strength\": 4}}");
  if (piola_scene_load_string(text, NULL, "s.json", &scene) != PIOLA_OK) fail_msg("%s", piola_last_error());
  piola_world *w = piola_scene_world(scene);
  const piola_plastic_state *ps = piola_world_solid_plastic_state(w, 0);
  assert_non_null(ps);
  /* the goal is the map: at rest the distance is |log diag(1.2, 1, 0.8)| */
  double d = piola_plastic_state_goal_distance(ps, piola_world_solid_positions(w, 0));
  assert_close(d, sqrt(log(1.2) * log(1.2) + log(0.8) * log(0.8)), 1e-9);
  piola_scene_destroy(scene);
}

static void goal_mesh_equal_to_the_rest_mesh_is_at_distance_zero(void **state) {
  (void)state;
  char text[4096];
  const char *mesh = PIOLA_DATA_DIR "/medit/cube_medium_tetra.mesh";
  snprintf(text, sizeof text,
           "{\"frames\": 1, \"solids\": [{\"mesh\": \"%s\", \"transform\": {\"scale\": 0.5}, "
           "\"plasticity\": {\"control\": {\"goal\": {\"mesh\": \"%s\"}}}}]}",
           mesh, mesh);
  piola_scene *scene = NULL;
  if (piola_scene_load_string(text, NULL, "s.json", &scene) != PIOLA_OK) fail_msg("%s", piola_last_error());
  piola_world *w = piola_scene_world(scene);
  const piola_plastic_state *ps = piola_world_solid_plastic_state(w, 0);
  assert_non_null(ps);
  assert_true(piola_plastic_state_goal_distance(ps, piola_world_solid_positions(w, 0)) < 1e-9);
  piola_scene_destroy(scene);
  /* a goal mesh with other connectivity is refused, naming the key */
  snprintf(text, sizeof text,
           "{\"frames\": 1, \"solids\": [{\"mesh\": \"%s\", "
           "\"plasticity\": {\"control\": {\"goal\": {\"mesh\": \"%s\"}}}}]}",
           mesh, PIOLA_DATA_DIR "/medit/unit_ball.mesh");
  assert_int_not_equal(piola_scene_load_string(text, NULL, "s.json", &scene), PIOLA_OK);
  assert_non_null(strstr(piola_last_error(), "solids[0].plasticity.control.goal.mesh"));
}

static void bad_plasticity_keys_name_their_path(void **state) {
  (void)state;
  expect_error("{\"yield\": -1}", "solids[0].plasticity.yield");
  expect_error("{\"limit\": 50}", "solids[0].plasticity.limit");
  expect_error("{\"hardening\": -0.1}", "solids[0].plasticity.hardening");
  expect_error("{\"volume_preserving\": 1}", "solids[0].plasticity.volume_preserving");
  expect_error("{\"bogus\": 1}", "solids[0].plasticity");
  expect_error("{\"control\": {\"strength\": 1}}", "solids[0].plasticity.control.goal");
  expect_error("{\"volume_preserving\": true, \"control\": {\"goal\": {\"map\": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}}}",
               "solids[0].plasticity.control");
  expect_error("{\"control\": {\"goal\": {\"map\": [[1, 0, 0], [0, 1, 0], [0, 0, -1]]}}}",
               "solids[0].plasticity.control.goal.map");
  expect_error("{\"control\": {\"goal\": {\"map\": [[1, 0], [0, 1]]}}}", "solids[0].plasticity.control.goal.map");
  expect_error("{\"control\": {\"goal\": {}}}", "solids[0].plasticity.control.goal");
  expect_error("{\"control\": {\"goal\": {\"map\": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}, \"strength\": -2}}",
               "solids[0].plasticity.control.strength");
}

int main(void) {
  piola_set_thread_count(1);
  omp_set_num_threads(1);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(plastic_solid_loads_with_its_settings),
      cmocka_unit_test(goal_mesh_equal_to_the_rest_mesh_is_at_distance_zero),
      cmocka_unit_test(bad_plasticity_keys_name_their_path),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
