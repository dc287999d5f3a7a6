/* Exact triangle-triangle intersection from orientation signs (see the header). */
#include "contact/triangle_intersection.h"

#include <math.h>

/* ------------------------------------------------------------ expansion arithmetic
 * An expansion is a sum of doubles, stored smallest magnitude first, whose components do not
 * overlap; its sign is the sign of its last (largest) component. */
enum { EXPANSION_MAX = 256 };

typedef struct expansion {
  int n;
  double v[EXPANSION_MAX];
} expansion;

static void two_sum(double a, double b, double *x, double *y) {
  double s = a + b, bv = s - a, av = s - bv;
  *x = s;
  *y = (a - av) + (b - bv);
}

static void two_product(double a, double b, double *x, double *y) {
  double p = a * b;
  *x = p;
  *y = fma(a, b, -p);
}

/* e += b, dropping zero components. */
static void grow(expansion *e, double b) {
  if (b == 0.0) return;
  double q = b;
  int m = 0;
  for (int i = 0; i < e->n; ++i) {
    double hi, lo;
    two_sum(q, e->v[i], &hi, &lo);
    if (lo != 0.0) e->v[m++] = lo;
    q = hi;
  }
  if (q != 0.0) e->v[m++] = q;
  e->n = m;
}

/* out += sign * x * y * z for two-component expansions x, y, z. */
static void add_triple_product(expansion *out, double sign, const double x[2], const double y[2],
                               const double z[2]) {
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      if (x[i] == 0.0 || y[j] == 0.0) continue;
      double xy[2];
      two_product(x[i], y[j], &xy[0], &xy[1]);
      for (int a = 0; a < 2; ++a)
        for (int k = 0; k < 2; ++k) {
          double p, q;
          two_product(xy[a], z[k], &p, &q);
          grow(out, sign * q);
          grow(out, sign * p);
        }
    }
}

static int expansion_sign(const expansion *e) {
  if (e->n == 0) return 0;
  double top = e->v[e->n - 1];
  return (top > 0.0) - (top < 0.0);
}

static void exact_difference(double a, double b, double out[2]) {
  double x, y;
  two_sum(a, -b, &x, &y);
  out[0] = x, out[1] = y;
}

int piola__orient3d_sign(const double a[3], const double b[3], const double c[3],
                         const double d[3]) {
  double u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) u[k] = b[k] - a[k], v[k] = c[k] - a[k], w[k] = d[k] - a[k];
  double det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
               u[2] * (v[0] * w[1] - v[1] * w[0]);
  double permanent = fabs(u[0]) * (fabs(v[1] * w[2]) + fabs(v[2] * w[1])) +
                     fabs(u[1]) * (fabs(v[0] * w[2]) + fabs(v[2] * w[0])) +
                     fabs(u[2]) * (fabs(v[0] * w[1]) + fabs(v[1] * w[0]));
  /* Far above the rounding error of the expression (about 8 ulp of the permanent). */
  if (fabs(det) > 1e-14 * permanent) return (det > 0.0) - (det < 0.0);
  double U[3][2], V[3][2], W[3][2];
  for (int k = 0; k < 3; ++k) {
    exact_difference(b[k], a[k], U[k]);
    exact_difference(c[k], a[k], V[k]);
    exact_difference(d[k], a[k], W[k]);
  }
  expansion e = {0};
  add_triple_product(&e, 1.0, U[0], V[1], W[2]);
  add_triple_product(&e, -1.0, U[0], V[2], W[1]);
  add_triple_product(&e, -1.0, U[1], V[0], W[2]);
  add_triple_product(&e, 1.0, U[1], V[2], W[0]);
  add_triple_product(&e, 1.0, U[2], V[0], W[1]);
  add_triple_product(&e, -1.0, U[2], V[1], W[0]);
  return expansion_sign(&e);
}

/* Sign of the 2D orientation of (a, b, c) in the coordinate plane (i, j). Exact. */
static int orient2d_sign(const double a[3], const double b[3], const double c[3], int i, int j) {
  double ux = b[i] - a[i], uy = b[j] - a[j], vx = c[i] - a[i], vy = c[j] - a[j];
  double det = ux * vy - uy * vx, permanent = fabs(ux * vy) + fabs(uy * vx);
  if (fabs(det) > 1e-14 * permanent) return (det > 0.0) - (det < 0.0);
  double U[2][2], V[2][2];
  exact_difference(b[i], a[i], U[0]);
  exact_difference(b[j], a[j], U[1]);
  exact_difference(c[i], a[i], V[0]);
  exact_difference(c[j], a[j], V[1]);
  static const double one[2] = {1.0, 0.0};
  expansion e = {0};
  add_triple_product(&e, 1.0, U[0], V[1], one);
  add_triple_product(&e, -1.0, U[1], V[0], one);
  return expansion_sign(&e);
}

static int is_collinear(const double a[3], const double b[3], const double c[3]) {
  return orient2d_sign(a, b, c, 0, 1) == 0 && orient2d_sign(a, b, c, 1, 2) == 0 &&
         orient2d_sign(a, b, c, 2, 0) == 0;
}

/* Is c, known to be on the line of (a, b) in the plane (i, j), within the segment? */
static int within_projected(const double a[3], const double b[3], const double c[3], int i, int j) {
  return fmin(a[i], b[i]) <= c[i] && c[i] <= fmax(a[i], b[i]) && fmin(a[j], b[j]) <= c[j] &&
         c[j] <= fmax(a[j], b[j]);
}

/* Closed segments (p0, p1) and (q0, q1), coplanar, in the projection to the plane (i, j). */
static int segments_intersect_2d(const double *p0, const double *p1, const double *q0,
                                 const double *q1, int i, int j) {
  int o1 = orient2d_sign(p0, p1, q0, i, j), o2 = orient2d_sign(p0, p1, q1, i, j);
  int o3 = orient2d_sign(q0, q1, p0, i, j), o4 = orient2d_sign(q0, q1, p1, i, j);
  if (o1 * o2 < 0 && o3 * o4 < 0) return 1;
  if (o1 == 0 && within_projected(p0, p1, q0, i, j)) return 1;
  if (o2 == 0 && within_projected(p0, p1, q1, i, j)) return 1;
  if (o3 == 0 && within_projected(q0, q1, p0, i, j)) return 1;
  if (o4 == 0 && within_projected(q0, q1, p1, i, j)) return 1;
  return 0;
}

static int point_in_triangle_2d(const double *p, const double *const t[3], int i, int j) {
  int o0 = orient2d_sign(t[0], t[1], p, i, j), o1 = orient2d_sign(t[1], t[2], p, i, j),
      o2 = orient2d_sign(t[2], t[0], p, i, j);
  return !((o0 < 0 || o1 < 0 || o2 < 0) && (o0 > 0 || o1 > 0 || o2 > 0));
}

/* Coordinate plane in which the (non-degenerate) triangle t projects without collapsing. */
static void projection_plane(const double *const t[3], int *i, int *j) {
  double u[3], v[3];
  for (int k = 0; k < 3; ++k) u[k] = t[1][k] - t[0][k], v[k] = t[2][k] - t[0][k];
  double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (fabs(n[k]) > fabs(n[axis])) axis = k;
  /* A float component can round to the wrong winner; make sure the projection is exact. */
  for (int tries = 0; tries < 3; ++tries) {
    int a = (axis + 1) % 3, b = (axis + 2) % 3;
    if (orient2d_sign(t[0], t[1], t[2], a, b) != 0) {
      *i = a, *j = b;
      return;
    }
    axis = (axis + 1) % 3;
  }
  *i = 0, *j = 1;
}

/* Closed segment (s, e) against the closed non-degenerate triangle t. */
static int segment_hits_triangle(const double *s, const double *e, const double *const t[3]) {
  int o1 = piola__orient3d_sign(t[0], t[1], t[2], s),
      o2 = piola__orient3d_sign(t[0], t[1], t[2], e);
  if ((o1 > 0 && o2 > 0) || (o1 < 0 && o2 < 0)) return 0;
  if (o1 == 0 && o2 == 0) {
    int i, j;
    projection_plane(t, &i, &j);
    if (point_in_triangle_2d(s, t, i, j) || point_in_triangle_2d(e, t, i, j)) return 1;
    for (int k = 0; k < 3; ++k)
      if (segments_intersect_2d(s, e, t[k], t[(k + 1) % 3], i, j)) return 1;
    return 0;
  }
  int a = piola__orient3d_sign(s, e, t[0], t[1]), b = piola__orient3d_sign(s, e, t[1], t[2]),
      c = piola__orient3d_sign(s, e, t[2], t[0]);
  return !((a < 0 || b < 0 || c < 0) && (a > 0 || b > 0 || c > 0));
}

static int edges_hit_triangle(const double *const p[3], const double *const q[3]) {
  for (int k = 0; k < 3; ++k)
    if (segment_hits_triangle(p[k], p[(k + 1) % 3], q)) return 1;
  return 0;
}

int piola__triangles_intersect(const double *const p[3], const double *const q[3]) {
  /* Disjoint bounding boxes: no intersection (comparisons are exact). */
  for (int k = 0; k < 3; ++k) {
    double pl = fmin(p[0][k], fmin(p[1][k], p[2][k])), ph = fmax(p[0][k], fmax(p[1][k], p[2][k]));
    double ql = fmin(q[0][k], fmin(q[1][k], q[2][k])), qh = fmax(q[0][k], fmax(q[1][k], q[2][k]));
    if (ph < ql || qh < pl) return 0;
  }
  int pd = is_collinear(p[0], p[1], p[2]), qd = is_collinear(q[0], q[1], q[2]);
  if (pd && qd) return -1;
  /* Two non-coplanar triangles meet in a segment whose ends lie on edges of one or the
   * other; coplanar ones overlap only if an edge of one meets the other. So testing the
   * edges of each against the other decides it. A degenerate triangle is its edges. */
  if (pd) return edges_hit_triangle(p, q);
  if (qd) return edges_hit_triangle(q, p);
  return edges_hit_triangle(p, q) || edges_hit_triangle(q, p);
}
