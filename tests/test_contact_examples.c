/* Issue 7's contract on the contact examples themselves: at the end of every step of
 * examples/solids_stack.json (two solids dropped onto each other), squeezed_solid.json (a solid
 * squeezed until its surface folds onto itself) and cloth_on_jelly.json (cloth on a soft
 * solid, two-way), no triangle of any solid's boundary or any shell intersects another,
 * except pairs of one body that share a vertex. The judge is the exact referee
 * (tests/support/triangle_referee.c), independent of the collision code. (cloth_folds.json is
 * judged the same way in test_contact_shells.c and test_collision_step.c.)
 *
 * Full runs in a Release build; under the sanitizers (PIOLA_TEST_SCALE) only the first frames. */
#include <stdio.h>
#include <stdlib.h>

#include "piola/mesh.h"
#include "piola/scene.h"
#include "piola/shell_body.h"
#include "piola/world.h"
#include "piola/world_shells.h"
#include "test_support.h"
#include "triangle_referee.h"

typedef struct judged_world {
  judged sets[16];
  piola_tri_mesh boundaries[16]; /* one per solid, over the solid's vertex numbering */
  int count;
  int solid_count;
} judged_world;

/* The boundary triangles of every solid (from its tets) and the triangles of every shell. */
static void judge_setup(const piola_world *w, judged_world *j) {
  j->count = 0;
  j->solid_count = piola_world_solid_count(w);
  assert_true(j->solid_count + piola_world_shell_count(w) <= 16);
  for (int32_t s = 0; s < j->solid_count; ++s) {
    const piola_elastic_body *b = piola_world_solid_body(w, s);
    piola_tet_mesh mesh = {0};
    mesh.vertex_count = piola_elastic_body_vertex_count(b);
    mesh.positions = (double *)piola_elastic_body_rest_positions(b);
    mesh.tet_count = piola_elastic_body_tet_count(b);
    mesh.tets = (int32_t *)piola_elastic_body_tets(b);
    assert_int_equal(piola_tet_mesh_boundary(&mesh, &j->boundaries[s]), PIOLA_OK);
    j->sets[j->count++] = (judged){NULL, j->boundaries[s].triangles, j->boundaries[s].triangle_count};
  }
  for (int32_t s = 0; s < piola_world_shell_count(w); ++s) {
    const piola_shell_body *b = piola_world_shell_body(w, s);
    j->sets[j->count++] =
        (judged){NULL, piola_shell_body_triangles(b), piola_shell_body_triangle_count(b)};
  }
}

/* Positions move (and their arrays may be replaced) every step: point the sets at them. */
static long judge_now(const piola_world *w, judged_world *j) {
  for (int32_t s = 0; s < j->solid_count; ++s) j->sets[s].x = piola_world_solid_positions(w, s);
  for (int k = j->solid_count; k < j->count; ++k)
    j->sets[k].x = piola_world_shell_positions(w, k - j->solid_count);
  return referee_count_intersections(j->sets, j->count);
}

static void judge_free(judged_world *j) {
  for (int32_t s = 0; s < j->solid_count; ++s) piola_tri_mesh_free(&j->boundaries[s]);
}

/* Runs the example for its frames (fewer under PIOLA_TEST_SCALE), judging every step. */
static void judge_example(const char *name, int64_t *contacts_out) {
  char path[512];
  snprintf(path, sizeof path, "%s/examples/%s.json", PIOLA_SOURCE_DIR, name);
  piola_scene *scene = NULL;
  if (piola_scene_load(path, &scene) != PIOLA_OK) fail_msg("%s", piola_last_error());
  piola_world *w = piola_scene_world(scene);
  judged_world j;
  judge_setup(w, &j);
  assert_int_equal(judge_now(w, &j), 0);
  const int frames = (int)test_samples(piola_scene_frames(scene), 3);
  const double fps = piola_scene_fps(scene);
  int64_t contacts = 0;
  long steps = 0;
  for (int f = 1; f <= frames; ++f) {
    const double t_frame = f / fps;
    while (piola_world_time(w) < t_frame) {
      piola_step_stats st;
      assert_int_equal(piola_world_step(w, t_frame - piola_world_time(w), &st), PIOLA_OK);
      contacts += st.contacts + st.impacts;
      ++steps;
      const long bad = judge_now(w, &j);
      if (bad) fail_msg("%s: %ld intersecting triangle pairs after step %ld (t = %g s)", name, bad,
                        steps, piola_world_time(w));
    }
  }
  print_message("%s: %d frames, %ld steps judged, %lld contacts and impacts\n", name, frames,
                steps, (long long)contacts);
  judge_free(&j);
  piola_scene_destroy(scene);
  *contacts_out = contacts;
}

static void two_solids_dropped_onto_each_other(void **state) {
  (void)state;
  int64_t contacts = 0;
  judge_example("solids_stack", &contacts);
  if (test_scale() >= 1) assert_true(contacts > 0); /* they do meet within the full run */
}

static void squeezed_solid_folding_onto_itself(void **state) {
  (void)state;
  int64_t contacts = 0;
  judge_example("squeezed_solid", &contacts);
  if (test_scale() >= 1) assert_true(contacts > 0); /* the hole closes from about 0.4 s */
}

static void cloth_on_a_soft_solid(void **state) {
  (void)state;
  int64_t contacts = 0;
  judge_example("cloth_on_jelly", &contacts);
  assert_true(contacts > 0); /* the cloth touches the block within its first frames */
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(two_solids_dropped_onto_each_other),
      cmocka_unit_test(squeezed_solid_folding_onto_itself),
      cmocka_unit_test(cloth_on_a_soft_solid),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
