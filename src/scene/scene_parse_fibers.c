/* A muscle solid's `fibers` key (docs/scene-format.md). */
#include <stdlib.h>
#include <string.h>

#include "scene/scene_parse_sections.h"

/* "fibers": {"axis": [x, y, z]} | {"curve": [[x, y, z], ...]} | {"from_mesh": true} |
 * {"around": {"axis": [x, y, z], "point": [x, y, z]}}. */
piola_status piola__scene_parse_fibers(scene_parser *p, const cJSON *obj, scene_fibers *f) {
  static const char *const allowed[] = {"axis", "curve", "from_mesh", "around", NULL};
  PIOLA_TRY(piola__json_check_keys(p, obj, allowed));
  const cJSON *axis = piola__json_get(obj, "axis"), *curve = piola__json_get(obj, "curve"),
              *mesh = piola__json_get(obj, "from_mesh"), *around = piola__json_get(obj, "around");
  if ((axis != NULL) + (curve != NULL) + (mesh != NULL) + (around != NULL) != 1)
    return piola__json_fail(p, PIOLA_ERROR_PARSE,
                            "needs exactly one of \"axis\", \"curve\", \"from_mesh\" and \"around\"");
  if (around) {
    size_t old = piola__json_push_key(p, "around");
    if (!cJSON_IsObject(around))
      return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an object {\"axis\": [x, y, z], \"point\": [x, y, z]}");
    static const char *const keys[] = {"axis", "point", NULL};
    PIOLA_TRY(piola__json_check_keys(p, around, keys));
    PIOLA_TRY(piola__json_required(p, around, "axis"));
    PIOLA_TRY(piola__json_opt_direction(p, around, "axis", &f->axis));
    f->point = (piola_vec3){0, 0, 0};
    PIOLA_TRY(piola__json_opt_vec3(p, around, "point", ANY, &f->point));
    f->kind = SCENE_FIBERS_AROUND;
    piola__json_pop(p, old);
    return PIOLA_OK;
  }
  if (axis) {
    f->kind = SCENE_FIBERS_AXIS;
    return piola__json_opt_direction(p, obj, "axis", &f->axis);
  }
  if (mesh) {
    size_t old = piola__json_push_key(p, "from_mesh");
    if (!cJSON_IsTrue(mesh))
      return piola__json_fail(p, BAD_VALUE, "must be true (leave the key out for no fibres)");
    f->kind = SCENE_FIBERS_FROM_MESH;
    piola__json_pop(p, old);
    return PIOLA_OK;
  }
  size_t old = piola__json_push_key(p, "curve");
  const int count = cJSON_IsArray(curve) ? cJSON_GetArraySize(curve) : 0;
  if (count < 2)
    return piola__json_fail(p, PIOLA_ERROR_PARSE,
                            "must be an array of at least 2 points [x, y, z] (m)");
  f->kind = SCENE_FIBERS_CURVE;
  f->curve = malloc(sizeof(double) * 3 * (size_t)count);
  if (!f->curve) return piola__json_fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  f->curve_points = count;
  int i = 0;
  for (const cJSON *e = curve->child; e; e = e->next, ++i) {
    size_t o2 = piola__json_push_index(p, i);
    piola_vec3 q;
    PIOLA_TRY(piola__json_vec3(p, e, ANY, &q));
    f->curve[3 * i] = q.x, f->curve[3 * i + 1] = q.y, f->curve[3 * i + 2] = q.z;
    if (i > 0 && f->curve[3 * i] == f->curve[3 * i - 3] &&
        f->curve[3 * i + 1] == f->curve[3 * i - 2] && f->curve[3 * i + 2] == f->curve[3 * i - 1])
      return piola__json_fail(p, BAD_VALUE,
                              "repeats the point before it (a segment needs a direction)");
    piola__json_pop(p, o2);
  }
  piola__json_pop(p, old);
  return PIOLA_OK;
}
