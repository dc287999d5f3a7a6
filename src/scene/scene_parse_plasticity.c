/* A solid's `plasticity` key: yield, limit, hardening and plasticity control. */

#include "scene/scene_parse_sections.h"

/* "plasticity": {yield, limit, hardening, volume_preserving, control: {goal: {map | mesh},
 * strength}} (docs/scene-format.md, docs/plasticity.md). */
piola_status piola__scene_parse_plasticity(scene_parser *p, const cJSON *obj, scene_solid_desc *d) {
  static const char *const allowed[] = {"yield", "limit", "hardening", "volume_preserving",
                                        "control", NULL};
  PIOLA_TRY(piola__json_check_keys(p, obj, allowed));
  piola_plasticity_def *def = &d->plasticity;
  *def = piola_default_plasticity_def();
  d->plastic = 1;
  PIOLA_TRY(piola__json_opt_number(p, obj, "yield", POSITIVE, &def->yield));
  static const json_range LIMIT = {0, 20, 1, 0};
  PIOLA_TRY(piola__json_opt_number(p, obj, "limit", LIMIT, &def->limit));
  PIOLA_TRY(piola__json_opt_number(p, obj, "hardening", NONNEGATIVE, &def->hardening));
  PIOLA_TRY(piola__json_opt_bool(p, obj, "volume_preserving", &def->volume_preserving));
  const cJSON *c = piola__json_get(obj, "control");
  if (!c) return PIOLA_OK;
  size_t old = piola__json_push_key(p, "control");
  static const char *const control_keys[] = {"goal", "strength", NULL};
  PIOLA_TRY(piola__json_check_keys(p, c, control_keys));
  PIOLA_TRY(piola__json_required(p, c, "goal"));
  if (def->volume_preserving)
    return piola__json_fail(
        p, BAD_VALUE,
        "cannot be used with volume_preserving: true (the goal rarely preserves volume)");
  PIOLA_TRY(piola__json_opt_number(p, c, "strength", NONNEGATIVE, &def->control.strength));
  const cJSON *g = piola__json_get(c, "goal");
  size_t o2 = piola__json_push_key(p, "goal");
  static const char *const goal_keys[] = {"map", "mesh", NULL};
  PIOLA_TRY(piola__json_check_keys(p, g, goal_keys));
  const cJSON *map = piola__json_get(g, "map"), *mesh = piola__json_get(g, "mesh");
  if ((map != NULL) == (mesh != NULL))
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "needs exactly one of \"map\" and \"mesh\"");
  if (map) {
    size_t o3 = piola__json_push_key(p, "map");
    def->control.goal = PIOLA_PLASTIC_GOAL_MAP;
    PIOLA_TRY(piola__json_mat3(p, map, &def->control.goal_map));
    const piola_mat3 *a = &def->control.goal_map;
    double det = a->m[0][0] * (a->m[1][1] * a->m[2][2] - a->m[1][2] * a->m[2][1]) -
                 a->m[0][1] * (a->m[1][0] * a->m[2][2] - a->m[1][2] * a->m[2][0]) +
                 a->m[0][2] * (a->m[1][0] * a->m[2][1] - a->m[1][1] * a->m[2][0]);
    if (!(det > 0))
      return piola__json_fail(p, BAD_VALUE, "must have a positive determinant, got %g", det);
    piola__json_pop(p, o3);
  } else {
    size_t o3 = piola__json_push_key(p, "mesh");
    def->control.goal = PIOLA_PLASTIC_GOAL_MESH;
    PIOLA_TRY(piola__json_path(p, mesh, d->goal_mesh_path));
    piola__json_pop(p, o3);
  }
  piola__json_pop(p, o2);
  piola__json_pop(p, old);
  return PIOLA_OK;
}
