/* The world's keys: fps, frames, gravity and integrator settings. */

#include <stdio.h>
#include <string.h>

#include "scene/scene_parse_sections.h"

/* The integrator keys that apply to "newmark" only, and to the implicit integrators only
 * (scene-format.md, `integrator`). */
static const char *const newmark_keys[] = {"max_dt", "cfl", "cg_tolerance", "cg_max_iterations",
                                           NULL};
static const char *const implicit_keys[] = {"dt",
                                            "newton_tolerance",
                                            "newton_max_iterations",
                                            "linear_tolerance",
                                            "linear_max_iterations",
                                            "preconditioner",
                                            "linear_forcing",
                                            "mpi_preconditioner",
                                            NULL};

/* Lists in out->ignored_integrator_keys the keys of `integrator` that its type does not use:
 * a scene that sets `dt` and forgets `type` runs Newmark, and should hear so. */
static void note_ignored_keys(const cJSON *integrator, scene_desc *out) {
  const char *const *unused =
      out->world.integrator == PIOLA_INTEGRATOR_NEWMARK ? implicit_keys : newmark_keys;
  char *list = out->ignored_integrator_keys;
  const size_t size = sizeof out->ignored_integrator_keys;
  list[0] = '\0';
  for (int k = 0; unused[k]; ++k) {
    if (!piola__json_get(integrator, unused[k])) continue;
    const size_t used = strlen(list);
    snprintf(list + used, size - used, "%sintegrator.%s", used ? ", " : "", unused[k]);
  }
}

piola_status piola__scene_parse_world(scene_parser *p, const cJSON *obj, scene_desc *out) {
  const cJSON *v;
  PIOLA_TRY(piola__json_opt_number(p, obj, "fps", (json_range){0, 10000, 1, 0}, &out->fps));
  int64_t frames = out->frames;
  PIOLA_TRY(piola__json_opt_int(p, obj, "frames", 0, 1000000, &frames));
  out->frames = (int32_t)frames;
  PIOLA_TRY(piola__json_opt_vec3_tracks(p, obj, "gravity", out->world.gravity));
  if ((v = piola__json_get(obj, "integrator"))) {
    size_t old = piola__json_push_key(p, "integrator");
    static const char *const keys[] = {"max_dt", "cfl", "cg_tolerance", "cg_max_iterations",
                                       "collision_interval", "type", "dt", "newton_tolerance",
                                       "newton_max_iterations", "linear_tolerance",
                                       "linear_max_iterations", "preconditioner",
                                       "linear_forcing", "mpi_preconditioner", NULL};
    PIOLA_TRY(piola__json_check_keys(p, v, keys));
    PIOLA_TRY(piola__json_opt_number(p, v, "max_dt", (json_range){0, 1, 1, 0}, &out->world.max_dt));
    PIOLA_TRY(piola__json_opt_number(p, v, "cfl", (json_range){0, 2, 1, 0}, &out->world.cfl));
    PIOLA_TRY(piola__json_opt_number(p, v, "cg_tolerance", (json_range){0, 1, 1, 1},
                                     &out->world.cg_tolerance));
    int64_t it = out->world.cg_max_iterations;
    PIOLA_TRY(piola__json_opt_int(p, v, "cg_max_iterations", 1, 1000000, &it));
    out->world.cg_max_iterations = (int32_t)it;
    PIOLA_TRY(piola__json_opt_number(p, v, "collision_interval", (json_range){0, 1, 0, 0},
                                     &out->world.collision_interval));
    const cJSON *type = piola__json_get(v, "type");
    if (type) {
      size_t o2 = piola__json_push_key(p, "type");
      if (!cJSON_IsString(type) ||
          !piola_integrator_type_from_name(type->valuestring, &out->world.integrator))
        return piola__json_fail(p, BAD_VALUE,
                                "must be \"newmark\", \"backward_euler\" or \"quasistatic\"");
      piola__json_pop(p, o2);
    }
    /* the implicit step defaults to the frame time */
    if (out->fps > 0) out->world.implicit_dt = 1.0 / out->fps;
    PIOLA_TRY(piola__json_opt_number(p, v, "dt", POSITIVE, &out->world.implicit_dt));
    PIOLA_TRY(piola__json_opt_number(p, v, "newton_tolerance", (json_range){0, 1, 1, 1},
                                     &out->world.newton_tolerance));
    it = out->world.newton_max_iterations;
    PIOLA_TRY(piola__json_opt_int(p, v, "newton_max_iterations", 1, 1000000, &it));
    out->world.newton_max_iterations = (int32_t)it;
    PIOLA_TRY(piola__json_opt_number(p, v, "linear_tolerance", (json_range){0, 1, 1, 1},
                                     &out->world.linear_tolerance));
    it = out->world.linear_max_iterations;
    PIOLA_TRY(piola__json_opt_int(p, v, "linear_max_iterations", 1, 1000000, &it));
    out->world.linear_max_iterations = (int32_t)it;
    const cJSON *pc = piola__json_get(v, "preconditioner");
    if (pc) {
      size_t o2 = piola__json_push_key(p, "preconditioner");
      if (!cJSON_IsString(pc) ||
          !piola_preconditioner_type_from_name(pc->valuestring, &out->world.preconditioner))
        return piola__json_fail(p, BAD_VALUE,
                                "must be \"block_jacobi\", \"incomplete_cholesky\" or \"multigrid\"");
      piola__json_pop(p, o2);
    }
    const cJSON *lf = piola__json_get(v, "linear_forcing");
    if (lf) {
      size_t o2 = piola__json_push_key(p, "linear_forcing");
      if (!cJSON_IsString(lf) ||
          !piola_linear_forcing_from_name(lf->valuestring, &out->world.linear_forcing))
        return piola__json_fail(p, BAD_VALUE, "must be \"eisenstat_walker\" or \"fixed\"");
      piola__json_pop(p, o2);
    }
    const cJSON *mp = piola__json_get(v, "mpi_preconditioner");
    if (mp) {
      size_t o2 = piola__json_push_key(p, "mpi_preconditioner");
      if (!cJSON_IsString(mp) ||
          !piola_mpi_preconditioner_from_name(mp->valuestring, &out->world.mpi_preconditioner))
        return piola__json_fail(p, BAD_VALUE, "must be \"gamg\" or \"block_jacobi_icc\"");
      piola__json_pop(p, o2);
    }
    note_ignored_keys(v, out);
    piola__json_pop(p, old);
  } else if (out->fps > 0) {
    out->world.implicit_dt = 1.0 / out->fps;
  }
  return PIOLA_OK;
}
