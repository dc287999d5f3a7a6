/* Closest points between a point and a triangle and between two segments. */
#include "contact/proximity.h"

static double clamp01(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }

/* Closest point on segment (a, b) to p as the weight s of b; squared distance returned. */
static double point_segment_closest(vec3 p, vec3 a, vec3 b, double *s) {
  vec3 ab = vec3_sub(b, a);
  double len2 = vec3_norm2(ab);
  double w = len2 > 0.0 ? clamp01(vec3_dot(vec3_sub(p, a), ab) / len2) : 0.0;
  *s = w;
  return vec3_norm2(vec3_sub(p, vec3_add(a, vec3_scale(ab, w))));
}

double piola__point_triangle_closest(vec3 p, vec3 a, vec3 b, vec3 c, double bary[3]) {
  vec3 ab = vec3_sub(b, a), ac = vec3_sub(c, a), ap = vec3_sub(p, a);
  vec3 n = vec3_cross(ab, ac);
  double scale2 = fmax(vec3_norm2(ab), fmax(vec3_norm2(ac), vec3_norm2(vec3_sub(c, b))));
  if (!(vec3_norm2(n) > 1e-24 * scale2 * scale2)) {
    /* Zero or nearly zero area: the closest point lies on one of the three edges. */
    double s, best = point_segment_closest(p, a, b, &s);
    bary[0] = 1.0 - s, bary[1] = s, bary[2] = 0.0;
    double d = point_segment_closest(p, b, c, &s);
    if (d < best) best = d, bary[0] = 0.0, bary[1] = 1.0 - s, bary[2] = s;
    d = point_segment_closest(p, a, c, &s);
    if (d < best) best = d, bary[0] = 1.0 - s, bary[1] = 0.0, bary[2] = s;
    return best;
  }
  /* Voronoi regions of the vertices, edges and face, tested in that order. */
  double d1 = vec3_dot(ab, ap), d2 = vec3_dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    bary[0] = 1.0, bary[1] = 0.0, bary[2] = 0.0;
    return vec3_norm2(ap);
  }
  vec3 bp = vec3_sub(p, b);
  double d3 = vec3_dot(ab, bp), d4 = vec3_dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) {
    bary[0] = 0.0, bary[1] = 1.0, bary[2] = 0.0;
    return vec3_norm2(bp);
  }
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    double s = clamp01(d1 / (d1 - d3));
    bary[0] = 1.0 - s, bary[1] = s, bary[2] = 0.0;
    return vec3_norm2(vec3_sub(p, vec3_add(a, vec3_scale(ab, s))));
  }
  vec3 cp = vec3_sub(p, c);
  double d5 = vec3_dot(ab, cp), d6 = vec3_dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) {
    bary[0] = 0.0, bary[1] = 0.0, bary[2] = 1.0;
    return vec3_norm2(cp);
  }
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    double s = clamp01(d2 / (d2 - d6));
    bary[0] = 1.0 - s, bary[1] = 0.0, bary[2] = s;
    return vec3_norm2(vec3_sub(p, vec3_add(a, vec3_scale(ac, s))));
  }
  double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    double s = clamp01((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    bary[0] = 0.0, bary[1] = 1.0 - s, bary[2] = s;
    return vec3_norm2(vec3_sub(p, vec3_add(b, vec3_scale(vec3_sub(c, b), s))));
  }
  double inv = 1.0 / (va + vb + vc);
  double w1 = vb * inv, w2 = vc * inv;
  bary[0] = 1.0 - w1 - w2, bary[1] = w1, bary[2] = w2;
  vec3 q = vec3_add(a, vec3_add(vec3_scale(ab, w1), vec3_scale(ac, w2)));
  return vec3_norm2(vec3_sub(p, q));
}

double piola__segment_segment_closest(vec3 p0, vec3 p1, vec3 q0, vec3 q1, double *s_out,
                                      double *t_out) {
  vec3 d1 = vec3_sub(p1, p0), d2 = vec3_sub(q1, q0), r = vec3_sub(p0, q0);
  double a = vec3_norm2(d1), e = vec3_norm2(d2), f = vec3_dot(d2, r);
  double s, t;
  if (a <= 0.0 && e <= 0.0) {
    s = 0.0, t = 0.0;
  } else if (a <= 0.0) {
    s = 0.0, t = clamp01(f / e);
  } else {
    double c = vec3_dot(d1, r);
    if (e <= 0.0) {
      t = 0.0, s = clamp01(-c / a);
    } else {
      double b = vec3_dot(d1, d2), denom = a * e - b * b;
      /* Parallel segments (denom ~ 0): any s works; 0 is then corrected below. */
      s = denom > 1e-14 * a * e ? clamp01((b * f - c * e) / denom) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0, s = clamp01(-c / a);
      } else if (t > 1.0) {
        t = 1.0, s = clamp01((b - c) / a);
      }
    }
  }
  *s_out = s, *t_out = t;
  vec3 cp = vec3_add(p0, vec3_scale(d1, s)), cq = vec3_add(q0, vec3_scale(d2, t));
  return vec3_norm2(vec3_sub(cp, cq));
}
