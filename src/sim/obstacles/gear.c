/* Gear obstacle: a toothed disk, the extrusion of a polygon outline along the axis.
 *
 * The outline is the polar curve r(phi) of tooth_count identical trapezoidal teeth: per tooth
 * period P = 2 pi / tooth_count, with u in [-1/2, 1/2) the position in the period relative
 * to the tooth centre,
 *   |u| <= TIP_HALF   r = tip radius               (the tooth's top land)
 *   |u| >= ROOT_FROM  r = tip radius - tooth_depth (the root land between teeth)
 *   in between        a straight flank
 * sampled at PIOLA_GEAR_VERTICES_PER_TOOTH vertices (the lands are polygon chords). The
 * shape IS that polygon extruded by +- half_length, and the signed distance to it is exact:
 *   2D: distance to the nearest outline edge, negative inside (the outline is star-shaped
 *       about the centre, so inside is "left of the outline edge the ray from the centre
 *       crosses", the winding test for this polygon);
 *   3D: with d2 the 2D distance and dh = |height| - half_length, max(d2, dh) when both are
 *       <= 0, else the length of (max(d2, 0), max(dh, 0)): exact for an extrusion.
 * Teeth are searched in order of angular separation from the point and the search stops
 * when a lower bound on the distance to the remaining teeth (from their angular separation
 * and the annulus that holds every edge) reaches the best distance found: exact, and only a
 * few teeth for points near the gear. Inside the inscribed disk a thin gear's distance is
 * the axial one whenever that is provably nearer than the outline, with no edge search.
 *
 * Tooth 0 is centred on the direction e1 of piola__shape_frame(axis) (for axis z that is +x), and
 * teeth follow counter-clockwise about the axis. The top land (2 TIP_HALF of a period) is
 * narrower than the root land (1 - 2 ROOT_FROM) so that a tooth fits into the gap of an
 * equal gear placed at centre distance 2 radius - tooth_depth with a gap facing it; see
 * docs/obstacles.md. */
#include <math.h>
#include <stdlib.h>

#include "common/status_report.h"
#include "geometry/analytic_shapes.h"
#include "sim/obstacles/obstacle_shapes.h"

#define TIP_HALF 0.09
#define ROOT_FROM 0.36

/* u positions (fraction of a period from the tooth centre) of the vertices of one tooth. */
static void tooth_vertex_u(double u[PIOLA_GEAR_VERTICES_PER_TOOTH + 1]) {
  int n = 0;
  for (int k = 0; k <= 4; ++k) u[n++] = -0.5 + k * (0.5 - ROOT_FROM) / 4.0; /* ends at -ROOT_FROM */
  for (int k = 0; k <= 6; ++k) u[n++] = -TIP_HALF + k * (2.0 * TIP_HALF) / 6.0;
  for (int k = 0; k <= 3; ++k) u[n++] = ROOT_FROM + k * (0.5 - ROOT_FROM) / 4.0;
  u[n] = 0.5; /* the next tooth's first vertex, closing the last edge */
}

static double profile_radius_u(double u, double tip, double root) {
  double a = fabs(u);
  if (a <= TIP_HALF) return tip;
  if (a >= ROOT_FROM) return root;
  return tip + (root - tip) * (a - TIP_HALF) / (ROOT_FROM - TIP_HALF);
}

double piola__gear_profile_radius(const piola__gear_shape *shape, double phi) {
  double period = 2.0 * M_PI / shape->tooth_count;
  double w = phi / period;
  double u = w - floor(w + 0.5);
  return profile_radius_u(u, shape->tip_radius, shape->root_radius);
}

typedef struct nearest2 {
  double dist2;  /* squared distance to the nearest point found */
  double cx, cy; /* that point */
  int32_t edge;  /* its edge (start vertex index) */
} nearest2;

static void visit_edge(const piola__gear_shape *shape, int32_t i, double x, double y,
                       nearest2 *best) {
  int32_t j = i + 1 == shape->vertex_count ? 0 : i + 1;
  double ax = shape->outline[2 * i], ay = shape->outline[2 * i + 1];
  double ex = shape->outline[2 * j] - ax, ey = shape->outline[2 * j + 1] - ay;
  double s = ((x - ax) * ex + (y - ay) * ey) / (ex * ex + ey * ey);
  s = s < 0 ? 0 : (s > 1 ? 1 : s);
  double cx = ax + s * ex, cy = ay + s * ey;
  double d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
  if (d2 < best->dist2) *best = (nearest2){d2, cx, cy, i};
}

piola_status piola__gear_init(const piola_obstacle_def *def, piola__gear_shape *shape) {
  shape->outline = NULL;
  PIOLA_TRY(piola__obstacle_positive(def->radius, "gear radius"));
  PIOLA_TRY(piola__obstacle_positive(def->half_length, "gear half_length"));
  PIOLA_TRY(piola__obstacle_positive(def->tooth_depth, "gear tooth_depth"));
  if (def->tooth_count < 3 || def->tooth_count > 100000)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "gear tooth_count must be in [3, 100000], got %d", def->tooth_count);
  if (!(def->tooth_depth < def->radius))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "gear tooth_depth (%g m) must be < radius (%g m)", def->tooth_depth,
                      def->radius);
  PIOLA_TRY(piola__obstacle_unit_axis(def->axis, "gear axis", &shape->axis));
  shape->center = def->center;
  shape->half_length = def->half_length;
  shape->tip_radius = def->radius;
  shape->root_radius = def->radius - def->tooth_depth;
  shape->tooth_count = def->tooth_count;
  piola__shape_frame(shape->axis, &shape->e1, &shape->e2);

  int32_t v = PIOLA_GEAR_VERTICES_PER_TOOTH;
  shape->vertex_count = v * def->tooth_count;
  shape->outline = malloc(sizeof(double) * 2 * (size_t)shape->vertex_count);
  if (!shape->outline)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "gear outline of %d vertices",
                      shape->vertex_count);
  double u[PIOLA_GEAR_VERTICES_PER_TOOTH + 1];
  tooth_vertex_u(u);
  double period = 2.0 * M_PI / def->tooth_count;
  for (int32_t j = 0; j < def->tooth_count; ++j) {
    for (int32_t k = 0; k < v; ++k) {
      double r = profile_radius_u(u[k], shape->tip_radius, shape->root_radius);
      double phi = (j + u[k]) * period;
      shape->outline[2 * (j * v + k)] = r * cos(phi);
      shape->outline[2 * (j * v + k) + 1] = r * sin(phi);
    }
  }
  /* The largest disk about the centre inside the outline: the nearest edge to the centre. */
  shape->inner_radius = shape->tip_radius;
  for (int32_t i = 0; i < shape->vertex_count; ++i) {
    nearest2 to_centre = {INFINITY, 0, 0, 0};
    visit_edge(shape, i, 0.0, 0.0, &to_centre);
    shape->inner_radius = fmin(shape->inner_radius, sqrt(to_centre.dist2));
  }
  return PIOLA_OK;
}

void piola__gear_free(piola__gear_shape *shape) {
  free(shape->outline);
  shape->outline = NULL;
}

/* Signed 2D distance to the outline at (x, y) in the gear plane; (nx, ny) outward normal. */
static double outline_distance(const piola__gear_shape *shape, double x, double y, double *nx,
                               double *ny) {
  int32_t n = shape->tooth_count, v = PIOLA_GEAR_VERTICES_PER_TOOTH;
  double period = 2.0 * M_PI / n;
  double rho = hypot(x, y);
  double w = atan2(y, x) / period;
  double k_real = floor(w + 0.5);
  double u = w - k_real;
  u = u < -0.5 ? -0.5 : (u > 0.5 ? 0.5 : u);
  int32_t k0 = ((int32_t)k_real % n + n) % n;

  /* Teeth in order of angular separation from the point: tooth k0 + m and k0 - m are at
   * least beta = (m - 1/2 - |u|) P away in angle, and every edge lies in the annulus
   * [inner_radius, tip_radius], so no point of them is nearer than the bound below; stop at
   * the first m whose bound cannot beat the best distance found. */
  nearest2 best = {INFINITY, 0, 0, 0};
  for (int32_t m = 0; 2 * m <= n; ++m) {
    double beta = fmin(fmax((m - 0.5 - fabs(u)) * period, 0.0), M_PI);
    double r = fmin(fmax(rho * cos(beta), shape->inner_radius), shape->tip_radius);
    double bound2 = r * r + rho * rho - 2.0 * rho * r * cos(beta);
    if (m > 0 && bound2 >= best.dist2) break;
    int32_t plus = (k0 + m) % n, minus = ((k0 - m) % n + n) % n;
    for (int32_t k = 0; k < v; ++k) visit_edge(shape, plus * v + k, x, y, &best);
    if (minus != plus)
      for (int32_t k = 0; k < v; ++k) visit_edge(shape, minus * v + k, x, y, &best);
  }

  /* Inside test: the outline is star-shaped about the centre, so the point is inside iff it
   * is left of the edge of tooth k0 that the ray from the centre through it crosses. */
  double uk[PIOLA_GEAR_VERTICES_PER_TOOTH + 1];
  tooth_vertex_u(uk);
  int32_t e = 0;
  while (e < v - 1 && uk[e + 1] < u) ++e;
  int32_t i = k0 * v + e, j = (i + 1) % shape->vertex_count;
  double ax = shape->outline[2 * i], ay = shape->outline[2 * i + 1];
  double ex = shape->outline[2 * j] - ax, ey = shape->outline[2 * j + 1] - ay;
  bool inside = ex * (y - ay) - ey * (x - ax) > 0;

  double d = sqrt(best.dist2);
  if (d > 1e-14 * shape->tip_radius) {
    double s = inside ? -1.0 / d : 1.0 / d;
    *nx = (x - best.cx) * s;
    *ny = (y - best.cy) * s;
  } else {
    /* On the outline: the outward normal of the nearest edge (right of a CCW edge). */
    int32_t b = best.edge, c = (b + 1) % shape->vertex_count;
    double fx = shape->outline[2 * c] - shape->outline[2 * b];
    double fy = shape->outline[2 * c + 1] - shape->outline[2 * b + 1];
    double len = hypot(fx, fy);
    *nx = fy / len;
    *ny = -fx / len;
  }
  return inside ? -d : d;
}

double piola__gear_distance(const piola__gear_shape *shape, vec3 p, vec3 *normal) {
  vec3 q = vec3_sub(p, shape->center);
  double x = vec3_dot(q, shape->e1), y = vec3_dot(q, shape->e2), h = vec3_dot(q, shape->axis);
  double dh = fabs(h) - shape->half_length;
  vec3 axial_n = h < 0 ? vec3_neg(shape->axis) : shape->axis;
  /* Inside the inscribed disk the outline is at least inner_radius - rho away; when the face
   * is nearer than that (or the point is beyond the face) the axial distance is the answer. */
  double rho = hypot(x, y);
  if (rho < shape->inner_radius && dh >= rho - shape->inner_radius) {
    if (normal) *normal = axial_n;
    return dh;
  }
  double nx, ny;
  double d2 = outline_distance(shape, x, y, &nx, &ny);
  vec3 radial_n = vec3_add(vec3_scale(shape->e1, nx), vec3_scale(shape->e2, ny));
  if (d2 <= 0 && dh <= 0) {
    if (normal) *normal = d2 >= dh ? radial_n : axial_n;
    return fmax(d2, dh);
  }
  double a = fmax(d2, 0), b = fmax(dh, 0);
  double dist = hypot(a, b);
  if (normal)
    *normal = vec3_scale(vec3_add(vec3_scale(radial_n, a), vec3_scale(axial_n, b)), 1.0 / dist);
  return dist;
}
