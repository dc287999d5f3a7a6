/* A `motion` object: the rigid motion of an obstacle, a bone or driven nodes. */

#include "scene/scene_parse_sections.h"

piola_status piola__scene_parse_motion(scene_parser *p, const cJSON *obj, piola_vec3 default_pivot,
                                       piola_vec3 default_axis, piola_rigid_motion_def *out) {
  static const char *const allowed[] = {"velocity", "angular_speed", "translation", "angle", "axis",
                                        "pivot", NULL};
  PIOLA_TRY(piola__json_check_keys(p, obj, allowed));
  *out = piola_default_rigid_motion_def();
  out->pivot = default_pivot;
  out->axis = default_axis;
  int velocity_kind = piola__json_get(obj, "velocity") || piola__json_get(obj, "angular_speed");
  int pose_kind = piola__json_get(obj, "translation") || piola__json_get(obj, "angle");
  if (velocity_kind && pose_kind)
    return piola__json_fail(p, PIOLA_ERROR_PARSE,
                            "give either velocity/angular_speed or translation/angle, not both");
  out->kind = pose_kind ? PIOLA_MOTION_POSE : PIOLA_MOTION_VELOCITY;
  PIOLA_TRY(piola__json_opt_vec3_tracks(p, obj, "velocity", out->velocity));
  PIOLA_TRY(piola__json_opt_track(p, obj, "angular_speed", ANY, &out->angular_speed));
  PIOLA_TRY(piola__json_opt_vec3_tracks(p, obj, "translation", out->translation));
  PIOLA_TRY(piola__json_opt_track(p, obj, "angle", ANY, &out->angle));
  PIOLA_TRY(piola__json_opt_direction(p, obj, "axis", &out->axis));
  PIOLA_TRY(piola__json_opt_vec3(p, obj, "pivot", ANY, &out->pivot));
  return PIOLA_OK;
}
