/* Scene keys that solids and shells share: name, transform, damping, self_collision. */
#include <stdio.h>
#include <string.h>

#include "scene/scene_parse_sections.h"

piola_status piola__scene_parse_name(scene_parser *p, const cJSON *obj, char *name,
                                     size_t capacity) {
  const cJSON *v = piola__json_get(obj, "name");
  if (!v) return PIOLA_OK;
  size_t old = piola__json_push_key(p, "name");
  if (!cJSON_IsString(v) || !v->valuestring[0] || strlen(v->valuestring) >= capacity)
    return piola__json_fail(p, PIOLA_ERROR_PARSE,
                            "must be a non-empty string of at most %d characters",
                            (int)capacity - 1);
  snprintf(name, capacity, "%s", v->valuestring);
  piola__json_pop(p, old);
  return PIOLA_OK;
}

piola_status piola__scene_parse_transform(scene_parser *p, const cJSON *v, scene_solid_desc *d) {
  size_t old = piola__json_push_key(p, "transform");
  static const char *const keys[] = {"translate", "rotate_degrees", "scale", NULL};
  PIOLA_TRY(piola__json_check_keys(p, v, keys));
  PIOLA_TRY(piola__json_opt_vec3(p, v, "translate", ANY, &d->translate));
  PIOLA_TRY(piola__json_opt_vec3(p, v, "rotate_degrees", ANY, &d->rotate_degrees));
  const cJSON *sc = piola__json_get(v, "scale");
  if (sc) {
    size_t o2 = piola__json_push_key(p, "scale");
    if (cJSON_IsNumber(sc)) {
      double s;
      PIOLA_TRY(piola__json_number(p, sc, POSITIVE, &s));
      d->scale = (piola_vec3){s, s, s};
    } else {
      PIOLA_TRY(piola__json_vec3(p, sc, POSITIVE, &d->scale));
    }
    piola__json_pop(p, o2);
  }
  piola__json_pop(p, old);
  return PIOLA_OK;
}

/* "self_collision": {"enabled": true, "thickness": m, "friction": mu}; giving the object
 * turns it on unless "enabled" is false (docs/contact.md). */
piola_status piola__scene_parse_self_collision(scene_parser *p, const cJSON *obj,
                                               piola_self_collision_def *out) {
  const cJSON *v = piola__json_get(obj, "self_collision");
  if (!v) return PIOLA_OK;
  size_t old = piola__json_push_key(p, "self_collision");
  static const char *const keys[] = {"enabled", "thickness", "friction", NULL};
  PIOLA_TRY(piola__json_check_keys(p, v, keys));
  out->enabled = true;
  PIOLA_TRY(piola__json_opt_bool(p, v, "enabled", &out->enabled));
  PIOLA_TRY(piola__json_opt_number(p, v, "thickness", POSITIVE, &out->thickness));
  PIOLA_TRY(piola__json_opt_number(p, v, "friction", NONNEGATIVE, &out->friction));
  piola__json_pop(p, old);
  return PIOLA_OK;
}

piola_status piola__scene_parse_damping(scene_parser *p, const cJSON *obj, scene_solid_desc *d) {
  const cJSON *v = piola__json_get(obj, "damping");
  if (!v) return PIOLA_OK;
  size_t old = piola__json_push_key(p, "damping");
  static const char *const keys[] = {"shear", "bulk", NULL};
  PIOLA_TRY(piola__json_check_keys(p, v, keys));
  PIOLA_TRY(piola__json_opt_track(p, v, "shear", NONNEGATIVE, &d->def.shear_viscosity));
  PIOLA_TRY(piola__json_opt_track(p, v, "bulk", NONNEGATIVE, &d->def.bulk_viscosity));
  piola__json_pop(p, old);
  return PIOLA_OK;
}
