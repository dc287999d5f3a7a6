/* The obstacles (and bones) of a scene file, for drawing, and its up direction. Only the
 * parser runs (piola_scene_parse_file): solids' meshes are neither read nor generated, so a
 * large scene's preview costs nothing extra; mesh obstacles read their surface file,
 * resolved against the scene's folder. */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "common/status_report.h"
#include "piola/mesh_io.h"
#include "piola/scene.h"
#include "render/render_internal.h"

static const char *const type_names[PIOLA_OBSTACLE_TYPE_COUNT] = {
    "plane", "sphere", "box", "cylinder", "capsule", "torus", "gear", "mesh"};

static const char *type_name(piola_obstacle_type t) {
  return (unsigned)t < PIOLA_OBSTACLE_TYPE_COUNT ? type_names[t] : "?";
}

/* Whether spec names entry i of the scene's obstacle list (obstacles, then bones). */
static bool spec_names(const piola_scene_desc *desc, int32_t i, const char *spec) {
  bool bone = piola_scene_desc_obstacle_is_bone(desc, i);
  int32_t first_bone = i;
  while (first_bone > 0 && piola_scene_desc_obstacle_is_bone(desc, first_bone - 1)) --first_bone;
  char indexed[64];
  snprintf(indexed, sizeof indexed, "%s[%d]", bone ? "bones" : "obstacles",
           (int)(bone ? i - first_bone : i));
  piola_obstacle_def def = piola_scene_desc_obstacle(desc, i, NULL);
  return strcmp(spec, "all") == 0 || strcmp(spec, piola_scene_desc_obstacle_name(desc, i)) == 0 ||
         strcmp(spec, indexed) == 0 || strcmp(spec, type_name(def.type)) == 0;
}

static piola_status unmatched(const piola_scene_desc *desc, const char *path, const char *spec) {
  char names[1024] = "";
  size_t n = 0;
  for (int32_t i = 0; i < piola_scene_desc_obstacle_count(desc) && n < sizeof names - 1; ++i) {
    int w = snprintf(names + n, sizeof names - n, "%s%s (%s)", i ? ", " : "",
                     piola_scene_desc_obstacle_name(desc, i),
                     type_name(piola_scene_desc_obstacle(desc, i, NULL).type));
    if (w < 0) break;
    n += (size_t)w < sizeof names - n ? (size_t)w : sizeof names - n - 1;
  }
  return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                    "%s: no obstacle or bone is named '%s' (the scene has: %s; also \"all\", a "
                    "type, obstacles[i] or bones[i])",
                    path, spec, n ? names : "no obstacles");
}

piola_status piola_renderer_load_scene_obstacles_hiding(piola_renderer *r, const char *path,
                                                        const char *const *hide,
                                                        int32_t hide_count) {
  if (!r || !path || (hide_count > 0 && !hide) || hide_count < 0)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "renderer: NULL argument");
  piola_scene_desc *desc;
  PIOLA_TRY(piola_scene_parse_file(path, &desc));
  int32_t total = piola_scene_desc_obstacle_count(desc);
  piola_status st = PIOLA_OK;
  for (int32_t h = 0; st == PIOLA_OK && h < hide_count; ++h) {
    bool any = false;
    for (int32_t i = 0; i < total && !any; ++i) any = spec_names(desc, i, hide[h]);
    if (!any && strcmp(hide[h], "all") != 0) st = unmatched(desc, path, hide[h]);
  }
  /* bones are obstacles too (their attachments do not matter for drawing) */
  for (int32_t i = 0; st == PIOLA_OK && i < total; ++i) {
    bool hidden = false;
    for (int32_t h = 0; h < hide_count && !hidden; ++h) hidden = spec_names(desc, i, hide[h]);
    if (hidden) continue;
    const char *mesh_path;
    piola_obstacle_def def = piola_scene_desc_obstacle(desc, i, &mesh_path);
    piola_tri_mesh surface = {0};
    if (def.type == PIOLA_OBSTACLE_MESH) {
      st = piola_tri_mesh_read(mesh_path, &surface);
      def.mesh = &surface;
    }
    if (st == PIOLA_OK) st = piola_renderer_add_obstacle(r, &def);
    piola_tri_mesh_free(&surface);
  }
  piola_scene_desc_destroy(desc);
  return st;
}

piola_status piola_renderer_load_scene_obstacles(piola_renderer *r, const char *path) {
  return piola_renderer_load_scene_obstacles_hiding(r, path, NULL, 0);
}

piola_status piola_render_scene_up(const char *path, piola_vec3 *up) {
  if (!path || !up) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "render: NULL argument");
  piola_scene_desc *desc;
  PIOLA_TRY(piola_scene_parse_file(path, &desc));
  piola_vec3 g = piola_scene_desc_gravity(desc, 0);
  piola_scene_desc_destroy(desc);
  double n = sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
  *up = n > 0 && isfinite(n) ? (piola_vec3){-g.x / n, -g.y / n, -g.z / n} : (piola_vec3){0, 0, 1};
  return PIOLA_OK;
}
