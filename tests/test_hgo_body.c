/* The Holzapfel-Gasser-Ogden model in an elastic body and a scene: forces are minus the
 * gradient of the body's energy (fibre energy included) with uniform and mixed materials,
 * an inverted tet with stiff fibres is pushed back, the explicit step's modulus bounds the
 * fibres' stiffness at the current state, and the scene keys (material.hgo, fibers.around)
 * reach the body or fail naming their key. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "force/elastic_body_internal.h"
#include "force/element_stiffness.h"
#include "force/stable_step.h"
#include "piola/diagonalize.h"
#include "piola/scene.h"
#include "piola/world.h"
#include "scene/scene_desc.h"
#include "test_elastic_body_fixtures.h"

static piola_material hgo(double kappa) {
  piola_material_def def = piola_default_material_def();
  def.model = PIOLA_MODEL_HGO;
  def.poisson_ratio = 0.45;
  def.hgo.mu = 1e4;
  def.hgo.k1 = 2e4;
  def.hgo.k2 = 2.0;
  def.hgo.kappa = kappa;
  def.hgo.fiber_angle_degrees = 40.0;
  piola_material m;
  assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
  return m;
}

/* Random fibres, never parallel to the default axis z. */
static double *random_fibers(test_rng *rng, int32_t tets) {
  double *a = malloc(sizeof(double) * 3 * (size_t)tets);
  for (int32_t t = 0; t < tets; ++t) {
    a[3 * t] = test_rng_uniform(rng, 0.3, 1);
    a[3 * t + 1] = test_rng_uniform(rng, -1, 1);
    a[3 * t + 2] = test_rng_uniform(rng, -1, 1);
  }
  return a;
}

static void forces_are_minus_the_energy_gradient(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(191);
  piola_tet_mesh mesh = fixture_grid(2, 0.1);
  const int n = 3 * mesh.vertex_count;
  double *fibers = random_fibers(&rng, mesh.tet_count);
  const piola_material mats[2] = {hgo(0.0), hgo(0.2)};
  const piola_material mixed[2] = {hgo(0.1), fixture_material(PIOLA_MODEL_NEOHOOKEAN)};
  int32_t *which = malloc(sizeof(int32_t) * (size_t)mesh.tet_count);
  for (int32_t t = 0; t < mesh.tet_count; ++t) which[t] = t % 3 == 1;
  double *x = malloc(sizeof(double) * (size_t)n), *f = malloc(sizeof(double) * (size_t)n);
  double *scratch = malloc(sizeof(double) * (size_t)n);
  for (int variant = 0; variant < 3; ++variant) {
    piola_elastic_body *body = variant < 2 ? fixture_body_with_fibers(&mesh, &mats[variant], 1, NULL, fibers)
                                           : fixture_body_with_fibers(&mesh, mixed, 2, which, fibers);
    for (int s = 0; s < 2; ++s) {
      /* stretched (fibres engaged, far up the exponential for s = 1) plus noise */
      for (int i = 0; i < n; ++i)
        x[i] = mesh.positions[i] * (i % 3 == 0 ? 1.2 + 0.4 * s : 0.97) +
               0.005 * test_rng_uniform(&rng, -1, 1);
      piola_elastic_stats st;
      assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, &st), PIOLA_OK);
      char what[48];
      snprintf(what, sizeof what, "variant %d sample %d", variant, s);
      fixture_check_energy_gradient(body, x, n, f, 1e-7, 1e-5, what);
      const double scale = fixture_max_abs(f, n);
      /* the fibres matter: without them the forces differ */
      piola_elastic_body *plain = variant < 2 ? fixture_body_with_fibers(&mesh, &mats[variant], 1, NULL, NULL)
                                              : fixture_body_with_fibers(&mesh, mixed, 2, which, NULL);
      assert_int_equal(piola_elastic_body_update(plain, x, 1.0, scratch, NULL), PIOLA_OK);
      double diff = 0;
      for (int i = 0; i < n; ++i) diff = fmax(diff, fabs(scratch[i] - f[i]));
      assert_true(diff > 0.05 * scale);
      piola_elastic_body_destroy(plain);
    }
    piola_elastic_body_destroy(body);
  }
  free(which), free(fibers), free(x), free(f), free(scratch);
  fixture_mesh_free(&mesh);
}

static void inverted_tet_with_stiff_fibres_is_pushed_back(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(192);
  piola_tet_mesh mesh = fixture_single_tet(1.0);
  piola_material_def def = piola_default_material_def();
  def.model = PIOLA_MODEL_HGO;
  def.poisson_ratio = 0.45;
  def.hgo.mu = 1e3; /* soft matrix, fibres 1000x stiffer */
  def.hgo.k1 = 1e6;
  def.hgo.kappa = 0.2;
  piola_material m;
  assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
  for (long k = 0; k < test_samples(300, 20); ++k) {
    double a[3] = {test_rng_normal(&rng) + 1e-3, test_rng_normal(&rng), test_rng_normal(&rng)};
    piola_elastic_body *body = fixture_body_with_fibers(&mesh, &m, 1, NULL, a);
    int32_t inverted;
    (void)fixture_check_apex_pushed_back(body, &mesh, &rng, a, &inverted);
    piola_elastic_body_destroy(body);
  }
  fixture_mesh_free(&mesh);
}

/* The step bound's modulus at a state is at least dF : C : dF for unit rank-one dF (plane
 * waves) of the whole material, fibres included, and grows with the fibre stretch. */
static void step_modulus_bounds_the_fibre_stiffness(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(193);
  piola_tet_mesh mesh = fixture_single_tet(1.0);
  const piola_material m = hgo(0.1);
  const double fiber[3] = {1, 0.2, 0.1};
  piola_elastic_body *body = fixture_body_with_fibers(&mesh, &m, 1, NULL, fiber);
  double previous = 0;
  for (int s = 0; s < 6; ++s) {
    const double stretch = 1.0 + 0.25 * s;
    const double fhat[3] = {stretch, 0.9, 1.0 / (0.9 * stretch)};
    const double bound = piola__elastic_body_tet_modulus(body, 0, fhat);
    assert_true(bound > previous);
    previous = bound;
    /* fibres in the diagonal frame: F = diag(fhat), any rotation of the fibre */
    const piola_mat3 f = {{{fhat[0], 0, 0}, {0, fhat[1], 0}, {0, 0, fhat[2]}}};
    for (int k = 0; k < 200; ++k) {
      double a[3] = {test_rng_normal(&rng), test_rng_normal(&rng), test_rng_normal(&rng)};
      double c[81];
      piola__element_dpdf(&m, &f, a, 0.0, 0, c);
      double u[3] = {test_rng_normal(&rng), test_rng_normal(&rng), test_rng_normal(&rng)};
      double w[3] = {test_rng_normal(&rng), test_rng_normal(&rng), test_rng_normal(&rng)};
      const double nu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      const double nw = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
      double d[9], q = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) d[3 * i + j] = u[i] * w[j] / (nu * nw);
      for (int r = 0; r < 9; ++r)
        for (int cc = 0; cc < 9; ++cc) q += d[r] * c[9 * r + cc] * d[cc];
      if (!(q <= bound * (1 + 1e-9)))
        fail_msg("stretch %g: plane-wave stiffness %g above the bound %g", stretch, q, bound);
    }
  }
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

#define HGO_SOLID(x) "{\"solids\": [{\"mesh\": \"a.veg\", \"material\": {\"model\": \"hgo\"" x "}]}"

static void scene_keys_reach_the_material(void **state) {
  (void)state;
  scene_desc d;
  const char *json =
      "{\"solids\": [{\"mesh\": \"a.veg\", \"material\": {\"model\": \"hgo\", \"poisson_ratio\": 0.49, "
      "\"hgo\": {\"mu\": 7640, \"k1\": 996600, \"k2\": 524.6, \"kappa\": 0.226, "
      "\"fiber_angle_degrees\": 49.98, \"axis\": [0, 2, 0], \"fiber_stretch_limit\": 1.4}}, "
      "\"fibers\": {\"around\": {\"axis\": [0, 3, 0], \"point\": [1, 0, 2]}}}]}";
  assert_int_equal(piola__scene_parse(json, ".", "t", &d), PIOLA_OK);
  const scene_solid_desc *s = &d.solids[0];
  const piola_hgo_def *h = &s->def.material.hgo;
  assert_int_equal(s->def.material.model, PIOLA_MODEL_HGO);
  assert_true(h->mu == 7640 && h->k1 == 996600 && h->k2 == 524.6 && h->kappa == 0.226);
  assert_true(h->fiber_angle_degrees == 49.98 && h->fiber_stretch_limit == 1.4);
  assert_true(h->axis[0] == 0 && h->axis[1] == 1 && h->axis[2] == 0);
  assert_int_equal(s->fibers.kind, SCENE_FIBERS_AROUND);
  assert_true(s->fibers.axis.y == 1 && s->fibers.point.x == 1 && s->fibers.point.z == 2);
  piola__scene_desc_free(&d);
}

typedef struct bad_case {
  const char *json;
  const char *expected;
} bad_case;

static const bad_case BAD[] = {
    {HGO_SOLID(", \"hgo\": {\"kappa\": 0.5}}"), "solids[0].material.hgo.kappa: must be in [0, 0.333"},
    {HGO_SOLID(", \"hgo\": {\"k1\": -1}}"), "solids[0].material.hgo.k1: must be >= 0"},
    {HGO_SOLID(", \"hgo\": {\"k2\": 0}}"), "solids[0].material.hgo.k2: must be > 0"},
    {HGO_SOLID(", \"hgo\": {\"mu\": 0}}"), "solids[0].material.hgo.mu: must be > 0"},
    {HGO_SOLID(", \"hgo\": {\"fiber_angle_degrees\": 95}}"), "solids[0].material.hgo.fiber_angle_degrees: must be in [0, 90]"},
    {HGO_SOLID(", \"hgo\": {\"fiber_stretch_limit\": 1}}"), "solids[0].material.hgo.fiber_stretch_limit: must be > 1"},
    {HGO_SOLID(", \"hgo\": {\"axis\": [0, 0, 0]}}"), "solids[0].material.hgo.axis: must be a nonzero vector"},
    {HGO_SOLID(", \"hgo\": {\"beta\": 30}}"), "solids[0].material.hgo.beta: unknown key"},
    {HGO_SOLID("}, \"fibers\": {\"around\": {\"point\": [0, 0, 0]}}"), "solids[0].fibers.around.axis"},
    {HGO_SOLID("}, \"fibers\": {\"around\": [0, 0, 1]}"), "solids[0].fibers.around: must be an object"},
    {"{\"solids\": [{\"mesh\": \"a.veg\", \"material\": {\"hgo\": {}}}]}", "solids[0].material.hgo: needs \"model\": \"hgo\""},
    {"{\"shells\": [{\"mesh\": \"a.obj\", \"thickness\": 0.001, \"material\": {\"model\": \"hgo\"}}]}", "shells[0].material.model: \"hgo\" is for solids only"},
};

static void bad_keys_name_their_path(void **state) {
  (void)state;
  for (size_t i = 0; i < sizeof BAD / sizeof BAD[0]; ++i) {
    scene_desc d;
    piola_clear_error();
    if (piola__scene_parse(BAD[i].json, ".", "bad.json", &d) == PIOLA_OK)
      fail_msg("case %zu was accepted: %s", i, BAD[i].json);
    if (!strstr(piola_last_error(), BAD[i].expected))
      fail_msg("case %zu: message '%s' does not contain '%s'", i, piola_last_error(), BAD[i].expected);
  }
}

/* A tube (a cylinder's mesh with the core unused) with circumferential fibres about its
 * axis: every tet's fibre is perpendicular to the axis and to its centroid's radius; fibres
 * parallel to hgo.axis are refused when the body is built. */
static void around_fibres_are_circumferential(void **state) {
  (void)state;
  const char *json =
      "{\"gravity\": [0, 0, 0], \"solids\": [{\"mesh\": {\"generate\": \"cylinder\", \"radius\": 1, "
      "\"half_length\": 1, \"cell_size\": 0.4}, \"transform\": {\"translate\": [2, 3, 0]}, "
      "\"material\": {\"model\": \"hgo\"}, \"fibers\": {\"around\": {\"axis\": [0, 0, 1], "
      "\"point\": [2, 3, 0]}}}]}";
  piola_scene *scene;
  assert_int_equal(piola_scene_load_string(json, ".", "tube.json", &scene), PIOLA_OK);
  const piola_elastic_body *body = piola_world_solid_body(piola_scene_world(scene), 0);
  const double *a = piola_elastic_body_fiber_directions(body);
  assert_non_null(a);
  const double *x = piola_elastic_body_rest_positions(body);
  const int32_t *tets = piola_elastic_body_tets(body);
  for (int32_t t = 0; t < piola_elastic_body_tet_count(body); ++t) {
    double c[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int i = 0; i < 3; ++i) c[i] += 0.25 * x[3 * tets[4 * t + k] + i];
    const double *e = a + 3 * t, rx = c[0] - 2, ry = c[1] - 3, rn = hypot(rx, ry);
    assert_close(e[2], 0.0, 1e-12);
    assert_close(e[0] * rx + e[1] * ry, 0.0, 1e-12 * rn);
    assert_close(e[0] * -ry + e[1] * rx, rn, 1e-12 * rn); /* counter-clockwise about +z */
  }
  assert_int_equal(piola_world_advance_to(piola_scene_world(scene), 0.01, NULL), PIOLA_OK);
  piola_scene_destroy(scene);
  /* fibres along the default axis z: no plane for the families */
  const char *parallel =
      "{\"solids\": [{\"mesh\": {\"generate\": \"box\", \"half_extents\": [0.5, 0.5, 0.5], "
      "\"cell_size\": 0.5}, \"material\": {\"model\": \"hgo\"}, \"fibers\": {\"axis\": [0, 0, 1]}}]}";
  piola_clear_error();
  assert_int_not_equal(piola_scene_load_string(parallel, ".", "p.json", &scene), PIOLA_OK);
  assert_non_null(strstr(piola_last_error(), "parallel to material.hgo.axis"));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(forces_are_minus_the_energy_gradient),
      cmocka_unit_test(inverted_tet_with_stiff_fibres_is_pushed_back),
      cmocka_unit_test(step_modulus_bounds_the_fibre_stiffness),
      cmocka_unit_test(scene_keys_reach_the_material),
      cmocka_unit_test(bad_keys_name_their_path),
      cmocka_unit_test(around_fibres_are_circumferential),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
