/* The scene parser's JSON walker (scene_json.h): key paths and typed readers. */
#include "scene/scene_json.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/number_text.h"
#include "math/mat3.h"
#include "scene/scene_desc.h"

size_t piola__json_push_key(scene_parser *p, const char *key) {
  size_t old = p->len;
  int n = snprintf(p->path + p->len, sizeof p->path - p->len, "%s%s", p->len ? "." : "", key);
  if (n > 0) p->len = strlen(p->path);
  return old;
}

size_t piola__json_push_index(scene_parser *p, int i) {
  size_t old = p->len;
  int n = snprintf(p->path + p->len, sizeof p->path - p->len, "[%d]", i);
  if (n > 0) p->len = strlen(p->path);
  return old;
}

void piola__json_pop(scene_parser *p, size_t old) {
  p->len = old;
  p->path[old] = '\0';
}

piola_status piola__json_fail(scene_parser *p, piola_status status, const char *format, ...) {
  char msg[512];
  va_list ap;
  va_start(ap, format);
  vsnprintf(msg, sizeof msg, format, ap);
  va_end(ap);
  return PIOLA_FAIL(status, "%s: %s: %s", p->label, p->len ? p->path : "(top level)", msg);
}

const char *piola__json_type_name(const cJSON *v) {
  if (cJSON_IsNumber(v)) return "a number";
  if (cJSON_IsString(v)) return "a string";
  if (cJSON_IsBool(v)) return "a boolean";
  if (cJSON_IsNull(v)) return "null";
  if (cJSON_IsArray(v)) return "an array";
  if (cJSON_IsObject(v)) return "an object";
  return "invalid";
}

piola_status piola__json_check_keys(scene_parser *p, const cJSON *obj, const char *const *allowed) {
  if (!cJSON_IsObject(obj))
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an object, got %s",
                            piola__json_type_name(obj));
  for (const cJSON *c = obj->child; c; c = c->next) {
    int ok = 0;
    for (const char *const *a = allowed; *a; ++a)
      if (strcmp(*a, c->string) == 0) ok = 1;
    size_t old = piola__json_push_key(p, c->string);
    if (!ok) {
      char list[512] = "";
      for (const char *const *a = allowed; *a; ++a) {
        strncat(list, *a, sizeof list - strlen(list) - 1);
        if (a[1]) strncat(list, ", ", sizeof list - strlen(list) - 1);
      }
      return piola__json_fail(p, PIOLA_ERROR_PARSE, "unknown key (allowed here: %s)", list);
    }
    for (const cJSON *d = obj->child; d != c; d = d->next)
      if (strcmp(d->string, c->string) == 0)
        return piola__json_fail(p, PIOLA_ERROR_PARSE, "duplicate key");
    piola__json_pop(p, old);
  }
  return PIOLA_OK;
}

const cJSON *piola__json_get(const cJSON *obj, const char *key) {
  return cJSON_GetObjectItemCaseSensitive(obj, key);
}

piola_status piola__json_check_range(scene_parser *p, double v, json_range r) {
  if (!isfinite(v)) return piola__json_fail(p, BAD_VALUE, "must be finite, got %g", v);
  int ok = (r.lo_open ? v > r.lo : v >= r.lo) && (r.hi_open ? v < r.hi : v <= r.hi);
  if (ok) return PIOLA_OK;
  char lo[32], hi[32], got[32];
  if (isinf(r.hi) && isfinite(r.lo))
    return piola__json_fail(p, BAD_VALUE, "must be %s %s, got %s",
                            r.lo_open ? ">" : ">=", piola__number_text(lo, r.lo),
                            piola__number_text(got, v));
  return piola__json_fail(p, BAD_VALUE, "must be in %c%s, %s%c, got %s", r.lo_open ? '(' : '[',
                          piola__number_text(lo, r.lo), piola__number_text(hi, r.hi),
                          r.hi_open ? ')' : ']', piola__number_text(got, v));
}

piola_status piola__json_number(scene_parser *p, const cJSON *v, json_range r, double *out) {
  if (cJSON_IsObject(v) && piola__json_get(v, "keys"))
    return piola__json_fail(
        p, PIOLA_ERROR_PARSE,
        "must be a constant number here (keyframes are not supported for this key)");
  if (!cJSON_IsNumber(v))
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be a number, got %s",
                            piola__json_type_name(v));
  PIOLA_TRY(piola__json_check_range(p, v->valuedouble, r));
  *out = v->valuedouble;
  return PIOLA_OK;
}

/* The optional readers (piola__json_opt_*): obj.key read by the plain reader when present,
 * with the key on the error path; when absent *out keeps its default. optional() gives the
 * value (NULL when absent) and pushes the key; popped() takes it off again after a read that
 * succeeded (a failure leaves the path as the message named it). */
static const cJSON *optional(scene_parser *p, const cJSON *obj, const char *key, size_t *old) {
  const cJSON *v = piola__json_get(obj, key);
  if (v) *old = piola__json_push_key(p, key);
  return v;
}

static piola_status popped(scene_parser *p, size_t old, piola_status read) {
  if (read == PIOLA_OK) piola__json_pop(p, old);
  return read;
}

piola_status piola__json_opt_number(scene_parser *p, const cJSON *obj, const char *key,
                                    json_range r, double *out) {
  size_t old = 0;
  const cJSON *v = optional(p, obj, key, &old);
  return v ? popped(p, old, piola__json_number(p, v, r, out)) : PIOLA_OK;
}

static piola_status integer(scene_parser *p, const cJSON *v, double lo, double hi, int64_t *out) {
  double d;
  PIOLA_TRY(piola__json_number(p, v, (json_range){lo, hi, 0, 0}, &d));
  if (d != floor(d)) return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an integer, got %g", d);
  *out = (int64_t)d;
  return PIOLA_OK;
}

piola_status piola__json_opt_int(scene_parser *p, const cJSON *obj, const char *key, double lo,
                                 double hi, int64_t *out) {
  size_t old = 0;
  const cJSON *v = optional(p, obj, key, &old);
  return v ? popped(p, old, integer(p, v, lo, hi, out)) : PIOLA_OK;
}

static piola_status boolean(scene_parser *p, const cJSON *v, bool *out) {
  if (!cJSON_IsBool(v))
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be true or false, got %s",
                            piola__json_type_name(v));
  *out = cJSON_IsTrue(v);
  return PIOLA_OK;
}

piola_status piola__json_opt_bool(scene_parser *p, const cJSON *obj, const char *key, bool *out) {
  size_t old = 0;
  const cJSON *v = optional(p, obj, key, &old);
  return v ? popped(p, old, boolean(p, v, out)) : PIOLA_OK;
}

/* A scalar or {"keys": [[t, v], ...]} at the current path. */
piola_status piola__json_track(scene_parser *p, const cJSON *v, json_range r, piola_track *out) {
  if (cJSON_IsNumber(v)) {
    PIOLA_TRY(piola__json_check_range(p, v->valuedouble, r));
    *out = piola_track_constant(v->valuedouble);
    return PIOLA_OK;
  }
  if (!cJSON_IsObject(v))
    return piola__json_fail(p, PIOLA_ERROR_PARSE,
                            "must be a number or {\"keys\": [[t, v], ...]}, got %s",
                            piola__json_type_name(v));
  static const char *const allowed[] = {"keys", NULL};
  PIOLA_TRY(piola__json_check_keys(p, v, allowed));
  const cJSON *keys = piola__json_get(v, "keys");
  size_t old = piola__json_push_key(p, "keys");
  if (!cJSON_IsArray(keys))
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an array of [time, value] pairs");
  int count = cJSON_GetArraySize(keys);
  if (count < 1 || count > PIOLA_MAX_KEYS)
    return piola__json_fail(p, BAD_VALUE, "must hold 1 to %d keys, got %d", PIOLA_MAX_KEYS, count);
  double times[PIOLA_MAX_KEYS], values[PIOLA_MAX_KEYS];
  int i = 0;
  for (const cJSON *k = keys->child; k; k = k->next, ++i) {
    size_t o2 = piola__json_push_index(p, i);
    if (!cJSON_IsArray(k) || cJSON_GetArraySize(k) != 2 || !cJSON_IsNumber(k->child) ||
        !cJSON_IsNumber(k->child->next))
      return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be a pair [time in s, value] of numbers");
    times[i] = k->child->valuedouble;
    values[i] = k->child->next->valuedouble;
    if (!isfinite(times[i])) return piola__json_fail(p, BAD_VALUE, "time must be finite");
    if (i > 0 && !(times[i] > times[i - 1]))
      return piola__json_fail(p, BAD_VALUE, "times must increase strictly (%g after %g)", times[i],
                              times[i - 1]);
    PIOLA_TRY(piola__json_check_range(p, values[i], r));
    piola__json_pop(p, o2);
  }
  piola__json_pop(p, old);
  if (piola_track_from_keys(times, values, count, out) != PIOLA_OK)
    return piola__json_fail(p, BAD_VALUE, "%s", piola_last_error());
  return PIOLA_OK;
}

piola_status piola__json_opt_track(scene_parser *p, const cJSON *obj, const char *key, json_range r,
                                   piola_track *out) {
  size_t old = 0;
  const cJSON *v = optional(p, obj, key, &old);
  return v ? popped(p, old, piola__json_track(p, v, r, out)) : PIOLA_OK;
}

/* v's type, and an array's length with it: "got an array" alone hides what is wrong. */
static const char *type_and_length(const cJSON *v, char *buf, size_t size) {
  if (!cJSON_IsArray(v)) return piola__json_type_name(v);
  snprintf(buf, size, "an array of %d", cJSON_GetArraySize(v));
  return buf;
}

piola_status piola__json_vec3(scene_parser *p, const cJSON *v, json_range r, piola_vec3 *out) {
  char got[32];
  if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be an array of 3 numbers, got %s",
                            type_and_length(v, got, sizeof got));
  double c[3];
  int i = 0;
  for (const cJSON *e = v->child; e; e = e->next, ++i) {
    size_t old = piola__json_push_index(p, i);
    PIOLA_TRY(piola__json_number(p, e, r, &c[i]));
    piola__json_pop(p, old);
  }
  *out = (piola_vec3){c[0], c[1], c[2]};
  return PIOLA_OK;
}

piola_status piola__json_opt_vec3(scene_parser *p, const cJSON *obj, const char *key, json_range r,
                                  piola_vec3 *out) {
  size_t old = 0;
  const cJSON *v = optional(p, obj, key, &old);
  return v ? popped(p, old, piola__json_vec3(p, v, r, out)) : PIOLA_OK;
}

static piola_status direction(scene_parser *p, const cJSON *v, piola_vec3 *out) {
  piola_vec3 d;
  PIOLA_TRY(piola__json_vec3(p, v, ANY, &d));
  double len = vec3_norm(d);
  if (!(len > 1e-300)) return piola__json_fail(p, BAD_VALUE, "must be a nonzero vector");
  *out = vec3_scale(d, 1.0 / len);
  return PIOLA_OK;
}

piola_status piola__json_opt_direction(scene_parser *p, const cJSON *obj, const char *key,
                                       piola_vec3 *out) {
  size_t old = 0;
  const cJSON *v = optional(p, obj, key, &old);
  return v ? popped(p, old, direction(p, v, out)) : PIOLA_OK;
}

static piola_status vec3_tracks(scene_parser *p, const cJSON *v, piola_track out[3]) {
  char got[32];
  if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
    return piola__json_fail(p, PIOLA_ERROR_PARSE,
                            "must be an array of 3 numbers (or keyframes), got %s",
                            type_and_length(v, got, sizeof got));
  int i = 0;
  for (const cJSON *e = v->child; e; e = e->next, ++i) {
    size_t old = piola__json_push_index(p, i);
    PIOLA_TRY(piola__json_track(p, e, ANY, &out[i]));
    piola__json_pop(p, old);
  }
  return PIOLA_OK;
}

piola_status piola__json_opt_vec3_tracks(scene_parser *p, const cJSON *obj, const char *key,
                                         piola_track out[3]) {
  size_t old = 0;
  const cJSON *v = optional(p, obj, key, &old);
  return v ? popped(p, old, vec3_tracks(p, v, out)) : PIOLA_OK;
}

piola_status piola__json_required(scene_parser *p, const cJSON *obj, const char *key) {
  if (piola__json_get(obj, key)) return PIOLA_OK;
  size_t old = piola__json_push_key(p, key);
  piola_status s = piola__json_fail(p, PIOLA_ERROR_PARSE, "is required");
  piola__json_pop(p, old);
  return s;
}

piola_status piola__json_path(scene_parser *p, const cJSON *v, char *out) {
  if (!cJSON_IsString(v) || !v->valuestring[0])
    return piola__json_fail(p, PIOLA_ERROR_PARSE, "must be a file path (string), got %s",
                            piola__json_type_name(v));
  int n;
  if (v->valuestring[0] == '/' || !p->base_dir || !p->base_dir[0])
    n = snprintf(out, SCENE_PATH_MAX, "%s", v->valuestring);
  else
    n = snprintf(out, SCENE_PATH_MAX, "%s/%s", p->base_dir, v->valuestring);
  if (n < 0 || n >= SCENE_PATH_MAX) return piola__json_fail(p, BAD_VALUE, "path is too long");
  return PIOLA_OK;
}

piola_status piola__json_mat3(scene_parser *p, const cJSON *mat, piola_mat3 *out) {
  if (!cJSON_IsArray(mat) || cJSON_GetArraySize(mat) != 3)
    return piola__json_fail(p, PIOLA_ERROR_PARSE,
                            "must be a 3x3 matrix given as 3 rows of 3 numbers");
  int r = 0;
  for (const cJSON *row = mat->child; row; row = row->next, ++r) {
    size_t old = piola__json_push_index(p, r);
    piola_vec3 rv;
    PIOLA_TRY(piola__json_vec3(p, row, ANY, &rv));
    out->m[r][0] = rv.x, out->m[r][1] = rv.y, out->m[r][2] = rv.z;
    piola__json_pop(p, old);
  }
  return PIOLA_OK;
}
