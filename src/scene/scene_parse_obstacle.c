/* The `obstacles` section: shapes, friction and motion. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_parse_sections.h"

piola_status piola__scene_parse_obstacle(scene_parser *p, const cJSON *obj,
                                         const char *const *extra_keys, scene_obstacle_desc *d) {
  static const char *const names[] = {"plane", "sphere", "box", "cylinder", "capsule", "torus",
                                      "gear", "mesh", NULL};
  static const char *const keysets[][10] = {
      {"type", "point", "normal", "friction", "motion", NULL},
      {"type", "center", "radius", "friction", "motion", NULL},
      {"type", "center", "half_extents", "friction", "motion", NULL},
      {"type", "center", "axis", "radius", "half_length", "friction", "motion", NULL},
      {"type", "center", "axis", "radius", "half_length", "friction", "motion", NULL},
      {"type", "center", "axis", "radius", "minor_radius", "friction", "motion", NULL},
      {"type", "center", "axis", "radius", "half_length", "teeth", "tooth_depth", "friction",
       "motion", NULL},
      {"type", "path", "friction", "motion", NULL},
  };
  static const char *const required_keys[][4] = {
      {"point", "normal", NULL},
      {"radius", NULL},
      {"half_extents", NULL},
      {"radius", "half_length", NULL},
      {"radius", "half_length", NULL},
      {"radius", "minor_radius", NULL},
      {"radius", "half_length", "teeth", NULL},
      {"path", NULL},
  };
  if (!cJSON_IsObject(obj))
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an object, got %s",
                            piola__json_type_name(obj));
  PIOLA_TRY(piola__json_required(p, obj, "type"));
  const cJSON *t = piola__json_get(obj, "type");
  size_t old = piola__json_push_key(p, "type");
  int found = -1;
  if (cJSON_IsString(t))
    for (int i = 0; names[i]; ++i)
      if (strcmp(t->valuestring, names[i]) == 0) found = i;
  if (found < 0)
    return piola__json_fail(
        p, BAD_VALUE,
        "must be one of \"plane\", \"sphere\", \"box\", \"cylinder\", \"capsule\", \"torus\", "
        "\"gear\", \"mesh\"");
  piola__json_pop(p, old);
  const char *allowed[16];
  int nallowed = 0;
  for (int i = 0; keysets[found][i]; ++i) allowed[nallowed++] = keysets[found][i];
  for (int i = 0; extra_keys && extra_keys[i] && nallowed < 15; ++i)
    allowed[nallowed++] = extra_keys[i];
  allowed[nallowed] = NULL;
  PIOLA_TRY(piola__json_check_keys(p, obj, allowed));
  for (int i = 0; required_keys[found][i]; ++i)
    PIOLA_TRY(piola__json_required(p, obj, required_keys[found][i]));
  piola_obstacle_def *o = &d->def;
  *o = piola_default_obstacle_def();
  o->type = (piola_obstacle_type)(PIOLA_OBSTACLE_PLANE + found);
  o->axis = (piola_vec3){0, 0, 1};
  if (o->type == PIOLA_OBSTACLE_PLANE) {
    PIOLA_TRY(piola__json_opt_vec3(p, obj, "point", ANY, &o->center));
    PIOLA_TRY(piola__json_opt_direction(p, obj, "normal", &o->axis));
  } else {
    PIOLA_TRY(piola__json_opt_vec3(p, obj, "center", ANY, &o->center));
    PIOLA_TRY(piola__json_opt_direction(p, obj, "axis", &o->axis));
  }
  PIOLA_TRY(piola__json_opt_number(p, obj, "radius", POSITIVE, &o->radius));
  PIOLA_TRY(piola__json_opt_number(p, obj, "minor_radius", POSITIVE, &o->minor_radius));
  PIOLA_TRY(piola__json_opt_number(p, obj, "half_length", POSITIVE, &o->half_length));
  PIOLA_TRY(piola__json_opt_vec3(p, obj, "half_extents", POSITIVE, &o->half_extents));
  int64_t teeth = 0;
  PIOLA_TRY(piola__json_opt_int(p, obj, "teeth", 3, 100000, &teeth));
  o->tooth_count = (int)teeth;
  if (o->type == PIOLA_OBSTACLE_GEAR) o->tooth_depth = 0.2 * o->radius;
  PIOLA_TRY(piola__json_opt_number(p, obj, "tooth_depth", POSITIVE, &o->tooth_depth));
  if (o->type == PIOLA_OBSTACLE_GEAR && !(o->tooth_depth < o->radius)) {
    piola__json_push_key(p, "tooth_depth");
    return piola__json_fail(p, BAD_VALUE, "must be smaller than radius (%g m), got %g", o->radius,
                            o->tooth_depth);
  }
  if (o->type == PIOLA_OBSTACLE_TORUS && !(o->minor_radius < o->radius)) {
    piola__json_push_key(p, "minor_radius");
    return piola__json_fail(p, BAD_VALUE, "must be smaller than radius (%g m), got %g", o->radius,
                            o->minor_radius);
  }
  PIOLA_TRY(piola__json_opt_number(p, obj, "friction", NONNEGATIVE, &o->friction));
  if (o->type == PIOLA_OBSTACLE_MESH) {
    old = piola__json_push_key(p, "path");
    PIOLA_TRY(piola__json_path(p, piola__json_get(obj, "path"), d->mesh_path));
    piola__json_pop(p, old);
  }
  const cJSON *mo = piola__json_get(obj, "motion");
  if (mo) {
    old = piola__json_push_key(p, "motion");
    /* A cylinder, capsule, torus or gear spins about its own axis unless told otherwise: a
     * gear with axis y turning about the global default z would swing through the scene
     * like a revolving door (the gears example once did exactly that). */
    int axial = o->type == PIOLA_OBSTACLE_CYLINDER || o->type == PIOLA_OBSTACLE_CAPSULE ||
                o->type == PIOLA_OBSTACLE_TORUS || o->type == PIOLA_OBSTACLE_GEAR;
    piola_vec3 default_axis = axial ? o->axis : (piola_vec3){0, 0, 1};
    PIOLA_TRY(piola__scene_parse_motion(p, mo, o->center, default_axis, &o->motion));
    piola__json_pop(p, old);
  } else {
    o->motion = piola_default_rigid_motion_def();
    o->motion.pivot = o->center;
  }
  return PIOLA_OK;
}

piola_status piola__scene_parse_obstacles(scene_parser *p, const cJSON *v, scene_desc *out) {
  size_t old = piola__json_push_key(p, "obstacles");
  if (!cJSON_IsArray(v))
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an array of obstacles");
  int count = cJSON_GetArraySize(v);
  out->obstacles = calloc((size_t)(count > 0 ? count : 1), sizeof *out->obstacles);
  if (!out->obstacles) return piola__json_fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  int i = 0;
  for (const cJSON *e = v->child; e; e = e->next, ++i) {
    size_t o2 = piola__json_push_index(p, i);
    out->obstacle_count = i + 1;
    static const char *const extra[] = {"name", NULL};
    scene_obstacle_desc *d = &out->obstacles[i];
    PIOLA_TRY(piola__scene_parse_obstacle(p, e, extra, d));
    snprintf(d->name, sizeof d->name, "obstacle%d", i);
    const cJSON *name = piola__json_get(e, "name");
    if (name) {
      size_t o3 = piola__json_push_key(p, "name");
      if (!cJSON_IsString(name) || !name->valuestring[0] ||
          strlen(name->valuestring) >= sizeof d->name)
        return piola__json_fail(p, PIOLA_ERROR_PARSE,
                                "must be a non-empty string of at most %d characters",
                                (int)sizeof d->name - 1);
      snprintf(d->name, sizeof d->name, "%s", name->valuestring);
      for (int j = 0; j < i; ++j)
        if (strcmp(out->obstacles[j].name, d->name) == 0)
          return piola__json_fail(p, BAD_VALUE, "\"%s\" is already the name of obstacles[%d]",
                                  d->name, j);
      piola__json_pop(p, o3);
    }
    piola__json_pop(p, o2);
  }
  piola__json_pop(p, old);
  return PIOLA_OK;
}
