/* Scene files: JSON (cJSON) -> definition structs, with every error naming its key path.
 *
 * The top level: the JSON text, the keys a scene may have, and the order in which the
 * sections are read (scene_parse_sections.h); freeing a parsed scene. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_parse_sections.h"

static piola_status parse_top(scene_parser *p, const cJSON *root, scene_desc *out) {
  static const char *const allowed[] = {"description", "fps", "frames", "gravity", "integrator",
                                        "solids", "obstacles", "shells", "bones", NULL};
  PIOLA_TRY(piola__json_check_keys(p, root, allowed));
  const cJSON *v;
  if ((v = piola__json_get(root, "description")) && !cJSON_IsString(v)) {
    piola__json_push_key(p, "description");
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be a string, got %s",
                            piola__json_type_name(v));
  }
  PIOLA_TRY(piola__scene_parse_world(p, root, out));
  /* a scene needs something to simulate: solids, or shells */
  const cJSON *shells = piola__json_get(root, "shells");
  if (shells)
    PIOLA_TRY(piola__scene_parse_shells(p, shells, out));
  else
    PIOLA_TRY(piola__json_required(p, root, "solids"));
  PIOLA_TRY(piola__scene_parse_solids(p, piola__json_get(root, "solids"), out));
  if (out->solid_count == 0 && out->shell_count == 0) {
    piola__json_push_key(p, "shells");
    return piola__json_fail(p, PIOLA_ERROR_PARSE,
                            "is empty and there are no solids: nothing to simulate");
  }
  if ((v = piola__json_get(root, "obstacles"))) PIOLA_TRY(piola__scene_parse_obstacles(p, v, out));
  if ((v = piola__json_get(root, "bones"))) PIOLA_TRY(piola__scene_parse_bones(p, v, out));
  return PIOLA_OK;
}

void piola__scene_desc_free(scene_desc *desc) {
  if (!desc) return;
  for (int32_t i = 0; i < desc->solid_count; ++i) {
    scene_solid_desc *s = &desc->solids[i];
    for (int32_t c = 0; c < s->constraint_count; ++c) free(s->index_lists[c]);
    free(s->index_lists);
    free(s->constraints);
    free(s->fibers.curve);
    free(s->fracture_cuts);
    free(s->fracture_blade_paths);
  }
  free(desc->solids);
  free(desc->obstacles);
  for (int32_t i = 0; i < desc->shell_count; ++i) {
    scene_solid_desc *s = &desc->shells[i].base;
    for (int32_t c = 0; c < s->constraint_count; ++c) free(s->index_lists[c]);
    free(s->index_lists);
    free(s->constraints);
  }
  free(desc->shells);
  for (int32_t i = 0; i < desc->bone_count; ++i) {
    scene_bone_desc *b = &desc->bones[i];
    for (int32_t a = 0; a < b->attachment_count; ++a) free(b->index_lists[a]);
    free(b->index_lists);
    free(b->attachments);
  }
  free(desc->bones);
  memset(desc, 0, sizeof *desc);
}

piola_status piola__scene_parse(const char *json, const char *base_dir, const char *label,
                                scene_desc *out) {
  memset(out, 0, sizeof *out);
  out->fps = 30;
  out->frames = 60;
  out->world = piola_default_world_def();
  scene_parser p = {label ? label : "scene", base_dir, "", 0};
  if (!json) return piola__json_fail(&p, PIOLA_ERROR_INVALID_ARGUMENT, "no text");
  const char *end = NULL;
  cJSON *root = cJSON_ParseWithOpts(json, &end, 1);
  if (!root) {
    int line = 1, col = 1;
    const char *at = end ? end : json;
    for (const char *c = json; c < at && *c; ++c) {
      if (*c == '\n')
        ++line, col = 1;
      else
        ++col;
    }
    return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: line %d, column %d: invalid JSON", p.label, line,
                      col);
  }
  piola_status st = parse_top(&p, root, out);
  cJSON_Delete(root);
  if (st != PIOLA_OK) piola__scene_desc_free(out);
  return st;
}
