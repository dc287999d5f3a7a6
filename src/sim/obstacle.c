/* Obstacle creation, validation and the shape dispatch (a tagged union and a switch). */
#include "sim/obstacle_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "common/status_report.h"

piola_obstacle_def piola_default_obstacle_def(void) {
  piola_obstacle_def def;
  def.type = PIOLA_OBSTACLE_PLANE;
  def.center = vec3_make(0, 0, 0);
  def.axis = vec3_make(0, 0, 1);
  def.radius = 0.0;
  def.minor_radius = 0.0;
  def.half_length = 0.0;
  def.half_extents = vec3_make(0, 0, 0);
  def.tooth_count = 0;
  def.tooth_depth = 0.0;
  def.mesh = NULL;
  def.friction = 0.0;
  def.motion = piola_default_rigid_motion_def();
  return def;
}

piola_status piola__obstacle_unit_axis(vec3 axis, const char *what, vec3 *out) {
  double n = vec3_norm(axis);
  if (!isfinite(n) || !(fabs(n - 1.0) <= 1e-3))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "%s must be a unit vector, got (%g, %g, %g) of length %g", what, axis.x,
                      axis.y, axis.z, n);
  *out = vec3_scale(axis, 1.0 / n);
  return PIOLA_OK;
}

piola_status piola__obstacle_positive(double value, const char *what) {
  if (!(value > 0) || !isfinite(value))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s must be finite and > 0 m, got %g", what,
                      value);
  return PIOLA_OK;
}

static bool vec3_finite(vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

static piola_status validate_track(const piola_track *track, const char *what) {
  if (track->key_count < 0 || track->key_count > PIOLA_MAX_KEYS)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "motion %s: key_count %d out of [0, %d]", what,
                      (int)track->key_count, PIOLA_MAX_KEYS);
  if (track->key_count == 0 && !isfinite(track->value))
    return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "motion %s: value must be finite", what);
  for (int32_t i = 0; i < track->key_count; ++i) {
    if (!isfinite(track->times[i]) || !isfinite(track->values[i]))
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "motion %s: key %d is not finite", what, (int)i);
    if (i > 0 && !(track->times[i] > track->times[i - 1]))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "motion %s: key %d time must increase", what,
                        (int)i);
  }
  return PIOLA_OK;
}

static piola_status validate_motion(const piola_rigid_motion_def *motion,
                                    piola_rigid_motion_def *out) {
  static const char *const axes[3] = {"x", "y", "z"};
  char what[32];
  if (motion->kind != PIOLA_MOTION_VELOCITY && motion->kind != PIOLA_MOTION_POSE)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "motion kind %d is unknown", (int)motion->kind);
  if (!vec3_finite(motion->pivot))
    return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "motion pivot must be finite");
  for (int k = 0; k < 3; ++k) {
    snprintf(what, sizeof what, "velocity.%s", axes[k]);
    PIOLA_TRY(validate_track(&motion->velocity[k], what));
    snprintf(what, sizeof what, "translation.%s", axes[k]);
    PIOLA_TRY(validate_track(&motion->translation[k], what));
  }
  PIOLA_TRY(validate_track(&motion->angular_speed, "angular_speed"));
  PIOLA_TRY(validate_track(&motion->angle, "angle"));
  *out = *motion;
  return piola__obstacle_unit_axis(motion->axis, "motion axis", &out->axis);
}

static void set_bounding_sphere(piola_obstacle *o) {
  o->bound_center = vec3_make(0, 0, 0);
  o->bound_radius = INFINITY;
  switch (o->type) {
    case PIOLA_OBSTACLE_SPHERE:
      o->bound_center = o->shape.sphere.center;
      o->bound_radius = o->shape.sphere.radius;
      break;
    case PIOLA_OBSTACLE_BOX:
      o->bound_center = o->shape.box.center;
      o->bound_radius = vec3_norm(o->shape.box.half_extents);
      break;
    case PIOLA_OBSTACLE_CYLINDER:
      o->bound_center = o->shape.cylinder.center;
      o->bound_radius = hypot(o->shape.cylinder.radius, o->shape.cylinder.half_length);
      break;
    case PIOLA_OBSTACLE_CAPSULE:
      o->bound_center = o->shape.capsule.center;
      o->bound_radius = o->shape.capsule.radius + o->shape.capsule.half_length;
      break;
    case PIOLA_OBSTACLE_TORUS:
      o->bound_center = o->shape.torus.center;
      o->bound_radius = o->shape.torus.major_radius + o->shape.torus.minor_radius;
      break;
    case PIOLA_OBSTACLE_GEAR:
      o->bound_center = o->shape.gear.center;
      o->bound_radius = hypot(o->shape.gear.tip_radius, o->shape.gear.half_length);
      break;
    case PIOLA_OBSTACLE_MESH: {
      const piola__mesh_shape *m = &o->shape.mesh;
      o->bound_center = vec3_scale(vec3_add(m->box_min, m->box_max), 0.5);
      o->bound_radius = 0.5 * vec3_norm(vec3_sub(m->box_max, m->box_min));
      break;
    }
    default:
      break;
  }
  /* Rounding: a point exactly on the surface may evaluate a hair inside. */
  o->bound_radius *= 1.0 + 1e-9;
}

piola_status piola_obstacle_create(const piola_obstacle_def *def, piola_obstacle **out) {
  if (!def || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "obstacle: NULL argument");
  *out = NULL;
  if (!vec3_finite(def->center))
    return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "obstacle center must be finite");
  if (!(def->friction >= 0) || !isfinite(def->friction))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "obstacle friction must be finite and >= 0, got %g", def->friction);
  piola_obstacle *o = calloc(1, sizeof *o);
  if (!o) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "obstacle");
  o->type = def->type;
  o->friction = def->friction;
  piola_status s = validate_motion(&def->motion, &o->motion);
  if (s == PIOLA_OK) {
    switch (def->type) {
      case PIOLA_OBSTACLE_PLANE:
        s = piola__plane_init(def, &o->shape.plane);
        break;
      case PIOLA_OBSTACLE_SPHERE:
        s = piola__sphere_init(def, &o->shape.sphere);
        break;
      case PIOLA_OBSTACLE_BOX:
        s = piola__box_init(def, &o->shape.box);
        break;
      case PIOLA_OBSTACLE_CYLINDER:
        s = piola__cylinder_init(def, &o->shape.cylinder);
        break;
      case PIOLA_OBSTACLE_CAPSULE:
        s = piola__capsule_init(def, &o->shape.capsule);
        break;
      case PIOLA_OBSTACLE_TORUS:
        s = piola__torus_init(def, &o->shape.torus);
        break;
      case PIOLA_OBSTACLE_GEAR:
        s = piola__gear_init(def, &o->shape.gear);
        break;
      case PIOLA_OBSTACLE_MESH:
        s = piola__mesh_obstacle_init(def, &o->shape.mesh);
        break;
      default:
        s = PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "obstacle type %d is unknown", (int)def->type);
        o->type = PIOLA_OBSTACLE_TYPE_COUNT; /* nothing to free */
        break;
    }
  }
  if (s != PIOLA_OK) {
    piola_obstacle_destroy(o);
    return s;
  }
  set_bounding_sphere(o);
  *out = o;
  return PIOLA_OK;
}

void piola_obstacle_destroy(piola_obstacle *obstacle) {
  if (!obstacle) return;
  switch (obstacle->type) {
    case PIOLA_OBSTACLE_GEAR:
      piola__gear_free(&obstacle->shape.gear);
      break;
    case PIOLA_OBSTACLE_MESH:
      piola__mesh_obstacle_free(&obstacle->shape.mesh);
      break;
    default:
      break;
  }
  free(obstacle);
}

double piola_obstacle_friction(const piola_obstacle *obstacle) {
  return obstacle ? obstacle->friction : 0.0;
}

piola_obstacle_type piola_obstacle_shape_type(const piola_obstacle *obstacle) {
  return obstacle->type;
}

piola_obstacle_pose piola_obstacle_pose_at(const piola_obstacle *obstacle, double t) {
  piola__rigid_state state;
  piola__rigid_motion_state(&obstacle->motion, t, &state);
  return (piola_obstacle_pose){state.rotation, state.translation};
}

void piola_obstacle_bounding_sphere(const piola_obstacle *obstacle, piola_vec3 *center,
                                    double *radius) {
  if (center) *center = obstacle->bound_center;
  if (radius) *radius = obstacle->bound_radius;
}

/* The shape's distance in its t = 0 frame. */
static double shape_distance(const piola_obstacle *o, vec3 p, vec3 *normal) {
  switch (o->type) {
    case PIOLA_OBSTACLE_PLANE:
      return piola__plane_distance(&o->shape.plane, p, normal);
    case PIOLA_OBSTACLE_SPHERE:
      return piola__sphere_distance(&o->shape.sphere, p, normal);
    case PIOLA_OBSTACLE_BOX:
      return piola__box_distance(&o->shape.box, p, normal);
    case PIOLA_OBSTACLE_CYLINDER:
      return piola__cylinder_distance(&o->shape.cylinder, p, normal);
    case PIOLA_OBSTACLE_CAPSULE:
      return piola__capsule_distance(&o->shape.capsule, p, normal);
    case PIOLA_OBSTACLE_TORUS:
      return piola__torus_distance(&o->shape.torus, p, normal);
    case PIOLA_OBSTACLE_GEAR:
      return piola__gear_distance(&o->shape.gear, p, normal);
    case PIOLA_OBSTACLE_MESH:
      return piola__mesh_obstacle_distance(&o->shape.mesh, p, normal);
    default:
      break;
  }
  if (normal) *normal = vec3_make(0, 0, 1);
  return INFINITY;
}

double piola__obstacle_distance_posed(const piola_obstacle *obstacle,
                                      const piola__rigid_state *state, vec3 p, vec3 *normal,
                                      vec3 *velocity) {
  /* x = R x0 + T  =>  x0 = R^T (x - T) */
  vec3 p0 = mat3_transpose_mul_vec(state->rotation, vec3_sub(p, state->translation));
  vec3 n0;
  double d = shape_distance(obstacle, p0, normal ? &n0 : NULL);
  if (normal) *normal = mat3_mul_vec(state->rotation, n0);
  if (velocity) *velocity = piola__rigid_state_velocity(state, p);
  return d;
}

/* A query at a non-finite point or time has no answer: NaN everywhere (a box's clamps
 * turned a NaN point into distance 0, on its surface). */
static int query_not_finite(double t, piola_vec3 p, piola_vec3 *normal, piola_vec3 *velocity) {
  if (isfinite(t) && isfinite(p.x) && isfinite(p.y) && isfinite(p.z)) return 0;
  if (normal) *normal = vec3_make(NAN, NAN, NAN);
  if (velocity) *velocity = vec3_make(NAN, NAN, NAN);
  return 1;
}

double piola_obstacle_posed_distance(const piola_obstacle *obstacle,
                                     const piola_obstacle_pose *pose, piola_vec3 p,
                                     piola_vec3 *normal) {
  if (query_not_finite(0.0, p, normal, NULL)) return NAN;
  piola__rigid_state state = {.rotation = pose->rotation, .translation = pose->translation};
  return piola__obstacle_distance_posed(obstacle, &state, p, normal, NULL);
}

double piola_obstacle_signed_distance(const piola_obstacle *obstacle, double t, piola_vec3 p,
                                      piola_vec3 *normal, piola_vec3 *velocity) {
  if (!obstacle) { /* nothing is inside no obstacle */
    if (normal) *normal = vec3_make(0, 0, 1);
    if (velocity) *velocity = vec3_make(0, 0, 0);
    return INFINITY;
  }
  if (query_not_finite(t, p, normal, velocity)) return NAN;
  piola__rigid_state state;
  piola__rigid_motion_state(&obstacle->motion, t, &state);
  return piola__obstacle_distance_posed(obstacle, &state, p, normal, velocity);
}
