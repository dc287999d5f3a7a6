/* `fixed` and `driven`: which nodes of a solid or shell are held, and how driven ones move. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_parse_sections.h"

piola_status piola__scene_parse_selector(scene_parser *p, const cJSON *obj, int driven,
                                         piola_constraint_def *out, int32_t **indices_out) {
  static const char *const fixed_keys[] = {"box", "sphere", "indices", NULL};
  static const char *const driven_keys[] = {"box", "sphere", "indices", "motion", NULL};
  PIOLA_TRY(piola__json_check_keys(p, obj, driven ? driven_keys : fixed_keys));
  memset(out, 0, sizeof *out);
  out->driven = driven;
  out->motion = piola_default_rigid_motion_def();
  int kinds = !!piola__json_get(obj, "box") + !!piola__json_get(obj, "sphere") +
              !!piola__json_get(obj, "indices");
  if (kinds != 1)
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "needs exactly one of box, sphere or indices");
  const cJSON *v;
  if ((v = piola__json_get(obj, "box"))) {
    size_t old = piola__json_push_key(p, "box");
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 2)
      return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be [[x0, y0, z0], [x1, y1, z1]]");
    out->selector.type = PIOLA_SELECT_BOX;
    size_t o2 = piola__json_push_index(p, 0);
    PIOLA_TRY(piola__json_vec3(p, v->child, ANY, &out->selector.box_min));
    piola__json_pop(p, o2);
    o2 = piola__json_push_index(p, 1);
    PIOLA_TRY(piola__json_vec3(p, v->child->next, ANY, &out->selector.box_max));
    piola__json_pop(p, o2);
    piola_vec3 a = out->selector.box_min, b = out->selector.box_max;
    if (a.x > b.x || a.y > b.y || a.z > b.z)
      return piola__json_fail(p, BAD_VALUE,
                              "the first corner must be <= the second in every coordinate");
    piola__json_pop(p, old);
  } else if ((v = piola__json_get(obj, "sphere"))) {
    size_t old = piola__json_push_key(p, "sphere");
    static const char *const keys[] = {"center", "radius", NULL};
    PIOLA_TRY(piola__json_check_keys(p, v, keys));
    PIOLA_TRY(piola__json_required(p, v, "radius"));
    out->selector.type = PIOLA_SELECT_SPHERE;
    PIOLA_TRY(piola__json_opt_vec3(p, v, "center", ANY, &out->selector.center));
    PIOLA_TRY(piola__json_opt_number(p, v, "radius", NONNEGATIVE, &out->selector.radius));
    piola__json_pop(p, old);
  } else {
    v = piola__json_get(obj, "indices");
    size_t old = piola__json_push_key(p, "indices");
    if (!cJSON_IsArray(v))
      return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an array of vertex indices");
    int count = cJSON_GetArraySize(v);
    int32_t *idx = malloc((size_t)(count > 0 ? count : 1) * sizeof *idx);
    if (!idx) return piola__json_fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
    *indices_out = idx;
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
      size_t o2 = piola__json_push_index(p, i);
      if (!cJSON_IsNumber(e) || e->valuedouble != floor(e->valuedouble) || e->valuedouble < 0 ||
          e->valuedouble > 2147483647.0)
        return piola__json_fail(p, BAD_VALUE, "must be a vertex index (an integer >= 0)");
      idx[i] = (int32_t)e->valuedouble;
      piola__json_pop(p, o2);
    }
    out->selector.type = PIOLA_SELECT_INDICES;
    out->selector.indices = idx;
    out->selector.index_count = count;
    piola__json_pop(p, old);
  }
  if (driven) {
    PIOLA_TRY(piola__json_required(p, obj, "motion"));
    size_t old = piola__json_push_key(p, "motion");
    PIOLA_TRY(piola__scene_parse_motion(p, piola__json_get(obj, "motion"), (piola_vec3){0, 0, 0},
                                        (piola_vec3){0, 0, 1}, &out->motion));
    piola__json_pop(p, old);
  }
  return PIOLA_OK;
}

piola_status piola__scene_parse_constraints(scene_parser *p, const cJSON *solid, const char *key,
                                            int driven, scene_solid_desc *d) {
  const cJSON *list = piola__json_get(solid, key);
  if (!list) return PIOLA_OK;
  size_t old = piola__json_push_key(p, key);
  if (!cJSON_IsArray(list))
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an array of selectors");
  int count = cJSON_GetArraySize(list);
  int total = d->constraint_count + count;
  piola_constraint_def *c = realloc(d->constraints, (size_t)(total > 0 ? total : 1) * sizeof *c);
  if (!c) return piola__json_fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  d->constraints = c;
  int32_t **lists = realloc(d->index_lists, (size_t)(total > 0 ? total : 1) * sizeof *lists);
  if (!lists) return piola__json_fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  d->index_lists = lists;
  int i = 0;
  for (const cJSON *e = list->child; e; e = e->next, ++i) {
    size_t o2 = piola__json_push_index(p, i);
    int32_t slot = d->constraint_count++;
    d->index_lists[slot] = NULL;
    memset(&d->constraints[slot], 0, sizeof d->constraints[slot]);
    PIOLA_TRY(
        piola__scene_parse_selector(p, e, driven, &d->constraints[slot], &d->index_lists[slot]));
    piola__json_pop(p, o2);
  }
  piola__json_pop(p, old);
  return PIOLA_OK;
}
