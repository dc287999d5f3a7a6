/* The public scene handle: parse, build, and keep the output settings next to the world. */
#include "piola/scene.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/input_path.h"
#include "common/status_internal.h"
#include "scene/scene_desc.h"

struct piola_scene {
  double fps;
  int32_t frames;
  piola_world *world;
};

piola_status piola_scene_load_string(const char *json, const char *base_dir, const char *label,
                                     piola_scene **out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "scene: out is NULL");
  *out = NULL;
  if (!label) label = "scene";
  if (!base_dir) base_dir = ".";
  scene_desc desc;
  if (json) PIOLA_TRY(piola__scene_check_text(json, label));
  PIOLA_TRY(piola__scene_parse(json, base_dir, label, &desc));
  piola_scene *scene = calloc(1, sizeof *scene);
  if (!scene) {
    piola__scene_desc_free(&desc);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", label);
  }
  scene->fps = desc.fps;
  scene->frames = desc.frames;
  piola_status st = piola__scene_build(&desc, label, &scene->world);
  piola__scene_desc_free(&desc);
  if (st != PIOLA_OK) {
    free(scene);
    return st;
  }
  *out = scene;
  return PIOLA_OK;
}

piola_status piola_scene_load(const char *path, piola_scene **out) {
  if (!out || !path) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "scene: NULL argument");
  *out = NULL;
  FILE *f;
  PIOLA_TRY(piola__open_input(path, &f));
  char *text = NULL;
  size_t len = 0, cap = 0;
  for (;;) {
    if (len + 4096 + 1 > cap) {
      cap = cap ? 2 * cap : 65536;
      if (cap > ((size_t)64 << 20)) {
        free(text);
        fclose(f);
        return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: scene file is larger than 64 MiB", path);
      }
      char *grown = realloc(text, cap);
      if (!grown) {
        free(text);
        fclose(f);
        return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
      }
      text = grown;
    }
    size_t got = fread(text + len, 1, 4096, f);
    len += got;
    if (got < 4096) break;
  }
  int bad = ferror(f);
  fclose(f);
  if (bad) {
    free(text);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: read error", path);
  }
  text[len] = '\0';
  if (strlen(text) != len) {
    free(text);
    return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: contains a NUL byte", path);
  }
  char dir[4096];
  snprintf(dir, sizeof dir, "%s", path);
  char *slash = strrchr(dir, '/');
  if (slash) *slash = '\0';
  else snprintf(dir, sizeof dir, ".");
  if (dir[0] == '\0') snprintf(dir, sizeof dir, "/");
  piola_status st = piola_scene_load_string(text, dir, path, out);
  free(text);
  return st;
}

void piola_scene_destroy(piola_scene *scene) {
  if (!scene) return;
  piola_world_destroy(scene->world);
  free(scene);
}

double piola_scene_fps(const piola_scene *scene) { return scene->fps; }
int32_t piola_scene_frames(const piola_scene *scene) { return scene->frames; }
piola_world *piola_scene_world(piola_scene *scene) { return scene->world; }
