/* Bones (piola/world_bones.h, docs/bones.md): attached nodes follow the bone's key-framed
 * pose exactly, the bone pushes the nodes it does not carry out of its shape, a bad
 * attachment leaves the world as it was, scene errors name their key, and an elbow flexed
 * through 150 degrees inverts tets that all recover once the arm is straight again. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "piola/mesh.h"
#include "piola/render.h"
#include "piola/scene.h"
#include "piola/world.h"
#include "piola/world_bones.h"

/* An n^3-cell box grid of cube side `side` (m) with its corner at `corner`. */
static void grid(int32_t n, double side, piola_vec3 corner, piola_tet_mesh *mesh) {
  double h = side / n;
  assert_int_equal(piola_tet_mesh_box_grid(n, n, n, (piola_vec3){h, h, h}, mesh), PIOLA_OK);
  for (int32_t i = 0; i < mesh->vertex_count; ++i) {
    mesh->positions[3 * i] += corner.x;
    mesh->positions[3 * i + 1] += corner.y;
    mesh->positions[3 * i + 2] += corner.z;
  }
}

static piola_world *world_without_gravity(void) {
  piola_world_def wdef = piola_default_world_def();
  wdef.gravity[2] = piola_track_constant(0);
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wdef, &w), PIOLA_OK);
  return w;
}

static void attached_nodes_follow_the_bone_pose_exactly(void **state) {
  (void)state;
  piola_world_def wdef = piola_default_world_def(); /* gravity on: it must not matter */
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wdef, &w), PIOLA_OK);
  piola_tet_mesh mesh = {0};
  grid(4, 0.1, (piola_vec3){0, 0, 0}, &mesh);
  piola_solid_def sdef = piola_default_solid_def();
  sdef.mesh = &mesh;
  sdef.material.youngs_modulus = 2e4;
  assert_int_equal(piola_world_add_solid(w, &sdef, NULL), PIOLA_OK);

  /* a capsule along the bottom edge line y = 0.05, z = 0, moved and turned by POSE keys */
  piola_bone_def bone = piola_default_bone_def();
  bone.shape.type = PIOLA_OBSTACLE_CAPSULE;
  bone.shape.center = (piola_vec3){0.05, 0.05, 0};
  bone.shape.axis = (piola_vec3){1, 0, 0};
  bone.shape.radius = 0.01;
  bone.shape.half_length = 0.05;
  piola_rigid_motion_def *m = &bone.shape.motion;
  m->kind = PIOLA_MOTION_POSE;
  m->pivot = (piola_vec3){0.05, 0.05, 0};
  m->axis = (piola_vec3){0, 1, 0};
  const double times[3] = {0, 0.1, 0.25};
  const double angles[3] = {0, -0.8, 0.3};
  const double tx[3] = {0, 0.02, -0.01}, tz[3] = {0, 0.05, 0.03};
  assert_int_equal(piola_track_from_keys(times, angles, 3, &m->angle), PIOLA_OK);
  assert_int_equal(piola_track_from_keys(times, tx, 3, &m->translation[0]), PIOLA_OK);
  assert_int_equal(piola_track_from_keys(times, tz, 3, &m->translation[2]), PIOLA_OK);
  piola_attachment_def at = piola_default_attachment_def();
  at.solid = 0;
  at.near_surface = true;
  at.distance = 0.001; /* the 5 grid nodes on the capsule's axis, nothing else */
  bone.attachments = &at;
  bone.attachment_count = 1;
  int32_t obstacle = -1, count = -1;
  assert_int_equal(piola_world_add_bone(w, &bone, &obstacle, &count), PIOLA_OK);
  assert_int_equal(obstacle, 0);
  assert_int_equal(count, 5);
  assert_int_equal(piola_world_obstacle_count(w), 1);

  const uint8_t *flags = piola_world_solid_constraint_flags(w, 0);
  int32_t driven = 0;
  for (int32_t i = 0; i < mesh.vertex_count; ++i) {
    const double *X = mesh.positions + 3 * i;
    int on_axis = fabs(X[1] - 0.05) < 1e-12 && fabs(X[2]) < 1e-12;
    assert_int_equal(flags[i], on_axis ? 2 : 0);
    driven += flags[i] == 2;
  }
  assert_int_equal(driven, 5);

  piola_obstacle *shape = NULL;
  assert_int_equal(piola_obstacle_create(&bone.shape, &shape), PIOLA_OK);
  for (int k = 1; k <= 6; ++k) {
    double t = 0.05 * k;
    assert_int_equal(piola_world_advance_to(w, t, NULL), PIOLA_OK);
    piola_mat3 r;
    piola_vec3 c;
    piola_rigid_motion_pose(m, t, &r, &c);
    const double *x = piola_world_solid_positions(w, 0);
    const double *v = piola_world_solid_velocities(w, 0);
    double moved = 0;
    for (int32_t i = 0; i < mesh.vertex_count; ++i) {
      if (flags[i] != 2) continue;
      const double *X = mesh.positions + 3 * i;
      double want[3];
      for (int a = 0; a < 3; ++a)
        want[a] = r.m[a][0] * X[0] + r.m[a][1] * X[1] + r.m[a][2] * X[2] + (&c.x)[a];
      piola_vec3 vw = piola_rigid_motion_velocity(m, t, (piola_vec3){want[0], want[1], want[2]});
      for (int a = 0; a < 3; ++a) {
        assert_close(x[3 * i + a], want[a], 1e-15);
        assert_close(v[3 * i + a], (&vw.x)[a], 1e-12);
      }
      moved = fmax(moved, fabs(x[3 * i + 2] - X[2]));
      /* the node is where the bone carries it: on the bone's moved axis, a radius deep */
      piola_vec3 p = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
      assert_close(piola_obstacle_signed_distance(shape, t, p, NULL, NULL), -0.01, 1e-12);
    }
    assert_true(moved > 0.01); /* the pose really moved them */
  }
  piola_obstacle_destroy(shape);
  piola_world_destroy(w);
  piola_tet_mesh_free(&mesh);
}

/* A sphere bone carrying a small solid sweeps through a free cube: every node of the cube
 * ends outside the sphere, the cube is pushed along, and the carried nodes (inside the
 * sphere by construction) are left where the bone puts them. */
static void bone_pushes_the_nodes_it_does_not_carry(void **state) {
  (void)state;
  piola_world *w = world_without_gravity();
  piola_tet_mesh carried = {0}, cube = {0};
  grid(2, 0.02, (piola_vec3){-0.01, 0.04, 0.04}, &carried);
  grid(4, 0.1, (piola_vec3){0.06, 0, 0}, &cube);
  piola_solid_def sdef = piola_default_solid_def();
  sdef.material.youngs_modulus = 2e4;
  sdef.shear_viscosity = piola_track_constant(1);
  sdef.mesh = &carried;
  assert_int_equal(piola_world_add_solid(w, &sdef, NULL), PIOLA_OK);
  sdef.mesh = &cube;
  assert_int_equal(piola_world_add_solid(w, &sdef, NULL), PIOLA_OK);

  piola_bone_def bone = piola_default_bone_def();
  bone.shape.type = PIOLA_OBSTACLE_SPHERE;
  bone.shape.center = (piola_vec3){0, 0.05, 0.05};
  bone.shape.radius = 0.03;
  bone.shape.motion.velocity[0] = piola_track_constant(0.5); /* m/s along +x */
  piola_attachment_def at = piola_default_attachment_def();
  at.solid = 0;
  at.near_surface = true;
  bone.attachments = &at;
  bone.attachment_count = 1;
  int32_t count = 0;
  assert_int_equal(piola_world_add_bone(w, &bone, NULL, &count), PIOLA_OK);
  assert_int_equal(count, 27); /* the whole 2^3-cell carrier lies inside the sphere */

  piola_obstacle *sphere = NULL;
  assert_int_equal(piola_obstacle_create(&bone.shape, &sphere), PIOLA_OK);
  double t_end = 0.2; /* the centre reaches x = 0.1, 4 cm into the cube */
  for (int k = 1; k <= 10; ++k) {
    double t = t_end * k / 10;
    assert_int_equal(piola_world_advance_to(w, t, NULL), PIOLA_OK);
    const double *x = piola_world_solid_positions(w, 1);
    for (int32_t i = 0; i < cube.vertex_count; ++i) {
      piola_vec3 p = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
      double phi = piola_obstacle_signed_distance(sphere, t, p, NULL, NULL);
      if (!(phi >= -1e-12)) fail_msg("cube node %d is %g m inside the bone at t = %g", (int)i, -phi, t);
    }
    const double *xc = piola_world_solid_positions(w, 0);
    for (int32_t i = 0; i < carried.vertex_count; ++i) {
      piola_vec3 p = {xc[3 * i], xc[3 * i + 1], xc[3 * i + 2]};
      assert_true(piola_obstacle_signed_distance(sphere, t, p, NULL, NULL) < 0);
      assert_close(xc[3 * i], carried.positions[3 * i] + 0.5 * t, 1e-12);
    }
  }
  /* the cube was pushed: its leftmost face moved right */
  const double *x = piola_world_solid_positions(w, 1);
  double push = 0;
  for (int32_t i = 0; i < cube.vertex_count; ++i) push = fmax(push, x[3 * i] - cube.positions[3 * i]);
  assert_true(push > 0.01);
  piola_obstacle_destroy(sphere);
  piola_world_destroy(w);
  piola_tet_mesh_free(&carried);
  piola_tet_mesh_free(&cube);
}

static void a_bad_attachment_leaves_the_world_unchanged(void **state) {
  (void)state;
  piola_world *w = world_without_gravity();
  piola_tet_mesh mesh = {0};
  grid(2, 0.1, (piola_vec3){0, 0, 0}, &mesh);
  piola_solid_def sdef = piola_default_solid_def();
  sdef.mesh = &mesh;
  assert_int_equal(piola_world_add_solid(w, &sdef, NULL), PIOLA_OK);
  piola_bone_def bone = piola_default_bone_def();
  bone.shape.type = PIOLA_OBSTACLE_SPHERE;
  bone.shape.radius = 0.02;
  piola_attachment_def at[3];
  at[0] = piola_default_attachment_def();
  at[0].near_surface = true; /* picks the corner node at the origin */
  at[1] = piola_default_attachment_def();
  at[1].selector.type = PIOLA_SELECT_BOX; /* a box away from the solid: nothing */
  at[1].selector.box_min = (piola_vec3){1, 1, 1};
  at[1].selector.box_max = (piola_vec3){2, 2, 2};
  bone.attachments = at;
  bone.attachment_count = 2;
  assert_int_equal(piola_world_add_bone(w, &bone, NULL, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "attachments[1]: selects no node of solid 'solid0'"));
  assert_int_equal(piola_world_obstacle_count(w), 0);
  const uint8_t *flags = piola_world_solid_constraint_flags(w, 0);
  for (int32_t i = 0; i < mesh.vertex_count; ++i) assert_int_equal(flags[i], 0);

  at[1] = piola_default_attachment_def();
  at[1].solid = 3;
  assert_int_equal(piola_world_add_bone(w, &bone, NULL, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "attachments[1]: solid 3 does not exist"));
  at[1] = piola_default_attachment_def();
  int32_t indices[2] = {0, 27};
  at[1].selector.indices = indices;
  at[1].selector.index_count = 2;
  assert_int_equal(piola_world_add_bone(w, &bone, NULL, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "attachments[1].indices[1]: vertex 27 is out of range"));
  bone.shape.radius = -1;
  assert_int_equal(piola_world_add_bone(w, &bone, NULL, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_world_obstacle_count(w), 0);

  /* and the good one goes in, with the counts of each attachment */
  bone.shape.radius = 0.02;
  at[1] = piola_default_attachment_def();
  indices[1] = 26;
  at[1].selector.indices = indices;
  at[1].selector.index_count = 2;
  int32_t counts[2] = {-1, -1};
  assert_int_equal(piola_world_add_bone(w, &bone, NULL, counts), PIOLA_OK);
  assert_int_equal(counts[0], 1);
  assert_int_equal(counts[1], 2);
  assert_int_equal(flags[0], 2);
  assert_int_equal(flags[26], 2);
  assert_int_equal(piola_world_obstacle_count(w), 1);
  piola_world_destroy(w);
  piola_tet_mesh_free(&mesh);
}

/* ------------------------------------------------------------------ scene */

static const char *scene_with_bones(const char *bones) {
  static char buf[4096];
  snprintf(buf, sizeof buf,
           "{\"frames\": 1, \"solids\": [{\"name\": \"flesh\", \"mesh\": {\"generate\": \"box\", "
           "\"half_extents\": [0.1, 0.1, 0.1], \"cell_size\": 0.05}}], \"bones\": %s}",
           bones);
  return buf;
}

static void expect_error(const char *bones, const char *part) {
  piola_scene *scene = NULL;
  piola_status st = piola_scene_load_string(scene_with_bones(bones), NULL, "s.json", &scene);
  if (st == PIOLA_OK) fail_msg("%s loaded", bones);
  if (!strstr(piola_last_error(), part)) fail_msg("error '%s' does not name '%s'", piola_last_error(), part);
  assert_null(scene);
}

static void scene_errors_name_the_key(void **state) {
  (void)state;
  expect_error("[{\"type\": \"capsule\", \"radius\": 0.01, \"half_length\": 0.05, "
               "\"attachments\": [{\"solid\": \"flesch\", \"within\": 0.01}]}]",
               "s.json: bones[0].attachments[0].solid: no solid is named \"flesch\" (solids: flesh)");
  expect_error("[{\"type\": \"sphere\", \"radius\": 0.01, \"center\": [1, 1, 1], "
               "\"attachments\": [{\"solid\": \"flesh\", \"within\": 0.01}]}]",
               "s.json: bones[0].attachments[0]: selects no node of solid 'flesh'");
  expect_error("[{\"type\": \"sphere\", \"radius\": 0.01, "
               "\"attachments\": [{\"solid\": \"flesh\", \"indices\": []}]}]",
               "bones[0].attachments[0]: selects no node");
  expect_error("[{\"type\": \"sphere\", \"radius\": 0.01, "
               "\"attachments\": [{\"solid\": \"flesh\", \"indices\": [0, 9999]}]}]",
               "bones[0].attachments[0].indices[1]: vertex 9999 is out of range");
  expect_error("[{\"type\": \"capsule\", \"radius\": 0.01}]", "bones[0].half_length: is required");
  expect_error("[{\"type\": \"capsule\", \"radius\": -0.01, \"half_length\": 0.05}]",
               "bones[0].radius: must be > 0");
  expect_error("[{\"type\": \"bone\"}]", "bones[0].type: must be one of");
  expect_error("[{\"type\": \"sphere\", \"radius\": 0.01, \"attachment\": []}]",
               "bones[0].attachment: unknown key");
  expect_error("[{\"type\": \"sphere\", \"radius\": 0.01, "
               "\"attachments\": [{\"solid\": \"flesh\", \"within\": 0.01, \"sphere\": {\"radius\": 1}}]}]",
               "bones[0].attachments[0]: needs exactly one of box, sphere, indices or within");
  expect_error("[{\"type\": \"sphere\", \"radius\": 0.01, "
               "\"attachments\": [{\"within\": 0.01}]}]",
               "bones[0].attachments[0].solid: is required");
  expect_error("[{\"type\": \"sphere\", \"radius\": 0.01, "
               "\"attachments\": [{\"solid\": \"flesh\", \"within\": -1}]}]",
               "bones[0].attachments[0].within: must be >= 0");
  expect_error("[{\"name\": \"a\", \"type\": \"sphere\", \"radius\": 0.01}, "
               "{\"name\": \"a\", \"type\": \"sphere\", \"radius\": 0.01}]",
               "bones[1].name: \"a\" is already the name of bones[0]");
  expect_error("{}", "bones: must be an array");
}

static void scene_bones_are_obstacles_with_attached_nodes(void **state) {
  (void)state;
  piola_scene *scene = NULL;
  const char *text = scene_with_bones(
      "[{\"type\": \"box\", \"center\": [0, 0, -0.1], \"half_extents\": [0.2, 0.2, 0.01], "
      "\"attachments\": [{\"solid\": \"flesh\", \"within\": 0.001}]}, "
      "{\"type\": \"sphere\", \"center\": [0, 0, 0.3], \"radius\": 0.05, \"friction\": 0.5, "
      "\"motion\": {\"velocity\": [0, 0, -0.1]}}]");
  if (piola_scene_load_string(text, NULL, "s.json", &scene) != PIOLA_OK) fail_msg("%s", piola_last_error());
  piola_world *w = piola_scene_world(scene);
  assert_int_equal(piola_world_obstacle_count(w), 2);
  const uint8_t *flags = piola_world_solid_constraint_flags(w, 0);
  const piola_elastic_body *body = piola_world_solid_body(w, 0);
  const double *rest = piola_elastic_body_rest_positions(body);
  int32_t n = piola_elastic_body_vertex_count(body), bottom = 0;
  for (int32_t i = 0; i < n; ++i) {
    int on_bottom = rest[3 * i + 2] <= -0.089; /* inside the slab or within 1 mm of it */
    assert_int_equal(flags[i], on_bottom ? 2 : 0);
    bottom += on_bottom;
  }
  assert_true(bottom >= 4);
  /* the bottom is held by the bone against gravity: it stays put */
  assert_int_equal(piola_world_advance_to(w, 0.05, NULL), PIOLA_OK);
  const double *x = piola_world_solid_positions(w, 0);
  for (int32_t i = 0; i < n; ++i)
    if (flags[i] == 2)
      for (int a = 0; a < 3; ++a) assert_close(x[3 * i + a], rest[3 * i + a], 0);
  piola_scene_destroy(scene);
}

/* The renderer draws what the scene's obstacles and bones are (piola render, previews). */
static void renderer_draws_bones_with_the_obstacles(void **state) {
  (void)state;
  char path[] = "/tmp/piola_bones_scene_XXXXXX";
  int fd = mkstemp(path);
  assert_true(fd >= 0);
  FILE *f = fdopen(fd, "w");
  assert_non_null(f);
  fputs(scene_with_bones("[{\"type\": \"capsule\", \"radius\": 0.01, \"half_length\": 0.05, "
                         "\"attachments\": [{\"solid\": \"flesh\", \"within\": 0.1}]}, "
                         "{\"type\": \"sphere\", \"center\": [1, 0, 0], \"radius\": 0.1}]"),
        f);
  fclose(f);
  piola_render_def def = piola_default_render_def();
  piola_renderer *r = NULL;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  if (piola_renderer_load_scene_obstacles(r, path) != PIOLA_OK) fail_msg("%s", piola_last_error());
  assert_int_equal(piola_renderer_obstacle_count(r), 2);
  piola_renderer_destroy(r);
  remove(path);
}

/* ------------------------------------------------------------------ the flexing arm */

/* examples/arm_flex.json made cheaper: a coarser flesh mesh and a faster flex (150 degrees
 * in 0.4 s, held 0.1 s, straightened in 0.4 s). Tets invert while the elbow is closed
 * and every one recovers after it opens. */
static void flexed_elbow_inverts_tets_that_recover(void **state) {
  (void)state;
  const char *text =
      "{\"fps\": 30, \"frames\": 40, \"gravity\": [0, 0, 0],"
      " \"integrator\": {\"max_dt\": 0.002, \"cfl\": 0.7},"
      " \"solids\": [{\"name\": \"flesh\", \"mesh\": {\"generate\": \"capsule\", \"axis\": [1, 0, 0],"
      "   \"radius\": 0.05, \"half_length\": 0.2, \"cell_size\": 0.03},"
      "   \"material\": {\"model\": \"neohookean\", \"youngs_modulus\": 3e4, \"poisson_ratio\": 0.4,"
      "                \"inversion\": {\"threshold\": 0.5}},"
      "   \"damping\": {\"shear\": 2, \"bulk\": 2}}],"
      " \"bones\": ["
      "  {\"name\": \"upper_arm\", \"type\": \"capsule\", \"center\": [-0.17, 0, 0], \"axis\": [1, 0, 0],"
      "   \"radius\": 0.02, \"half_length\": 0.11, \"friction\": 0.3,"
      "   \"attachments\": [{\"solid\": \"flesh\", \"within\": 0.005}]},"
      "  {\"name\": \"forearm\", \"type\": \"capsule\", \"center\": [0.17, 0, 0], \"axis\": [1, 0, 0],"
      "   \"radius\": 0.02, \"half_length\": 0.11, \"friction\": 0.3,"
      "   \"motion\": {\"pivot\": [0, 0, 0], \"axis\": [0, 1, 0],"
      "              \"angle\": {\"keys\": [[0, 0], [0.4, -2.618], [0.5, -2.618], [0.9, 0]]}},"
      "   \"attachments\": [{\"solid\": \"flesh\", \"within\": 0.005}]}]}";
  piola_scene *scene = NULL;
  if (piola_scene_load_string(text, NULL, "arm.json", &scene) != PIOLA_OK) fail_msg("%s", piola_last_error());
  piola_world *w = piola_scene_world(scene);
  int32_t frames = piola_scene_frames(scene), most = 0, at_full_flex = 0;
  double fps = piola_scene_fps(scene);
  for (int32_t f = 1; f <= frames; ++f) {
    if (piola_world_advance_to(w, f / fps, NULL) != PIOLA_OK) fail_msg("frame %d: %s", (int)f, piola_last_error());
    piola_solid_stats st = piola_world_solid_stats(w, 0);
    if (st.inverted_count > most) most = st.inverted_count;
    if (f == 15) at_full_flex = st.inverted_count; /* t = 0.5 s, the end of the hold */
  }
  piola_solid_stats end = piola_world_solid_stats(w, 0);
  print_message("arm flex: %d tets inverted at most, %d at full flex, %d at the end (t = %g s), "
                "min det F %g\n", (int)most, (int)at_full_flex, (int)end.inverted_count,
                piola_world_time(w), end.min_det_f);
  assert_true(most > 0);
  assert_true(at_full_flex > 0);
  assert_int_equal(end.inverted_count, 0);
  assert_true(end.min_det_f > 0.5);
  piola_scene_destroy(scene);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(attached_nodes_follow_the_bone_pose_exactly),
      cmocka_unit_test(bone_pushes_the_nodes_it_does_not_carry),
      cmocka_unit_test(a_bad_attachment_leaves_the_world_unchanged),
      cmocka_unit_test(scene_errors_name_the_key),
      cmocka_unit_test(scene_bones_are_obstacles_with_attached_nodes),
      cmocka_unit_test(renderer_draws_bones_with_the_obstacles),
      cmocka_unit_test(flexed_elbow_inverts_tets_that_recover),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
