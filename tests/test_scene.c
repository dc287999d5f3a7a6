/* Scene files: every key reaches its definition struct, defaults hold when keys are left
 * out, keyframes evaluate piecewise linearly, and every bad input is refused with a message
 * that names its key path. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "piola/keyframes.h"
#include "piola/scene.h"
#include "piola/world.h"
#include "scene/scene_desc.h"
#include "scene_cases.h"

static void defaults_hold_when_keys_are_left_out(void **state) {
  (void)state;
  scene_desc d;
  assert_int_equal(piola__scene_parse("{\"solids\": [{\"mesh\": \"m/a.veg\"}]}", "/base", "t", &d), PIOLA_OK);
  assert_close(d.fps, 30, 0);
  assert_int_equal(d.frames, 60);
  assert_close(piola_track_eval(&d.world.gravity[2], 0), -9.81, 0);
  assert_close(piola_track_eval(&d.world.gravity[0], 0), 0, 0);
  assert_close(d.world.max_dt, 1e-3, 0);
  assert_close(d.world.cfl, 0.5, 0);
  assert_int_equal(d.solid_count, 1);
  assert_int_equal(d.obstacle_count, 0);
  const scene_solid_desc *s = &d.solids[0];
  assert_string_equal(s->mesh_path, "/base/m/a.veg");
  assert_string_equal(s->name, "solid0");
  assert_int_equal(s->mesh_generated, 0);
  assert_close(s->def.density, 1000, 0);
  assert_close(piola_track_eval(&s->def.stiffness_scale, 3), 1, 0);
  assert_close(s->scale.x, 1, 0);
  assert_close(s->def.initial_matrix.m[1][1], 1, 0);
  assert_close(s->def.initial_matrix.m[0][1], 0, 0);
  assert_int_equal((int)s->def.scramble_seed, 1);
  assert_int_equal(s->constraint_count, 0);
  piola__scene_desc_free(&d);

  assert_int_equal(piola__scene_parse("{\"solids\": [{\"mesh\": \"/abs/b.msh\"}]}", "/base", "t", &d), PIOLA_OK);
  assert_string_equal(d.solids[0].mesh_path, "/abs/b.msh");
  piola__scene_desc_free(&d);
}

static const char *FULL =
    "{\"description\": \"every key\", \"fps\": 24, \"frames\": 12, \"gravity\": [1, {\"keys\": [[0, 0], [2, -4]]}, -3],\n"
    " \"integrator\": {\"max_dt\": 0.002, \"cfl\": 0.4, \"cg_tolerance\": 1e-6, \"cg_max_iterations\": 50},\n"
    " \"solids\": [{\"name\": \"blob\", \"mesh\": {\"generate\": \"torus\", \"center\": [0, 0, 1], \"axis\": [0, 2, 0],\n"
    "    \"radius\": 0.5, \"minor_radius\": 0.2, \"cell_size\": 0.1, \"refinement_levels\": 1},\n"
    "   \"transform\": {\"translate\": [1, 2, 3], \"rotate_degrees\": [90, 0, 45], \"scale\": [1, 2, 3]},\n"
    "   \"density\": 1100, \"material\": {\"model\": \"spline\", \"youngs_modulus\": 2e5, \"poisson_ratio\": 0.45,\n"
    "     \"stiffness_scale\": {\"keys\": [[0, 1], [1, 0], [2, 1]]}, \"inversion\": {\"threshold\": 0.2, \"mode\": \"clamp\"},\n"
    "     \"spline\": {\"compression_stretch\": 0.7, \"elongation_stretch\": 1.3, \"stiffening\": 5}},\n"
    "   \"damping\": {\"shear\": 2, \"bulk\": {\"keys\": [[0, 1], [1, 3]]}}, \"velocity\": [0, 0, -1],\n"
    "   \"fixed\": [{\"box\": [[-1, -1, -1], [1, 1, 0]]}, {\"sphere\": {\"center\": [0, 0, 2], \"radius\": 0.1}},\n"
    "             {\"indices\": [0, 5, 7]}],\n"
    "   \"driven\": [{\"indices\": [3], \"motion\": {\"velocity\": [0, 0, 1], \"angular_speed\": 2, \"axis\": [1, 0, 0],\n"
    "                                           \"pivot\": [0, 1, 0]}}],\n"
    "   \"initial\": {\"matrix\": [[1, 0, 0], [0, 1, 0], [0, 0, 0]], \"scramble\": 0.01, \"seed\": 7}},\n"
    "  {\"name\": \"second\", \"mesh\": \"x.node\"}],\n"
    " \"obstacles\": [{\"type\": \"plane\", \"point\": [0, 0, -1], \"normal\": [0, 0, 2], \"friction\": 0.3},\n"
    "   {\"type\": \"sphere\", \"center\": [1, 1, 1], \"radius\": 0.5, \"motion\": {\"translation\": [{\"keys\": [[0, 0], [1, 1]]}, 0, 0],\n"
    "                                                                       \"angle\": 0.5}},\n"
    "   {\"type\": \"gear\", \"center\": [0, 0, 0], \"axis\": [0, 1, 0], \"radius\": 0.3, \"half_length\": 0.1, \"teeth\": 12,\n"
    "    \"tooth_depth\": 0.05, \"motion\": {\"angular_speed\": 1.5}},\n"
    "   {\"type\": \"mesh\", \"path\": \"bowl.obj\"}]}";

static void every_key_reaches_its_definition(void **state) {
  (void)state;
  scene_desc d;
  assert_int_equal(piola__scene_parse(FULL, "dir", "full", &d), PIOLA_OK);
  assert_close(d.fps, 24, 0);
  assert_int_equal(d.frames, 12);
  assert_close(piola_track_eval(&d.world.gravity[0], 5), 1, 0);
  assert_close(piola_track_eval(&d.world.gravity[1], 1), -2, 1e-15);
  assert_close(piola_track_eval(&d.world.gravity[2], 1), -3, 0);
  assert_close(d.world.max_dt, 0.002, 0);
  assert_close(d.world.cfl, 0.4, 0);
  assert_close(d.world.cg_tolerance, 1e-6, 0);
  assert_int_equal(d.world.cg_max_iterations, 50);
  assert_int_equal(d.solid_count, 2);
  const scene_solid_desc *s = &d.solids[0];
  assert_string_equal(s->name, "blob");
  assert_int_equal(s->mesh_generated, 1);
  assert_int_equal(s->mesher.shapes[0].type, PIOLA_SHAPE_TORUS);
  assert_close(s->mesher.shapes[0].axis.y, 1, 1e-15); /* normalized */
  assert_close(s->mesher.shapes[0].center.z, 1, 0);
  assert_close(s->mesher.shapes[0].radius, 0.5, 0);
  assert_close(s->mesher.shapes[0].minor_radius, 0.2, 0);
  assert_close(s->mesher.cell_size, 0.1, 0);
  assert_int_equal(s->mesher.refinement_levels, 1);
  assert_close(s->translate.y, 2, 0);
  assert_close(s->rotate_degrees.x, 90, 0);
  assert_close(s->rotate_degrees.z, 45, 0);
  assert_close(s->scale.z, 3, 0);
  assert_close(s->def.density, 1100, 0);
  assert_int_equal(s->def.material.model, PIOLA_MODEL_SPLINE);
  assert_close(s->def.material.youngs_modulus, 2e5, 0);
  assert_close(s->def.material.poisson_ratio, 0.45, 0);
  assert_close(s->def.material.inversion_threshold, 0.2, 0);
  assert_int_equal(s->def.material.inversion_mode, PIOLA_INVERSION_CLAMP);
  assert_close(s->def.material.spline.compression_stretch, 0.7, 0);
  assert_close(s->def.material.spline.elongation_stretch, 1.3, 0);
  assert_close(s->def.material.spline.stiffening, 5, 0);
  assert_close(piola_track_eval(&s->def.stiffness_scale, 0.5), 0.5, 1e-15);
  assert_close(piola_track_eval(&s->def.stiffness_scale, 1.5), 0.5, 1e-15);
  assert_close(piola_track_eval(&s->def.stiffness_scale, 9), 1, 0);
  assert_close(piola_track_eval(&s->def.shear_viscosity, 0.3), 2, 0);
  assert_close(piola_track_eval(&s->def.bulk_viscosity, 0.5), 2, 1e-15);
  assert_close(s->def.velocity.z, -1, 0);
  assert_int_equal(s->constraint_count, 4);
  assert_int_equal(s->constraints[0].selector.type, PIOLA_SELECT_BOX);
  assert_false(s->constraints[0].driven);
  assert_close(s->constraints[0].selector.box_max.z, 0, 0);
  assert_close(s->constraints[0].selector.box_min.x, -1, 0);
  assert_int_equal(s->constraints[1].selector.type, PIOLA_SELECT_SPHERE);
  assert_close(s->constraints[1].selector.radius, 0.1, 0);
  assert_close(s->constraints[1].selector.center.z, 2, 0);
  assert_int_equal(s->constraints[2].selector.type, PIOLA_SELECT_INDICES);
  assert_int_equal(s->constraints[2].selector.index_count, 3);
  assert_int_equal(s->constraints[2].selector.indices[2], 7);
  assert_true(s->constraints[3].driven);
  assert_int_equal(s->constraints[3].motion.kind, PIOLA_MOTION_VELOCITY);
  assert_close(piola_track_eval(&s->constraints[3].motion.velocity[2], 0), 1, 0);
  assert_close(piola_track_eval(&s->constraints[3].motion.angular_speed, 0), 2, 0);
  assert_close(s->constraints[3].motion.axis.x, 1, 0);
  assert_close(s->constraints[3].motion.pivot.y, 1, 0);
  assert_close(s->def.initial_matrix.m[2][2], 0, 0);
  assert_close(s->def.initial_matrix.m[1][1], 1, 0);
  assert_close(s->def.scramble_radius, 0.01, 0);
  assert_int_equal((int)s->def.scramble_seed, 7);
  assert_string_equal(d.solids[1].mesh_path, "dir/x.node");
  assert_int_equal(d.obstacle_count, 4);
  const piola_obstacle_def *o = &d.obstacles[0].def;
  assert_int_equal(o->type, PIOLA_OBSTACLE_PLANE);
  assert_close(o->center.z, -1, 0);
  assert_close(o->axis.z, 1, 1e-15);
  assert_close(o->friction, 0.3, 0);
  o = &d.obstacles[1].def;
  assert_int_equal(o->type, PIOLA_OBSTACLE_SPHERE);
  assert_close(o->radius, 0.5, 0);
  assert_int_equal(o->motion.kind, PIOLA_MOTION_POSE);
  assert_close(piola_track_eval(&o->motion.translation[0], 0.25), 0.25, 1e-15);
  assert_close(piola_track_eval(&o->motion.angle, 0), 0.5, 0);
  assert_close(o->motion.pivot.x, 1, 0); /* defaults to the centre */
  assert_close(o->motion.axis.z, 1, 0);   /* a sphere has no axis: z */
  o = &d.obstacles[2].def;
  assert_int_equal(o->type, PIOLA_OBSTACLE_GEAR);
  assert_int_equal(o->tooth_count, 12);
  assert_close(o->tooth_depth, 0.05, 0);
  assert_close(o->half_length, 0.1, 0);
  assert_close(piola_track_eval(&o->motion.angular_speed, 3), 1.5, 0);
  /* A gear spins about its own axis (y here) unless the motion names another one. */
  assert_close(o->motion.axis.x, 0, 0);
  assert_close(o->motion.axis.y, 1, 0);
  assert_close(o->motion.axis.z, 0, 0);
  assert_close(o->motion.pivot.x, 0, 0);
  assert_int_equal(d.obstacles[3].def.type, PIOLA_OBSTACLE_MESH);
  assert_string_equal(d.obstacles[3].mesh_path, "dir/bowl.obj");
  piola__scene_desc_free(&d);
}

#define SOLID(x) "{\"solids\": [{\"mesh\": \"a.veg\"" x "}]}"

static const bad_scene_case BAD[] = {
    {SOLID(", \"material\": {\"poisson_ratio\": 0.7}"),
     "bad.json: solids[0].material.poisson_ratio: must be in (-1, 0.5)"},
    {SOLID(", \"material\": {\"poison_ratio\": 0.3}"),
     "solids[0].material.poison_ratio: unknown key"},
    {SOLID(", \"material\": {\"youngs_modulus\": -5}"),
     "solids[0].material.youngs_modulus: must be > 0"},
    {SOLID(", \"material\": {\"model\": \"jelly\"}"), "solids[0].material.model: must be one of"},
    {SOLID(", \"material\": {\"inversion\": {\"mode\": \"cubic\"}}"),
     "solids[0].material.inversion.mode"},
    {SOLID(", \"material\": {\"inversion\": {\"threshold\": 1.5}}"),
     "solids[0].material.inversion.threshold"},
    {SOLID(", \"material\": {\"stiffness_scale\": {\"keys\": [[0, 1], [0, 2]]}}"),
     "solids[0].material.stiffness_scale.keys[1]: times must increase"},
    {SOLID(", \"material\": {\"stiffness_scale\": {\"keys\": [[0, 1], [1, -2]]}}"),
     "solids[0].material.stiffness_scale.keys[1]: must be >= 0"},
    {SOLID(", \"material\": {\"stiffness_scale\": {\"keys\": [[0, 1, 3]]}}"),
     "solids[0].material.stiffness_scale.keys[0]: must be a pair"},
    {SOLID(", \"material\": {\"stiffness_scale\": {\"kyes\": []}}"),
     "solids[0].material.stiffness_scale.kyes: unknown key"},
    {SOLID(", \"density\": \"heavy\""), "solids[0].density: must be a number, got a string"},
    {SOLID(", \"density\": 0"), "solids[0].density: must be > 0"},
    {SOLID(", \"density\": {\"keys\": [[0, 1]]}"), "solids[0].density: must be a constant"},
    {SOLID(", \"damping\": {\"shear\": -1}"), "solids[0].damping.shear: must be >= 0"},
    {SOLID(", \"velocity\": [1, 2]"),
     "solids[0].velocity: must be an array of 3 numbers, got an array of 2"},
    {SOLID(", \"velocity\": 1"), "solids[0].velocity: must be an array of 3 numbers, got a number"},
    {SOLID(", \"driven\": [{\"indices\": [1], \"motion\": {\"velocity\": [0, 0, 1, 0]}}]"),
     "solids[0].driven[0].motion.velocity: must be an array of 3 numbers (or keyframes), got an "
     "array of 4"},
    {SOLID(", \"transform\": {\"scale\": 0}"), "solids[0].transform.scale: must be > 0"},
    {SOLID(", \"transform\": {\"rotate\": [0, 0, 0]}"), "solids[0].transform.rotate: unknown key"},
    {SOLID(", \"fixed\": [{\"box\": [[0, 0, 0], [1, 1, 1]], \"sphere\": {\"radius\": 1}}]"),
     "solids[0].fixed[0]: needs exactly one of"},
    {SOLID(", \"fixed\": [{\"box\": [[0, 0, 0], [-1, 1, 1]]}]"),
     "solids[0].fixed[0].box: the first corner"},
    {SOLID(", \"fixed\": [{\"indices\": [0, -3]}]"),
     "solids[0].fixed[0].indices[1]: must be a vertex index"},
    {SOLID(", \"fixed\": [{\"indices\": [1], \"motion\": {}}]"),
     "solids[0].fixed[0].motion: unknown key"},
    {SOLID(", \"driven\": [{\"indices\": [1]}]"), "solids[0].driven[0].motion: is required"},
    {SOLID(
         ", \"driven\": [{\"indices\": [1], \"motion\": {\"velocity\": [0, 0, 1], \"angle\": 1}}]"),
     "solids[0].driven[0].motion: give either"},
    {SOLID(", \"initial\": {\"matrix\": [[1, 0, 0], [0, 1, 0]]}"),
     "solids[0].initial.matrix: must be a 3x3 matrix"},
    {SOLID(", \"initial\": {\"matrix\": [[1, 0, 0], [0, 1, 0], [0, \"x\", 0]]}"),
     "solids[0].initial.matrix[2][1]: must be a number"},
    {SOLID(", \"initial\": {\"scramble\": -0.1}"), "solids[0].initial.scramble: must be >= 0"},
    {SOLID(", \"initial\": {\"seed\": 1.5}"), "solids[0].initial.seed: must be an integer"},
    {SOLID(", \"name\": 3"), "solids[0].name: must be a non-empty string"},
    {"{\"solids\": [{\"mesh\": {\"generate\": \"sphere\", \"radius\": 1}}]}",
     "solids[0].mesh.cell_size: is required"},
    {"{\"solids\": [{\"mesh\": {\"generate\": \"blob\", \"cell_size\": 1}}]}",
     "solids[0].mesh.generate: must be one of"},
    {"{\"solids\": [{\"mesh\": {\"generate\": \"torus\", \"radius\": 1, \"minor_radius\": 2, "
     "\"cell_size\": 0.1}}]}",
     "solids[0].mesh.minor_radius: must be smaller"},
    {"{\"solids\": [{\"mesh\": 5}]}", "solids[0].mesh: must be a file path or a generator object"},
    {"{\"solids\": [{\"name\": \"a\"}]}", "solids[0].mesh: is required"},
    {"{\"solids\": [{\"mesh\": \"a.veg\", \"name\": \"x\"}, {\"mesh\": \"a.veg\", \"name\": "
     "\"x\"}]}",
     "solids[1].name: \"x\" is already"},
    {"{\"solids\": []}", "solids: must be a non-empty array"},
    {"{\"fps\": 30}", "solids: is required"},
    {"{\"fps\": \"30\", \"solids\": [{\"mesh\": \"a.veg\"}]}",
     "fps: must be a number, got a string"},
    {"{\"fps\": -1, \"solids\": [{\"mesh\": \"a.veg\"}]}", "fps: must be in (0, 10000]"},
    {"{\"frames\": 2.5, \"solids\": [{\"mesh\": \"a.veg\"}]}", "frames: must be an integer"},
    {"{\"frame\": 2, \"solids\": [{\"mesh\": \"a.veg\"}]}", "frame: unknown key"},
    {"{\"fps\": 2, \"fps\": 3, \"solids\": [{\"mesh\": \"a.veg\"}]}", "fps: duplicate key"},
    {"{\"gravity\": [0, 0], \"solids\": [{\"mesh\": \"a.veg\"}]}",
     "gravity: must be an array of 3"},
    {"{\"integrator\": {\"cfl\": 0}, \"solids\": [{\"mesh\": \"a.veg\"}]}",
     "integrator.cfl: must be in (0, 2]"},
    {"{\"integrator\": {\"max_dt\": -1}, \"solids\": [{\"mesh\": \"a.veg\"}]}",
     "integrator.max_dt"},
    {"{\"integrator\": {\"cg_max_iterations\": 0}, \"solids\": [{\"mesh\": \"a.veg\"}]}",
     "integrator.cg_max_iterations"},
    /* the bounds and the refused value in full: %g printed "[1, 1e+06], got 1e+06" */
    {"{\"integrator\": {\"newton_max_iterations\": 1000001}, \"solids\": [{\"mesh\": \"a.veg\"}]}",
     "integrator.newton_max_iterations: must be in [1, 1000000], got 1000001"},
    {"{\"integrator\": {\"newton_tolerance\": 1.0000001}, \"solids\": [{\"mesh\": \"a.veg\"}]}",
     "integrator.newton_tolerance: must be in (0, 1), got 1.0000001"},
    {"{\"solids\": [{\"mesh\": \"a.veg\"}], \"obstacles\": [{\"type\": \"cone\"}]}",
     "obstacles[0].type: must be one of"},
    {"{\"solids\": [{\"mesh\": \"a.veg\"}], \"obstacles\": [{\"type\": \"plane\", \"point\": [0, "
     "0, 0]}]}",
     "obstacles[0].normal: is required"},
    {"{\"solids\": [{\"mesh\": \"a.veg\"}], \"obstacles\": [{\"type\": \"plane\", \"point\": [0, "
     "0, 0], \"normal\": [0, 0, 0]}]}",
     "obstacles[0].normal: must be a nonzero vector"},
    {"{\"solids\": [{\"mesh\": \"a.veg\"}], \"obstacles\": [{\"type\": \"sphere\", \"radius\": 1, "
     "\"normal\": [0, 0, 1]}]}",
     "obstacles[0].normal: unknown key"},
    {"{\"solids\": [{\"mesh\": \"a.veg\"}], \"obstacles\": [{\"type\": \"sphere\", \"radius\": 1, "
     "\"friction\": -0.5}]}",
     "obstacles[0].friction: must be >= 0"},
    {"{\"solids\": [{\"mesh\": \"a.veg\"}], \"obstacles\": [{\"type\": \"sphere\", \"radius\": 1, "
     "\"motion\": {\"speed\": 1}}]}",
     "obstacles[0].motion.speed: unknown key"},
    {"{\"solids\": [{\"mesh\": \"a.veg\"}], \"obstacles\": [{\"type\": \"gear\", \"radius\": 1, "
     "\"half_length\": 1, \"teeth\": 2}]}",
     "obstacles[0].teeth: must be in [3, 100000]"},
    {"{\"solids\": [{\"mesh\": \"a.veg\"}],\n \"fps\": 3,,}", "bad.json: line 2, column"},
    {"[1, 2]", "(top level): must be an object"},
};

static void bad_input_names_its_key_path(void **state) {
  (void)state;
  assert_bad_scenes_refused(BAD, sizeof BAD / sizeof BAD[0]);
}

/* The message of warning KIND (or "", copied into text) of the world the scene JSON builds,
 * after STEPS steps of 1e-4 s; with steps > 0 it must not be raised before the first. */
static const char *scene_warning(const char *json, piola_warning_kind kind, int steps, char *text,
                                 size_t size) {
  piola_scene *scene = NULL;
  if (piola_scene_load_string(json, ".", NULL, &scene) != PIOLA_OK)
    fail_msg("%s", piola_last_error());
  piola_world *world = piola_scene_world(scene);
  if (steps > 0) assert_null(piola_world_warning(world, kind));
  for (int k = 0; k < steps; ++k) {
    piola_step_stats stats;
    if (piola_world_step(world, 1e-4, &stats) != PIOLA_OK) fail_msg("%s", piola_last_error());
  }
  const char *w = piola_world_warning(world, kind);
  snprintf(text, size, "%s", w ? w : "");
  piola_scene_destroy(scene);
  return text;
}

/* A fixed or driven selector that picks no node is accepted (a coarse mesh may have none
 * in a small box) with a warning naming the solid and the scene key; the first empty one
 * is named, and a scene whose selectors all pick nodes raises none. */
static const char *empty_selection_warning(const char *constraints, char *text, size_t size) {
  char json[2048];
  snprintf(json, sizeof json,
           "{\"solids\": [{\"name\": \"oct\", \"mesh\": \"%s\", %s}]}",
           test_data_path("tetgen/octahedron.node"), constraints);
  return scene_warning(json, PIOLA_WARNING_EMPTY_SELECTION, 0, text, size);
}

static void empty_selection_is_a_warning_naming_its_key(void **state) {
  (void)state;
  char text[1024];
  const char *far = "{\"sphere\": {\"center\": [50, 50, 50], \"radius\": 0.1}}";
  const char *all = "{\"box\": [[-100, -100, -100], [100, 100, 100]]}";
  char constraints[512];
  snprintf(constraints, sizeof constraints, "\"fixed\": [%s, %s]", all, far);
  assert_non_null(strstr(empty_selection_warning(constraints, text, sizeof text),
                         "solid 'oct': solids[0].fixed[1] selects no node"));
  snprintf(constraints, sizeof constraints,
           "\"fixed\": [%s], \"driven\": [{\"box\": [[40, 40, 40], [41, 41, 41]], "
           "\"motion\": {\"velocity\": [0, 0, 1]}}]", far);
  /* the first empty selector is named: fixed before driven, as the keys come */
  assert_non_null(strstr(empty_selection_warning(constraints, text, sizeof text), "solids[0].fixed[0] "));
  snprintf(constraints, sizeof constraints,
           "\"fixed\": [{\"indices\": [0]}], \"driven\": [{\"box\": [[40, 40, 40], [41, 41, 41]], "
           "\"motion\": {\"velocity\": [0, 0, 1]}}]");
  assert_non_null(strstr(empty_selection_warning(constraints, text, sizeof text), "solids[0].driven[0] "));
  snprintf(constraints, sizeof constraints,
           "\"fixed\": [{\"indices\": [0]}, %s], \"driven\": [{\"indices\": [1], "
           "\"motion\": {\"velocity\": [0, 0, 1]}}]", all);
  assert_string_equal(empty_selection_warning(constraints, text, sizeof text), "");
}

/* Free nodes that start inside an obstacle deeper than 1% of the body's size raise a warning
 * at the first step naming the body, the obstacle and the depth (cli.md, "Warnings"); a body
 * above the obstacle, resting on it, or inside it with every node fixed raises none. The
 * octahedron spans [-4, 4] in each axis (diagonal 13.9 m). */
static const char *starts_inside_warning(const char *placement, char *text, size_t size) {
  char json[2048];
  snprintf(json, sizeof json,
           "{\"gravity\": [0, 0, 0], \"solids\": [{\"name\": \"oct\", \"mesh\": \"%s\"%s}], "
           "\"obstacles\": [{\"type\": \"sphere\", \"center\": [50, 0, 0], \"radius\": 1}, "
           "{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 0, 1]}]}",
           test_data_path("tetgen/octahedron.node"), placement);
  return scene_warning(json, PIOLA_WARNING_STARTS_INSIDE, 1, text, size);
}

static void starting_inside_an_obstacle_is_a_warning(void **state) {
  (void)state;
  char text[1024];
  /* centred on the plane: the lower half is inside, the bottom vertex 4 m deep */
  const char *w = starts_inside_warning("", text, sizeof text);
  assert_non_null(strstr(w, "solid 'oct': "));
  assert_non_null(strstr(w, "start inside obstacle 1 "));
  assert_non_null(strstr(w, "deepest at 4 m"));
  assert_string_equal(
      starts_inside_warning(", \"transform\": {\"translate\": [0, 0, 5]}", text, sizeof text), "");
  /* resting on it: the bottom vertex on the plane, a rounding error deep at most */
  assert_string_equal(
      starts_inside_warning(", \"transform\": {\"translate\": [0, 0, 4]}", text, sizeof text), "");
  assert_string_equal(starts_inside_warning(", \"fixed\": [{\"box\": [[-9, -9, -9], [9, 9, 9]]}]",
                                            text, sizeof text),
                      "");
  /* collapsed to a point 1 m below the plane: every node inside, and no size to compare with */
  w = starts_inside_warning(
      ", \"transform\": {\"translate\": [0, 0, -1]}, \"initial\": {\"matrix\": "
      "[[0, 0, 0], [0, 0, 0], [0, 0, 0]]}",
      text, sizeof text);
  assert_non_null(strstr(w, "solid 'oct': 330 of its 330 nodes start inside obstacle 1 "));
  assert_null(strstr(w, "inf"));
}

/* The public description's getters name what is there, and nothing for an index outside it
 * (they read past the arrays before: a stray name pointer, a garbage material, a crash). */
static void description_getters_check_their_index(void **state) {
  (void)state;
  piola_scene_desc *d = NULL;
  const char *json =
      "{\"solids\": [{\"name\": \"ball\", \"mesh\": \"m/a.veg\"}],"
      " \"obstacles\": [{\"type\": \"plane\", \"name\": \"floor\", \"point\": [0, 0, 0],"
      " \"normal\": [0, 0, 1]}]}";
  if (piola_scene_parse_string(json, "/base", "t", &d) != PIOLA_OK)
    fail_msg("%s", piola_last_error());
  assert_string_equal(piola_scene_desc_solid_name(d, 0), "ball");
  assert_string_equal(piola_scene_desc_obstacle_name(d, 0), "floor");
  assert_false(piola_scene_desc_obstacle_is_bone(d, 0));
  const int32_t outside[] = {-1, 1, 7, INT32_MAX, INT32_MIN};
  for (int k = 0; k < 5; ++k) {
    const int32_t i = outside[k];
    assert_null(piola_scene_desc_solid_name(d, i));
    assert_true(piola_scene_desc_solid_material(d, i).youngs_modulus == 0);
    const char *path = "x";
    const piola_obstacle_def o = piola_scene_desc_obstacle(d, i, &path);
    assert_null(path);
    assert_true(o.mesh == NULL && o.friction == 0);
    assert_null(piola_scene_desc_obstacle_name(d, i));
    assert_false(piola_scene_desc_obstacle_is_bone(d, i));
  }
  piola_scene_desc_destroy(d);
}

/* Integrator keys of the other integrator are accepted with a warning naming them: a scene
 * that sets `dt` and forgets `type` runs Newmark, and says so. */
static const char *ignored_keys_warning(const char *integrator, char *text, size_t size) {
  char json[2048];
  snprintf(json, sizeof json, "{\"integrator\": {%s}, \"solids\": [{\"mesh\": \"%s\"}]}",
           integrator, test_data_path("tetgen/octahedron.node"));
  return scene_warning(json, PIOLA_WARNING_IGNORED_KEYS, 0, text, size);
}

static void other_integrators_keys_are_a_warning(void **state) {
  (void)state;
  char text[1024];
  assert_non_null(strstr(
      ignored_keys_warning("\"dt\": 0.01, \"preconditioner\": \"multigrid\"", text, sizeof text),
      "scene: integrator.dt, integrator.preconditioner apply to "
      "\"backward_euler\" and \"quasistatic\" only: the scene's integrator "
      "is \"newmark\""));
  assert_non_null(
      strstr(ignored_keys_warning("\"type\": \"quasistatic\", \"cfl\": 0.3", text, sizeof text),
             "scene: integrator.cfl applies to \"newmark\" only: the scene's "
             "integrator is \"quasistatic\", which ignores it"));
  /* each integrator's own keys, and the shared one, raise nothing */
  assert_string_equal(ignored_keys_warning("\"type\": \"backward_euler\", \"dt\": 0.01, "
                                           "\"newton_tolerance\": 1e-6, \"collision_interval\": 0",
                                           text, sizeof text),
                      "");
  assert_string_equal(ignored_keys_warning("\"max_dt\": 1e-4, \"cfl\": 0.3, "
                                           "\"cg_tolerance\": 1e-5, \"cg_max_iterations\": 50",
                                           text, sizeof text),
                      "");
}

/* A collision interval under an implicit integrator, with a body that self-collides, is a
 * warning at the first step; with Newmark, or no body that self-collides, none. */
static void implicit_collision_interval_is_a_warning(void **state) {
  (void)state;
  char text[1024], json[2048];
  const char *cases[4][2] = {{"backward_euler", "true"},
                             {"quasistatic", "true"},
                             {"newmark", "true"},
                             {"backward_euler", "false"}};
  for (int k = 0; k < 4; ++k) {
    snprintf(json, sizeof json,
             "{\"integrator\": {\"type\": \"%s\", \"collision_interval\": 0.01},"
             " \"solids\": [{\"name\": \"oct\", \"mesh\": \"%s\","
             " \"self_collision\": {\"enabled\": %s}}]}",
             cases[k][0], test_data_path("tetgen/octahedron.node"), cases[k][1]);
    scene_warning(json, PIOLA_WARNING_IMPLICIT_INTERVAL, 1, text, sizeof text);
    if (k < 2) {
      assert_non_null(strstr(text, "integrator.collision_interval is 0.01 s with"));
      assert_non_null(strstr(text, "solid 'oct' has self_collision"));
    } else {
      assert_string_equal(text, "");
    }
  }
}

/* Two bodies with self-collision under quasistatics are a warning at the first step; one
 * body, or backward Euler, none. */
static void quasistatic_contact_is_a_warning(void **state) {
  (void)state;
  char text[1024], json[2048];
  const char *cases[3][2] = {
      {"quasistatic", "true"}, {"quasistatic", "false"}, {"backward_euler", "true"}};
  const char *oct = test_data_path("tetgen/octahedron.node");
  for (int k = 0; k < 3; ++k) {
    snprintf(json, sizeof json,
             "{\"integrator\": {\"type\": \"%s\"},"
             " \"solids\": [{\"name\": \"lower\", \"mesh\": \"%s\","
             " \"self_collision\": {\"enabled\": true}},"
             " {\"name\": \"upper\", \"mesh\": \"%s\","
             " \"transform\": {\"translate\": [0, 0, 3]},"
             " \"self_collision\": {\"enabled\": %s}}]}",
             cases[k][0], oct, oct, cases[k][1]);
    scene_warning(json, PIOLA_WARNING_QUASISTATIC_CONTACT, 1, text, sizeof text);
    if (k == 0)
      assert_non_null(strstr(text,
                             "solid 'lower' and solid 'upper' have self_collision under "
                             "\"quasistatic\""));
    else
      assert_string_equal(text, "");
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(defaults_hold_when_keys_are_left_out),
      cmocka_unit_test(every_key_reaches_its_definition),
      cmocka_unit_test(bad_input_names_its_key_path),
      cmocka_unit_test(empty_selection_is_a_warning_naming_its_key),
      cmocka_unit_test(starting_inside_an_obstacle_is_a_warning),
      cmocka_unit_test(description_getters_check_their_index),
      cmocka_unit_test(other_integrators_keys_are_a_warning),
      cmocka_unit_test(implicit_collision_interval_is_a_warning),
      cmocka_unit_test(quasistatic_contact_is_a_warning),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
