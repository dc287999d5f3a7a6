/* The scene key `shells`: every key reaches the shell definition, defaults hold, bad input
 * names its key path, and a loaded scene has the shell in its world with generated meshes
 * placed by their transform. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/keyframes.h"
#include "piola/scene.h"
#include "piola/world_shells.h"
#include "scene/scene_desc.h"
#include "scene_cases.h"

static const char *FULL =
    "{\"shells\": [{\"name\": \"cape\", \"mesh\": {\"generate\": \"rectangle\", \"size\": [2, 1], "
    "\"resolution\": [4, 2]},\n"
    "  \"transform\": {\"translate\": [0, 0, 1], \"rotate_degrees\": [90, 0, 0]}, \"thickness\": 0.002,\n"
    "  \"density\": 300, \"material\": {\"model\": \"stvk\", \"youngs_modulus\": 3e5, \"poisson_ratio\": 0.2},\n"
    "  \"damping\": {\"shear\": 0.5, \"bulk\": 0.25},\n"
    "  \"bending\": {\"stiffness\": 1e-4, \"damping\": 2e-5, \"plasticity\": {\"yield_angle_degrees\": 10, \"rate\": 5}},\n"
    "  \"plasticity\": {\"yield_strain\": 0.05, \"rate\": 7, \"max_plastic_stretch\": 3},\n"
    "  \"reference_normals\": true, \"velocity\": [0, 1, 0], \"collide_with_solids\": true,\n"
    "  \"solid_friction\": 0.1,\n"
    "  \"fixed\": [{\"indices\": [0, 4]}]},\n"
    " {\"mesh\": {\"generate\": \"disk\", \"radius\": 0.5, \"rings\": 3}},\n"
    " {\"mesh\": {\"generate\": \"torus\", \"radius\": 0.5, \"minor_radius\": 0.1, \"segments\": [8, 6], "
    "\"sweep_degrees\": 180}},\n"
    " {\"mesh\": \"cloth.obj\"}]}";

static void every_shell_key_reaches_its_definition(void **state) {
  (void)state;
  scene_desc d;
  if (piola__scene_parse(FULL, "/base", "t", &d) != PIOLA_OK) fail_msg("%s", piola_last_error());
  assert_int_equal(d.solid_count, 0);
  assert_int_equal(d.shell_count, 4);
  const scene_shell_desc *s = &d.shells[0];
  assert_string_equal(s->base.name, "cape");
  assert_int_equal(s->generator, 1);
  assert_close(s->size[0], 2, 0);
  assert_int_equal(s->resolution[1], 2);
  assert_close(s->base.translate.z, 1, 0);
  assert_close(s->base.rotate_degrees.x, 90, 0);
  assert_close(s->def.thickness, 0.002, 0);
  assert_close(s->base.def.density, 300, 0);
  assert_int_equal(s->base.def.material.model, PIOLA_MODEL_STVK);
  assert_close(s->base.def.material.youngs_modulus, 3e5, 0);
  assert_close(piola_track_eval(&s->base.def.shear_viscosity, 0), 0.5, 0);
  assert_close(piola_track_eval(&s->base.def.bulk_viscosity, 0), 0.25, 0);
  assert_close(s->def.bending.stiffness, 1e-4, 0);
  assert_close(s->def.bending.damping, 2e-5, 0);
  assert_close(s->def.bending.yield_angle, 10 * M_PI / 180, 1e-15);
  assert_close(s->def.bending.plastic_rate, 5, 0);
  assert_close(s->def.plasticity.yield_strain, 0.05, 0);
  assert_close(s->def.plasticity.rate, 7, 0);
  assert_close(s->def.plasticity.max_plastic_stretch, 3, 0);
  assert_true(s->def.use_reference_normals);
  assert_true(s->def.collide_with_solids);
  assert_close(s->def.solid_friction, 0.1, 0);
  assert_close(s->base.def.velocity.y, 1, 0);
  assert_int_equal(s->base.constraint_count, 1);
  /* defaults */
  s = &d.shells[1];
  assert_string_equal(s->base.name, "shell1");
  assert_int_equal(s->generator, 2);
  assert_int_equal(s->resolution[0], 3);
  assert_close(s->def.thickness, 1e-3, 0);
  assert_close(s->def.bending.stiffness, 0, 0);
  assert_true(isinf(s->def.bending.yield_angle));
  assert_true(isinf(s->def.plasticity.yield_strain));
  assert_false(s->def.use_reference_normals);
  assert_false(s->def.collide_with_solids);
  assert_close(s->def.solid_friction, 0.3, 0);
  assert_int_equal(d.shells[2].generator, 3);
  assert_close(d.shells[2].sweep_degrees, 180, 0);
  assert_int_equal(d.shells[3].generator, 0);
  assert_string_equal(d.shells[3].base.mesh_path, "/base/cloth.obj");
  piola__scene_desc_free(&d);
}

static const bad_scene_case BAD[] = {
    {"{\"shells\": {}}", "shells: must be an array"},
    {"{\"shells\": [{}]}", "shells[0].mesh: is required"},
    {"{\"shells\": [{\"mesh\": 3}]}", "shells[0].mesh: must be a triangle mesh file path"},
    {"{\"shells\": [{\"mesh\": {\"generate\": \"cube\"}}]}", "shells[0].mesh.generate: must be"},
    {"{\"shells\": [{\"mesh\": {\"generate\": \"rectangle\", \"size\": [1, 0], \"resolution\": [2, 2]}}]}",
     "shells[0].mesh.size"},
    {"{\"shells\": [{\"mesh\": {\"generate\": \"rectangle\", \"size\": [1, 1], \"resolution\": [2, 0.5]}}]}",
     "shells[0].mesh.resolution: must be two integers"},
    {"{\"shells\": [{\"mesh\": {\"generate\": \"disk\", \"radius\": 1}}]}", "shells[0].mesh.rings: is required"},
    {"{\"shells\": [{\"mesh\": {\"generate\": \"torus\", \"radius\": 1, \"minor_radius\": 2, \"segments\": [8, 8]}}]}",
     "shells[0].mesh.minor_radius: must be smaller"},
    {"{\"shells\": [{\"mesh\": \"a.obj\", \"thickness\": 0}]}", "shells[0].thickness"},
    {"{\"shells\": [{\"mesh\": \"a.obj\", \"bendng\": {}}]}", "shells[0].bendng: unknown key"},
    {"{\"shells\": [{\"mesh\": \"a.obj\", \"bending\": {\"stiffness\": -1}}]}", "shells[0].bending.stiffness"},
    {"{\"shells\": [{\"mesh\": \"a.obj\", \"bending\": {\"plasticity\": {\"rate\": 1}}}]}",
     "shells[0].bending.plasticity.yield_angle_degrees: is required"},
    {"{\"shells\": [{\"mesh\": \"a.obj\", \"plasticity\": {\"yield_strain\": 0.1, \"max_plastic_stretch\": 1}}]}",
     "shells[0].plasticity.max_plastic_stretch"},
    {"{\"shells\": [{\"mesh\": \"a.obj\", \"reference_normals\": 1}]}", "shells[0].reference_normals: must be true or false"},
    {"{\"shells\": [{\"mesh\": \"a.obj\", \"name\": \"x\"}, {\"mesh\": \"b.obj\", \"name\": \"x\"}]}",
     "shells[1].name: \"x\" is already the name of shells[0]"},
    {"{\"obstacles\": []}", "solids: is required"},
};

static void bad_shell_input_names_its_key_path(void **state) {
  (void)state;
  assert_bad_scenes_refused(BAD, sizeof BAD / sizeof BAD[0]);
}

/* A cloth-only scene loads, its generated sheet is placed by the transform, and the fixed
 * selector holds the nodes it names. */
static void cloth_scene_builds_its_world(void **state) {
  (void)state;
  const char *json =
      "{\"shells\": [{\"name\": \"cloth\", \"mesh\": {\"generate\": \"rectangle\", \"size\": [1, 1], "
      "\"resolution\": [4, 4]}, \"transform\": {\"translate\": [0, 0, 2]},\n"
      "  \"bending\": {\"stiffness\": 1e-4}, \"fixed\": [{\"box\": [[-1, 0.49, 1], [1, 1, 3]]}]}],\n"
      " \"obstacles\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 0, 1]}]}";
  piola_scene *scene;
  if (piola_scene_load_string(json, ".", "cloth", &scene) != PIOLA_OK) fail_msg("%s", piola_last_error());
  piola_world *world = piola_scene_world(scene);
  assert_int_equal(piola_world_solid_count(world), 0);
  assert_int_equal(piola_world_shell_count(world), 1);
  assert_string_equal(piola_world_shell_name(world, 0), "cloth");
  const double *x = piola_world_shell_positions(world, 0);
  const uint8_t *flags = piola_world_shell_constraint_flags(world, 0);
  int fixed = 0;
  for (int i = 0; i < 25; ++i) {
    assert_close(x[3 * i + 2], 2.0, 1e-15);
    fixed += flags[i] != 0;
  }
  assert_int_equal(fixed, 5); /* the row y = +0.5 */
  assert_int_equal(piola_world_advance_to(world, 0.02, NULL), PIOLA_OK);
  x = piola_world_shell_positions(world, 0);
  assert_true(x[2] < 2.0);      /* a free corner falls */
  assert_close(x[3 * 24 + 2], 2.0, 1e-12); /* a pinned one does not */
  piola_scene_destroy(scene);
}

static double det3(double m[3][3]) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

/* Cloth (16 cm, 8 x 8 cells) lying on a fixed solid box tilted 25 degrees, held by
 * collide_with_solids with solid_friction mu, integrator "newmark" or "backward_euler": the
 * sliding acceleration of its mean position down the slope over 0.1-0.4 s, fitted, and in
 * *moved how far it went down the slope in that time (m). */
static double cloth_slide_acceleration(double mu, const char *integrator, double *moved) {
  const double angle = 25.0 * M_PI / 180.0;
  char json[2048];
  snprintf(json, sizeof json,
           "{\"fps\": 30, \"integrator\": {\"type\": \"%s\"},\n"
           " \"solids\": [{\"mesh\": {\"generate\": \"box\", \"half_extents\": [0.3, 0.3, 0.05],"
           " \"cell_size\": 0.05}, \"transform\": {\"rotate_degrees\": [25, 0, 0]},"
           " \"fixed\": [{\"box\": [[-1, -1, -1], [1, 1, 1]]}]}],\n"
           " \"shells\": [{\"mesh\": {\"generate\": \"rectangle\", \"size\": [0.16, 0.16],"
           " \"resolution\": [8, 8]}, \"transform\": {\"rotate_degrees\": [25, 0, 0],"
           " \"translate\": [0, %.17g, %.17g]}, \"thickness\": 0.0005, \"density\": 300,"
           " \"material\": {\"model\": \"corotated\", \"youngs_modulus\": 5e5},"
           " \"damping\": {\"shear\": 0.2, \"bulk\": 0.2}, \"bending\": {\"stiffness\": 1e-5},"
           " \"collide_with_solids\": true, \"solid_friction\": %.17g}]}",
           integrator, -0.053 * sin(angle), 0.053 * cos(angle), mu);
  piola_scene *scene = NULL;
  if (piola_scene_load_string(json, ".", NULL, &scene) != PIOLA_OK)
    fail_msg("%s", piola_last_error());
  piola_world *w = piola_scene_world(scene);
  const int32_t n = piola_shell_body_vertex_count(piola_world_shell_body(w, 0));
  const double down[3] = {0, -cos(angle), -sin(angle)};
  /* least squares of s(t) = c0 + c1 t + c2 t^2 over frames 3..12 */
  double sums[5] = {0}, rhs[3] = {0};
  for (int frame = 1; frame <= 12; ++frame) {
    const double t = frame / 30.0;
    assert_int_equal(piola_world_advance_to(w, t, NULL), PIOLA_OK);
    if (frame < 3) continue;
    const double *x = piola_world_shell_positions(w, 0);
    double along = 0;
    for (int32_t i = 0; i < n; ++i)
      along += (x[3 * i] * down[0] + x[3 * i + 1] * down[1] + x[3 * i + 2] * down[2]) / n;
    for (int k = 0; k < 5; ++k) sums[k] += pow(t, k);
    for (int k = 0; k < 3; ++k) rhs[k] += pow(t, k) * along;
    if (frame == 3) *moved = -along;
    if (frame == 12) *moved += along;
  }
  piola_scene_destroy(scene);
  /* the normal equations by Cramer's rule: c2 = det(A with its last column rhs) / det(A) */
  double a[3][3], b[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a[r][c] = b[r][c] = sums[r + c];
  for (int r = 0; r < 3; ++r) b[r][2] = rhs[r];
  return 2.0 * det3(b) / det3(a);
}

/* A cloth held by a solid's surface (collide_with_solids) feels Coulomb friction with its
 * solid_friction, as on an obstacle, and stays where mu > tan of the slope: with Newmark it slid at
 * g (sin - mu/2 cos), the friction of the half of the normal impulse the collision step applies,
 * until the friction after the final solve took the shell's coefficient and the solid's surface
 * velocity (it took the nearest obstacle's, none here). */
static void cloth_on_a_tilted_solid_slides_as_coulomb_says(void **state) {
  (void)state;
  const double angle = 25.0 * M_PI / 180.0, g = 9.81;
  const double mus[2] = {0.2, 0.4};
  const char *integrators[2] = {"newmark", "backward_euler"};
  double moved = 0;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j) {
      const double a = cloth_slide_acceleration(mus[k], integrators[j], &moved);
      const double coulomb = g * (sin(angle) - mus[k] * cos(angle));
      if (getenv("PIOLA_TEST_VERBOSE"))
        print_message("%s, mu %g: %.4f m/s^2 (Coulomb %.4f)\n", integrators[j], mus[k], a, coulomb);
      if (!(fabs(a - coulomb) < 0.01 * g))
        fail_msg("%s, mu %g: slides at %.4f m/s^2, Coulomb says %.4f", integrators[j], mus[k], a,
                 coulomb);
    }
  /* mu = 1 > tan 25 degrees: it stays. Backward Euler's friction after the solve took the
   * holds that gave back the potential energy the frictionless solve had spent for a rise,
   * and the cloth crept down at dt g sin 25 degrees (13.8 cm/s at one step per frame) */
  for (int j = 0; j < 2; ++j) {
    (void)cloth_slide_acceleration(1.0, integrators[j], &moved);
    if (getenv("PIOLA_TEST_VERBOSE"))
      print_message("%s, mu 1: moved %.3g m in 0.3 s\n", integrators[j], moved);
    if (!(fabs(moved) < 1e-3)) fail_msg("%s, mu 1: crept %.4g m in 0.3 s", integrators[j], moved);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(every_shell_key_reaches_its_definition),
      cmocka_unit_test(bad_shell_input_names_its_key_path),
      cmocka_unit_test(cloth_scene_builds_its_world),
      cmocka_unit_test(cloth_on_a_tilted_solid_slides_as_coulomb_says),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
