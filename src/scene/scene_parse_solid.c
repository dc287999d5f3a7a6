/* The `solids` section: a solid's mesh (file or generator), placement, density, initial
 * state and the per-concept keys read by the other section files. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_parse_sections.h"

static piola_status parse_generator(scene_parser *p, const cJSON *obj, piola_mesher_def *m) {
  static const char *const allowed[] = {"generate", "center", "axis", "radius", "minor_radius",
                                        "half_length", "half_extents", "cell_size",
                                        "refinement_levels", NULL};
  PIOLA_TRY(piola__json_check_keys(p, obj, allowed));
  PIOLA_TRY(piola__json_required(p, obj, "generate"));
  PIOLA_TRY(piola__json_required(p, obj, "cell_size"));
  *m = piola_default_mesher_def();
  m->shape_count = 1;
  piola_shape *s = &m->shapes[0];
  memset(s, 0, sizeof *s);
  s->axis = (piola_vec3){0, 0, 1};
  const cJSON *g = piola__json_get(obj, "generate");
  size_t old = piola__json_push_key(p, "generate");
  static const char *const names[] = {"sphere", "box", "torus", "cylinder", "capsule", NULL};
  static const piola_shape_type types[] = {PIOLA_SHAPE_SPHERE, PIOLA_SHAPE_BOX, PIOLA_SHAPE_TORUS,
                                           PIOLA_SHAPE_CYLINDER, PIOLA_SHAPE_CAPSULE};
  int found = -1;
  if (cJSON_IsString(g))
    for (int i = 0; names[i]; ++i)
      if (strcmp(g->valuestring, names[i]) == 0) found = i;
  if (found < 0)
    return piola__json_fail(
        p, BAD_VALUE, "must be one of \"sphere\", \"box\", \"torus\", \"cylinder\", \"capsule\"");
  s->type = types[found];
  piola__json_pop(p, old);
  const char *need[3] = {NULL, NULL, NULL};
  switch (s->type) {
    case PIOLA_SHAPE_SPHERE:
      need[0] = "radius";
      break;
    case PIOLA_SHAPE_BOX:
      need[0] = "half_extents";
      break;
    case PIOLA_SHAPE_TORUS:
      need[0] = "radius", need[1] = "minor_radius";
      break;
    default:
      need[0] = "radius", need[1] = "half_length";
      break;
  }
  for (int i = 0; need[i]; ++i) PIOLA_TRY(piola__json_required(p, obj, need[i]));
  PIOLA_TRY(piola__json_opt_vec3(p, obj, "center", ANY, &s->center));
  PIOLA_TRY(piola__json_opt_direction(p, obj, "axis", &s->axis));
  PIOLA_TRY(piola__json_opt_number(p, obj, "radius", POSITIVE, &s->radius));
  PIOLA_TRY(piola__json_opt_number(p, obj, "minor_radius", POSITIVE, &s->minor_radius));
  PIOLA_TRY(piola__json_opt_number(p, obj, "half_length", POSITIVE, &s->half_length));
  PIOLA_TRY(piola__json_opt_vec3(p, obj, "half_extents", POSITIVE, &s->half_extents));
  PIOLA_TRY(piola__json_opt_number(p, obj, "cell_size", POSITIVE, &m->cell_size));
  int64_t levels = m->refinement_levels;
  PIOLA_TRY(piola__json_opt_int(p, obj, "refinement_levels", 0, 6, &levels));
  m->refinement_levels = (int)levels;
  if (s->type == PIOLA_SHAPE_TORUS && !(s->minor_radius < s->radius)) {
    piola__json_push_key(p, "minor_radius");
    return piola__json_fail(p, BAD_VALUE, "must be smaller than radius (%g m), got %g", s->radius,
                            s->minor_radius);
  }
  return PIOLA_OK;
}

static piola_status parse_solid(scene_parser *p, const cJSON *obj, int index, scene_solid_desc *d) {
  static const char *const allowed[] = {"name", "mesh", "transform", "density", "material",
                                        "damping", "velocity", "fixed", "driven", "initial",
                                        "plasticity", "self_collision", "fibers", "activation",
                                        NULL};
  PIOLA_TRY(piola__json_check_keys(p, obj, allowed));
  PIOLA_TRY(piola__json_required(p, obj, "mesh"));
  d->def = piola_default_solid_def();
  d->scale = (piola_vec3){1, 1, 1};
  snprintf(d->name, sizeof d->name, "solid%d", index);
  PIOLA_TRY(piola__scene_parse_name(p, obj, d->name, sizeof d->name));
  const cJSON *v = piola__json_get(obj, "mesh");
  size_t old = piola__json_push_key(p, "mesh");
  if (cJSON_IsObject(v)) {
    d->mesh_generated = 1;
    PIOLA_TRY(parse_generator(p, v, &d->mesher));
  } else {
    if (!cJSON_IsString(v))
      return piola__json_fail(p, PIOLA_ERROR_PARSE,
                              "must be a file path or a generator object, got %s",
                              piola__json_type_name(v));
    PIOLA_TRY(piola__json_path(p, v, d->mesh_path));
  }
  piola__json_pop(p, old);
  if ((v = piola__json_get(obj, "transform"))) PIOLA_TRY(piola__scene_parse_transform(p, v, d));
  PIOLA_TRY(piola__json_opt_number(p, obj, "density", POSITIVE, &d->def.density));
  if ((v = piola__json_get(obj, "material"))) {
    old = piola__json_push_key(p, "material");
    PIOLA_TRY(piola__scene_parse_material(p, v, d));
    piola__json_pop(p, old);
  }
  PIOLA_TRY(piola__scene_parse_damping(p, obj, d));
  PIOLA_TRY(piola__json_opt_vec3(p, obj, "velocity", ANY, &d->def.velocity));
  PIOLA_TRY(piola__scene_parse_self_collision(p, obj, &d->def.self_collision));
  if ((v = piola__json_get(obj, "plasticity"))) {
    old = piola__json_push_key(p, "plasticity");
    PIOLA_TRY(piola__scene_parse_plasticity(p, v, d));
    piola__json_pop(p, old);
  }
  PIOLA_TRY(piola__scene_parse_constraints(p, obj, "fixed", 0, d));
  d->fixed_count = d->constraint_count;
  PIOLA_TRY(piola__scene_parse_constraints(p, obj, "driven", 1, d));
  if ((v = piola__json_get(obj, "fibers"))) {
    old = piola__json_push_key(p, "fibers");
    if (d->def.material.model != PIOLA_MODEL_MUSCLE && d->def.material.model != PIOLA_MODEL_HGO)
      return piola__json_fail(p, BAD_VALUE, "needs material.model \"muscle\" or \"hgo\"");
    if (d->plastic)
      return piola__json_fail(p, BAD_VALUE, "cannot be combined with plasticity (not supported)");
    PIOLA_TRY(piola__scene_parse_fibers(p, v, &d->fibers));
    piola__json_pop(p, old);
  }
  if ((v = piola__json_get(obj, "activation"))) {
    old = piola__json_push_key(p, "activation");
    if (d->def.material.model != PIOLA_MODEL_MUSCLE)
      return piola__json_fail(p, BAD_VALUE, "needs material.model \"muscle\"");
    PIOLA_TRY(piola__json_track(p, v, (json_range){0, 1, 0, 0}, &d->def.activation));
    piola__json_pop(p, old);
  }
  if ((v = piola__json_get(obj, "initial"))) {
    old = piola__json_push_key(p, "initial");
    static const char *const keys[] = {"matrix", "scramble", "seed", NULL};
    PIOLA_TRY(piola__json_check_keys(p, v, keys));
    const cJSON *mat = piola__json_get(v, "matrix");
    if (mat) {
      size_t o2 = piola__json_push_key(p, "matrix");
      PIOLA_TRY(piola__json_mat3(p, mat, &d->def.initial_matrix));
      piola__json_pop(p, o2);
    }
    PIOLA_TRY(piola__json_opt_number(p, v, "scramble", NONNEGATIVE, &d->def.scramble_radius));
    int64_t seed = 1;
    PIOLA_TRY(piola__json_opt_int(p, v, "seed", 0, 9007199254740991.0, &seed));
    d->def.scramble_seed = (uint64_t)seed;
    piola__json_pop(p, old);
  }
  return PIOLA_OK;
}

piola_status piola__scene_parse_solids(scene_parser *p, const cJSON *v, scene_desc *out) {
  size_t old = piola__json_push_key(p, "solids");
  if (v && (!cJSON_IsArray(v) || cJSON_GetArraySize(v) < 1))
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be a non-empty array of solids");
  int count = v ? cJSON_GetArraySize(v) : 0;
  out->solids = calloc((size_t)(count > 0 ? count : 1), sizeof *out->solids);
  if (!out->solids) return piola__json_fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  int i = 0;
  for (const cJSON *e = v ? v->child : NULL; e; e = e->next, ++i) {
    size_t o2 = piola__json_push_index(p, i);
    out->solid_count = i + 1;
    PIOLA_TRY(parse_solid(p, e, i, &out->solids[i]));
    for (int j = 0; j < i; ++j)
      if (strcmp(out->solids[j].name, out->solids[i].name) == 0) {
        piola__json_push_key(p, "name");
        return piola__json_fail(p, BAD_VALUE, "\"%s\" is already the name of solids[%d]",
                                out->solids[i].name, j);
      }
    piola__json_pop(p, o2);
  }
  piola__json_pop(p, old);
  return PIOLA_OK;
}
