/* The scene parser's JSON walker: a key path for error messages plus typed, range-checked
 * readers of cJSON values.
 *
 * A small parser context carries the key path of the value being read ("solids[0].material")
 * so each check can say exactly where the problem is. Every object's keys are checked against
 * the list the format allows, so a misspelt key is an error rather than a silently ignored
 * setting. The section parsers (scene_parse_*.c) are built from these readers.
 *
 * Conventions: a reader named for a value (piola__json_number, piola__json_vec3, ...) reads the
 * value at the current path; piola__json_opt_* reads obj.key if present and otherwise leaves
 * *out at its default; every reader restores the path when it succeeds, and on failure the
 * path names the offending key. */
#ifndef PIOLA_SCENE_SCENE_JSON_H
#define PIOLA_SCENE_SCENE_JSON_H

#include <cjson/cJSON.h>
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "common/status_report.h"
#include "piola/keyframes.h"
#include "piola/math_types.h"

typedef struct scene_parser {
  const char *label;    /* prefixes every message (the file name) */
  const char *base_dir; /* relative paths are resolved against it */
  char path[512];       /* key path of the value being read */
  size_t len;
} scene_parser;

#define BAD_VALUE PIOLA_ERROR_INVALID_ARGUMENT

/* Range kinds for numbers. */
typedef struct json_range {
  double lo, hi;
  int lo_open, hi_open;
} json_range;
static const json_range ANY = {-INFINITY, INFINITY, 0, 0};
static const json_range POSITIVE = {0, INFINITY, 1, 0};
static const json_range NONNEGATIVE = {0, INFINITY, 0, 0};

/* The key path: push returns the old length for piola__json_pop. */
size_t piola__json_push_key(scene_parser *p, const char *key);
size_t piola__json_push_index(scene_parser *p, int i);
void piola__json_pop(scene_parser *p, size_t old);

/* Stores "label: path: message" for piola_last_error() and returns status. */
piola_status piola__json_fail(scene_parser *p, piola_status status, const char *format, ...)
    PIOLA_PRINTF_LIKE(3, 4);

/* "a number", "an object", ... for messages. */
const char *piola__json_type_name(const cJSON *v);
const cJSON *piola__json_get(const cJSON *obj, const char *key);

/* Unknown and duplicate keys of obj (allowed is NULL-terminated; the path points at obj). */
piola_status piola__json_check_keys(scene_parser *p, const cJSON *obj, const char *const *allowed);
/* An error naming obj.key unless obj has it. */
piola_status piola__json_required(scene_parser *p, const cJSON *obj, const char *key);

piola_status piola__json_check_range(scene_parser *p, double v, json_range r);
/* A plain number (keyframes not allowed). */
piola_status piola__json_number(scene_parser *p, const cJSON *v, json_range r, double *out);
piola_status piola__json_opt_number(scene_parser *p, const cJSON *obj, const char *key,
                                    json_range r, double *out);
/* An integer in [lo, hi]. */
piola_status piola__json_opt_int(scene_parser *p, const cJSON *obj, const char *key, double lo,
                                 double hi, int64_t *out);
piola_status piola__json_opt_bool(scene_parser *p, const cJSON *obj, const char *key, bool *out);
/* A scalar or {"keys": [[t, v], ...]}. */
piola_status piola__json_track(scene_parser *p, const cJSON *v, json_range r, piola_track *out);
piola_status piola__json_opt_track(scene_parser *p, const cJSON *obj, const char *key, json_range r,
                                   piola_track *out);
piola_status piola__json_vec3(scene_parser *p, const cJSON *v, json_range r, piola_vec3 *out);
piola_status piola__json_opt_vec3(scene_parser *p, const cJSON *obj, const char *key, json_range r,
                                  piola_vec3 *out);
/* A unit direction: nonzero, normalized. */
piola_status piola__json_opt_direction(scene_parser *p, const cJSON *obj, const char *key,
                                       piola_vec3 *out);
/* Three tracks (each a number or keyframes). */
piola_status piola__json_opt_vec3_tracks(scene_parser *p, const cJSON *obj, const char *key,
                                         piola_track out[3]);
/* A 3x3 matrix given as 3 rows of 3 numbers. */
piola_status piola__json_mat3(scene_parser *p, const cJSON *mat, piola_mat3 *out);
/* A file path, resolved against the scene's folder into out (SCENE_PATH_MAX bytes). */
piola_status piola__json_path(scene_parser *p, const cJSON *v, char *out);

#endif
