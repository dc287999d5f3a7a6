/* A scene file copied with absolute mesh paths (piola_scene_copy_resolved): `piola run` keeps
 * one in its output folder so `piola render DIR` finds the obstacles from anywhere. */
#include <cjson/cJSON.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "piola/files.h"
#include "piola/scene.h"
#include "scene/scene_desc.h"

/* Makes a relative path string absolute against folder. */
static void make_absolute(cJSON *item, const char *folder) {
  if (!cJSON_IsString(item) || !item->valuestring || item->valuestring[0] == '/' ||
      !item->valuestring[0])
    return;
  char buf[PATH_MAX + 512];
  snprintf(buf, sizeof buf, "%s/%s", folder, item->valuestring);
  cJSON_SetValuestring(item, buf);
}

/* key of every element of root[list] (a generator object is left alone). */
static void make_list_absolute(cJSON *root, const char *list, const char *key,
                               const char *folder) {
  cJSON *it;
  cJSON_ArrayForEach(it, cJSON_GetObjectItemCaseSensitive(root, list))
      make_absolute(cJSON_GetObjectItemCaseSensitive(it, key), folder);
}

piola_status piola_scene_copy_resolved(const char *scene_path, const char *out_path) {
  if (!scene_path || !out_path)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "scene copy: NULL argument");
  char *text;
  size_t len;
  PIOLA_TRY(piola_read_file(scene_path, (size_t)64 << 20, &text, &len));
  cJSON *root = cJSON_Parse(text);
  free(text);
  if (!root) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: not valid JSON", scene_path);
  char folder[PATH_MAX];
  char tmp[SCENE_PATH_MAX];
  piola__scene_folder(scene_path, tmp);
  if (!realpath(tmp, folder)) snprintf(folder, sizeof folder, "%s", tmp);
  make_list_absolute(root, "solids", "mesh", folder);
  make_list_absolute(root, "shells", "mesh", folder);
  make_list_absolute(root, "obstacles", "path", folder);
  make_list_absolute(root, "bones", "path", folder);
  cJSON *solid;
  cJSON_ArrayForEach(solid, cJSON_GetObjectItemCaseSensitive(root, "solids")) {
    cJSON *plasticity = cJSON_GetObjectItemCaseSensitive(solid, "plasticity");
    cJSON *control = cJSON_GetObjectItemCaseSensitive(plasticity, "control");
    cJSON *goal = cJSON_GetObjectItemCaseSensitive(control, "goal");
    make_absolute(cJSON_GetObjectItemCaseSensitive(goal, "mesh"), folder);
    cJSON *fracture = cJSON_GetObjectItemCaseSensitive(solid, "fracture");
    make_list_absolute(fracture, "cuts", "mesh", folder);
  }
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
