/* A solid's or shell's `material` key: model, elastic constants, inversion, spline and
 * muscle parameters. */
#include <stdio.h>
#include <string.h>

#include "piola/material.h"
#include "scene/scene_parse_sections.h"

/* `ogden`: {"mu": [Pa, ...], "alpha": [...]}, two arrays of the same length 1..6, nonzero
 * entries, with a positive shear modulus 1/2 sum mu_p alpha_p. */
static piola_status parse_ogden(scene_parser *p, const cJSON *obj, piola_material_def *m) {
  const cJSON *og = piola__json_get(obj, "ogden");
  if (!og) return PIOLA_OK;
  size_t old = piola__json_push_key(p, "ogden");
  if (m->model != PIOLA_MODEL_OGDEN) return piola__json_fail(p, BAD_VALUE, "needs \"model\": \"ogden\"");
  static const char *const keys[] = {"mu", "alpha", NULL};
  PIOLA_TRY(piola__json_check_keys(p, og, keys));
  PIOLA_TRY(piola__json_required(p, og, "mu"));
  PIOLA_TRY(piola__json_required(p, og, "alpha"));
  static const char *const names[2] = {"mu", "alpha"};
  int counts[2];
  for (int a = 0; a < 2; ++a) {
    const cJSON *arr = piola__json_get(og, names[a]);
    size_t o2 = piola__json_push_key(p, names[a]);
    if (!cJSON_IsArray(arr) || cJSON_GetArraySize(arr) < 1 ||
        cJSON_GetArraySize(arr) > PIOLA_OGDEN_MAX_TERMS)
      return piola__json_fail(p, BAD_VALUE, "must be an array of 1 to %d numbers", PIOLA_OGDEN_MAX_TERMS);
    counts[a] = cJSON_GetArraySize(arr);
    for (int i = 0; i < counts[a]; ++i) {
      size_t o3 = piola__json_push_index(p, i);
      double v;
      PIOLA_TRY(piola__json_number(p, cJSON_GetArrayItem(arr, i), ANY, &v));
      if (v == 0) return piola__json_fail(p, BAD_VALUE, "must be nonzero");
      (a == 0 ? m->ogden.mu : m->ogden.alpha)[i] = v;
      piola__json_pop(p, o3);
    }
    piola__json_pop(p, o2);
  }
  if (counts[0] != counts[1])
    return piola__json_fail(p, BAD_VALUE, "mu has %d terms and alpha %d: they must match", counts[0],
                            counts[1]);
  m->ogden.term_count = counts[0];
  double shear = 0;
  for (int i = 0; i < counts[0]; ++i) shear += 0.5 * m->ogden.mu[i] * m->ogden.alpha[i];
  if (!(shear > 0))
    return piola__json_fail(p, BAD_VALUE, "the shear modulus 1/2 sum mu_p alpha_p must be > 0 Pa, got %g", shear);
  piola__json_pop(p, old);
  return PIOLA_OK;
}

/* `hgo`: {"mu", "k1", "k2", "kappa", "fiber_angle_degrees", "axis", "fiber_stretch_limit"}
 * (materials.md). */
static piola_status parse_hgo(scene_parser *p, const cJSON *obj, piola_material_def *m) {
  const cJSON *h = piola__json_get(obj, "hgo");
  if (!h) return PIOLA_OK;
  size_t old = piola__json_push_key(p, "hgo");
  if (m->model != PIOLA_MODEL_HGO) return piola__json_fail(p, BAD_VALUE, "needs \"model\": \"hgo\"");
  static const char *const keys[] = {"mu", "k1", "k2", "kappa", "fiber_angle_degrees", "axis",
                                     "fiber_stretch_limit", NULL};
  PIOLA_TRY(piola__json_check_keys(p, h, keys));
  piola_hgo_def *hd = &m->hgo;
  PIOLA_TRY(piola__json_opt_number(p, h, "mu", POSITIVE, &hd->mu));
  PIOLA_TRY(piola__json_opt_number(p, h, "k1", NONNEGATIVE, &hd->k1));
  PIOLA_TRY(piola__json_opt_number(p, h, "k2", POSITIVE, &hd->k2));
  PIOLA_TRY(piola__json_opt_number(p, h, "kappa", (json_range){0, 1.0 / 3.0, 0, 0}, &hd->kappa));
  PIOLA_TRY(piola__json_opt_number(p, h, "fiber_angle_degrees", (json_range){0, 90, 0, 0},
                                   &hd->fiber_angle_degrees));
  PIOLA_TRY(piola__json_opt_number(p, h, "fiber_stretch_limit", (json_range){1, INFINITY, 1, 0},
                                   &hd->fiber_stretch_limit));
  if (piola__json_get(h, "axis")) {
    piola_vec3 a;
    PIOLA_TRY(piola__json_opt_direction(p, h, "axis", &a));
    hd->axis[0] = a.x, hd->axis[1] = a.y, hd->axis[2] = a.z;
  }
  piola__json_pop(p, old);
  return PIOLA_OK;
}

piola_status piola__scene_parse_material(scene_parser *p, const cJSON *obj, scene_solid_desc *d) {
  static const char *const allowed[] = {"model",  "youngs_modulus", "poisson_ratio",
                                        "stiffness_scale", "inversion", "spline", "muscle",
                                        "ogden", "mooney_rivlin", "hgo", NULL};
  PIOLA_TRY(piola__json_check_keys(p, obj, allowed));
  piola_material_def *m = &d->def.material;
  const cJSON *model = piola__json_get(obj, "model");
  if (model) {
    size_t old = piola__json_push_key(p, "model");
    if (!cJSON_IsString(model) || !piola_material_model_from_name(model->valuestring, &m->model)) {
      char list[256] = "";
      for (int i = 0; i < PIOLA_MODEL_COUNT; ++i) {
        size_t len = strlen(list);
        snprintf(list + len, sizeof list - len, "%s\"%s\"", i ? ", " : "",
                 piola_material_model_name((piola_material_model)i));
      }
      return piola__json_fail(p, BAD_VALUE, "must be one of %s", list);
    }
    piola__json_pop(p, old);
  }
  PIOLA_TRY(piola__json_opt_number(p, obj, "youngs_modulus", POSITIVE, &m->youngs_modulus));
  PIOLA_TRY(piola__json_opt_number(p, obj, "poisson_ratio", (json_range){-1, 0.5, 1, 1},
                                   &m->poisson_ratio));
  PIOLA_TRY(piola__json_opt_track(p, obj, "stiffness_scale", NONNEGATIVE, &d->def.stiffness_scale));
  const cJSON *inv = piola__json_get(obj, "inversion");
  if (inv) {
    size_t old = piola__json_push_key(p, "inversion");
    static const char *const keys[] = {"threshold", "mode", NULL};
    PIOLA_TRY(piola__json_check_keys(p, inv, keys));
    PIOLA_TRY(piola__json_opt_number(p, inv, "threshold", (json_range){0, 1, 1, 1},
                                     &m->inversion_threshold));
    const cJSON *mode = piola__json_get(inv, "mode");
    if (mode) {
      size_t o2 = piola__json_push_key(p, "mode");
      if (!cJSON_IsString(mode) ||
          !piola_inversion_mode_from_name(mode->valuestring, &m->inversion_mode))
        return piola__json_fail(p, BAD_VALUE,
                                "must be \"linear\", \"clamp\", \"energy\" or \"default\"");
      piola__json_pop(p, o2);
    }
    piola__json_pop(p, old);
  }
  const cJSON *sp = piola__json_get(obj, "spline");
  if (sp) {
    size_t old = piola__json_push_key(p, "spline");
    if (m->model != PIOLA_MODEL_SPLINE)
      return piola__json_fail(p, BAD_VALUE, "needs \"model\": \"spline\"");
    static const char *const keys[] = {"compression_stretch", "elongation_stretch", "stiffening",
                                       NULL};
    PIOLA_TRY(piola__json_check_keys(p, sp, keys));
    PIOLA_TRY(piola__json_opt_number(p, sp, "compression_stretch", (json_range){0, 1, 1, 1},
                                     &m->spline.compression_stretch));
    PIOLA_TRY(piola__json_opt_number(p, sp, "elongation_stretch", (json_range){1, INFINITY, 1, 0},
                                     &m->spline.elongation_stretch));
    PIOLA_TRY(piola__json_opt_number(p, sp, "stiffening", (json_range){1, INFINITY, 0, 0},
                                     &m->spline.stiffening));
    piola__json_pop(p, old);
  }
  const cJSON *mu = piola__json_get(obj, "muscle");
  if (mu) {
    size_t old = piola__json_push_key(p, "muscle");
    if (m->model != PIOLA_MODEL_MUSCLE)
      return piola__json_fail(p, BAD_VALUE, "needs \"model\": \"muscle\"");
    static const char *const keys[] = {"passive_stiffness", "passive_toe_stretch",
                                       "max_active_stress", "optimal_stretch", "active_width",
                                       NULL};
    PIOLA_TRY(piola__json_check_keys(p, mu, keys));
    piola_muscle_def *md = &m->muscle;
    PIOLA_TRY(
        piola__json_opt_number(p, mu, "passive_stiffness", NONNEGATIVE, &md->passive_stiffness));
    PIOLA_TRY(piola__json_opt_number(p, mu, "passive_toe_stretch", (json_range){1, INFINITY, 1, 0},
                                     &md->passive_toe_stretch));
    PIOLA_TRY(
        piola__json_opt_number(p, mu, "max_active_stress", NONNEGATIVE, &md->max_active_stress));
    PIOLA_TRY(piola__json_opt_number(p, mu, "optimal_stretch", POSITIVE, &md->optimal_stretch));
    PIOLA_TRY(
        piola__json_opt_number(p, mu, "active_width", (json_range){0, 1, 1, 1}, &md->active_width));
    piola__json_pop(p, old);
  }
  PIOLA_TRY(parse_ogden(p, obj, m));
  PIOLA_TRY(parse_hgo(p, obj, m));
  const cJSON *mr = piola__json_get(obj, "mooney_rivlin");
  if (mr) {
    size_t old = piola__json_push_key(p, "mooney_rivlin");
    if (m->model != PIOLA_MODEL_MOONEY_RIVLIN)
      return piola__json_fail(p, BAD_VALUE, "needs \"model\": \"mooney_rivlin\"");
    static const char *const keys[] = {"c10", "c01", NULL};
    PIOLA_TRY(piola__json_check_keys(p, mr, keys));
    PIOLA_TRY(piola__json_opt_number(p, mr, "c10", ANY, &m->mooney_rivlin.c10));
    PIOLA_TRY(piola__json_opt_number(p, mr, "c01", ANY, &m->mooney_rivlin.c01));
    if (!(m->mooney_rivlin.c10 + m->mooney_rivlin.c01 > 0))
      return piola__json_fail(p, BAD_VALUE, "c10 + c01 must be > 0 Pa (the shear modulus is 2 (c10 + c01)), got %g",
                              m->mooney_rivlin.c10 + m->mooney_rivlin.c01);
    piola__json_pop(p, old);
  }
  return PIOLA_OK;
}
