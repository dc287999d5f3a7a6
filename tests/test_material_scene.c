/* Scene keys of the models and inversion mode beyond the paper: material.model
 * "stable_neohookean", "mooney_rivlin", "ogden" with material.mooney_rivlin and
 * material.ogden, material.inversion.mode "energy"; errors name the key path; a loaded scene
 * with each runs. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "piola/elastic_body.h"
#include "piola/scene.h"
#include "piola/world.h"
#include "scene/scene_desc.h"
#include "scene_cases.h"
#include "test_support.h"

static void keys_reach_their_definitions(void **state) {
  (void)state;
  scene_desc d;
  const char *json =
      "{\"solids\": ["
      "{\"mesh\": \"a.veg\", \"material\": {\"model\": \"stable_neohookean\", \"inversion\": "
      "{\"mode\": \"energy\", \"threshold\": 0.4}}},"
      "{\"mesh\": \"a.veg\", \"material\": {\"model\": \"ogden\", \"poisson_ratio\": 0.45, "
      "\"ogden\": {\"mu\": [6e5, -1e4], \"alpha\": [1.5, -2]}}},"
      "{\"mesh\": \"a.veg\", \"material\": {\"model\": \"mooney_rivlin\", \"mooney_rivlin\": "
      "{\"c10\": 2e4, \"c01\": -1e3}}},"
      "{\"mesh\": \"a.veg\", \"material\": {\"model\": \"ogden\"}}]}";
  assert_int_equal(piola__scene_parse(json, ".", "t", &d), PIOLA_OK);
  const piola_material_def *a = &d.solids[0].def.material, *b = &d.solids[1].def.material;
  const piola_material_def *c = &d.solids[2].def.material, *e = &d.solids[3].def.material;
  assert_int_equal(a->model, PIOLA_MODEL_STABLE_NEOHOOKEAN);
  assert_int_equal(a->inversion_mode, PIOLA_INVERSION_ENERGY);
  assert_true(a->inversion_threshold == 0.4);
  assert_int_equal(b->model, PIOLA_MODEL_OGDEN);
  assert_int_equal(b->ogden.term_count, 2);
  assert_true(b->ogden.mu[0] == 6e5 && b->ogden.mu[1] == -1e4);
  assert_true(b->ogden.alpha[0] == 1.5 && b->ogden.alpha[1] == -2);
  assert_int_equal(c->model, PIOLA_MODEL_MOONEY_RIVLIN);
  assert_true(c->mooney_rivlin.c10 == 2e4 && c->mooney_rivlin.c01 == -1e3);
  const piola_material_def def = piola_default_material_def();
  assert_memory_equal(&e->ogden, &def.ogden, sizeof def.ogden); /* Ogden's 1972 fit */
  piola__scene_desc_free(&d);
}

#define SOLID(m) "{\"solids\": [{\"mesh\": \"a.veg\", \"material\": " m "}]}"

static const bad_scene_case BAD[] = {
    {SOLID("{\"inversion\": {\"mode\": \"energetic\"}}"),
     "solids[0].material.inversion.mode: must be \"linear\", \"clamp\", \"energy\" or \"default\""},
    {SOLID("{\"model\": \"stable-neohookean\"}"), "solids[0].material.model: must be one of"},
    {SOLID("{\"ogden\": {\"mu\": [1], \"alpha\": [2]}}"),
     "solids[0].material.ogden: needs \"model\": \"ogden\""},
    {SOLID("{\"model\": \"ogden\", \"ogden\": {\"mu\": [1e5, 2e3], \"alpha\": [2]}}"),
     "solids[0].material.ogden: mu has 2 terms and alpha 1"},
    {SOLID("{\"model\": \"ogden\", \"ogden\": {\"mu\": [1e5], \"alpha\": [0]}}"),
     "solids[0].material.ogden.alpha[0]: must be nonzero"},
    {SOLID("{\"model\": \"ogden\", \"ogden\": {\"mu\": [], \"alpha\": []}}"),
     "solids[0].material.ogden.mu: must be an array of 1 to 6 numbers"},
    {SOLID("{\"model\": \"ogden\", \"ogden\": {\"mu\": [-1e5], \"alpha\": [2]}}"),
     "solids[0].material.ogden: the shear modulus"},
    {SOLID("{\"model\": \"ogden\", \"ogden\": {\"alpha\": [2]}}"), "solids[0].material.ogden.mu"},
    {SOLID("{\"model\": \"mooney_rivlin\", \"mooney_rivlin\": {\"c10\": -1e4}}"),
     "solids[0].material.mooney_rivlin: c10 + c01 must be > 0"},
    {SOLID("{\"model\": \"mooney_rivlin\", \"mooney_rivlin\": {\"c20\": 1}}"),
     "solids[0].material.mooney_rivlin.c20: unknown key"},
    {SOLID("{\"model\": \"neohookean\", \"mooney_rivlin\": {\"c10\": 1}}"),
     "solids[0].material.mooney_rivlin: needs \"model\": \"mooney_rivlin\""},
    {SOLID("{\"model\": \"neohookean\", \"spline\": {\"stiffening\": 5}}"),
     "solids[0].material.spline: needs \"model\": \"spline\""},
};

static void bad_keys_name_their_path(void **state) {
  (void)state;
  assert_bad_scenes_refused(BAD, sizeof BAD / sizeof BAD[0]);
}

/* Each new model and the energy mode load and run a few steps with finite results. */
static void scenes_with_the_new_models_run(void **state) {
  (void)state;
  static const char *const materials[] = {
      "{\"model\": \"stable_neohookean\", \"youngs_modulus\": 1e4}",
      "{\"model\": \"neohookean\", \"youngs_modulus\": 1e4, \"inversion\": {\"mode\": \"energy\"}}",
      "{\"model\": \"mooney_rivlin\", \"mooney_rivlin\": {\"c10\": 3e3, \"c01\": 1e3}}",
      "{\"model\": \"ogden\", \"ogden\": {\"mu\": [6e3, 10, -100], \"alpha\": [1.3, 5, -2]}}"};
  for (size_t i = 0; i < sizeof materials / sizeof materials[0]; ++i) {
    char json[1024];
    snprintf(json, sizeof json,
             "{\"frames\": 2, \"solids\": [{\"mesh\": {\"generate\": \"box\", \"half_extents\": "
             "[0.1, 0.1, 0.1], \"cell_size\": 0.05}, \"material\": %s}]}",
             materials[i]);
    piola_scene *scene;
    if (piola_scene_load_string(json, ".", "m.json", &scene) != PIOLA_OK)
      fail_msg("%s: %s", materials[i], piola_last_error());
    piola_world *world = piola_scene_world(scene);
    for (int s = 0; s < 5; ++s) assert_int_equal(piola_world_step(world, 0.002, NULL), PIOLA_OK);
    const piola_elastic_body *body = piola_world_solid_body(world, 0);
    const double *x = piola_world_solid_positions(world, 0);
    for (int32_t v = 0; v < 3 * piola_elastic_body_vertex_count(body); ++v) assert_true(isfinite(x[v]));
    piola_scene_destroy(scene);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(keys_reach_their_definitions),
      cmocka_unit_test(bad_keys_name_their_path),
      cmocka_unit_test(scenes_with_the_new_models_run),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
