/* A scene file copied with absolute mesh paths (piola_scene_copy_resolved): `piola run` keeps
 * one in its output folder so `piola render DIR` finds the obstacles from anywhere. */
#include <cjson/cJSON.h>
#include <limits.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/fnv1a.h"
#include "common/status_report.h"
#include "piola/files.h"
#include "piola/scene.h"
#include "scene/scene_desc.h"

/* The path item names, made absolute against folder when relative, into buf; false where
 * item is no path (a generator object, an empty string). */
static bool resolved_path(const cJSON *item, const char *folder, char *buf, size_t size) {
  if (!cJSON_IsString(item) || !item->valuestring || !item->valuestring[0]) return false;
  if (item->valuestring[0] == '/')
    snprintf(buf, size, "%s", item->valuestring);
  else
    snprintf(buf, size, "%s/%s", folder, item->valuestring);
  return true;
}

/* Makes a relative path string absolute against folder. */
static void make_absolute(cJSON *item, const char *folder, void *unused) {
  (void)unused;
  char buf[PATH_MAX + 512];
  if (resolved_path(item, folder, buf, sizeof buf) && item->valuestring[0] != '/')
    cJSON_SetValuestring(item, buf);
}

typedef void (*path_visitor)(cJSON *item, const char *folder, void *context);

/* key of every element of root[list] (a generator object too: the visitor skips it). */
static void visit_list(cJSON *root, const char *list, const char *key, path_visitor visit,
                       const char *folder, void *context) {
  cJSON *it;
  cJSON_ArrayForEach(it, cJSON_GetObjectItemCaseSensitive(root, list))
      visit(cJSON_GetObjectItemCaseSensitive(it, key), folder, context);
}

/* Every key of a scene that names a file: the meshes of solids, shells, obstacles and bones,
 * plastic goal meshes and fracture cut meshes. */
static void visit_paths(cJSON *root, path_visitor visit, const char *folder, void *context) {
  visit_list(root, "solids", "mesh", visit, folder, context);
  visit_list(root, "shells", "mesh", visit, folder, context);
  visit_list(root, "obstacles", "path", visit, folder, context);
  visit_list(root, "bones", "path", visit, folder, context);
  cJSON *solid;
  cJSON_ArrayForEach(solid, cJSON_GetObjectItemCaseSensitive(root, "solids")) {
    cJSON *plasticity = cJSON_GetObjectItemCaseSensitive(solid, "plasticity");
    cJSON *control = cJSON_GetObjectItemCaseSensitive(plasticity, "control");
    cJSON *goal = cJSON_GetObjectItemCaseSensitive(control, "goal");
    visit(cJSON_GetObjectItemCaseSensitive(goal, "mesh"), folder, context);
    cJSON *fracture = cJSON_GetObjectItemCaseSensitive(solid, "fracture");
    visit_list(fracture, "cuts", "mesh", visit, folder, context);
  }
}

/* The scene at scene_path as JSON, and its folder (absolute where it resolves). */
static piola_status read_scene_json(const char *scene_path, cJSON **root, char folder[PATH_MAX]) {
  char *text;
  size_t len;
  PIOLA_TRY(piola_read_file(scene_path, (size_t)64 << 20, &text, &len));
  *root = cJSON_Parse(text);
  free(text);
  if (!*root) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: not valid JSON", scene_path);
  char tmp[SCENE_PATH_MAX];
  piola__scene_folder(scene_path, tmp);
  if (!realpath(tmp, folder)) snprintf(folder, PATH_MAX, "%s", tmp);
  return PIOLA_OK;
}

/* Folds the path and the bytes of the file it names (resolved against folder) into the key;
 * an unreadable file by its path alone (the scene's build has refused it already). */
static void hash_file(cJSON *item, const char *folder, void *context) {
  uint64_t *key = context;
  char path[PATH_MAX + 512];
  if (!resolved_path(item, folder, path, sizeof path)) return;
  *key = piola__fnv1a(*key, path, strlen(path) + 1);
  char *bytes;
  size_t len;
  if (piola_read_file(path, (size_t)1 << 31, &bytes, &len) != PIOLA_OK) {
    piola_clear_error();
    return;
  }
  *key = piola__fnv1a(*key, bytes, len);
  free(bytes);
}

piola_status piola_scene_inputs_key(const char *scene_path, uint64_t *key) {
  if (!scene_path || !key)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "scene inputs key: NULL argument");
  cJSON *root;
  char folder[PATH_MAX];
  PIOLA_TRY(read_scene_json(scene_path, &root, folder));
  *key = PIOLA_FNV_OFFSET;
  visit_paths(root, hash_file, folder, key);
  cJSON_Delete(root);
  return PIOLA_OK;
}

piola_status piola_scene_copy_resolved(const char *scene_path, const char *out_path) {
  if (!scene_path || !out_path)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "scene copy: NULL argument");
  cJSON *root;
  char folder[PATH_MAX];
  PIOLA_TRY(read_scene_json(scene_path, &root, folder));
  visit_paths(root, make_absolute, folder, NULL);
  char *out = cJSON_Print(root);
  cJSON_Delete(root);
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "scene copy: out of memory");
  piola_atomic_file af;
  piola_status st = piola_atomic_file_open(&af, out_path);
  if (st == PIOLA_OK) {
    fputs(out, af.stream);
    fputc('\n', af.stream);
    st = piola_atomic_file_commit(&af);
  }
  free(out);
  return st;
}
