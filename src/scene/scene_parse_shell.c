/* The `shells` section: thin shells, their meshes (files or generators), bending and
 * plasticity. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_parse_sections.h"

/* A shell's mesh: a triangle surface file, or {"generate": "rectangle", "size": [w, h],
 * "resolution": [nx, ny]} / {"generate": "disk", "radius": r, "rings": n} in the z = 0
 * plane centred at the origin, or {"generate": "torus", "radius": R, "minor_radius": r,
 * "segments": [around, tube], "sweep_degrees": s} around the z axis, before the transform. */
static piola_status parse_shell_mesh(scene_parser *p, const cJSON *v, scene_shell_desc *d) {
  size_t old = piola__json_push_key(p, "mesh");
  if (cJSON_IsString(v)) {
    PIOLA_TRY(piola__json_path(p, v, d->base.mesh_path));
    piola__json_pop(p, old);
    return PIOLA_OK;
  }
  if (!cJSON_IsObject(v))
    return piola__json_fail(p, PIOLA_ERROR_PARSE,
                            "must be a triangle mesh file path or a generator object, got %s",
                            piola__json_type_name(v));
  const cJSON *g = piola__json_get(v, "generate");
  if (cJSON_IsString(g) && strcmp(g->valuestring, "rectangle") == 0) {
    static const char *const keys[] = {"generate", "size", "resolution", NULL};
    PIOLA_TRY(piola__json_check_keys(p, v, keys));
    PIOLA_TRY(piola__json_required(p, v, "size"));
    PIOLA_TRY(piola__json_required(p, v, "resolution"));
    d->generator = 1;
    const cJSON *size = piola__json_get(v, "size"), *res = piola__json_get(v, "resolution");
    size_t o2 = piola__json_push_key(p, "size");
    if (!cJSON_IsArray(size) || cJSON_GetArraySize(size) != 2)
      return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be [width, height] in m");
    PIOLA_TRY(piola__json_number(p, size->child, POSITIVE, &d->size[0]));
    PIOLA_TRY(piola__json_number(p, size->child->next, POSITIVE, &d->size[1]));
    piola__json_pop(p, o2);
    o2 = piola__json_push_key(p, "resolution");
    if (!cJSON_IsArray(res) || cJSON_GetArraySize(res) != 2)
      return piola__json_fail(p, PIOLA_ERROR_PARSE,
                              "must be [cells along width, cells along height]");
    int k = 0;
    for (const cJSON *e = res->child; e; e = e->next, ++k) {
      if (!cJSON_IsNumber(e) || e->valuedouble != floor(e->valuedouble) || e->valuedouble < 1 ||
          e->valuedouble > 100000)
        return piola__json_fail(p, BAD_VALUE, "must be two integers in 1..100000");
      d->resolution[k] = (int32_t)e->valuedouble;
    }
    piola__json_pop(p, o2);
  } else if (cJSON_IsString(g) && strcmp(g->valuestring, "disk") == 0) {
    static const char *const keys[] = {"generate", "radius", "rings", NULL};
    PIOLA_TRY(piola__json_check_keys(p, v, keys));
    PIOLA_TRY(piola__json_required(p, v, "radius"));
    PIOLA_TRY(piola__json_required(p, v, "rings"));
    d->generator = 2;
    PIOLA_TRY(piola__json_opt_number(p, v, "radius", POSITIVE, &d->radius));
    int64_t rings = 1;
    PIOLA_TRY(piola__json_opt_int(p, v, "rings", 1, 20000, &rings));
    d->resolution[0] = (int32_t)rings;
  } else if (cJSON_IsString(g) && strcmp(g->valuestring, "torus") == 0) {
    static const char *const keys[] = {"generate", "radius", "minor_radius", "segments",
                                       "sweep_degrees", NULL};
    PIOLA_TRY(piola__json_check_keys(p, v, keys));
    PIOLA_TRY(piola__json_required(p, v, "radius"));
    PIOLA_TRY(piola__json_required(p, v, "minor_radius"));
    PIOLA_TRY(piola__json_required(p, v, "segments"));
    d->generator = 3;
    d->sweep_degrees = 360;
    PIOLA_TRY(piola__json_opt_number(p, v, "radius", POSITIVE, &d->radius));
    PIOLA_TRY(piola__json_opt_number(p, v, "minor_radius", POSITIVE, &d->minor_radius));
    PIOLA_TRY(piola__json_opt_number(p, v, "sweep_degrees", (json_range){0, 360, 1, 0},
                                     &d->sweep_degrees));
    if (!(d->minor_radius < d->radius)) {
      piola__json_push_key(p, "minor_radius");
      return piola__json_fail(p, BAD_VALUE, "must be smaller than radius (%g m), got %g", d->radius,
                              d->minor_radius);
    }
    const cJSON *seg = piola__json_get(v, "segments");
    size_t o2 = piola__json_push_key(p, "segments");
    if (!cJSON_IsArray(seg) || cJSON_GetArraySize(seg) != 2)
      return piola__json_fail(p, PIOLA_ERROR_PARSE,
                              "must be [segments around the ring, segments around the tube]");
    int k = 0;
    for (const cJSON *e = seg->child; e; e = e->next, ++k) {
      if (!cJSON_IsNumber(e) || e->valuedouble != floor(e->valuedouble) || e->valuedouble < 3 ||
          e->valuedouble > 100000)
        return piola__json_fail(p, BAD_VALUE, "must be two integers in 3..100000");
      d->resolution[k] = (int32_t)e->valuedouble;
    }
    piola__json_pop(p, o2);
  } else {
    piola__json_push_key(p, "generate");
    return piola__json_fail(p, BAD_VALUE, "must be \"rectangle\", \"disk\" or \"torus\"");
  }
  piola__json_pop(p, old);
  return PIOLA_OK;
}

static piola_status parse_shell(scene_parser *p, const cJSON *obj, int index, scene_shell_desc *d) {
  static const char *const allowed[] = {"name", "mesh", "transform", "thickness", "density",
                                        "material", "damping", "bending", "plasticity",
                                        "reference_normals", "velocity", "fixed", "driven",
                                        "collide_with_solids", "solid_friction", "self_collision",
                                        NULL};
  PIOLA_TRY(piola__json_check_keys(p, obj, allowed));
  PIOLA_TRY(piola__json_required(p, obj, "mesh"));
  d->def = piola_default_shell_def();
  d->base.def = piola_default_solid_def();
  d->base.def.density = d->def.density;
  d->base.scale = (piola_vec3){1, 1, 1};
  snprintf(d->base.name, sizeof d->base.name, "shell%d", index);
  PIOLA_TRY(piola__scene_parse_name(p, obj, d->base.name, sizeof d->base.name));
  PIOLA_TRY(parse_shell_mesh(p, piola__json_get(obj, "mesh"), d));
  const cJSON *v;
  if ((v = piola__json_get(obj, "transform")))
    PIOLA_TRY(piola__scene_parse_transform(p, v, &d->base));
  PIOLA_TRY(piola__json_opt_number(p, obj, "thickness", POSITIVE, &d->def.thickness));
  PIOLA_TRY(piola__json_opt_number(p, obj, "density", POSITIVE, &d->base.def.density));
  if ((v = piola__json_get(obj, "material"))) {
    size_t old = piola__json_push_key(p, "material");
    PIOLA_TRY(piola__scene_parse_material(p, v, &d->base));
    if (d->base.def.material.model == PIOLA_MODEL_MUSCLE ||
        d->base.def.material.model == PIOLA_MODEL_HGO) {
      piola__json_push_key(p, "model");
      return piola__json_fail(p, BAD_VALUE, "\"%s\" is for solids only (shells have no fibres)",
                              piola_material_model_name(d->base.def.material.model));
    }
    piola__json_pop(p, old);
  }
  PIOLA_TRY(piola__scene_parse_damping(p, obj, &d->base));
  if ((v = piola__json_get(obj, "bending"))) {
    size_t old = piola__json_push_key(p, "bending");
    static const char *const keys[] = {"stiffness", "damping", "plasticity", NULL};
    PIOLA_TRY(piola__json_check_keys(p, v, keys));
    PIOLA_TRY(piola__json_opt_number(p, v, "stiffness", NONNEGATIVE, &d->def.bending.stiffness));
    PIOLA_TRY(piola__json_opt_number(p, v, "damping", NONNEGATIVE, &d->def.bending.damping));
    const cJSON *pl = piola__json_get(v, "plasticity");
    if (pl) {
      size_t o2 = piola__json_push_key(p, "plasticity");
      static const char *const pkeys[] = {"yield_angle_degrees", "rate", NULL};
      PIOLA_TRY(piola__json_check_keys(p, pl, pkeys));
      PIOLA_TRY(piola__json_required(p, pl, "yield_angle_degrees"));
      double degrees = 0;
      PIOLA_TRY(piola__json_opt_number(p, pl, "yield_angle_degrees", (json_range){0, 180, 0, 0},
                                       &degrees));
      d->def.bending.yield_angle = degrees * M_PI / 180.0;
      PIOLA_TRY(piola__json_opt_number(p, pl, "rate", POSITIVE, &d->def.bending.plastic_rate));
      piola__json_pop(p, o2);
    }
    piola__json_pop(p, old);
  }
  if ((v = piola__json_get(obj, "plasticity"))) {
    size_t old = piola__json_push_key(p, "plasticity");
    static const char *const keys[] = {"yield_strain", "rate", "max_plastic_stretch", NULL};
    PIOLA_TRY(piola__json_check_keys(p, v, keys));
    PIOLA_TRY(piola__json_required(p, v, "yield_strain"));
    PIOLA_TRY(
        piola__json_opt_number(p, v, "yield_strain", NONNEGATIVE, &d->def.plasticity.yield_strain));
    PIOLA_TRY(piola__json_opt_number(p, v, "rate", POSITIVE, &d->def.plasticity.rate));
    PIOLA_TRY(piola__json_opt_number(p, v, "max_plastic_stretch", (json_range){1, INFINITY, 1, 0},
                                     &d->def.plasticity.max_plastic_stretch));
    piola__json_pop(p, old);
  }
  PIOLA_TRY(piola__json_opt_bool(p, obj, "reference_normals", &d->def.use_reference_normals));
  PIOLA_TRY(piola__json_opt_bool(p, obj, "collide_with_solids", &d->def.collide_with_solids));
  PIOLA_TRY(piola__json_opt_number(p, obj, "solid_friction", NONNEGATIVE, &d->def.solid_friction));
  PIOLA_TRY(piola__scene_parse_self_collision(p, obj, &d->def.self_collision));
  PIOLA_TRY(piola__json_opt_vec3(p, obj, "velocity", ANY, &d->base.def.velocity));
  PIOLA_TRY(piola__scene_parse_constraints(p, obj, "fixed", 0, &d->base));
  d->base.fixed_count = d->base.constraint_count;
  PIOLA_TRY(piola__scene_parse_constraints(p, obj, "driven", 1, &d->base));
  return PIOLA_OK;
}

piola_status piola__scene_parse_shells(scene_parser *p, const cJSON *v, scene_desc *out) {
  size_t old = piola__json_push_key(p, "shells");
  if (!cJSON_IsArray(v))
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an array of shells");
  int count = cJSON_GetArraySize(v);
  out->shells = calloc((size_t)(count > 0 ? count : 1), sizeof *out->shells);
  if (!out->shells) return piola__json_fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  int i = 0;
  for (const cJSON *e = v->child; e; e = e->next, ++i) {
    size_t o2 = piola__json_push_index(p, i);
    out->shell_count = i + 1;
    PIOLA_TRY(parse_shell(p, e, i, &out->shells[i]));
    for (int j = 0; j < i; ++j)
      if (strcmp(out->shells[j].base.name, out->shells[i].base.name) == 0) {
        piola__json_push_key(p, "name");
        return piola__json_fail(p, BAD_VALUE, "\"%s\" is already the name of shells[%d]",
                                out->shells[i].base.name, j);
      }
    piola__json_pop(p, o2);
  }
  piola__json_pop(p, old);
  return PIOLA_OK;
}
