/* A program outside piola's tree, built against an installed copy of piola by
 * tests/scripts/test_install.sh, once through CMake's find_package and once through
 * pkg-config. It uses the three layers: a scene parsed and built from text (piola_scene),
 * one frame simulated (the core), and the scene's obstacle rendered to a PNG
 * (piola_render). Exit status 0 only if the ball fell as gravity says and the picture was
 * written and reads back at its size. */
#include <math.h>
#include <piola/piola.h>
#include <stdio.h>

static const char *const SCENE =
    "{\"fps\": 50, \"frames\": 1, \"gravity\": [0, 0, -9.81],"
    " \"solids\": [{\"name\": \"ball\","
    "   \"mesh\": {\"generate\": \"sphere\", \"radius\": 0.1, \"cell_size\": 0.05},"
    "   \"transform\": {\"translate\": [0, 0, 1]},"
    "   \"material\": {\"model\": \"neohookean\", \"youngs_modulus\": 1e5}}],"
    " \"obstacles\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 0, 1]}]}";

static int fail(const char *what) {
  fprintf(stderr, "consumer: %s: %s\n", what, piola_last_error());
  return 1;
}

/* Mean height of the solid's nodes, m. */
static double mean_height(const piola_world *world) {
  const piola_elastic_body *body = piola_world_solid_body(world, 0);
  int32_t n = piola_elastic_body_vertex_count(body);
  const double *x = piola_world_solid_positions(world, 0);
  double sum = 0;
  for (int32_t i = 0; i < n; ++i) sum += x[3 * i + 2];
  return sum / n;
}

int main(int argc, char **argv) {
  const char *png = argc > 1 ? argv[1] : "consumer.png";
  piola_scene_desc *desc;
  if (piola_scene_parse_string(SCENE, ".", "consumer", &desc) != PIOLA_OK) return fail("parse");
  if (piola_scene_desc_solid_count(desc) != 1 || piola_scene_desc_obstacle_count(desc) != 1) {
    fprintf(stderr, "consumer: the parsed scene has the wrong number of solids or obstacles\n");
    return 1;
  }
  piola_scene *scene;
  if (piola_scene_build(desc, &scene) != PIOLA_OK) return fail("build");
  piola_world *world = piola_scene_world(scene);
  double t = 1.0 / piola_scene_fps(scene);
  double z0 = mean_height(world);
  if (piola_world_advance_to(world, t, NULL) != PIOLA_OK) return fail("advance");
  /* free fall of the centre of mass for t = 0.02 s: g t^2 / 2 = 1.96 mm */
  double drop = z0 - mean_height(world), expected = 0.5 * 9.81 * t * t;
  if (!(fabs(drop - expected) < 0.05 * expected)) {
    fprintf(stderr, "consumer: the ball fell %g m in %g s, expected %g m\n", drop, t, expected);
    return 1;
  }
  piola_scene_destroy(scene);

  piola_render_def def = piola_default_render_def();
  def.width = 64, def.height = 48;
  piola_renderer *renderer;
  if (piola_renderer_create(&def, &renderer) != PIOLA_OK) return fail("renderer");
  piola_obstacle_def plane = piola_scene_desc_obstacle(desc, 0, NULL);
  if (piola_renderer_add_obstacle(renderer, &plane) != PIOLA_OK) return fail("obstacle");
  piola_renderer_fit_camera(renderer, (piola_vec3){-0.1, -0.1, 0.9}, (piola_vec3){0.1, 0.1, 1.1});
  piola_image image = {0}, back = {0};
  if (piola_renderer_render(renderer, NULL, &image) != PIOLA_OK) return fail("render");
  if (piola_image_write_png(png, &image) != PIOLA_OK) return fail("write png");
  if (piola_image_read_png(png, &back) != PIOLA_OK) return fail("read png");
  int ok = back.width == 64 && back.height == 48;
  piola_image_free(&image);
  piola_image_free(&back);
  piola_renderer_destroy(renderer);
  piola_scene_desc_destroy(desc);
  if (!ok) fprintf(stderr, "consumer: the PNG reads back at the wrong size\n");
  return ok ? 0 : 1;
}
