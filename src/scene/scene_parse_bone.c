/* The `bones` section (docs/bones.md): an obstacle's shape and motion plus the nodes of
 * solids it carries. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_parse_sections.h"

/* {"solid": NAME, one of box | sphere | indices | within}: which nodes of a solid the bone
 * carries (docs/bones.md). Solids are parsed before bones, so the name resolves here. */
static piola_status parse_attachment(scene_parser *p, const cJSON *obj, const scene_desc *scene,
                                     piola_attachment_def *out, int32_t **indices_out) {
  static const char *const keys[] = {"solid", "box", "sphere", "indices", "within", NULL};
  PIOLA_TRY(piola__json_check_keys(p, obj, keys));
  PIOLA_TRY(piola__json_required(p, obj, "solid"));
  *out = piola_default_attachment_def();
  const cJSON *v = piola__json_get(obj, "solid");
  size_t old = piola__json_push_key(p, "solid");
  if (!cJSON_IsString(v))
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be the name of a solid, got %s",
                            piola__json_type_name(v));
  out->solid = -1;
  for (int32_t i = 0; i < scene->solid_count; ++i)
    if (strcmp(scene->solids[i].name, v->valuestring) == 0) out->solid = i;
  if (out->solid < 0) {
    for (int32_t i = 0; i < scene->shell_count; ++i)
      if (strcmp(scene->shells[i].base.name, v->valuestring) == 0)
        return piola__json_fail(p, BAD_VALUE, "\"%s\" is a shell: bones attach to solids only",
                                v->valuestring);
    char list[256] = "";
    for (int32_t i = 0; i < scene->solid_count; ++i) {
      if (i) strncat(list, ", ", sizeof list - strlen(list) - 1);
      strncat(list, scene->solids[i].name, sizeof list - strlen(list) - 1);
    }
    return piola__json_fail(p, BAD_VALUE, "no solid is named \"%s\" (solids: %s)", v->valuestring,
                            scene->solid_count ? list : "none");
  }
  piola__json_pop(p, old);
  int kinds = !!piola__json_get(obj, "box") + !!piola__json_get(obj, "sphere") +
              !!piola__json_get(obj, "indices") + !!piola__json_get(obj, "within");
  if (kinds != 1)
    return piola__json_fail(p, PIOLA_ERROR_PARSE,
                            "needs exactly one of box, sphere, indices or within");
  if (piola__json_get(obj, "within")) {
    out->near_surface = true;
    return piola__json_opt_number(p, obj, "within", NONNEGATIVE, &out->distance);
  }
  /* the selector keys are those of `fixed`: parse a copy without "solid" */
  cJSON *copy = cJSON_Duplicate(obj, 1);
  if (!copy) return piola__json_fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  cJSON_DeleteItemFromObjectCaseSensitive(copy, "solid");
  piola_constraint_def con;
  piola_status st = piola__scene_parse_selector(p, copy, 0, &con, indices_out);
  cJSON_Delete(copy);
  if (st == PIOLA_OK) out->selector = con.selector;
  return st;
}

static piola_status parse_bone(scene_parser *p, const cJSON *obj, int index,
                               const scene_desc *scene, scene_bone_desc *d) {
  static const char *const extra[] = {"name", "attachments", NULL};
  snprintf(d->name, sizeof d->name, "bone%d", index);
  PIOLA_TRY(piola__scene_parse_obstacle(p, obj, extra, &d->obstacle));
  PIOLA_TRY(piola__scene_parse_name(p, obj, d->name, sizeof d->name));
  const cJSON *list = piola__json_get(obj, "attachments");
  if (!list) return PIOLA_OK;
  size_t old = piola__json_push_key(p, "attachments");
  if (!cJSON_IsArray(list))
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an array of attachments");
  int count = cJSON_GetArraySize(list);
  d->attachments = calloc((size_t)(count > 0 ? count : 1), sizeof *d->attachments);
  d->index_lists = calloc((size_t)(count > 0 ? count : 1), sizeof *d->index_lists);
  if (!d->attachments || !d->index_lists)
    return piola__json_fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  int i = 0;
  for (const cJSON *e = list->child; e; e = e->next, ++i) {
    size_t o2 = piola__json_push_index(p, i);
    d->attachment_count = i + 1;
    PIOLA_TRY(parse_attachment(p, e, scene, &d->attachments[i], &d->index_lists[i]));
    piola__json_pop(p, o2);
  }
  piola__json_pop(p, old);
  return PIOLA_OK;
}

piola_status piola__scene_parse_bones(scene_parser *p, const cJSON *v, scene_desc *out) {
  size_t old = piola__json_push_key(p, "bones");
  if (!cJSON_IsArray(v)) return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an array of bones");
  int count = cJSON_GetArraySize(v);
  out->bones = calloc((size_t)(count > 0 ? count : 1), sizeof *out->bones);
  if (!out->bones) return piola__json_fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  int i = 0;
  for (const cJSON *e = v->child; e; e = e->next, ++i) {
    size_t o2 = piola__json_push_index(p, i);
    out->bone_count = i + 1;
    PIOLA_TRY(parse_bone(p, e, i, out, &out->bones[i]));
    for (int j = 0; j < i; ++j)
      if (strcmp(out->bones[j].name, out->bones[i].name) == 0) {
        piola__json_push_key(p, "name");
        return piola__json_fail(p, BAD_VALUE, "\"%s\" is already the name of bones[%d]",
                                out->bones[i].name, j);
      }
    piola__json_pop(p, o2);
  }
  piola__json_pop(p, old);
  return PIOLA_OK;
}
