/* The plasticity examples run (a short version: the first frames, more with
 * PIOLA_TEST_SCALE > 1), and in every frame every tet has det Fp > 0 and log-stretches
 * within the scene's limit, with finite positions. */
#include "test_support.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/plasticity.h"
#include "piola/scene.h"

typedef struct example {
  const char *file;
  double limit; /* the scene's plasticity.limit */
} example;

static void run_example(const example *ex) {
  char path[1024];
  snprintf(path, sizeof path, "%s/examples/%s", PIOLA_SOURCE_DIR, ex->file);
  piola_scene *scene = NULL;
  if (piola_scene_load(path, &scene) != PIOLA_OK) fail_msg("%s", piola_last_error());
  piola_world *w = piola_scene_world(scene);
  const piola_plastic_state *ps = piola_world_solid_plastic_state(w, 0);
  assert_non_null(ps);
  int frames = (int)test_samples(3, 2);
  if (frames > piola_scene_frames(scene)) frames = piola_scene_frames(scene);
  int32_t yielded = 0;
  for (int f = 1; f <= frames; ++f) {
    piola_step_stats st;
    memset(&st, 0, sizeof st);
    if (piola_world_advance_to(w, f / piola_scene_fps(scene), &st) != PIOLA_OK)
      fail_msg("%s frame %d: %s", ex->file, f, piola_last_error());
    yielded += piola_world_solid_plastic_stats(w, 0).yielded_count;
    double largest, min_det;
    piola_plastic_state_measure(ps, &largest, &min_det);
    if (!(min_det > 0) || !(largest <= ex->limit + 1e-9))
      fail_msg("%s frame %d: min det Fp %g, largest log-stretch %g (limit %g)", ex->file, f, min_det,
               largest, ex->limit);
    const double *x = piola_world_solid_positions(w, 0);
    int32_t n = piola_elastic_body_vertex_count(piola_world_solid_body(w, 0));
    for (int32_t i = 0; i < 3 * n; ++i) assert_true(isfinite(x[i]));
  }
  (void)yielded;
  piola_scene_destroy(scene);
}

static void sphere_through_gears(void **state) {
  (void)state;
  example ex = {"plastic_sphere_gears.json", 1.6};
  run_example(&ex);
}

static void bar_bend(void **state) {
  (void)state;
  example ex = {"plastic_bar_bend.json", 1.0};
  run_example(&ex);
}

static void control(void **state) {
  (void)state;
  example ex = {"plastic_control.json", 1.2};
  run_example(&ex);
}

int main(void) {
  /* one thread: the machine running the tests is shared, and spinning threads cost more
   * than they give on these small meshes */
  piola_set_thread_count(1);
  omp_set_num_threads(1);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(sphere_through_gears),
      cmocka_unit_test(bar_bend),
      cmocka_unit_test(control),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
