/* The public scene API: parse (scene_parse*.c) into a description, build (scene_build.c) it
 * into a world, and keep the output settings next to the world. */
#include "piola/scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "piola/files.h"
#include "piola/keyframes.h"
#include "scene/scene_desc.h"

/* Scene files are small; a bigger file is a mistake (a mesh passed as the scene). */
#define SCENE_FILE_MAX_BYTES ((size_t)64 << 20)

struct piola_scene {
  double fps;
  int32_t frames;
  piola_world *world;
};

struct piola_scene_desc {
  scene_desc desc;
  char label[SCENE_PATH_MAX]; /* starts every message of the build */
};

piola_status piola_scene_parse_string(const char *json, const char *base_dir, const char *label,
                                      piola_scene_desc **out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "scene: out is NULL");
  *out = NULL;
  if (!label) label = "scene";
  if (!base_dir) base_dir = ".";
  if (json) PIOLA_TRY(piola__scene_check_text(json, label));
  piola_scene_desc *d = calloc(1, sizeof *d);
  if (!d) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", label);
  snprintf(d->label, sizeof d->label, "%s", label);
  piola_status st = piola__scene_parse(json, base_dir, label, &d->desc);
  if (st != PIOLA_OK) {
    free(d);
    return st;
  }
  *out = d;
  return PIOLA_OK;
}

void piola__scene_folder(const char *path, char dir[SCENE_PATH_MAX]) {
  snprintf(dir, SCENE_PATH_MAX, "%s", path);
  char *slash = strrchr(dir, '/');
  if (slash)
    *slash = '\0';
  else
    snprintf(dir, SCENE_PATH_MAX, ".");
  if (dir[0] == '\0') snprintf(dir, SCENE_PATH_MAX, "/");
}

/* The text of a scene file: a NUL byte inside would cut the JSON short without a word. */
static piola_status read_scene_text(const char *path, char **text) {
  size_t len;
  PIOLA_TRY(piola_read_file(path, SCENE_FILE_MAX_BYTES, text, &len));
  if (strlen(*text) != len) {
    free(*text);
    *text = NULL;
    return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: contains a NUL byte", path);
  }
  return PIOLA_OK;
}

piola_status piola_scene_parse_file(const char *path, piola_scene_desc **out) {
  if (!out || !path) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "scene: NULL argument");
  *out = NULL;
  char *text;
  PIOLA_TRY(read_scene_text(path, &text));
  char dir[SCENE_PATH_MAX];
  piola__scene_folder(path, dir);
  piola_status st = piola_scene_parse_string(text, dir, path, out);
  free(text);
  return st;
}

void piola_scene_desc_destroy(piola_scene_desc *desc) {
  if (!desc) return;
  piola__scene_desc_free(&desc->desc);
  free(desc);
}

piola_status piola_scene_build(const piola_scene_desc *desc, piola_scene **out) {
  return piola_scene_build_split(desc, NULL, out);
}

piola_status piola_scene_build_split(const piola_scene_desc *desc,
                                     const piola_work_split_planner *planner, piola_scene **out) {
  if (!desc || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "scene: NULL argument");
  *out = NULL;
  piola_scene *scene = calloc(1, sizeof *scene);
  if (!scene) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", desc->label);
  scene->fps = desc->desc.fps;
  scene->frames = desc->desc.frames;
  piola_status st = piola__scene_build(&desc->desc, desc->label, planner, &scene->world);
  if (st != PIOLA_OK) {
    free(scene);
    return st;
  }
  *out = scene;
  return PIOLA_OK;
}

/* Builds a parsed description and frees it. */
static piola_status build_and_free(piola_scene_desc *desc, piola_scene **out) {
  piola_status st = piola_scene_build(desc, out);
  piola_scene_desc_destroy(desc);
  return st;
}

piola_status piola_scene_load_string(const char *json, const char *base_dir, const char *label,
                                     piola_scene **out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "scene: out is NULL");
  *out = NULL;
  piola_scene_desc *desc;
  PIOLA_TRY(piola_scene_parse_string(json, base_dir, label, &desc));
  return build_and_free(desc, out);
}

piola_status piola_scene_load(const char *path, piola_scene **out) {
  if (!out || !path) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "scene: NULL argument");
  *out = NULL;
  piola_scene_desc *desc;
  PIOLA_TRY(piola_scene_parse_file(path, &desc));
  return build_and_free(desc, out);
}

void piola_scene_destroy(piola_scene *scene) {
  if (!scene) return;
  piola_world_destroy(scene->world);
  free(scene);
}

double piola_scene_fps(const piola_scene *scene) { return scene->fps; }
int32_t piola_scene_frames(const piola_scene *scene) { return scene->frames; }
piola_world *piola_scene_world(piola_scene *scene) { return scene->world; }

double piola_scene_desc_fps(const piola_scene_desc *d) { return d->desc.fps; }
int32_t piola_scene_desc_frames(const piola_scene_desc *d) { return d->desc.frames; }
int32_t piola_scene_desc_solid_count(const piola_scene_desc *d) { return d->desc.solid_count; }

/* Whether i names a solid of d, or an entry of its obstacle list (obstacles, then bones). */
static bool is_solid(const piola_scene_desc *d, int32_t i) {
  return i >= 0 && i < d->desc.solid_count;
}
static bool is_obstacle(const piola_scene_desc *d, int32_t i) {
  return i >= 0 && i < d->desc.obstacle_count + d->desc.bone_count;
}

const char *piola_scene_desc_solid_name(const piola_scene_desc *d, int32_t i) {
  return is_solid(d, i) ? d->desc.solids[i].name : NULL;
}

piola_material_def piola_scene_desc_solid_material(const piola_scene_desc *d, int32_t i) {
  if (!is_solid(d, i)) return (piola_material_def){0};
  return d->desc.solids[i].def.material;
}

int32_t piola_scene_desc_obstacle_count(const piola_scene_desc *d) {
  return d->desc.obstacle_count + d->desc.bone_count;
}

piola_obstacle_def piola_scene_desc_obstacle(const piola_scene_desc *d, int32_t i,
                                             const char **mesh_path) {
  const scene_desc *s = &d->desc;
  if (!is_obstacle(d, i)) {
    if (mesh_path) *mesh_path = NULL;
    return (piola_obstacle_def){0};
  }
  const scene_obstacle_desc *o =
      i < s->obstacle_count ? &s->obstacles[i] : &s->bones[i - s->obstacle_count].obstacle;
  if (mesh_path) *mesh_path = o->mesh_path;
  return o->def;
}

const char *piola_scene_desc_obstacle_name(const piola_scene_desc *d, int32_t i) {
  const scene_desc *s = &d->desc;
  if (!is_obstacle(d, i)) return NULL;
  return i < s->obstacle_count ? s->obstacles[i].name : s->bones[i - s->obstacle_count].name;
}

bool piola_scene_desc_obstacle_is_bone(const piola_scene_desc *d, int32_t i) {
  return is_obstacle(d, i) && i >= d->desc.obstacle_count;
}

piola_vec3 piola_scene_desc_gravity(const piola_scene_desc *d, double t) {
  const piola_track *g = d->desc.world.gravity;
  return (piola_vec3){piola_track_eval(&g[0], t), piola_track_eval(&g[1], t),
                      piola_track_eval(&g[2], t)};
}
