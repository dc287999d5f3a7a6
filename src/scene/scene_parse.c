/* Scene files: JSON (cJSON) -> definition structs, with every error naming its key path.
 *
 * A small parser context carries the key path of the value being read ("solids[0].material")
 * so each check can say exactly where the problem is. Every object's keys are checked against
 * the list the format allows, so a misspelt key is an error rather than a silently ignored
 * setting. */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_internal.h"
#include "math/mat3.h"
#include "scene/scene_desc.h"

typedef struct parser {
  const char *label;
  const char *base_dir;
  char path[512];
  size_t len;
} parser;

static size_t push_key(parser *p, const char *key) {
  size_t old = p->len;
  int n = snprintf(p->path + p->len, sizeof p->path - p->len, "%s%s", p->len ? "." : "", key);
  if (n > 0) p->len = strlen(p->path);
  return old;
}

static size_t push_index(parser *p, int i) {
  size_t old = p->len;
  int n = snprintf(p->path + p->len, sizeof p->path - p->len, "[%d]", i);
  if (n > 0) p->len = strlen(p->path);
  return old;
}

static void pop(parser *p, size_t old) {
  p->len = old;
  p->path[old] = '\0';
}

static piola_status fail(parser *p, piola_status status, const char *format, ...)
    PIOLA_PRINTF_LIKE(3, 4);
static piola_status fail(parser *p, piola_status status, const char *format, ...) {
  char msg[512];
  va_list ap;
  va_start(ap, format);
  vsnprintf(msg, sizeof msg, format, ap);
  va_end(ap);
  return PIOLA_FAIL(status, "%s: %s: %s", p->label, p->len ? p->path : "(top level)", msg);
}

#define BAD_VALUE PIOLA_ERROR_INVALID_ARGUMENT

static const char *type_name(const cJSON *v) {
  if (cJSON_IsNumber(v)) return "a number";
  if (cJSON_IsString(v)) return "a string";
  if (cJSON_IsBool(v)) return "a boolean";
  if (cJSON_IsNull(v)) return "null";
  if (cJSON_IsArray(v)) return "an array";
  if (cJSON_IsObject(v)) return "an object";
  return "invalid";
}

/* Unknown and duplicate keys of obj (the path points at obj). */
static piola_status check_keys(parser *p, const cJSON *obj, const char *const *allowed) {
  if (!cJSON_IsObject(obj)) return fail(p, PIOLA_ERROR_PARSE, "must be an object, got %s", type_name(obj));
  for (const cJSON *c = obj->child; c; c = c->next) {
    int ok = 0;
    for (const char *const *a = allowed; *a; ++a)
      if (strcmp(*a, c->string) == 0) ok = 1;
    size_t old = push_key(p, c->string);
    if (!ok) {
      char list[512] = "";
      for (const char *const *a = allowed; *a; ++a) {
        strncat(list, *a, sizeof list - strlen(list) - 1);
        if (a[1]) strncat(list, ", ", sizeof list - strlen(list) - 1);
      }
      return fail(p, PIOLA_ERROR_PARSE, "unknown key (allowed here: %s)", list);
    }
    for (const cJSON *d = obj->child; d != c; d = d->next)
      if (strcmp(d->string, c->string) == 0) return fail(p, PIOLA_ERROR_PARSE, "duplicate key");
    pop(p, old);
  }
  return PIOLA_OK;
}

static const cJSON *get(const cJSON *obj, const char *key) {
  return cJSON_GetObjectItemCaseSensitive(obj, key);
}

/* Range kinds for numbers. */
typedef struct range {
  double lo, hi;
  int lo_open, hi_open;
} range;
static const range ANY = {-INFINITY, INFINITY, 0, 0};
static const range POSITIVE = {0, INFINITY, 1, 0};
static const range NONNEGATIVE = {0, INFINITY, 0, 0};

static piola_status check_range(parser *p, double v, range r) {
  if (!isfinite(v)) return fail(p, BAD_VALUE, "must be finite, got %g", v);
  int ok = (r.lo_open ? v > r.lo : v >= r.lo) && (r.hi_open ? v < r.hi : v <= r.hi);
  if (ok) return PIOLA_OK;
  if (isinf(r.hi) && r.lo == 0) return fail(p, BAD_VALUE, "must be %s 0, got %g", r.lo_open ? ">" : ">=", v);
  return fail(p, BAD_VALUE, "must be in %c%g, %g%c, got %g", r.lo_open ? '(' : '[', r.lo, r.hi,
              r.hi_open ? ')' : ']', v);
}

/* A plain number (keyframes not allowed) at the current path. */
static piola_status number_value(parser *p, const cJSON *v, range r, double *out) {
  if (cJSON_IsObject(v) && get(v, "keys"))
    return fail(p, PIOLA_ERROR_PARSE, "must be a constant number here (keyframes are not supported for this key)");
  if (!cJSON_IsNumber(v)) return fail(p, PIOLA_ERROR_PARSE, "must be a number, got %s", type_name(v));
  PIOLA_TRY(check_range(p, v->valuedouble, r));
  *out = v->valuedouble;
  return PIOLA_OK;
}

/* obj.key as a number if present (else *out keeps its default). */
static piola_status opt_number(parser *p, const cJSON *obj, const char *key, range r, double *out) {
  const cJSON *v = get(obj, key);
  if (!v) return PIOLA_OK;
  size_t old = push_key(p, key);
  PIOLA_TRY(number_value(p, v, r, out));
  pop(p, old);
  return PIOLA_OK;
}

static piola_status opt_int(parser *p, const cJSON *obj, const char *key, double lo, double hi,
                            int64_t *out) {
  const cJSON *v = get(obj, key);
  if (!v) return PIOLA_OK;
  size_t old = push_key(p, key);
  double d;
  PIOLA_TRY(number_value(p, v, (range){lo, hi, 0, 0}, &d));
  if (d != floor(d)) return fail(p, PIOLA_ERROR_PARSE, "must be an integer, got %g", d);
  *out = (int64_t)d;
  pop(p, old);
  return PIOLA_OK;
}

/* A scalar or {"keys": [[t, v], ...]} at the current path. */
static piola_status track_value(parser *p, const cJSON *v, range r, piola_track *out) {
  if (cJSON_IsNumber(v)) {
    PIOLA_TRY(check_range(p, v->valuedouble, r));
    *out = piola_track_constant(v->valuedouble);
    return PIOLA_OK;
  }
  if (!cJSON_IsObject(v))
    return fail(p, PIOLA_ERROR_PARSE, "must be a number or {\"keys\": [[t, v], ...]}, got %s", type_name(v));
  static const char *const allowed[] = {"keys", NULL};
  PIOLA_TRY(check_keys(p, v, allowed));
  const cJSON *keys = get(v, "keys");
  size_t old = push_key(p, "keys");
  if (!cJSON_IsArray(keys)) return fail(p, PIOLA_ERROR_PARSE, "must be an array of [time, value] pairs");
  int count = cJSON_GetArraySize(keys);
  if (count < 1 || count > PIOLA_MAX_KEYS)
    return fail(p, BAD_VALUE, "must hold 1 to %d keys, got %d", PIOLA_MAX_KEYS, count);
  double times[PIOLA_MAX_KEYS], values[PIOLA_MAX_KEYS];
  int i = 0;
  for (const cJSON *k = keys->child; k; k = k->next, ++i) {
    size_t o2 = push_index(p, i);
    if (!cJSON_IsArray(k) || cJSON_GetArraySize(k) != 2 || !cJSON_IsNumber(k->child) ||
        !cJSON_IsNumber(k->child->next))
      return fail(p, PIOLA_ERROR_PARSE, "must be a pair [time in s, value] of numbers");
    times[i] = k->child->valuedouble;
    values[i] = k->child->next->valuedouble;
    if (!isfinite(times[i])) return fail(p, BAD_VALUE, "time must be finite");
    if (i > 0 && !(times[i] > times[i - 1]))
      return fail(p, BAD_VALUE, "times must increase strictly (%g after %g)", times[i], times[i - 1]);
    PIOLA_TRY(check_range(p, values[i], r));
    pop(p, o2);
  }
  pop(p, old);
  if (piola_track_from_keys(times, values, count, out) != PIOLA_OK)
    return fail(p, BAD_VALUE, "%s", piola_last_error());
  return PIOLA_OK;
}

static piola_status opt_track(parser *p, const cJSON *obj, const char *key, range r, piola_track *out) {
  const cJSON *v = get(obj, key);
  if (!v) return PIOLA_OK;
  size_t old = push_key(p, key);
  PIOLA_TRY(track_value(p, v, r, out));
  pop(p, old);
  return PIOLA_OK;
}

static piola_status vec3_value(parser *p, const cJSON *v, range r, piola_vec3 *out) {
  if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
    return fail(p, PIOLA_ERROR_PARSE, "must be an array of 3 numbers, got %s", type_name(v));
  double c[3];
  int i = 0;
  for (const cJSON *e = v->child; e; e = e->next, ++i) {
    size_t old = push_index(p, i);
    PIOLA_TRY(number_value(p, e, r, &c[i]));
    pop(p, old);
  }
  *out = (piola_vec3){c[0], c[1], c[2]};
  return PIOLA_OK;
}

static piola_status opt_vec3(parser *p, const cJSON *obj, const char *key, range r, piola_vec3 *out) {
  const cJSON *v = get(obj, key);
  if (!v) return PIOLA_OK;
  size_t old = push_key(p, key);
  PIOLA_TRY(vec3_value(p, v, r, out));
  pop(p, old);
  return PIOLA_OK;
}

/* A unit direction: nonzero, normalized. */
static piola_status opt_direction(parser *p, const cJSON *obj, const char *key, piola_vec3 *out) {
  const cJSON *v = get(obj, key);
  if (!v) return PIOLA_OK;
  size_t old = push_key(p, key);
  piola_vec3 d;
  PIOLA_TRY(vec3_value(p, v, ANY, &d));
  double len = vec3_norm(d);
  if (!(len > 1e-300)) return fail(p, BAD_VALUE, "must be a nonzero vector");
  *out = vec3_scale(d, 1.0 / len);
  pop(p, old);
  return PIOLA_OK;
}

static piola_status opt_vec3_tracks(parser *p, const cJSON *obj, const char *key, piola_track out[3]) {
  const cJSON *v = get(obj, key);
  if (!v) return PIOLA_OK;
  size_t old = push_key(p, key);
  if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
    return fail(p, PIOLA_ERROR_PARSE, "must be an array of 3 numbers (or keyframes), got %s", type_name(v));
  int i = 0;
  for (const cJSON *e = v->child; e; e = e->next, ++i) {
    size_t o2 = push_index(p, i);
    PIOLA_TRY(track_value(p, e, ANY, &out[i]));
    pop(p, o2);
  }
  pop(p, old);
  return PIOLA_OK;
}

static piola_status required(parser *p, const cJSON *obj, const char *key) {
  if (get(obj, key)) return PIOLA_OK;
  size_t old = push_key(p, key);
  piola_status s = fail(p, PIOLA_ERROR_PARSE, "is required");
  pop(p, old);
  return s;
}

static piola_status resolve_path(parser *p, const cJSON *v, char *out) {
  if (!cJSON_IsString(v) || !v->valuestring[0])
    return fail(p, PIOLA_ERROR_PARSE, "must be a file path (string), got %s", type_name(v));
  int n;
  if (v->valuestring[0] == '/' || !p->base_dir || !p->base_dir[0])
    n = snprintf(out, SCENE_PATH_MAX, "%s", v->valuestring);
  else
    n = snprintf(out, SCENE_PATH_MAX, "%s/%s", p->base_dir, v->valuestring);
  if (n < 0 || n >= SCENE_PATH_MAX) return fail(p, BAD_VALUE, "path is too long");
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ motion */

/* default_pivot and default_axis: where and about what the rotation turns unless the scene
 * says otherwise (an obstacle's centre and, for shapes with an axis, that axis). */
static piola_status parse_motion(parser *p, const cJSON *obj, piola_vec3 default_pivot,
                                 piola_vec3 default_axis, piola_rigid_motion_def *out) {
  static const char *const allowed[] = {"velocity", "angular_speed", "translation", "angle",
                                        "axis", "pivot", NULL};
  PIOLA_TRY(check_keys(p, obj, allowed));
  *out = piola_default_rigid_motion_def();
  out->pivot = default_pivot;
  out->axis = default_axis;
  int velocity_kind = get(obj, "velocity") || get(obj, "angular_speed");
  int pose_kind = get(obj, "translation") || get(obj, "angle");
  if (velocity_kind && pose_kind)
    return fail(p, PIOLA_ERROR_PARSE,
                "give either velocity/angular_speed or translation/angle, not both");
  out->kind = pose_kind ? PIOLA_MOTION_POSE : PIOLA_MOTION_VELOCITY;
  PIOLA_TRY(opt_vec3_tracks(p, obj, "velocity", out->velocity));
  PIOLA_TRY(opt_track(p, obj, "angular_speed", ANY, &out->angular_speed));
  PIOLA_TRY(opt_vec3_tracks(p, obj, "translation", out->translation));
  PIOLA_TRY(opt_track(p, obj, "angle", ANY, &out->angle));
  PIOLA_TRY(opt_direction(p, obj, "axis", &out->axis));
  PIOLA_TRY(opt_vec3(p, obj, "pivot", ANY, &out->pivot));
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ solids */

static piola_status parse_selector(parser *p, const cJSON *obj, int driven, piola_constraint_def *out,
                                   int32_t **indices_out) {
  static const char *const fixed_keys[] = {"box", "sphere", "indices", NULL};
  static const char *const driven_keys[] = {"box", "sphere", "indices", "motion", NULL};
  PIOLA_TRY(check_keys(p, obj, driven ? driven_keys : fixed_keys));
  memset(out, 0, sizeof *out);
  out->driven = driven;
  out->motion = piola_default_rigid_motion_def();
  int kinds = !!get(obj, "box") + !!get(obj, "sphere") + !!get(obj, "indices");
  if (kinds != 1) return fail(p, PIOLA_ERROR_PARSE, "needs exactly one of box, sphere or indices");
  const cJSON *v;
  if ((v = get(obj, "box"))) {
    size_t old = push_key(p, "box");
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 2)
      return fail(p, PIOLA_ERROR_PARSE, "must be [[x0, y0, z0], [x1, y1, z1]]");
    out->selector.type = PIOLA_SELECT_BOX;
    size_t o2 = push_index(p, 0);
    PIOLA_TRY(vec3_value(p, v->child, ANY, &out->selector.box_min));
    pop(p, o2);
    o2 = push_index(p, 1);
    PIOLA_TRY(vec3_value(p, v->child->next, ANY, &out->selector.box_max));
    pop(p, o2);
    piola_vec3 a = out->selector.box_min, b = out->selector.box_max;
    if (a.x > b.x || a.y > b.y || a.z > b.z)
      return fail(p, BAD_VALUE, "the first corner must be <= the second in every coordinate");
    pop(p, old);
  } else if ((v = get(obj, "sphere"))) {
    size_t old = push_key(p, "sphere");
    static const char *const keys[] = {"center", "radius", NULL};
    PIOLA_TRY(check_keys(p, v, keys));
    PIOLA_TRY(required(p, v, "radius"));
    out->selector.type = PIOLA_SELECT_SPHERE;
    PIOLA_TRY(opt_vec3(p, v, "center", ANY, &out->selector.center));
    PIOLA_TRY(opt_number(p, v, "radius", NONNEGATIVE, &out->selector.radius));
    pop(p, old);
  } else {
    v = get(obj, "indices");
    size_t old = push_key(p, "indices");
    if (!cJSON_IsArray(v)) return fail(p, PIOLA_ERROR_PARSE, "must be an array of vertex indices");
    int count = cJSON_GetArraySize(v);
    int32_t *idx = malloc((size_t)(count > 0 ? count : 1) * sizeof *idx);
    if (!idx) return fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
    *indices_out = idx;
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
      size_t o2 = push_index(p, i);
      if (!cJSON_IsNumber(e) || e->valuedouble != floor(e->valuedouble) || e->valuedouble < 0 ||
          e->valuedouble > 2147483647.0)
        return fail(p, BAD_VALUE, "must be a vertex index (an integer >= 0)");
      idx[i] = (int32_t)e->valuedouble;
      pop(p, o2);
    }
    out->selector.type = PIOLA_SELECT_INDICES;
    out->selector.indices = idx;
    out->selector.index_count = count;
    pop(p, old);
  }
  if (driven) {
    PIOLA_TRY(required(p, obj, "motion"));
    size_t old = push_key(p, "motion");
    PIOLA_TRY(parse_motion(p, get(obj, "motion"), (piola_vec3){0, 0, 0}, (piola_vec3){0, 0, 1},
                           &out->motion));
    pop(p, old);
  }
  return PIOLA_OK;
}

static piola_status parse_constraints(parser *p, const cJSON *solid, const char *key, int driven,
                                      scene_solid_desc *d) {
  const cJSON *list = get(solid, key);
  if (!list) return PIOLA_OK;
  size_t old = push_key(p, key);
  if (!cJSON_IsArray(list)) return fail(p, PIOLA_ERROR_PARSE, "must be an array of selectors");
  int count = cJSON_GetArraySize(list);
  int total = d->constraint_count + count;
  piola_constraint_def *c = realloc(d->constraints, (size_t)(total > 0 ? total : 1) * sizeof *c);
  if (!c) return fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  d->constraints = c;
  int32_t **lists = realloc(d->index_lists, (size_t)(total > 0 ? total : 1) * sizeof *lists);
  if (!lists) return fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  d->index_lists = lists;
  int i = 0;
  for (const cJSON *e = list->child; e; e = e->next, ++i) {
    size_t o2 = push_index(p, i);
    int32_t slot = d->constraint_count++;
    d->index_lists[slot] = NULL;
    memset(&d->constraints[slot], 0, sizeof d->constraints[slot]);
    PIOLA_TRY(parse_selector(p, e, driven, &d->constraints[slot], &d->index_lists[slot]));
    pop(p, o2);
  }
  pop(p, old);
  return PIOLA_OK;
}

static piola_status parse_generator(parser *p, const cJSON *obj, piola_mesher_def *m) {
  static const char *const allowed[] = {"generate", "center", "axis", "radius", "minor_radius",
                                        "half_length", "half_extents", "cell_size",
                                        "refinement_levels", NULL};
  PIOLA_TRY(check_keys(p, obj, allowed));
  PIOLA_TRY(required(p, obj, "generate"));
  PIOLA_TRY(required(p, obj, "cell_size"));
  *m = piola_default_mesher_def();
  m->shape_count = 1;
  piola_shape *s = &m->shapes[0];
  memset(s, 0, sizeof *s);
  s->axis = (piola_vec3){0, 0, 1};
  const cJSON *g = get(obj, "generate");
  size_t old = push_key(p, "generate");
  static const char *const names[] = {"sphere", "box", "torus", "cylinder", "capsule", NULL};
  static const piola_shape_type types[] = {PIOLA_SHAPE_SPHERE, PIOLA_SHAPE_BOX, PIOLA_SHAPE_TORUS,
                                           PIOLA_SHAPE_CYLINDER, PIOLA_SHAPE_CAPSULE};
  int found = -1;
  if (cJSON_IsString(g))
    for (int i = 0; names[i]; ++i)
      if (strcmp(g->valuestring, names[i]) == 0) found = i;
  if (found < 0)
    return fail(p, BAD_VALUE, "must be one of \"sphere\", \"box\", \"torus\", \"cylinder\", \"capsule\"");
  s->type = types[found];
  pop(p, old);
  const char *need[3] = {NULL, NULL, NULL};
  switch (s->type) {
    case PIOLA_SHAPE_SPHERE: need[0] = "radius"; break;
    case PIOLA_SHAPE_BOX: need[0] = "half_extents"; break;
    case PIOLA_SHAPE_TORUS: need[0] = "radius", need[1] = "minor_radius"; break;
    default: need[0] = "radius", need[1] = "half_length"; break;
  }
  for (int i = 0; need[i]; ++i) PIOLA_TRY(required(p, obj, need[i]));
  PIOLA_TRY(opt_vec3(p, obj, "center", ANY, &s->center));
  PIOLA_TRY(opt_direction(p, obj, "axis", &s->axis));
  PIOLA_TRY(opt_number(p, obj, "radius", POSITIVE, &s->radius));
  PIOLA_TRY(opt_number(p, obj, "minor_radius", POSITIVE, &s->minor_radius));
  PIOLA_TRY(opt_number(p, obj, "half_length", POSITIVE, &s->half_length));
  PIOLA_TRY(opt_vec3(p, obj, "half_extents", POSITIVE, &s->half_extents));
  PIOLA_TRY(opt_number(p, obj, "cell_size", POSITIVE, &m->cell_size));
  int64_t levels = m->refinement_levels;
  PIOLA_TRY(opt_int(p, obj, "refinement_levels", 0, 6, &levels));
  m->refinement_levels = (int)levels;
  if (s->type == PIOLA_SHAPE_TORUS && !(s->minor_radius < s->radius)) {
    push_key(p, "minor_radius");
    return fail(p, BAD_VALUE, "must be smaller than radius (%g m), got %g", s->radius, s->minor_radius);
  }
  return PIOLA_OK;
}

static piola_status parse_material(parser *p, const cJSON *obj, scene_solid_desc *d) {
  static const char *const allowed[] = {"model", "youngs_modulus", "poisson_ratio", "stiffness_scale",
                                        "inversion", "spline", "muscle", NULL};
  PIOLA_TRY(check_keys(p, obj, allowed));
  piola_material_def *m = &d->def.material;
  const cJSON *model = get(obj, "model");
  if (model) {
    size_t old = push_key(p, "model");
    static const char *const names[] = {"rotated_linear", "corotated", "stvk", "neohookean", "spline",
                                        "muscle", NULL};
    static const piola_material_model models[] = {PIOLA_MODEL_ROTATED_LINEAR, PIOLA_MODEL_COROTATED,
                                                  PIOLA_MODEL_STVK, PIOLA_MODEL_NEOHOOKEAN,
                                                  PIOLA_MODEL_SPLINE, PIOLA_MODEL_MUSCLE};
    int found = -1;
    if (cJSON_IsString(model))
      for (int i = 0; names[i]; ++i)
        if (strcmp(model->valuestring, names[i]) == 0) found = i;
    if (found < 0)
      return fail(p, BAD_VALUE,
                  "must be one of \"rotated_linear\", \"corotated\", \"stvk\", \"neohookean\", \"spline\", "
                  "\"muscle\"");
    m->model = models[found];
    pop(p, old);
  }
  PIOLA_TRY(opt_number(p, obj, "youngs_modulus", POSITIVE, &m->youngs_modulus));
  PIOLA_TRY(opt_number(p, obj, "poisson_ratio", (range){-1, 0.5, 1, 1}, &m->poisson_ratio));
  PIOLA_TRY(opt_track(p, obj, "stiffness_scale", NONNEGATIVE, &d->def.stiffness_scale));
  const cJSON *inv = get(obj, "inversion");
  if (inv) {
    size_t old = push_key(p, "inversion");
    static const char *const keys[] = {"threshold", "mode", NULL};
    PIOLA_TRY(check_keys(p, inv, keys));
    PIOLA_TRY(opt_number(p, inv, "threshold", (range){0, 1, 1, 1}, &m->inversion_threshold));
    const cJSON *mode = get(inv, "mode");
    if (mode) {
      size_t o2 = push_key(p, "mode");
      if (cJSON_IsString(mode) && strcmp(mode->valuestring, "linear") == 0)
        m->inversion_mode = PIOLA_INVERSION_LINEAR;
      else if (cJSON_IsString(mode) && strcmp(mode->valuestring, "clamp") == 0)
        m->inversion_mode = PIOLA_INVERSION_CLAMP;
      else
        return fail(p, BAD_VALUE, "must be \"linear\" or \"clamp\"");
      pop(p, o2);
    }
    pop(p, old);
  }
  const cJSON *sp = get(obj, "spline");
  if (sp) {
    size_t old = push_key(p, "spline");
    static const char *const keys[] = {"compression_stretch", "elongation_stretch", "stiffening", NULL};
    PIOLA_TRY(check_keys(p, sp, keys));
    PIOLA_TRY(opt_number(p, sp, "compression_stretch", (range){0, 1, 1, 1}, &m->spline.compression_stretch));
    PIOLA_TRY(opt_number(p, sp, "elongation_stretch", (range){1, INFINITY, 1, 0}, &m->spline.elongation_stretch));
    PIOLA_TRY(opt_number(p, sp, "stiffening", (range){1, INFINITY, 0, 0}, &m->spline.stiffening));
    pop(p, old);
  }
  const cJSON *mu = get(obj, "muscle");
  if (mu) {
    size_t old = push_key(p, "muscle");
    if (m->model != PIOLA_MODEL_MUSCLE) return fail(p, BAD_VALUE, "needs \"model\": \"muscle\"");
    static const char *const keys[] = {"passive_stiffness", "passive_toe_stretch", "max_active_stress",
                                       "optimal_stretch", "active_width", NULL};
    PIOLA_TRY(check_keys(p, mu, keys));
    piola_muscle_def *md = &m->muscle;
    PIOLA_TRY(opt_number(p, mu, "passive_stiffness", NONNEGATIVE, &md->passive_stiffness));
    PIOLA_TRY(opt_number(p, mu, "passive_toe_stretch", (range){1, INFINITY, 1, 0}, &md->passive_toe_stretch));
    PIOLA_TRY(opt_number(p, mu, "max_active_stress", NONNEGATIVE, &md->max_active_stress));
    PIOLA_TRY(opt_number(p, mu, "optimal_stretch", POSITIVE, &md->optimal_stretch));
    PIOLA_TRY(opt_number(p, mu, "active_width", (range){0, 1, 1, 1}, &md->active_width));
    pop(p, old);
  }
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ muscle fibres */

/* "fibers": {"axis": [x, y, z]} | {"curve": [[x, y, z], ...]} | {"from_mesh": true}. */
static piola_status parse_fibers(parser *p, const cJSON *obj, scene_fibers *f) {
  static const char *const allowed[] = {"axis", "curve", "from_mesh", NULL};
  PIOLA_TRY(check_keys(p, obj, allowed));
  const cJSON *axis = get(obj, "axis"), *curve = get(obj, "curve"), *mesh = get(obj, "from_mesh");
  if ((axis != NULL) + (curve != NULL) + (mesh != NULL) != 1)
    return fail(p, PIOLA_ERROR_PARSE, "needs exactly one of \"axis\", \"curve\" and \"from_mesh\"");
  if (axis) {
    f->kind = SCENE_FIBERS_AXIS;
    return opt_direction(p, obj, "axis", &f->axis);
  }
  if (mesh) {
    size_t old = push_key(p, "from_mesh");
    if (!cJSON_IsTrue(mesh)) return fail(p, BAD_VALUE, "must be true (leave the key out for no fibres)");
    f->kind = SCENE_FIBERS_FROM_MESH;
    pop(p, old);
    return PIOLA_OK;
  }
  size_t old = push_key(p, "curve");
  const int count = cJSON_IsArray(curve) ? cJSON_GetArraySize(curve) : 0;
  if (count < 2) return fail(p, PIOLA_ERROR_PARSE, "must be an array of at least 2 points [x, y, z] (m)");
  f->kind = SCENE_FIBERS_CURVE;
  f->curve = malloc(sizeof(double) * 3 * (size_t)count);
  if (!f->curve) return fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  f->curve_points = count;
  int i = 0;
  for (const cJSON *e = curve->child; e; e = e->next, ++i) {
    size_t o2 = push_index(p, i);
    piola_vec3 q;
    PIOLA_TRY(vec3_value(p, e, ANY, &q));
    f->curve[3 * i] = q.x, f->curve[3 * i + 1] = q.y, f->curve[3 * i + 2] = q.z;
    if (i > 0 && f->curve[3 * i] == f->curve[3 * i - 3] && f->curve[3 * i + 1] == f->curve[3 * i - 2] &&
        f->curve[3 * i + 2] == f->curve[3 * i - 1])
      return fail(p, BAD_VALUE, "repeats the point before it (a segment needs a direction)");
    pop(p, o2);
  }
  pop(p, old);
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ plasticity */

/* A 3x3 matrix given as 3 rows of 3 numbers, at the current path. */
static piola_status mat3_value(parser *p, const cJSON *mat, piola_mat3 *out) {
  if (!cJSON_IsArray(mat) || cJSON_GetArraySize(mat) != 3)
    return fail(p, PIOLA_ERROR_PARSE, "must be a 3x3 matrix given as 3 rows of 3 numbers");
  int r = 0;
  for (const cJSON *row = mat->child; row; row = row->next, ++r) {
    size_t old = push_index(p, r);
    piola_vec3 rv;
    PIOLA_TRY(vec3_value(p, row, ANY, &rv));
    out->m[r][0] = rv.x, out->m[r][1] = rv.y, out->m[r][2] = rv.z;
    pop(p, old);
  }
  return PIOLA_OK;
}

/* "plasticity": {yield, limit, hardening, volume_preserving, control: {goal: {map | mesh},
 * strength}} (docs/scene-format.md, docs/plasticity.md). */
static piola_status parse_plasticity(parser *p, const cJSON *obj, scene_solid_desc *d) {
  static const char *const allowed[] = {"yield", "limit", "hardening", "volume_preserving", "control", NULL};
  PIOLA_TRY(check_keys(p, obj, allowed));
  piola_plasticity_def *def = &d->plasticity;
  *def = piola_default_plasticity_def();
  d->plastic = 1;
  PIOLA_TRY(opt_number(p, obj, "yield", POSITIVE, &def->yield));
  static const range LIMIT = {0, 20, 1, 0};
  PIOLA_TRY(opt_number(p, obj, "limit", LIMIT, &def->limit));
  PIOLA_TRY(opt_number(p, obj, "hardening", NONNEGATIVE, &def->hardening));
  const cJSON *v = get(obj, "volume_preserving");
  if (v) {
    size_t old = push_key(p, "volume_preserving");
    if (!cJSON_IsBool(v)) return fail(p, PIOLA_ERROR_PARSE, "must be true or false, got %s", type_name(v));
    def->volume_preserving = cJSON_IsTrue(v);
    pop(p, old);
  }
  const cJSON *c = get(obj, "control");
  if (!c) return PIOLA_OK;
  size_t old = push_key(p, "control");
  static const char *const control_keys[] = {"goal", "strength", NULL};
  PIOLA_TRY(check_keys(p, c, control_keys));
  PIOLA_TRY(required(p, c, "goal"));
  if (def->volume_preserving)
    return fail(p, BAD_VALUE, "cannot be used with volume_preserving: true (the goal rarely preserves volume)");
  PIOLA_TRY(opt_number(p, c, "strength", NONNEGATIVE, &def->control.strength));
  const cJSON *g = get(c, "goal");
  size_t o2 = push_key(p, "goal");
  static const char *const goal_keys[] = {"map", "mesh", NULL};
  PIOLA_TRY(check_keys(p, g, goal_keys));
  const cJSON *map = get(g, "map"), *mesh = get(g, "mesh");
  if ((map != NULL) == (mesh != NULL)) return fail(p, PIOLA_ERROR_PARSE, "needs exactly one of \"map\" and \"mesh\"");
  if (map) {
    size_t o3 = push_key(p, "map");
    def->control.goal = PIOLA_PLASTIC_GOAL_MAP;
    PIOLA_TRY(mat3_value(p, map, &def->control.goal_map));
    const piola_mat3 *a = &def->control.goal_map;
    double det = a->m[0][0] * (a->m[1][1] * a->m[2][2] - a->m[1][2] * a->m[2][1]) -
                 a->m[0][1] * (a->m[1][0] * a->m[2][2] - a->m[1][2] * a->m[2][0]) +
                 a->m[0][2] * (a->m[1][0] * a->m[2][1] - a->m[1][1] * a->m[2][0]);
    if (!(det > 0)) return fail(p, BAD_VALUE, "must have a positive determinant, got %g", det);
    pop(p, o3);
  } else {
    size_t o3 = push_key(p, "mesh");
    def->control.goal = PIOLA_PLASTIC_GOAL_MESH;
    PIOLA_TRY(resolve_path(p, mesh, d->goal_mesh_path));
    pop(p, o3);
  }
  pop(p, o2);
  pop(p, old);
  return PIOLA_OK;
}

/* "self_collision": {"enabled": true, "thickness": m, "friction": mu}; giving the object
 * turns it on unless "enabled" is false (docs/contact.md). */
static piola_status parse_self_collision(parser *p, const cJSON *obj,
                                         piola_self_collision_def *out) {
  const cJSON *v = get(obj, "self_collision");
  if (!v) return PIOLA_OK;
  size_t old = push_key(p, "self_collision");
  static const char *const keys[] = {"enabled", "thickness", "friction", NULL};
  PIOLA_TRY(check_keys(p, v, keys));
  out->enabled = true;
  const cJSON *e = get(v, "enabled");
  if (e) {
    size_t o2 = push_key(p, "enabled");
    if (!cJSON_IsBool(e)) return fail(p, PIOLA_ERROR_PARSE, "must be true or false, got %s", type_name(e));
    out->enabled = cJSON_IsTrue(e);
    pop(p, o2);
  }
  PIOLA_TRY(opt_number(p, v, "thickness", POSITIVE, &out->thickness));
  PIOLA_TRY(opt_number(p, v, "friction", NONNEGATIVE, &out->friction));
  pop(p, old);
  return PIOLA_OK;
}

static piola_status parse_transform(parser *p, const cJSON *v, scene_solid_desc *d) {
  size_t old = push_key(p, "transform");
  static const char *const keys[] = {"translate", "rotate_degrees", "scale", NULL};
  PIOLA_TRY(check_keys(p, v, keys));
  PIOLA_TRY(opt_vec3(p, v, "translate", ANY, &d->translate));
  PIOLA_TRY(opt_vec3(p, v, "rotate_degrees", ANY, &d->rotate_degrees));
  const cJSON *sc = get(v, "scale");
  if (sc) {
    size_t o2 = push_key(p, "scale");
    if (cJSON_IsNumber(sc)) {
      double s;
      PIOLA_TRY(number_value(p, sc, POSITIVE, &s));
      d->scale = (piola_vec3){s, s, s};
    } else {
      PIOLA_TRY(vec3_value(p, sc, POSITIVE, &d->scale));
    }
    pop(p, o2);
  }
  pop(p, old);
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ solids */

/* The name key of a solid or a shell. */
static piola_status parse_name(parser *p, const cJSON *obj, scene_solid_desc *d) {
  const cJSON *v = get(obj, "name");
  if (!v) return PIOLA_OK;
  size_t old = push_key(p, "name");
  if (!cJSON_IsString(v) || !v->valuestring[0] || strlen(v->valuestring) >= sizeof d->name)
    return fail(p, PIOLA_ERROR_PARSE, "must be a non-empty string of at most %d characters",
                (int)sizeof d->name - 1);
  snprintf(d->name, sizeof d->name, "%s", v->valuestring);
  pop(p, old);
  return PIOLA_OK;
}

static piola_status parse_solid(parser *p, const cJSON *obj, int index, scene_solid_desc *d) {
  static const char *const allowed[] = {"name", "mesh", "transform", "density", "material",
                                        "damping", "velocity", "fixed", "driven", "initial",
                                        "plasticity", "self_collision", "fibers", "activation", NULL};
  PIOLA_TRY(check_keys(p, obj, allowed));
  PIOLA_TRY(required(p, obj, "mesh"));
  d->def = piola_default_solid_def();
  d->scale = (piola_vec3){1, 1, 1};
  snprintf(d->name, sizeof d->name, "solid%d", index);
  PIOLA_TRY(parse_name(p, obj, d));
  const cJSON *v = get(obj, "mesh");
  size_t old = push_key(p, "mesh");
  if (cJSON_IsObject(v)) {
    d->mesh_generated = 1;
    PIOLA_TRY(parse_generator(p, v, &d->mesher));
  } else {
    if (!cJSON_IsString(v))
      return fail(p, PIOLA_ERROR_PARSE, "must be a file path or a generator object, got %s", type_name(v));
    PIOLA_TRY(resolve_path(p, v, d->mesh_path));
  }
  pop(p, old);
  if ((v = get(obj, "transform"))) PIOLA_TRY(parse_transform(p, v, d));
  PIOLA_TRY(opt_number(p, obj, "density", POSITIVE, &d->def.density));
  if ((v = get(obj, "material"))) {
    old = push_key(p, "material");
    PIOLA_TRY(parse_material(p, v, d));
    pop(p, old);
  }
  if ((v = get(obj, "damping"))) {
    old = push_key(p, "damping");
    static const char *const keys[] = {"shear", "bulk", NULL};
    PIOLA_TRY(check_keys(p, v, keys));
    PIOLA_TRY(opt_track(p, v, "shear", NONNEGATIVE, &d->def.shear_viscosity));
    PIOLA_TRY(opt_track(p, v, "bulk", NONNEGATIVE, &d->def.bulk_viscosity));
    pop(p, old);
  }
  PIOLA_TRY(opt_vec3(p, obj, "velocity", ANY, &d->def.velocity));
  PIOLA_TRY(parse_self_collision(p, obj, &d->def.self_collision));
  if ((v = get(obj, "plasticity"))) {
    old = push_key(p, "plasticity");
    PIOLA_TRY(parse_plasticity(p, v, d));
    pop(p, old);
  }
  PIOLA_TRY(parse_constraints(p, obj, "fixed", 0, d));
  d->fixed_count = d->constraint_count;
  PIOLA_TRY(parse_constraints(p, obj, "driven", 1, d));
  if ((v = get(obj, "fibers"))) {
    old = push_key(p, "fibers");
    if (d->def.material.model != PIOLA_MODEL_MUSCLE)
      return fail(p, BAD_VALUE, "needs material.model \"muscle\"");
    if (d->plastic) return fail(p, BAD_VALUE, "cannot be combined with plasticity (not supported)");
    PIOLA_TRY(parse_fibers(p, v, &d->fibers));
    pop(p, old);
  }
  if ((v = get(obj, "activation"))) {
    old = push_key(p, "activation");
    if (d->def.material.model != PIOLA_MODEL_MUSCLE)
      return fail(p, BAD_VALUE, "needs material.model \"muscle\"");
    PIOLA_TRY(track_value(p, v, (range){0, 1, 0, 0}, &d->def.activation));
    pop(p, old);
  }
  if ((v = get(obj, "initial"))) {
    old = push_key(p, "initial");
    static const char *const keys[] = {"matrix", "scramble", "seed", NULL};
    PIOLA_TRY(check_keys(p, v, keys));
    const cJSON *mat = get(v, "matrix");
    if (mat) {
      size_t o2 = push_key(p, "matrix");
      if (!cJSON_IsArray(mat) || cJSON_GetArraySize(mat) != 3)
        return fail(p, PIOLA_ERROR_PARSE, "must be a 3x3 matrix given as 3 rows of 3 numbers");
      int r = 0;
      for (const cJSON *row = mat->child; row; row = row->next, ++r) {
        size_t o3 = push_index(p, r);
        piola_vec3 rv;
        PIOLA_TRY(vec3_value(p, row, ANY, &rv));
        d->def.initial_matrix.m[r][0] = rv.x;
        d->def.initial_matrix.m[r][1] = rv.y;
        d->def.initial_matrix.m[r][2] = rv.z;
        pop(p, o3);
      }
      pop(p, o2);
    }
    PIOLA_TRY(opt_number(p, v, "scramble", NONNEGATIVE, &d->def.scramble_radius));
    int64_t seed = 1;
    PIOLA_TRY(opt_int(p, v, "seed", 0, 9007199254740991.0, &seed));
    d->def.scramble_seed = (uint64_t)seed;
    pop(p, old);
  }
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ obstacles */

/* An obstacle, or the obstacle part of a bone: extra_keys (NULL-terminated, or NULL) are
 * also allowed and left to the caller. */
static piola_status parse_obstacle(parser *p, const cJSON *obj, const char *const *extra_keys,
                                   scene_obstacle_desc *d) {
  static const char *const names[] = {"plane", "sphere", "box", "cylinder", "capsule", "torus",
                                      "gear", "mesh", NULL};
  static const char *const keysets[][10] = {
      {"type", "point", "normal", "friction", "motion", NULL},
      {"type", "center", "radius", "friction", "motion", NULL},
      {"type", "center", "half_extents", "friction", "motion", NULL},
      {"type", "center", "axis", "radius", "half_length", "friction", "motion", NULL},
      {"type", "center", "axis", "radius", "half_length", "friction", "motion", NULL},
      {"type", "center", "axis", "radius", "minor_radius", "friction", "motion", NULL},
      {"type", "center", "axis", "radius", "half_length", "teeth", "tooth_depth", "friction", "motion", NULL},
      {"type", "path", "friction", "motion", NULL},
  };
  static const char *const required_keys[][4] = {
      {"point", "normal", NULL},          {"radius", NULL},
      {"half_extents", NULL},             {"radius", "half_length", NULL},
      {"radius", "half_length", NULL},    {"radius", "minor_radius", NULL},
      {"radius", "half_length", "teeth", NULL}, {"path", NULL},
  };
  if (!cJSON_IsObject(obj)) return fail(p, PIOLA_ERROR_PARSE, "must be an object, got %s", type_name(obj));
  PIOLA_TRY(required(p, obj, "type"));
  const cJSON *t = get(obj, "type");
  size_t old = push_key(p, "type");
  int found = -1;
  if (cJSON_IsString(t))
    for (int i = 0; names[i]; ++i)
      if (strcmp(t->valuestring, names[i]) == 0) found = i;
  if (found < 0)
    return fail(p, BAD_VALUE,
                "must be one of \"plane\", \"sphere\", \"box\", \"cylinder\", \"capsule\", \"torus\", "
                "\"gear\", \"mesh\"");
  pop(p, old);
  const char *allowed[16];
  int nallowed = 0;
  for (int i = 0; keysets[found][i]; ++i) allowed[nallowed++] = keysets[found][i];
  for (int i = 0; extra_keys && extra_keys[i] && nallowed < 15; ++i) allowed[nallowed++] = extra_keys[i];
  allowed[nallowed] = NULL;
  PIOLA_TRY(check_keys(p, obj, allowed));
  for (int i = 0; required_keys[found][i]; ++i) PIOLA_TRY(required(p, obj, required_keys[found][i]));
  piola_obstacle_def *o = &d->def;
  *o = piola_default_obstacle_def();
  o->type = (piola_obstacle_type)(PIOLA_OBSTACLE_PLANE + found);
  o->axis = (piola_vec3){0, 0, 1};
  if (o->type == PIOLA_OBSTACLE_PLANE) {
    PIOLA_TRY(opt_vec3(p, obj, "point", ANY, &o->center));
    PIOLA_TRY(opt_direction(p, obj, "normal", &o->axis));
  } else {
    PIOLA_TRY(opt_vec3(p, obj, "center", ANY, &o->center));
    PIOLA_TRY(opt_direction(p, obj, "axis", &o->axis));
  }
  PIOLA_TRY(opt_number(p, obj, "radius", POSITIVE, &o->radius));
  PIOLA_TRY(opt_number(p, obj, "minor_radius", POSITIVE, &o->minor_radius));
  PIOLA_TRY(opt_number(p, obj, "half_length", POSITIVE, &o->half_length));
  PIOLA_TRY(opt_vec3(p, obj, "half_extents", POSITIVE, &o->half_extents));
  int64_t teeth = 0;
  PIOLA_TRY(opt_int(p, obj, "teeth", 3, 10000, &teeth));
  o->tooth_count = (int)teeth;
  if (o->type == PIOLA_OBSTACLE_GEAR) o->tooth_depth = 0.2 * o->radius;
  PIOLA_TRY(opt_number(p, obj, "tooth_depth", POSITIVE, &o->tooth_depth));
  if (o->type == PIOLA_OBSTACLE_GEAR && !(o->tooth_depth < o->radius)) {
    push_key(p, "tooth_depth");
    return fail(p, BAD_VALUE, "must be smaller than radius (%g m), got %g", o->radius, o->tooth_depth);
  }
  if (o->type == PIOLA_OBSTACLE_TORUS && !(o->minor_radius < o->radius)) {
    push_key(p, "minor_radius");
    return fail(p, BAD_VALUE, "must be smaller than radius (%g m), got %g", o->radius, o->minor_radius);
  }
  PIOLA_TRY(opt_number(p, obj, "friction", NONNEGATIVE, &o->friction));
  if (o->type == PIOLA_OBSTACLE_MESH) {
    old = push_key(p, "path");
    PIOLA_TRY(resolve_path(p, get(obj, "path"), d->mesh_path));
    pop(p, old);
  }
  const cJSON *mo = get(obj, "motion");
  if (mo) {
    old = push_key(p, "motion");
    /* A cylinder, capsule, torus or gear spins about its own axis unless told otherwise: a
     * gear with axis y turning about the global default z would swing through the scene
     * like a revolving door (the gears example once did exactly that). */
    int axial = o->type == PIOLA_OBSTACLE_CYLINDER || o->type == PIOLA_OBSTACLE_CAPSULE ||
                o->type == PIOLA_OBSTACLE_TORUS || o->type == PIOLA_OBSTACLE_GEAR;
    piola_vec3 default_axis = axial ? o->axis : (piola_vec3){0, 0, 1};
    PIOLA_TRY(parse_motion(p, mo, o->center, default_axis, &o->motion));
    pop(p, old);
  } else {
    o->motion = piola_default_rigid_motion_def();
    o->motion.pivot = o->center;
  }
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ shells */

/* A shell's mesh: a triangle surface file, or {"generate": "rectangle", "size": [w, h],
 * "resolution": [nx, ny]} / {"generate": "disk", "radius": r, "rings": n} in the z = 0
 * plane centred at the origin, or {"generate": "torus", "radius": R, "minor_radius": r,
 * "segments": [around, tube], "sweep_degrees": s} around the z axis, before the transform. */
static piola_status parse_shell_mesh(parser *p, const cJSON *v, scene_shell_desc *d) {
  size_t old = push_key(p, "mesh");
  if (cJSON_IsString(v)) {
    PIOLA_TRY(resolve_path(p, v, d->base.mesh_path));
    pop(p, old);
    return PIOLA_OK;
  }
  if (!cJSON_IsObject(v))
    return fail(p, PIOLA_ERROR_PARSE, "must be a triangle mesh file path or a generator object, got %s",
                type_name(v));
  const cJSON *g = get(v, "generate");
  if (cJSON_IsString(g) && strcmp(g->valuestring, "rectangle") == 0) {
    static const char *const keys[] = {"generate", "size", "resolution", NULL};
    PIOLA_TRY(check_keys(p, v, keys));
    PIOLA_TRY(required(p, v, "size"));
    PIOLA_TRY(required(p, v, "resolution"));
    d->generator = 1;
    const cJSON *size = get(v, "size"), *res = get(v, "resolution");
    size_t o2 = push_key(p, "size");
    if (!cJSON_IsArray(size) || cJSON_GetArraySize(size) != 2)
      return fail(p, PIOLA_ERROR_PARSE, "must be [width, height] in m");
    PIOLA_TRY(number_value(p, size->child, POSITIVE, &d->size[0]));
    PIOLA_TRY(number_value(p, size->child->next, POSITIVE, &d->size[1]));
    pop(p, o2);
    o2 = push_key(p, "resolution");
    if (!cJSON_IsArray(res) || cJSON_GetArraySize(res) != 2)
      return fail(p, PIOLA_ERROR_PARSE, "must be [cells along width, cells along height]");
    int k = 0;
    for (const cJSON *e = res->child; e; e = e->next, ++k) {
      if (!cJSON_IsNumber(e) || e->valuedouble != floor(e->valuedouble) || e->valuedouble < 1 ||
          e->valuedouble > 100000)
        return fail(p, BAD_VALUE, "must be two integers in 1..100000");
      d->resolution[k] = (int32_t)e->valuedouble;
    }
    pop(p, o2);
  } else if (cJSON_IsString(g) && strcmp(g->valuestring, "disk") == 0) {
    static const char *const keys[] = {"generate", "radius", "rings", NULL};
    PIOLA_TRY(check_keys(p, v, keys));
    PIOLA_TRY(required(p, v, "radius"));
    PIOLA_TRY(required(p, v, "rings"));
    d->generator = 2;
    PIOLA_TRY(opt_number(p, v, "radius", POSITIVE, &d->radius));
    int64_t rings = 1;
    PIOLA_TRY(opt_int(p, v, "rings", 1, 20000, &rings));
    d->resolution[0] = (int32_t)rings;
  } else if (cJSON_IsString(g) && strcmp(g->valuestring, "torus") == 0) {
    static const char *const keys[] = {"generate", "radius", "minor_radius", "segments",
                                       "sweep_degrees", NULL};
    PIOLA_TRY(check_keys(p, v, keys));
    PIOLA_TRY(required(p, v, "radius"));
    PIOLA_TRY(required(p, v, "minor_radius"));
    PIOLA_TRY(required(p, v, "segments"));
    d->generator = 3;
    d->sweep_degrees = 360;
    PIOLA_TRY(opt_number(p, v, "radius", POSITIVE, &d->radius));
    PIOLA_TRY(opt_number(p, v, "minor_radius", POSITIVE, &d->minor_radius));
    PIOLA_TRY(opt_number(p, v, "sweep_degrees", (range){0, 360, 1, 0}, &d->sweep_degrees));
    if (!(d->minor_radius < d->radius)) {
      push_key(p, "minor_radius");
      return fail(p, BAD_VALUE, "must be smaller than radius (%g m), got %g", d->radius, d->minor_radius);
    }
    const cJSON *seg = get(v, "segments");
    size_t o2 = push_key(p, "segments");
    if (!cJSON_IsArray(seg) || cJSON_GetArraySize(seg) != 2)
      return fail(p, PIOLA_ERROR_PARSE, "must be [segments around the ring, segments around the tube]");
    int k = 0;
    for (const cJSON *e = seg->child; e; e = e->next, ++k) {
      if (!cJSON_IsNumber(e) || e->valuedouble != floor(e->valuedouble) || e->valuedouble < 3 ||
          e->valuedouble > 100000)
        return fail(p, BAD_VALUE, "must be two integers in 3..100000");
      d->resolution[k] = (int32_t)e->valuedouble;
    }
    pop(p, o2);
  } else {
    push_key(p, "generate");
    return fail(p, BAD_VALUE, "must be \"rectangle\", \"disk\" or \"torus\"");
  }
  pop(p, old);
  return PIOLA_OK;
}

static piola_status parse_shell(parser *p, const cJSON *obj, int index, scene_shell_desc *d) {
  static const char *const allowed[] = {"name", "mesh", "transform", "thickness", "density",
                                        "material", "damping", "bending", "plasticity",
                                        "reference_normals", "velocity", "fixed", "driven",
                                        "collide_with_solids", "solid_friction",
                                        "self_collision", NULL};
  PIOLA_TRY(check_keys(p, obj, allowed));
  PIOLA_TRY(required(p, obj, "mesh"));
  d->def = piola_default_shell_def();
  d->base.def = piola_default_solid_def();
  d->base.def.density = d->def.density;
  d->base.scale = (piola_vec3){1, 1, 1};
  snprintf(d->base.name, sizeof d->base.name, "shell%d", index);
  PIOLA_TRY(parse_name(p, obj, &d->base));
  PIOLA_TRY(parse_shell_mesh(p, get(obj, "mesh"), d));
  const cJSON *v;
  if ((v = get(obj, "transform"))) PIOLA_TRY(parse_transform(p, v, &d->base));
  PIOLA_TRY(opt_number(p, obj, "thickness", POSITIVE, &d->def.thickness));
  PIOLA_TRY(opt_number(p, obj, "density", POSITIVE, &d->base.def.density));
  if ((v = get(obj, "material"))) {
    size_t old = push_key(p, "material");
    PIOLA_TRY(parse_material(p, v, &d->base));
    if (d->base.def.material.model == PIOLA_MODEL_MUSCLE) {
      push_key(p, "model");
      return fail(p, BAD_VALUE, "\"muscle\" is for solids only (shells have no fibres)");
    }
    pop(p, old);
  }
  if ((v = get(obj, "damping"))) {
    size_t old = push_key(p, "damping");
    static const char *const keys[] = {"shear", "bulk", NULL};
    PIOLA_TRY(check_keys(p, v, keys));
    PIOLA_TRY(opt_track(p, v, "shear", NONNEGATIVE, &d->base.def.shear_viscosity));
    PIOLA_TRY(opt_track(p, v, "bulk", NONNEGATIVE, &d->base.def.bulk_viscosity));
    pop(p, old);
  }
  if ((v = get(obj, "bending"))) {
    size_t old = push_key(p, "bending");
    static const char *const keys[] = {"stiffness", "damping", "plasticity", NULL};
    PIOLA_TRY(check_keys(p, v, keys));
    PIOLA_TRY(opt_number(p, v, "stiffness", NONNEGATIVE, &d->def.bending.stiffness));
    PIOLA_TRY(opt_number(p, v, "damping", NONNEGATIVE, &d->def.bending.damping));
    const cJSON *pl = get(v, "plasticity");
    if (pl) {
      size_t o2 = push_key(p, "plasticity");
      static const char *const pkeys[] = {"yield_angle_degrees", "rate", NULL};
      PIOLA_TRY(check_keys(p, pl, pkeys));
      PIOLA_TRY(required(p, pl, "yield_angle_degrees"));
      double degrees = 0;
      PIOLA_TRY(opt_number(p, pl, "yield_angle_degrees", (range){0, 180, 0, 0}, &degrees));
      d->def.bending.yield_angle = degrees * M_PI / 180.0;
      PIOLA_TRY(opt_number(p, pl, "rate", POSITIVE, &d->def.bending.plastic_rate));
      pop(p, o2);
    }
    pop(p, old);
  }
  if ((v = get(obj, "plasticity"))) {
    size_t old = push_key(p, "plasticity");
    static const char *const keys[] = {"yield_strain", "rate", "max_plastic_stretch", NULL};
    PIOLA_TRY(check_keys(p, v, keys));
    PIOLA_TRY(required(p, v, "yield_strain"));
    PIOLA_TRY(opt_number(p, v, "yield_strain", NONNEGATIVE, &d->def.plasticity.yield_strain));
    PIOLA_TRY(opt_number(p, v, "rate", POSITIVE, &d->def.plasticity.rate));
    PIOLA_TRY(opt_number(p, v, "max_plastic_stretch", (range){1, INFINITY, 1, 0},
                         &d->def.plasticity.max_plastic_stretch));
    pop(p, old);
  }
  if ((v = get(obj, "reference_normals"))) {
    size_t old = push_key(p, "reference_normals");
    if (!cJSON_IsBool(v)) return fail(p, PIOLA_ERROR_PARSE, "must be true or false, got %s", type_name(v));
    d->def.use_reference_normals = cJSON_IsTrue(v);
    pop(p, old);
  }
  if ((v = get(obj, "collide_with_solids"))) {
    size_t old = push_key(p, "collide_with_solids");
    if (!cJSON_IsBool(v)) return fail(p, PIOLA_ERROR_PARSE, "must be true or false, got %s", type_name(v));
    d->def.collide_with_solids = cJSON_IsTrue(v);
    pop(p, old);
  }
  PIOLA_TRY(opt_number(p, obj, "solid_friction", NONNEGATIVE, &d->def.solid_friction));
  PIOLA_TRY(parse_self_collision(p, obj, &d->def.self_collision));
  PIOLA_TRY(opt_vec3(p, obj, "velocity", ANY, &d->base.def.velocity));
  PIOLA_TRY(parse_constraints(p, obj, "fixed", 0, &d->base));
  PIOLA_TRY(parse_constraints(p, obj, "driven", 1, &d->base));
  return PIOLA_OK;
}

static piola_status parse_shells(parser *p, const cJSON *v, scene_desc *out) {
  size_t old = push_key(p, "shells");
  if (!cJSON_IsArray(v)) return fail(p, PIOLA_ERROR_PARSE, "must be an array of shells");
  int count = cJSON_GetArraySize(v);
  out->shells = calloc((size_t)(count > 0 ? count : 1), sizeof *out->shells);
  if (!out->shells) return fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  int i = 0;
  for (const cJSON *e = v->child; e; e = e->next, ++i) {
    size_t o2 = push_index(p, i);
    out->shell_count = i + 1;
    PIOLA_TRY(parse_shell(p, e, i, &out->shells[i]));
    for (int j = 0; j < i; ++j)
      if (strcmp(out->shells[j].base.name, out->shells[i].base.name) == 0) {
        push_key(p, "name");
        return fail(p, BAD_VALUE, "\"%s\" is already the name of shells[%d]",
                    out->shells[i].base.name, j);
      }
    pop(p, o2);
  }
  pop(p, old);
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ bones */

/* {"solid": NAME, one of box | sphere | indices | within}: which nodes of a solid the bone
 * carries (docs/bones.md). Solids are parsed before bones, so the name resolves here. */
static piola_status parse_attachment(parser *p, const cJSON *obj, const scene_desc *scene,
                                     piola_attachment_def *out, int32_t **indices_out) {
  static const char *const keys[] = {"solid", "box", "sphere", "indices", "within", NULL};
  PIOLA_TRY(check_keys(p, obj, keys));
  PIOLA_TRY(required(p, obj, "solid"));
  *out = piola_default_attachment_def();
  const cJSON *v = get(obj, "solid");
  size_t old = push_key(p, "solid");
  if (!cJSON_IsString(v)) return fail(p, PIOLA_ERROR_PARSE, "must be the name of a solid, got %s", type_name(v));
  out->solid = -1;
  for (int32_t i = 0; i < scene->solid_count; ++i)
    if (strcmp(scene->solids[i].name, v->valuestring) == 0) out->solid = i;
  if (out->solid < 0) {
    for (int32_t i = 0; i < scene->shell_count; ++i)
      if (strcmp(scene->shells[i].base.name, v->valuestring) == 0)
        return fail(p, BAD_VALUE, "\"%s\" is a shell: bones attach to solids only", v->valuestring);
    char list[256] = "";
    for (int32_t i = 0; i < scene->solid_count; ++i) {
      if (i) strncat(list, ", ", sizeof list - strlen(list) - 1);
      strncat(list, scene->solids[i].name, sizeof list - strlen(list) - 1);
    }
    return fail(p, BAD_VALUE, "no solid is named \"%s\" (solids: %s)", v->valuestring,
                scene->solid_count ? list : "none");
  }
  pop(p, old);
  int kinds = !!get(obj, "box") + !!get(obj, "sphere") + !!get(obj, "indices") + !!get(obj, "within");
  if (kinds != 1) return fail(p, PIOLA_ERROR_PARSE, "needs exactly one of box, sphere, indices or within");
  if (get(obj, "within")) {
    out->near_surface = true;
    return opt_number(p, obj, "within", NONNEGATIVE, &out->distance);
  }
  /* the selector keys are those of `fixed`: parse a copy without "solid" */
  cJSON *copy = cJSON_Duplicate(obj, 1);
  if (!copy) return fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  cJSON_DeleteItemFromObjectCaseSensitive(copy, "solid");
  piola_constraint_def con;
  piola_status st = parse_selector(p, copy, 0, &con, indices_out);
  cJSON_Delete(copy);
  if (st == PIOLA_OK) out->selector = con.selector;
  return st;
}

static piola_status parse_bone(parser *p, const cJSON *obj, int index, const scene_desc *scene,
                               scene_bone_desc *d) {
  static const char *const extra[] = {"name", "attachments", NULL};
  snprintf(d->name, sizeof d->name, "bone%d", index);
  PIOLA_TRY(parse_obstacle(p, obj, extra, &d->obstacle));
  const cJSON *v = get(obj, "name");
  if (v) {
    size_t old = push_key(p, "name");
    if (!cJSON_IsString(v) || !v->valuestring[0] || strlen(v->valuestring) >= sizeof d->name)
      return fail(p, PIOLA_ERROR_PARSE, "must be a non-empty string of at most %d characters",
                  (int)sizeof d->name - 1);
    snprintf(d->name, sizeof d->name, "%s", v->valuestring);
    pop(p, old);
  }
  const cJSON *list = get(obj, "attachments");
  if (!list) return PIOLA_OK;
  size_t old = push_key(p, "attachments");
  if (!cJSON_IsArray(list)) return fail(p, PIOLA_ERROR_PARSE, "must be an array of attachments");
  int count = cJSON_GetArraySize(list);
  d->attachments = calloc((size_t)(count > 0 ? count : 1), sizeof *d->attachments);
  d->index_lists = calloc((size_t)(count > 0 ? count : 1), sizeof *d->index_lists);
  if (!d->attachments || !d->index_lists) return fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  int i = 0;
  for (const cJSON *e = list->child; e; e = e->next, ++i) {
    size_t o2 = push_index(p, i);
    d->attachment_count = i + 1;
    PIOLA_TRY(parse_attachment(p, e, scene, &d->attachments[i], &d->index_lists[i]));
    pop(p, o2);
  }
  pop(p, old);
  return PIOLA_OK;
}

static piola_status parse_bones(parser *p, const cJSON *v, scene_desc *out) {
  size_t old = push_key(p, "bones");
  if (!cJSON_IsArray(v)) return fail(p, PIOLA_ERROR_PARSE, "must be an array of bones");
  int count = cJSON_GetArraySize(v);
  out->bones = calloc((size_t)(count > 0 ? count : 1), sizeof *out->bones);
  if (!out->bones) return fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  int i = 0;
  for (const cJSON *e = v->child; e; e = e->next, ++i) {
    size_t o2 = push_index(p, i);
    out->bone_count = i + 1;
    PIOLA_TRY(parse_bone(p, e, i, out, &out->bones[i]));
    for (int j = 0; j < i; ++j)
      if (strcmp(out->bones[j].name, out->bones[i].name) == 0) {
        push_key(p, "name");
        return fail(p, BAD_VALUE, "\"%s\" is already the name of bones[%d]", out->bones[i].name, j);
      }
    pop(p, o2);
  }
  pop(p, old);
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ top level */

static piola_status parse_top(parser *p, const cJSON *root, scene_desc *out) {
  static const char *const allowed[] = {"description", "fps", "frames", "gravity", "integrator",
                                        "solids", "obstacles", "shells", "bones", NULL};
  PIOLA_TRY(check_keys(p, root, allowed));
  const cJSON *v;
  if ((v = get(root, "description")) && !cJSON_IsString(v)) {
    push_key(p, "description");
    return fail(p, PIOLA_ERROR_PARSE, "must be a string, got %s", type_name(v));
  }
  PIOLA_TRY(opt_number(p, root, "fps", (range){0, 10000, 1, 0}, &out->fps));
  int64_t frames = out->frames;
  PIOLA_TRY(opt_int(p, root, "frames", 0, 1000000, &frames));
  out->frames = (int32_t)frames;
  PIOLA_TRY(opt_vec3_tracks(p, root, "gravity", out->world.gravity));
  if ((v = get(root, "integrator"))) {
    size_t old = push_key(p, "integrator");
    static const char *const keys[] = {"max_dt", "cfl", "cg_tolerance", "cg_max_iterations",
                                       "collision_interval", NULL};
    PIOLA_TRY(check_keys(p, v, keys));
    PIOLA_TRY(opt_number(p, v, "max_dt", (range){0, 1, 1, 0}, &out->world.max_dt));
    PIOLA_TRY(opt_number(p, v, "cfl", (range){0, 2, 1, 0}, &out->world.cfl));
    PIOLA_TRY(opt_number(p, v, "cg_tolerance", (range){0, 1, 1, 1}, &out->world.cg_tolerance));
    int64_t it = out->world.cg_max_iterations;
    PIOLA_TRY(opt_int(p, v, "cg_max_iterations", 1, 1000000, &it));
    out->world.cg_max_iterations = (int32_t)it;
    PIOLA_TRY(opt_number(p, v, "collision_interval", (range){0, 1, 0, 0},
                         &out->world.collision_interval));
    pop(p, old);
  }
  /* a scene needs something to simulate: solids, or shells */
  const cJSON *shells = get(root, "shells");
  if (shells)
    PIOLA_TRY(parse_shells(p, shells, out));
  else
    PIOLA_TRY(required(p, root, "solids"));
  v = get(root, "solids");
  size_t old = push_key(p, "solids");
  if (v && (!cJSON_IsArray(v) || cJSON_GetArraySize(v) < 1))
    return fail(p, PIOLA_ERROR_PARSE, "must be a non-empty array of solids");
  int count = v ? cJSON_GetArraySize(v) : 0;
  out->solids = calloc((size_t)(count > 0 ? count : 1), sizeof *out->solids);
  if (!out->solids) return fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  int i = 0;
  for (const cJSON *e = v ? v->child : NULL; e; e = e->next, ++i) {
    size_t o2 = push_index(p, i);
    out->solid_count = i + 1;
    PIOLA_TRY(parse_solid(p, e, i, &out->solids[i]));
    for (int j = 0; j < i; ++j)
      if (strcmp(out->solids[j].name, out->solids[i].name) == 0) {
        push_key(p, "name");
        return fail(p, BAD_VALUE, "\"%s\" is already the name of solids[%d]", out->solids[i].name, j);
      }
    pop(p, o2);
  }
  pop(p, old);
  if ((v = get(root, "obstacles"))) {
    old = push_key(p, "obstacles");
    if (!cJSON_IsArray(v)) return fail(p, PIOLA_ERROR_PARSE, "must be an array of obstacles");
    count = cJSON_GetArraySize(v);
    out->obstacles = calloc((size_t)(count > 0 ? count : 1), sizeof *out->obstacles);
    if (!out->obstacles) return fail(p, PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
    i = 0;
    for (const cJSON *e = v->child; e; e = e->next, ++i) {
      size_t o2 = push_index(p, i);
      out->obstacle_count = i + 1;
      static const char *const extra[] = {"name", NULL};
      scene_obstacle_desc *d = &out->obstacles[i];
      PIOLA_TRY(parse_obstacle(p, e, extra, d));
      snprintf(d->name, sizeof d->name, "obstacle%d", i);
      const cJSON *name = get(e, "name");
      if (name) {
        size_t o3 = push_key(p, "name");
        if (!cJSON_IsString(name) || !name->valuestring[0] ||
            strlen(name->valuestring) >= sizeof d->name)
          return fail(p, PIOLA_ERROR_PARSE, "must be a non-empty string of at most %d characters",
                      (int)sizeof d->name - 1);
        snprintf(d->name, sizeof d->name, "%s", name->valuestring);
        for (int j = 0; j < i; ++j)
          if (strcmp(out->obstacles[j].name, d->name) == 0)
            return fail(p, BAD_VALUE, "\"%s\" is already the name of obstacles[%d]", d->name, j);
        pop(p, o3);
      }
      pop(p, o2);
    }
    pop(p, old);
  }
  if ((v = get(root, "bones"))) PIOLA_TRY(parse_bones(p, v, out));
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
  parser p = {label ? label : "scene", base_dir, "", 0};
  if (!json) return fail(&p, PIOLA_ERROR_INVALID_ARGUMENT, "no text");
  const char *end = NULL;
  cJSON *root = cJSON_ParseWithOpts(json, &end, 1);
  if (!root) {
    int line = 1, col = 1;
    const char *at = end ? end : json;
    for (const char *c = json; c < at && *c; ++c) {
      if (*c == '\n') ++line, col = 1;
      else ++col;
    }
    return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: line %d, column %d: invalid JSON", p.label, line, col);
  }
  piola_status st = parse_top(&p, root, out);
  cJSON_Delete(root);
  if (st != PIOLA_OK) piola__scene_desc_free(out);
  return st;
}
