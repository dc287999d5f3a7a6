/* Scene keys of the muscle model: material.model "muscle" and material.muscle, a solid's
 * fibers (axis, curve, from_mesh) and activation, with errors that name the key, and the
 * direction fields as the built body sees them. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "piola/mesh_io.h"
#include "piola/scene.h"
#include "piola/world.h"
#include "scene/scene_desc.h"
#include "scene_cases.h"
#include "test_support.h"

#define MUSCLE(x)                                                                             \
  "{\"solids\": [{\"mesh\": \"a.veg\", \"material\": {\"model\": \"muscle\"}" x "}]}"

static void keys_reach_their_definitions(void **state) {
  (void)state;
  scene_desc d;
  const char *json =
      "{\"solids\": [{\"mesh\": \"a.veg\", \"material\": {\"model\": \"muscle\", "
      "\"youngs_modulus\": 2e4, \"poisson_ratio\": 0.45, \"muscle\": {\"passive_stiffness\": 3e4, "
      "\"passive_toe_stretch\": 1.3, \"max_active_stress\": 2.5e5, \"optimal_stretch\": 1.1, "
      "\"active_width\": 0.4}}, \"fibers\": {\"curve\": [[0, 0, 0], [1, 0, 0], [1, 2, 0]]}, "
      "\"activation\": {\"keys\": [[0, 0], [1, 0.75]]}},"
      "{\"mesh\": \"b.veg\", \"material\": {\"model\": \"muscle\"}, \"fibers\": {\"axis\": [0, 3, 4]}}]}";
  assert_int_equal(piola__scene_parse(json, ".", "t", &d), PIOLA_OK);
  const scene_solid_desc *s = &d.solids[0];
  const piola_material_def *m = &s->def.material;
  assert_int_equal(m->model, PIOLA_MODEL_MUSCLE);
  assert_true(m->muscle.passive_stiffness == 3e4);
  assert_true(m->muscle.passive_toe_stretch == 1.3);
  assert_true(m->muscle.max_active_stress == 2.5e5);
  assert_true(m->muscle.optimal_stretch == 1.1);
  assert_true(m->muscle.active_width == 0.4);
  assert_int_equal(s->fibers.kind, SCENE_FIBERS_CURVE);
  assert_int_equal(s->fibers.curve_points, 3);
  assert_true(s->fibers.curve[7] == 2.0);
  assert_int_equal(s->def.activation.key_count, 2);
  assert_true(piola_track_eval(&s->def.activation, 0.5) == 0.375);
  const scene_solid_desc *b = &d.solids[1];
  assert_int_equal(b->fibers.kind, SCENE_FIBERS_AXIS);
  assert_close(b->fibers.axis.y, 0.6, 1e-15);
  assert_close(b->fibers.axis.z, 0.8, 1e-15);
  /* defaults: muscle parameters of piola_default_material_def, activation 0 */
  const piola_material_def def = piola_default_material_def();
  assert_memory_equal(&b->def.material.muscle, &def.muscle, sizeof def.muscle);
  assert_int_equal(b->def.activation.key_count, 0);
  assert_true(b->def.activation.value == 0.0);
  piola__scene_desc_free(&d);
}

static const bad_scene_case BAD[] = {
    {MUSCLE(", \"fibers\": {\"axis\": [0, 0, 0]}"), "solids[0].fibers.axis: must be a nonzero vector"},
    {MUSCLE(", \"fibers\": {\"axis\": [1, 0, 0], \"curve\": [[0, 0, 0], [1, 0, 0]]}"), "solids[0].fibers: needs exactly one of"},
    {MUSCLE(", \"fibers\": {}"), "solids[0].fibers: needs exactly one of"},
    {MUSCLE(", \"fibers\": {\"along\": [1, 0, 0]}"), "solids[0].fibers.along: unknown key"},
    {MUSCLE(", \"fibers\": {\"curve\": [[0, 0, 0]]}"), "solids[0].fibers.curve: must be an array of at least 2 points"},
    {MUSCLE(", \"fibers\": {\"curve\": [[0, 0, 0], [1, 0]]}"), "solids[0].fibers.curve[1]: must be an array of 3 numbers"},
    {MUSCLE(", \"fibers\": {\"curve\": [[0, 0, 0], [1, 0, 0], [1, 0, 0]]}"), "solids[0].fibers.curve[2]: repeats the point"},
    {MUSCLE(", \"fibers\": {\"from_mesh\": false}"), "solids[0].fibers.from_mesh: must be true"},
    {MUSCLE(", \"activation\": 1.5"), "solids[0].activation: must be in [0, 1]"},
    {MUSCLE(", \"activation\": {\"keys\": [[0, 0], [1, -0.1]]}"), "solids[0].activation.keys[1]: must be in [0, 1]"},
    {MUSCLE(", \"plasticity\": {}, \"fibers\": {\"axis\": [1, 0, 0]}"), "solids[0].fibers: cannot be combined with plasticity"},
    {"{\"solids\": [{\"mesh\": \"a.veg\", \"fibers\": {\"axis\": [1, 0, 0]}}]}", "solids[0].fibers: needs material.model \"muscle\""},
    {"{\"solids\": [{\"mesh\": \"a.veg\", \"activation\": 0.5}]}", "solids[0].activation: needs material.model \"muscle\""},
    {"{\"solids\": [{\"mesh\": \"a.veg\", \"material\": {\"muscle\": {}}}]}", "solids[0].material.muscle: needs \"model\": \"muscle\""},
    {"{\"solids\": [{\"mesh\": \"a.veg\", \"material\": {\"model\": \"muscle\", \"muscle\": {\"active_width\": 1}}}]}", "solids[0].material.muscle.active_width: must be in (0, 1)"},
    {"{\"solids\": [{\"mesh\": \"a.veg\", \"material\": {\"model\": \"muscle\", \"muscle\": {\"passive_toe_stretch\": 1}}}]}", "solids[0].material.muscle.passive_toe_stretch"},
    {"{\"solids\": [{\"mesh\": \"a.veg\", \"material\": {\"model\": \"muscle\", \"muscle\": {\"max_active_stress\": -1}}}]}", "solids[0].material.muscle.max_active_stress: must be >= 0"},
    {"{\"solids\": [{\"mesh\": \"a.veg\", \"material\": {\"model\": \"muscle\", \"muscle\": {\"optimal_stretch\": 0}}}]}", "solids[0].material.muscle.optimal_stretch: must be > 0"},
    {"{\"solids\": [{\"mesh\": \"a.veg\", \"material\": {\"model\": \"muscle\", \"muscle\": {\"strength\": 1}}}]}", "solids[0].material.muscle.strength: unknown key"},
    {"{\"shells\": [{\"mesh\": \"a.obj\", \"thickness\": 0.001, \"material\": {\"model\": \"muscle\"}}]}", "shells[0].material.model: \"muscle\" is for solids only"},
};

static void bad_muscle_keys_name_their_path(void **state) {
  (void)state;
  assert_bad_scenes_refused(BAD, sizeof BAD / sizeof BAD[0]);
}

/* An L-shaped polyline over a 4 x 1 x 1 box (after a transform): tets whose centroid is
 * nearer the first segment follow it, the others the second; the activation track reaches
 * the body. */
static void curve_fibres_follow_the_nearest_segment(void **state) {
  (void)state;
  const char *json =
      "{\"gravity\": [0, 0, 0], \"solids\": [{\"mesh\": {\"generate\": \"box\", \"half_extents\": "
      "[2, 0.5, 0.5], \"cell_size\": 0.25}, \"transform\": {\"translate\": [2, 0, 0]}, "
      "\"material\": {\"model\": \"muscle\", \"youngs_modulus\": 1e4, \"poisson_ratio\": 0.4}, "
      "\"fibers\": {\"curve\": [[0, 0, 0], [3, 0, 0], [3, 0, 2]]}, "
      "\"activation\": {\"keys\": [[0, 0.2], [1, 0.8]]}}]}";
  piola_scene *scene;
  assert_int_equal(piola_scene_load_string(json, ".", "curve.json", &scene), PIOLA_OK);
  piola_world *world = piola_scene_world(scene);
  const piola_elastic_body *body = piola_world_solid_body(world, 0);
  const double *a = piola_elastic_body_fiber_directions(body);
  assert_non_null(a);
  const double *x = piola_elastic_body_rest_positions(body);
  const int32_t *tets = piola_elastic_body_tets(body);
  int along_x = 0, along_z = 0;
  for (int32_t t = 0; t < piola_elastic_body_tet_count(body); ++t) {
    double c[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int i = 0; i < 3; ++i) c[i] += 0.25 * x[3 * tets[4 * t + k] + i];
    /* distance to segment 1 (x axis, 0..3) and to segment 2 (x = 3, z from 0 to 2) */
    const double cx1 = fmin(fmax(c[0], 0), 3), d1 = hypot(hypot(c[0] - cx1, c[1]), c[2]);
    const double cz2 = fmin(fmax(c[2], 0), 2), d2 = hypot(hypot(c[0] - 3, c[1]), c[2] - cz2);
    if (fabs(d1 - d2) < 1e-9) continue;
    const double *e = a + 3 * t;
    if (d1 < d2) {
      assert_true(e[0] == 1.0 && e[1] == 0.0 && e[2] == 0.0);
      ++along_x;
    } else {
      assert_true(e[0] == 0.0 && e[1] == 0.0 && e[2] == 1.0);
      ++along_z;
    }
  }
  assert_true(along_x > 0 && along_z > 0);
  assert_close(piola_elastic_body_activation(body), 0.2, 1e-15);
  assert_int_equal(piola_world_advance_to(world, 0.25, NULL), PIOLA_OK);
  body = piola_world_solid_body(world, 0);
  /* set at the last force update, at t = 0.25 */
  assert_close(piola_elastic_body_activation(body), 0.35, 1e-12);
  piola_scene_destroy(scene);
}

static void fibres_from_the_mesh_need_mesh_data(void **state) {
  (void)state;
  const char *json =
      "{\"solids\": [{\"mesh\": {\"generate\": \"box\", \"half_extents\": [1, 1, 1], "
      "\"cell_size\": 0.5}, \"material\": {\"model\": \"muscle\"}, \"fibers\": {\"from_mesh\": true}}]}";
  piola_scene *scene = NULL;
  assert_int_not_equal(piola_scene_load_string(json, ".", "mesh.json", &scene), PIOLA_OK);
  assert_non_null(strstr(piola_last_error(), "solids[0].fibers.from_mesh"));
  assert_non_null(strstr(piola_last_error(), "no per-tet fibre data"));
}

/* Fibres written into a .vtu cell array reach the body, turned with the solid's transform. */
static void fibres_from_the_mesh_file_reach_the_body(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(2, 2, 3, (piola_vec3){0.01, 0.01, 0.02}, &mesh), PIOLA_OK);
  mesh.tet_fibers = malloc(sizeof(double) * 3 * (size_t)mesh.tet_count);
  assert_non_null(mesh.tet_fibers);
  for (int32_t t = 0; t < mesh.tet_count; ++t) { /* a different direction per tet */
    mesh.tet_fibers[3 * t] = 1.0;
    mesh.tet_fibers[3 * t + 1] = 0.1 * (t % 7);
    mesh.tet_fibers[3 * t + 2] = 2.0 + 0.05 * (t % 5);
  }
  char dir[] = "/tmp/piola_fibres_XXXXXX";
  assert_non_null(mkdtemp(dir));
  char path[256];
  snprintf(path, sizeof path, "%s/fibres.vtu", dir);
  assert_int_equal(piola_tet_mesh_write(path, &mesh), PIOLA_OK);
  /* a quarter turn about z maps (x, y, z) to (-y, x, z) */
  const char *json =
      "{\"solids\": [{\"mesh\": \"fibres.vtu\", \"transform\": {\"rotate_degrees\": [0, 0, 90]}, "
      "\"material\": {\"model\": \"muscle\"}, \"fibers\": {\"from_mesh\": true}}]}";
  piola_scene *scene = NULL;
  assert_int_equal(piola_scene_load_string(json, dir, "fibres.json", &scene), PIOLA_OK);
  const piola_elastic_body *body = piola_world_solid_body(piola_scene_world(scene), 0);
  const double *a = piola_elastic_body_fiber_directions(body);
  assert_int_equal(piola_elastic_body_tet_count(body), mesh.tet_count);
  for (int32_t t = 0; t < mesh.tet_count; ++t) {
    const double *g = mesh.tet_fibers + 3 * t;
    const double n = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    assert_close(a[3 * t], -g[1] / n, 1e-12);
    assert_close(a[3 * t + 1], g[0] / n, 1e-12);
    assert_close(a[3 * t + 2], g[2] / n, 1e-12);
  }
  piola_scene_destroy(scene);
  piola_tet_mesh_free(&mesh);
  remove(path);
  rmdir(dir);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(keys_reach_their_definitions),
      cmocka_unit_test(bad_muscle_keys_name_their_path),
      cmocka_unit_test(curve_fibres_follow_the_nearest_segment),
      cmocka_unit_test(fibres_from_the_mesh_need_mesh_data),
      cmocka_unit_test(fibres_from_the_mesh_file_reach_the_body),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
