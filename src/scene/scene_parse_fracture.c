/* A solid's `fracture` key: scripted plane cuts by the virtual node algorithm and the stress
 * criterion (docs/fracture.md). */
#include <stdlib.h>
#include <string.h>

#include "scene/scene_parse_sections.h"

static piola_status parse_cut(scene_parser *p, const cJSON *obj, piola_fracture_cut *cut) {
  static const char *const allowed[] = {"time", "plane", "mesh", NULL};
  PIOLA_TRY(piola__json_check_keys(p, obj, allowed));
  if (piola__json_get(obj, "mesh")) {
    piola__json_push_key(p, "mesh");
    return piola__json_fail(p, BAD_VALUE, "cuts by a surface mesh are not supported: give a \"plane\"");
  }
  PIOLA_TRY(piola__json_required(p, obj, "time"));
  PIOLA_TRY(piola__json_required(p, obj, "plane"));
  PIOLA_TRY(piola__json_opt_number(p, obj, "time", NONNEGATIVE, &cut->time));
  const cJSON *plane = piola__json_get(obj, "plane");
  size_t old = piola__json_push_key(p, "plane");
  static const char *const plane_keys[] = {"point", "normal", NULL};
  PIOLA_TRY(piola__json_check_keys(p, plane, plane_keys));
  PIOLA_TRY(piola__json_required(p, plane, "point"));
  PIOLA_TRY(piola__json_required(p, plane, "normal"));
  PIOLA_TRY(piola__json_opt_vec3(p, plane, "point", ANY, &cut->point));
  PIOLA_TRY(piola__json_opt_direction(p, plane, "normal", &cut->normal));
  piola__json_pop(p, old);
  return PIOLA_OK;
}

/* "fracture": {"cuts": [{"time": t, "plane": {"point": [..], "normal": [..]}}, ...],
 * "max_cuts_per_step": n, "criterion": "stress", "threshold": Pa}. */
piola_status piola__scene_parse_fracture(scene_parser *p, const cJSON *obj, scene_solid_desc *d) {
  static const char *const allowed[] = {"cuts", "max_cuts_per_step", "criterion", "threshold", NULL};
  PIOLA_TRY(piola__json_check_keys(p, obj, allowed));
  d->fractures = 1;
  d->fracture = piola_default_fracture_def();
  const cJSON *criterion = piola__json_get(obj, "criterion");
  if (criterion) {
    size_t o2 = piola__json_push_key(p, "criterion");
    if (cJSON_IsString(criterion) && strcmp(criterion->valuestring, "plastic_strain") == 0)
      return piola__json_fail(p, BAD_VALUE, "\"plastic_strain\" is not supported: use \"stress\"");
    if (!cJSON_IsString(criterion) || strcmp(criterion->valuestring, "stress") != 0)
      return piola__json_fail(p, BAD_VALUE, "must be \"stress\"");
    piola__json_pop(p, o2);
    PIOLA_TRY(piola__json_required(p, obj, "threshold"));
    d->fracture.criterion = PIOLA_FRACTURE_STRESS;
    PIOLA_TRY(piola__json_opt_number(p, obj, "threshold", POSITIVE, &d->fracture.threshold));
  } else if (piola__json_get(obj, "threshold")) {
    piola__json_push_key(p, "threshold");
    return piola__json_fail(p, BAD_VALUE, "needs \"criterion\": \"stress\"");
  } else {
    PIOLA_TRY(piola__json_required(p, obj, "cuts"));
  }
  int64_t most = 0;
  PIOLA_TRY(piola__json_opt_int(p, obj, "max_cuts_per_step", 1, 1000000, &most));
  d->fracture.max_cuts_per_step = (int32_t)most;
  const cJSON *cuts = piola__json_get(obj, "cuts");
  if (!cuts) return PIOLA_OK;
  size_t old = piola__json_push_key(p, "cuts");
  if (!cJSON_IsArray(cuts) || cJSON_GetArraySize(cuts) < 1)
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be a non-empty array of cuts");
  const int count = cJSON_GetArraySize(cuts);
  d->fracture_cuts = calloc((size_t)count, sizeof *d->fracture_cuts);
  if (!d->fracture_cuts) return piola__json_fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  int i = 0;
  for (const cJSON *e = cuts->child; e; e = e->next, ++i) {
    size_t o2 = piola__json_push_index(p, i);
    if (!cJSON_IsObject(e)) return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an object");
    PIOLA_TRY(parse_cut(p, e, &d->fracture_cuts[i]));
    d->fracture.cut_count = i + 1;
    piola__json_pop(p, o2);
  }
  d->fracture.cuts = d->fracture_cuts;
  piola__json_pop(p, old);
  return PIOLA_OK;
}
