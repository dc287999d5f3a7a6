#include "geometry/analytic_shapes.h"

#include <math.h>

/* A unit vector along v, or `fallback` when v is (numerically) zero: used on the medial set
 * (the centre of a sphere, the axis of a cylinder) where any direction is a valid normal. */
static vec3 unit_or(vec3 v, vec3 fallback) {
  double n = vec3_norm(v);
  return n > 1e-300 ? vec3_scale(v, 1.0 / n) : fallback;
}

void piola__shape_frame(vec3 axis, vec3 *e1, vec3 *e2) {
  /* Pick the world axis least aligned with `axis` to start Gram-Schmidt. */
  vec3 seed = fabs(axis.x) < 0.57 ? vec3_make(1, 0, 0)
              : (fabs(axis.y) < 0.57 ? vec3_make(0, 1, 0) : vec3_make(0, 0, 1));
  vec3 a = vec3_sub(seed, vec3_scale(axis, vec3_dot(seed, axis)));
  *e1 = vec3_scale(a, 1.0 / vec3_norm(a));
  *e2 = vec3_cross(axis, *e1);
}

double piola__shape_sphere_distance(vec3 p, vec3 center, double radius, vec3 *normal) {
  vec3 d = vec3_sub(p, center);
  if (normal) *normal = unit_or(d, vec3_make(0, 0, 1));
  return vec3_norm(d) - radius;
}

double piola__shape_plane_distance(vec3 p, vec3 point, vec3 unit_normal, vec3 *normal) {
  if (normal) *normal = unit_normal;
  return vec3_dot(vec3_sub(p, point), unit_normal);
}

double piola__shape_box_distance(vec3 p, vec3 center, vec3 half_extents, vec3 *normal) {
  vec3 d = vec3_sub(p, center);
  double q[3] = {fabs(d.x) - half_extents.x, fabs(d.y) - half_extents.y, fabs(d.z) - half_extents.z};
  double s[3] = {d.x < 0 ? -1 : 1, d.y < 0 ? -1 : 1, d.z < 0 ? -1 : 1};
  if (q[0] <= 0 && q[1] <= 0 && q[2] <= 0) {
    /* Inside: the nearest face is the one with the largest (least negative) q. */
    int k = q[0] >= q[1] ? (q[0] >= q[2] ? 0 : 2) : (q[1] >= q[2] ? 1 : 2);
    if (normal) {
      double n[3] = {0, 0, 0};
      n[k] = s[k];
      *normal = vec3_make(n[0], n[1], n[2]);
    }
    return q[k];
  }
  vec3 outside = vec3_make(fmax(q[0], 0) * s[0], fmax(q[1], 0) * s[1], fmax(q[2], 0) * s[2]);
  double dist = vec3_norm(outside);
  if (normal) *normal = vec3_scale(outside, 1.0 / dist);
  return dist;
}

/* Distance to a capped cylinder in its 2D (radial, axial) half-plane. */
double piola__shape_cylinder_distance(vec3 p, vec3 center, vec3 axis, double radius, double half_length,
                               vec3 *normal) {
  vec3 d = vec3_sub(p, center);
  double h = vec3_dot(d, axis);
  vec3 radial = vec3_sub(d, vec3_scale(axis, h));
  double r = vec3_norm(radial);
  vec3 e1, e2;
  piola__shape_frame(axis, &e1, &e2);
  vec3 radial_dir = unit_or(radial, e1);
  vec3 axial_dir = h < 0 ? vec3_neg(axis) : axis;
  double qr = r - radius, qh = fabs(h) - half_length;
  double dist;
  vec3 n;
  if (qr <= 0 && qh <= 0) {
    if (qr >= qh) {
      dist = qr;
      n = radial_dir;
    } else {
      dist = qh;
      n = axial_dir;
    }
  } else {
    double a = fmax(qr, 0), b = fmax(qh, 0);
    dist = sqrt(a * a + b * b);
    n = unit_or(vec3_add(vec3_scale(radial_dir, a), vec3_scale(axial_dir, b)), axial_dir);
  }
  if (normal) *normal = n;
  return dist;
}

double piola__shape_capsule_distance(vec3 p, vec3 center, vec3 axis, double radius, double half_length,
                              vec3 *normal) {
  vec3 d = vec3_sub(p, center);
  double h = fmax(-half_length, fmin(half_length, vec3_dot(d, axis)));
  vec3 to_segment = vec3_sub(d, vec3_scale(axis, h));
  vec3 e1, e2;
  piola__shape_frame(axis, &e1, &e2);
  if (normal) *normal = unit_or(to_segment, e1);
  return vec3_norm(to_segment) - radius;
}

double piola__shape_torus_distance(vec3 p, vec3 center, vec3 axis, double major_radius,
                            double minor_radius, vec3 *normal) {
  vec3 d = vec3_sub(p, center);
  double h = vec3_dot(d, axis);
  vec3 radial = vec3_sub(d, vec3_scale(axis, h));
  vec3 e1, e2;
  piola__shape_frame(axis, &e1, &e2);
  vec3 radial_dir = unit_or(radial, e1);
  vec3 ring_point = vec3_scale(radial_dir, major_radius); /* nearest point of the core circle */
  vec3 to_tube = vec3_sub(d, ring_point);
  if (normal) *normal = unit_or(to_tube, axis);
  return vec3_norm(to_tube) - minor_radius;
}
