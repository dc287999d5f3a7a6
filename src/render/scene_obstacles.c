/* The obstacles (and bones) of a scene file, for drawing. Only the parser runs (src/scene): solids'
 * meshes are neither read nor generated, so a large scene's preview costs nothing extra;
 * mesh obstacles read their surface file, resolved against the scene's folder. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/input_path.h"
#include "common/status_internal.h"
#include "piola/mesh_io.h"
#include "render/render_internal.h"
#include "scene/scene_desc.h"

static piola_status read_all(const char *path, char **out) {
  *out = NULL;
  FILE *f;
  PIOLA_TRY(piola__open_input(path, &f));
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

piola_status piola_renderer_load_scene_obstacles(piola_renderer *r, const char *path) {
  if (!r || !path) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "renderer: NULL argument");
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
  scene_desc desc;
  piola_status st = piola__scene_parse(text, dir, path, &desc);
  free(text);
  PIOLA_TRY(st);
  /* bones are obstacles too (their attachments do not matter for drawing) */
  for (int32_t i = 0; st == PIOLA_OK && i < desc.obstacle_count + desc.bone_count; ++i) {
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
