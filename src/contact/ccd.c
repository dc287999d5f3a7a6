/* Continuous collision detection: coplanarity times and the distance checks at them. */
#include "contact/ccd.h"

#include <float.h>

#include "contact/proximity.h"

enum { MAX_CANDIDATES = 32 };

/* Real roots of a s^2 + b s + c in [0, 1] (to within 1e-12). When the discriminant is
 * negative the vertex of the parabola is returned instead: it is where the quadratic comes
 * closest to zero, which is what a candidate time is for. */
static int quadratic_candidates(double a, double b, double c, double r[2]) {
  double scale = fmax(fabs(a), fmax(fabs(b), fabs(c)));
  if (scale == 0.0) return 0;
  int n = 0;
  double roots[2];
  if (fabs(a) <= 1e-14 * scale) {
    if (fabs(b) <= 1e-14 * scale) return 0;
    roots[n++] = -c / b;
  } else {
    double disc = b * b - 4.0 * a * c;
    if (disc < 0.0) {
      roots[n++] = -b / (2.0 * a);
    } else {
      double q = -0.5 * (b + copysign(sqrt(disc), b));
      roots[n++] = q / a;
      if (q != 0.0) roots[n++] = c / q;
    }
  }
  int kept = 0;
  for (int i = 0; i < n; ++i) {
    double t = roots[i];
    if (t >= -1e-12 && t <= 1.0 + 1e-12) r[kept++] = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  }
  return kept;
}

static double cubic_value(const double c[4], double s) {
  return ((c[3] * s + c[2]) * s + c[1]) * s + c[0];
}

static void sort_times(double *t, int n) {
  for (int i = 1; i < n; ++i) {
    double x = t[i];
    int j = i - 1;
    while (j >= 0 && t[j] > x) t[j + 1] = t[j], --j;
    t[j + 1] = x;
  }
}

/* Coefficients of f(s) = (e1 x e2) . e3 with e_i = u_i + s du_i, lowest degree first. */
static void coplanarity_cubic(const vec3 u[3], const vec3 du[3], double c[4]) {
  vec3 n0 = vec3_cross(u[0], u[1]);
  vec3 n1 = vec3_add(vec3_cross(u[0], du[1]), vec3_cross(du[0], u[1]));
  vec3 n2 = vec3_cross(du[0], du[1]);
  c[0] = vec3_dot(n0, u[2]);
  c[1] = vec3_dot(n0, du[2]) + vec3_dot(n1, u[2]);
  c[2] = vec3_dot(n1, du[2]) + vec3_dot(n2, u[2]);
  c[3] = vec3_dot(n2, du[2]);
}

int piola__coplanarity_times(const vec3 u[3], const vec3 du[3], double times[8]) {
  double c[4];
  coplanarity_cubic(u, du, c);
  /* Break points: the ends and the critical points, between which f is monotone. */
  double brk[4];
  int nb = 0;
  brk[nb++] = 0.0;
  double crit[2];
  int nc = quadratic_candidates(3.0 * c[3], 2.0 * c[2], c[1], crit);
  for (int i = 0; i < nc; ++i) brk[nb++] = crit[i];
  brk[nb++] = 1.0;
  sort_times(brk, nb);
  int n = 0;
  for (int i = 0; i < nb; ++i) times[n++] = brk[i];
  for (int i = 0; i + 1 < nb; ++i) {
    double lo = brk[i], hi = brk[i + 1];
    double flo = cubic_value(c, lo), fhi = cubic_value(c, hi);
    if (!((flo < 0.0 && fhi > 0.0) || (flo > 0.0 && fhi < 0.0))) continue;
    for (int it = 0; it < 200; ++it) {
      double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      double fm = cubic_value(c, mid);
      if (fm == 0.0) {
        lo = hi = mid;
        break;
      }
      if ((fm < 0.0) == (flo < 0.0))
        lo = mid, flo = fm;
      else
        hi = mid;
    }
    times[n++] = 0.5 * (lo + hi);
  }
  sort_times(times, n);
  return n;
}

static vec3 at(vec3 x, vec3 d, double s) { return vec3_add(x, vec3_scale(d, s)); }

/* Is the cubic negligible against the size of its terms (the pair moves within one plane)? */
static int is_flat(const vec3 u[3], const vec3 du[3]) {
  double c[4];
  coplanarity_cubic(u, du, c);
  double len = 0.0;
  for (int i = 0; i < 3; ++i) len = fmax(len, vec3_norm(u[i]) + vec3_norm(du[i]));
  double size = len * len * len;
  return fabs(c[0]) + fabs(c[1]) + fabs(c[2]) + fabs(c[3]) <= 1e-10 * size;
}

/* Times at which point p crosses the line of (a, b) inside the plane with normal nrm. */
static int line_crossings(vec3 a, vec3 da, vec3 b, vec3 db, vec3 p, vec3 dp, vec3 nrm,
                          double r[2]) {
  vec3 A0 = vec3_sub(b, a), dA = vec3_sub(db, da), B0 = vec3_sub(p, a), dB = vec3_sub(dp, da);
  double c0 = vec3_dot(vec3_cross(A0, B0), nrm);
  double c1 = vec3_dot(vec3_add(vec3_cross(A0, dB), vec3_cross(dA, B0)), nrm);
  double c2 = vec3_dot(vec3_cross(dA, dB), nrm);
  return quadratic_candidates(c2, c1, c0, r);
}

/* The largest of a few cross products, as the normal of a plane that all four points stay in. */
static vec3 common_plane_normal(const vec3 x[4], const vec3 d[4]) {
  vec3 best = {0, 0, 0};
  for (int k = 0; k <= 2; ++k) {
    double s = 0.5 * k;
    vec3 p[4];
    for (int i = 0; i < 4; ++i) p[i] = at(x[i], d[i], s);
    vec3 cand[3] = {vec3_cross(vec3_sub(p[1], p[0]), vec3_sub(p[2], p[0])),
                    vec3_cross(vec3_sub(p[1], p[0]), vec3_sub(p[3], p[0])),
                    vec3_cross(vec3_sub(p[3], p[2]), vec3_sub(p[1], p[2]))};
    for (int j = 0; j < 3; ++j)
      if (vec3_norm2(cand[j]) > vec3_norm2(best)) best = cand[j];
  }
  double len = vec3_norm(best);
  return len > 0.0 ? vec3_scale(best, 1.0 / len) : best;
}

/* All four points on one line: the times at which two of them pass each other along it. */
static int collinear_meetings(const vec3 x[4], const vec3 d[4], double out[12]) {
  vec3 dir = {0, 0, 0};
  for (int k = 0; k <= 2; ++k)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        vec3 a = vec3_sub(at(x[i], d[i], 0.5 * k), at(x[j], d[j], 0.5 * k));
        if (vec3_norm2(a) > vec3_norm2(dir)) dir = a;
      }
  int n = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      double g0 = vec3_dot(vec3_sub(x[i], x[j]), dir), g1 = vec3_dot(vec3_sub(d[i], d[j]), dir);
      if (g1 == 0.0) continue;
      double s = -g0 / g1;
      if (s >= 0.0 && s <= 1.0) out[n++] = s;
    }
  return n;
}

/* Orients and stores the normal of a hit (see piola__ccd_hit). */
static void orient_normal(const vec3 x[4], const vec3 d[4], vec3 n, piola__ccd_hit *hit) {
  vec3 rel0 = {0, 0, 0}, drel = {0, 0, 0};
  double size = 0.0;
  for (int k = 0; k < 4; ++k) {
    rel0 = vec3_add(rel0, vec3_scale(x[k], hit->w[k]));
    drel = vec3_add(drel, vec3_scale(d[k], hit->w[k]));
    size = fmax(size, vec3_norm(x[k]));
  }
  double g = vec3_dot(rel0, n);
  if (fabs(g) > 1e-14 * size) {
    if (g < 0.0) n = vec3_neg(n);
  } else if (vec3_dot(drel, n) > 0.0) {
    n = vec3_neg(n);
  }
  hit->normal = n;
}

static vec3 unit_or_zero(vec3 v) {
  double len = vec3_norm(v);
  return len > 0.0 ? vec3_scale(v, 1.0 / len) : v;
}

/* A normal for a hit whose preferred normal (plane of the pair at s) is degenerate: the
 * direction between the closest points, at s or else at the start, or else any axis. */
static vec3 fallback_normal(const vec3 x[4], const vec3 d[4], const double w[4], double s) {
  vec3 rel_s = {0, 0, 0}, rel_0 = {0, 0, 0};
  for (int k = 0; k < 4; ++k) {
    rel_s = vec3_add(rel_s, vec3_scale(at(x[k], d[k], s), w[k]));
    rel_0 = vec3_add(rel_0, vec3_scale(x[k], w[k]));
  }
  vec3 n = unit_or_zero(rel_s);
  if (vec3_norm2(n) == 0.0) n = unit_or_zero(rel_0);
  if (vec3_norm2(n) == 0.0) n = (vec3){0, 0, 1};
  return n;
}

typedef enum pair_kind { POINT_TRIANGLE, EDGE_EDGE } pair_kind;

/* Edge vectors whose triple product is the coplanarity function of the pair. */
static void edge_vectors(pair_kind kind, const vec3 x[4], const vec3 d[4], vec3 u[3], vec3 du[3]) {
  if (kind == POINT_TRIANGLE) {
    u[0] = vec3_sub(x[2], x[1]), du[0] = vec3_sub(d[2], d[1]);
    u[1] = vec3_sub(x[3], x[1]), du[1] = vec3_sub(d[3], d[1]);
    u[2] = vec3_sub(x[0], x[1]), du[2] = vec3_sub(d[0], d[1]);
  } else {
    u[0] = vec3_sub(x[1], x[0]), du[0] = vec3_sub(d[1], d[0]);
    u[1] = vec3_sub(x[3], x[2]), du[1] = vec3_sub(d[3], d[2]);
    u[2] = vec3_sub(x[2], x[0]), du[2] = vec3_sub(d[2], d[0]);
  }
}

static int ccd_pair(pair_kind kind, const vec3 x[4], const vec3 d[4], double eps,
                    piola__ccd_hit *hit) {
  vec3 u[3], du[3];
  edge_vectors(kind, x, d, u, du);
  double times[MAX_CANDIDATES];
  int n = piola__coplanarity_times(u, du, times);
  if (is_flat(u, du)) {
    vec3 nrm = common_plane_normal(x, d);
    if (vec3_norm2(nrm) == 0.0) n += collinear_meetings(x, d, times + n);
    double r[2];
    int m;
    if (kind == POINT_TRIANGLE) {
      static const int edges[3][2] = {{1, 2}, {2, 3}, {3, 1}};
      for (int e = 0; e < 3; ++e) {
        m = line_crossings(x[edges[e][0]], d[edges[e][0]], x[edges[e][1]], d[edges[e][1]], x[0],
                           d[0], nrm, r);
        for (int i = 0; i < m; ++i) times[n++] = r[i];
      }
    } else {
      static const int lines[4][3] = {{0, 1, 2}, {0, 1, 3}, {2, 3, 0}, {2, 3, 1}};
      for (int e = 0; e < 4; ++e) {
        const int *l = lines[e];
        m = line_crossings(x[l[0]], d[l[0]], x[l[1]], d[l[1]], x[l[2]], d[l[2]], nrm, r);
        for (int i = 0; i < m; ++i) times[n++] = r[i];
      }
    }
    sort_times(times, n);
  }
  double len = 0.0;
  for (int i = 0; i < 3; ++i) len = fmax(len, vec3_norm(u[i]) + vec3_norm(du[i]));
  const double slack = 64.0 * DBL_EPSILON * len * len * len;
  for (int i = 0; i < n; ++i) {
    if (i > 0 && times[i] == times[i - 1]) continue;
    double s = times[i];
    vec3 p[4];
    for (int k = 0; k < 4; ++k) p[k] = at(x[k], d[k], s);
    /* Cheap filter: |f| is |e1 x e2| times the distance to a plane (or between lines), which
     * is at most the distance of the pair. */
    static const vec3 still[4] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    vec3 e[3], de[3];
    edge_vectors(kind, p, still, e, de);
    vec3 cr = vec3_cross(e[0], e[1]);
    double f = vec3_dot(cr, e[2]);
    if (fabs(f) > 1.01 * eps * vec3_norm(cr) + slack) continue;
    double dist2;
    if (kind == POINT_TRIANGLE) {
      double b[3];
      dist2 = piola__point_triangle_closest(p[0], p[1], p[2], p[3], b);
      hit->w[0] = 1.0, hit->w[1] = -b[0], hit->w[2] = -b[1], hit->w[3] = -b[2];
    } else {
      double a, b;
      dist2 = piola__segment_segment_closest(p[0], p[1], p[2], p[3], &a, &b);
      hit->w[0] = 1.0 - a, hit->w[1] = a, hit->w[2] = -(1.0 - b), hit->w[3] = -b;
    }
    if (!(dist2 < eps * eps)) continue;
    hit->s = s;
    hit->distance = sqrt(dist2);
    vec3 normal = unit_or_zero(cr);
    /* Near-parallel edges or a collapsed triangle: the plane's normal means little. */
    if (vec3_norm(cr) <= 1e-8 * vec3_norm(e[0]) * vec3_norm(e[1]) || vec3_norm2(normal) == 0.0)
      normal = fallback_normal(x, d, hit->w, s);
    orient_normal(x, d, normal, hit);
    return 1;
  }
  return 0;
}

int piola__ccd_point_triangle(const vec3 x[4], const vec3 d[4], double eps, piola__ccd_hit *hit) {
  return ccd_pair(POINT_TRIANGLE, x, d, eps, hit);
}

int piola__ccd_edge_edge(const vec3 x[4], const vec3 d[4], double eps, piola__ccd_hit *hit) {
  return ccd_pair(EDGE_EDGE, x, d, eps, hit);
}
