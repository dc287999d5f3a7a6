/* A solid's `fracture` key: scripted cuts by planes and triangle surfaces (the virtual node
 * algorithm) and the stress and plastic strain criteria (docs/fracture.md). */
#include <stdlib.h>
#include <string.h>

#include "scene/scene_parse_sections.h"

/* A moving blade's "end_time" (s, > time) and "velocity" (m/s): both or neither. */
static piola_status parse_motion(scene_parser *p, const cJSON *obj, piola_fracture_cut *cut) {
  const cJSON *end = piola__json_get(obj, "end_time"), *velocity = piola__json_get(obj, "velocity");
  if (!end && !velocity) return PIOLA_OK;
  if (!piola__json_get(obj, "mesh")) {
    piola__json_push_key(p, end ? "end_time" : "velocity");
    return piola__json_fail(p, BAD_VALUE, "only a blade moves: needs \"mesh\"");
  }
  PIOLA_TRY(piola__json_required(p, obj, "end_time"));
  PIOLA_TRY(piola__json_required(p, obj, "velocity"));
  PIOLA_TRY(piola__json_opt_number(p, obj, "end_time", NONNEGATIVE, &cut->end_time));
  if (!(cut->end_time > cut->time)) {
    piola__json_push_key(p, "end_time");
    return piola__json_fail(p, BAD_VALUE, "must be > \"time\" (%g s), got %g", cut->time, cut->end_time);
  }
  return piola__json_opt_vec3(p, obj, "velocity", ANY, &cut->velocity);
}

/* {"time": t, "plane": {...}} or {"time": t, "mesh": "blade.obj"} (a moving blade with
 * "end_time" and "velocity"); a mesh's path goes to blade_path (resolved against the scene's
 * folder; the builder reads it). */
static piola_status parse_cut(scene_parser *p, const cJSON *obj, piola_fracture_cut *cut, char *blade_path) {
  static const char *const allowed[] = {"time", "plane", "mesh", "end_time", "velocity", NULL};
  PIOLA_TRY(piola__json_check_keys(p, obj, allowed));
  PIOLA_TRY(piola__json_required(p, obj, "time"));
  PIOLA_TRY(piola__json_opt_number(p, obj, "time", NONNEGATIVE, &cut->time));
  const cJSON *mesh = piola__json_get(obj, "mesh");
  if (mesh && piola__json_get(obj, "plane"))
    return piola__json_fail(p, BAD_VALUE, "give either \"plane\" or \"mesh\", not both");
  PIOLA_TRY(parse_motion(p, obj, cut));
  if (mesh) {
    size_t old = piola__json_push_key(p, "mesh");
    PIOLA_TRY(piola__json_path(p, mesh, blade_path));
    piola__json_pop(p, old);
    return PIOLA_OK;
  }
  PIOLA_TRY(piola__json_required(p, obj, "plane"));
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

/* "fracture": {"cuts": [{"time": t, "plane": {"point": [..], "normal": [..]}} or
 * {"time": t, "mesh": path, "end_time": t1, "velocity": [..]}, ...], "max_cuts_per_step": n,
 * "criterion": "stress" or "plastic_strain", "threshold": Pa or strain, "max_tets_per_step": n,
 * "max_crack_speed": m/s, "growth_threshold": Pa or strain}. */
piola_status piola__scene_parse_fracture(scene_parser *p, const cJSON *obj, scene_solid_desc *d) {
  static const char *const allowed[] = {"cuts", "max_cuts_per_step", "criterion", "threshold",
                                        "max_tets_per_step", "max_crack_speed", "growth_threshold", NULL};
  PIOLA_TRY(piola__json_check_keys(p, obj, allowed));
  d->fractures = 1;
  d->fracture = piola_default_fracture_def();
  const cJSON *criterion = piola__json_get(obj, "criterion");
  if (criterion) {
    size_t o2 = piola__json_push_key(p, "criterion");
    const int plastic = cJSON_IsString(criterion) && strcmp(criterion->valuestring, "plastic_strain") == 0;
    if (!plastic && (!cJSON_IsString(criterion) || strcmp(criterion->valuestring, "stress") != 0))
      return piola__json_fail(p, BAD_VALUE, "must be \"stress\" or \"plastic_strain\"");
    if (plastic && !d->plastic)
      return piola__json_fail(p, BAD_VALUE, "\"plastic_strain\" needs the solid's \"plasticity\"");
    piola__json_pop(p, o2);
    PIOLA_TRY(piola__json_required(p, obj, "threshold"));
    d->fracture.criterion = plastic ? PIOLA_FRACTURE_PLASTIC_STRAIN : PIOLA_FRACTURE_STRESS;
    PIOLA_TRY(piola__json_opt_number(p, obj, "threshold", POSITIVE, &d->fracture.threshold));
    int64_t tets = 0;
    PIOLA_TRY(piola__json_opt_int(p, obj, "max_tets_per_step", 1, 100000000, &tets));
    d->fracture.max_tets_per_step = (int32_t)tets;
    PIOLA_TRY(piola__json_opt_number(p, obj, "max_crack_speed", POSITIVE, &d->fracture.max_crack_speed));
    PIOLA_TRY(piola__json_opt_number(p, obj, "growth_threshold", POSITIVE, &d->fracture.growth_threshold));
  } else if (piola__json_get(obj, "threshold") || piola__json_get(obj, "max_tets_per_step") ||
             piola__json_get(obj, "max_crack_speed") || piola__json_get(obj, "growth_threshold")) {
    const char *key = piola__json_get(obj, "threshold")           ? "threshold"
                      : piola__json_get(obj, "max_tets_per_step") ? "max_tets_per_step"
                      : piola__json_get(obj, "max_crack_speed")   ? "max_crack_speed"
                                                                  : "growth_threshold";
    piola__json_push_key(p, key);
    return piola__json_fail(p, BAD_VALUE, "needs a \"criterion\"");
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
  d->fracture_blade_paths = calloc((size_t)count, sizeof *d->fracture_blade_paths);
  if (!d->fracture_cuts || !d->fracture_blade_paths) return piola__json_fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  int i = 0;
  for (const cJSON *e = cuts->child; e; e = e->next, ++i) {
    size_t o2 = piola__json_push_index(p, i);
    if (!cJSON_IsObject(e)) return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an object");
    PIOLA_TRY(parse_cut(p, e, &d->fracture_cuts[i], d->fracture_blade_paths[i]));
    d->fracture.cut_count = i + 1;
    piola__json_pop(p, o2);
  }
  d->fracture.cuts = d->fracture_cuts;
  piola__json_pop(p, old);
  return PIOLA_OK;
}
