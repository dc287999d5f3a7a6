/* The obstacles (and bones) of a scene file, for drawing. Only the parser runs (src/scene): solids'
 * meshes are neither read nor generated, so a large scene's preview costs nothing extra;
 * mesh obstacles read their surface file, resolved against the scene's folder. */
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_internal.h"
#include "piola/keyframes.h"
#include "piola/mesh_io.h"
#include "render/render_internal.h"
#include "scene/scene_desc.h"

static piola_status read_all(const char *path, char **out) {
  *out = NULL;
  FILE *f = fopen(path, "rb");
  if (!f) return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot open: %s", path, strerror(errno));
  long n = -1;
  if (fseek(f, 0, SEEK_END) == 0) n = ftell(f);
  if (n < 0 || n > (64L << 20) || fseek(f, 0, SEEK_SET) != 0) {
    fclose(f);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot read (or larger than 64 MiB)", path);
  }
  char *text = malloc((size_t)n + 1);
  if (!text || fread(text, 1, (size_t)n, f) != (size_t)n) {
    free(text);
    fclose(f);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: read error", path);
  }
  fclose(f);
  text[n] = '\0';
  if (strlen(text) != (size_t)n) {
    free(text);
    return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: contains a NUL byte", path);
  }
  *out = text;
  return PIOLA_OK;
}

/* Parses the scene file at path (its mesh paths resolved against its folder). */
static piola_status parse_scene_file(const char *path, scene_desc *desc) {
  char *text;
  PIOLA_TRY(read_all(path, &text));
  char dir[SCENE_PATH_MAX];
  snprintf(dir, sizeof dir, "%s", path);
  char *slash = strrchr(dir, '/');
  if (slash)
    *slash = '\0';
  else
    snprintf(dir, sizeof dir, ".");
  if (dir[0] == '\0') snprintf(dir, sizeof dir, "/");
  piola_status st = piola__scene_parse(text, dir, path, desc);
  free(text);
  return st;
}

static const char *const type_names[PIOLA_OBSTACLE_TYPE_COUNT] = {
    "plane", "sphere", "box", "cylinder", "capsule", "torus", "gear", "mesh"};

/* Whether spec names obstacle i of the scene's obstacles and bones together (bones after
 * the obstacles). */
static bool spec_names(const scene_desc *desc, int32_t i, const char *spec) {
  bool bone = i >= desc->obstacle_count;
  int32_t k = bone ? i - desc->obstacle_count : i;
  const scene_obstacle_desc *d = bone ? &desc->bones[k].obstacle : &desc->obstacles[i];
  const char *name = bone ? desc->bones[k].name : d->name;
  char indexed[64];
  snprintf(indexed, sizeof indexed, "%s[%d]", bone ? "bones" : "obstacles", (int)k);
  return strcmp(spec, "all") == 0 || strcmp(spec, name) == 0 || strcmp(spec, indexed) == 0 ||
         ((unsigned)d->def.type < PIOLA_OBSTACLE_TYPE_COUNT &&
          strcmp(spec, type_names[d->def.type]) == 0);
}

static piola_status unmatched(const scene_desc *desc, const char *path, const char *spec) {
  char names[1024] = "";
  size_t n = 0;
  for (int32_t i = 0; i < desc->obstacle_count + desc->bone_count && n < sizeof names - 1; ++i) {
    bool bone = i >= desc->obstacle_count;
    const scene_obstacle_desc *d =
        bone ? &desc->bones[i - desc->obstacle_count].obstacle : &desc->obstacles[i];
    int w = snprintf(names + n, sizeof names - n, "%s%s (%s)", i ? ", " : "",
                     bone ? desc->bones[i - desc->obstacle_count].name : d->name,
                     type_names[d->def.type]);
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
  scene_desc desc;
  PIOLA_TRY(parse_scene_file(path, &desc));
  int32_t total = desc.obstacle_count + desc.bone_count;
  piola_status st = PIOLA_OK;
  for (int32_t h = 0; st == PIOLA_OK && h < hide_count; ++h) {
    bool any = false;
    for (int32_t i = 0; i < total && !any; ++i) any = spec_names(&desc, i, hide[h]);
    if (!any && strcmp(hide[h], "all") != 0) st = unmatched(&desc, path, hide[h]);
  }
  /* bones are obstacles too (their attachments do not matter for drawing) */
  for (int32_t i = 0; st == PIOLA_OK && i < total; ++i) {
    bool hidden = false;
    for (int32_t h = 0; h < hide_count && !hidden; ++h) hidden = spec_names(&desc, i, hide[h]);
    if (hidden) continue;
    scene_obstacle_desc *d = i < desc.obstacle_count ? &desc.obstacles[i]
                                                     : &desc.bones[i - desc.obstacle_count].obstacle;
    piola_obstacle_def def = d->def;
    piola_tri_mesh surface = {0};
    if (def.type == PIOLA_OBSTACLE_MESH) {
      st = piola_tri_mesh_read(d->mesh_path, &surface);
      def.mesh = &surface;
    }
    if (st == PIOLA_OK) st = piola_renderer_add_obstacle(r, &def);
    piola_tri_mesh_free(&surface);
  }
  piola__scene_desc_free(&desc);
  return st;
}

piola_status piola_renderer_load_scene_obstacles(piola_renderer *r, const char *path) {
  return piola_renderer_load_scene_obstacles_hiding(r, path, NULL, 0);
}

piola_status piola_render_scene_up(const char *path, piola_vec3 *up) {
  if (!path || !up) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "render: NULL argument");
  scene_desc desc;
  PIOLA_TRY(parse_scene_file(path, &desc));
  double g[3];
  for (int k = 0; k < 3; ++k) g[k] = piola_track_eval(&desc.world.gravity[k], 0);
  piola__scene_desc_free(&desc);
  double n = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  *up = n > 0 && isfinite(n) ? (piola_vec3){-g[0] / n, -g[1] / n, -g[2] / n}
                             : (piola_vec3){0, 0, 1};
  return PIOLA_OK;
}
