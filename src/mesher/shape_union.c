#include "mesher/shape_union.h"

#include <math.h>
#include <string.h>

#include "common/status_report.h"
#include "geometry/analytic_shapes.h"

static const char *shape_name(piola_shape_type t) {
  switch (t) {
    case PIOLA_SHAPE_SPHERE: return "sphere";
    case PIOLA_SHAPE_BOX: return "box";
    case PIOLA_SHAPE_TORUS: return "torus";
    case PIOLA_SHAPE_CYLINDER: return "cylinder";
    case PIOLA_SHAPE_CAPSULE: return "capsule";
    case PIOLA_SHAPE_SURFACE: return "surface";
  }
  return "unknown";
}

piola_status piola__shape_union_create(const piola_mesher_def *def, piola__shape_union *out) {
  memset(out, 0, sizeof(*out));
  if (def->shape_count < 1 || def->shape_count > PIOLA_MESHER_MAX_SHAPES)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "mesher: shape_count must be in [1, %d], got %d",
                      PIOLA_MESHER_MAX_SHAPES, def->shape_count);
  for (int i = 0; i < def->shape_count; ++i) {
    piola_shape s = def->shapes[i];
    const char *name = shape_name(s.type);
    double axis_len = vec3_norm(s.axis);
    if (s.type != PIOLA_SHAPE_SPHERE && s.type != PIOLA_SHAPE_BOX && s.type != PIOLA_SHAPE_SURFACE) {
      if (!(axis_len > 0) || !isfinite(axis_len))
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "mesher: shape %d (%s) has a zero axis", i, name);
      s.axis = vec3_scale(s.axis, 1.0 / axis_len);
    }
    if (!isfinite(s.center.x) || !isfinite(s.center.y) || !isfinite(s.center.z))
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "mesher: shape %d (%s) has a non-finite center", i, name);
    switch (s.type) {
      case PIOLA_SHAPE_SPHERE:
        if (!(s.radius > 0) || !isfinite(s.radius))
          return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "mesher: shape %d (sphere) radius must be > 0 m, got %g", i, s.radius);
        break;
      case PIOLA_SHAPE_BOX:
        if (!(s.half_extents.x > 0 && s.half_extents.y > 0 && s.half_extents.z > 0) ||
            !isfinite(s.half_extents.x + s.half_extents.y + s.half_extents.z))
          return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "mesher: shape %d (box) half_extents must be > 0 m", i);
        break;
      case PIOLA_SHAPE_TORUS:
        if (!(s.minor_radius > 0) || !(s.radius > s.minor_radius) || !isfinite(s.radius))
          return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                            "mesher: shape %d (torus) needs radius > minor_radius > 0 m, got %g and %g",
                            i, s.radius, s.minor_radius);
        break;
      case PIOLA_SHAPE_CYLINDER:
      case PIOLA_SHAPE_CAPSULE:
        if (!(s.radius > 0) || !(s.half_length >= 0) || !isfinite(s.radius + s.half_length) ||
            (s.type == PIOLA_SHAPE_CYLINDER && !(s.half_length > 0)))
          return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                            "mesher: shape %d (%s) needs radius > 0 m and half_length > 0 m, got %g and %g",
                            i, name, s.radius, s.half_length);
        break;
      case PIOLA_SHAPE_SURFACE: {
        if (!s.surface)
          return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "mesher: shape %d (surface) has no surface mesh", i);
        piola_status st = piola__surface_distance_create(s.surface, &out->surfaces[i]);
        if (st != PIOLA_OK) {
          piola__shape_union_destroy(out);
          return st;
        }
        break;
      }
      default:
        piola__shape_union_destroy(out);
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "mesher: shape %d has unknown type %d", i, (int)s.type);
    }
    out->shapes[i] = s;
    out->count = i + 1;
  }
  return PIOLA_OK;
}

void piola__shape_union_destroy(piola__shape_union *u) {
  for (int i = 0; i < PIOLA_MESHER_MAX_SHAPES; ++i) {
    piola__surface_distance_destroy(u->surfaces[i]);
    u->surfaces[i] = NULL;
  }
  u->count = 0;
}

void piola__shape_union_bounds(const piola__shape_union *u, vec3 *lo, vec3 *hi) {
  *lo = vec3_make(INFINITY, INFINITY, INFINITY);
  *hi = vec3_neg(*lo);
  for (int i = 0; i < u->count; ++i) {
    const piola_shape *s = &u->shapes[i];
    vec3 a, b;
    if (s->type == PIOLA_SHAPE_SURFACE) {
      piola__surface_bounds(u->surfaces[i], &a, &b);
    } else {
      vec3 r;
      switch (s->type) {
        case PIOLA_SHAPE_BOX: r = s->half_extents; break;
        case PIOLA_SHAPE_SPHERE: r = vec3_make(s->radius, s->radius, s->radius); break;
        default: {
          double e = s->type == PIOLA_SHAPE_TORUS ? s->radius + s->minor_radius
                                                  : s->radius + s->half_length;
          r = vec3_make(e, e, e);
        }
      }
      a = vec3_sub(s->center, r);
      b = vec3_add(s->center, r);
    }
    *lo = vec3_make(fmin(lo->x, a.x), fmin(lo->y, a.y), fmin(lo->z, a.z));
    *hi = vec3_make(fmax(hi->x, b.x), fmax(hi->y, b.y), fmax(hi->z, b.z));
  }
}

static double shape_phi(const piola__shape_union *u, int i, vec3 p, vec3 *n) {
  const piola_shape *s = &u->shapes[i];
  switch (s->type) {
    case PIOLA_SHAPE_SPHERE: return piola__shape_sphere_distance(p, s->center, s->radius, n);
    case PIOLA_SHAPE_BOX: return piola__shape_box_distance(p, s->center, s->half_extents, n);
    case PIOLA_SHAPE_TORUS:
      return piola__shape_torus_distance(p, s->center, s->axis, s->radius, s->minor_radius, n);
    case PIOLA_SHAPE_CYLINDER:
      return piola__shape_cylinder_distance(p, s->center, s->axis, s->radius, s->half_length, n);
    case PIOLA_SHAPE_CAPSULE:
      return piola__shape_capsule_distance(p, s->center, s->axis, s->radius, s->half_length, n);
    case PIOLA_SHAPE_SURFACE: return piola__surface_signed_distance(u->surfaces[i], p, n, NULL);
  }
  return INFINITY;
}

double piola__shape_union_phi(const piola__shape_union *u, vec3 p, vec3 *normal) {
  double best = INFINITY;
  vec3 best_n = vec3_make(0, 0, 1);
  for (int i = 0; i < u->count; ++i) {
    vec3 n;
    double d = shape_phi(u, i, p, normal ? &n : NULL);
    if (d < best) {
      best = d;
      if (normal) best_n = n;
    }
  }
  if (normal) *normal = best_n;
  return best;
}

double piola__shape_union_phi_analytic(const piola__shape_union *u, vec3 p) {
  double best = INFINITY;
  for (int i = 0; i < u->count; ++i)
    if (u->shapes[i].type != PIOLA_SHAPE_SURFACE) best = fmin(best, shape_phi(u, i, p, NULL));
  return best;
}

vec3 piola__shape_union_project(const piola__shape_union *u, vec3 p) {
  if (u->count == 1 && u->shapes[0].type == PIOLA_SHAPE_SURFACE) {
    vec3 q;
    piola__surface_closest_point(u->surfaces[0], p, &q, NULL);
    return q;
  }
  for (int iter = 0; iter < 4; ++iter) {
    vec3 n;
    double d = piola__shape_union_phi(u, p, &n);
    p = vec3_sub(p, vec3_scale(n, d));
  }
  return p;
}
