/* The polygons of one cut tet copy in barycentric coordinates: each face clipped to the
 * copy's side of the crack, the crack polygon, and the material fraction from them.
 *
 * Each face is clipped against the plane (Sutherland-Hodgman); where the clipped outline
 * leaves the material (exit point X) and comes back (entry point Y), its edge X -> Y runs
 * along the crack. The crack polygon is closed from those edges reversed (Y -> X), so the
 * faces and the crack together are a closed surface, every edge traversed once each way,
 * outward from the material. The fraction is that surface's enclosed volume over the
 * tet's, by the divergence theorem in barycentric coordinates: the same polygons the
 * output draws give the mass, so the two cannot disagree. */
#include <math.h>
#include <string.h>

#include "sim/fracture_internal.h"

const int8_t piola__cut_tet_face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

static cut_point corner(int a) { return (cut_point){(int8_t)a, (int8_t)a, 0.0}; }

static cut_point crossing(const double dist[4], const int32_t ids[4], int a, int b) {
  if (ids[b] < ids[a]) {
    int tmp = a;
    a = b, b = tmp;
  }
  return (cut_point){(int8_t)a, (int8_t)b, dist[a] / (dist[a] - dist[b])};
}

/* The point in barycentric coordinates (lambda_1, lambda_2, lambda_3; corner 0 is the
 * origin): a linear image of the rest tet with positive determinant. */
static void lambda3(cut_point p, double out[3]) {
  double l[4] = {0, 0, 0, 0};
  l[p.lo] += 1.0 - p.t;
  l[p.hi] += p.t;
  out[0] = l[1], out[1] = l[2], out[2] = l[3];
}

static double polygon_volume(const cut_point *poly, int32_t n) {
  double sum = 0, a[3], b[3], c[3];
  if (n < 3) return 0;
  lambda3(poly[0], a);
  for (int32_t i = 1; i + 1 < n; ++i) {
    lambda3(poly[i], b);
    lambda3(poly[i + 1], c);
    sum += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return sum; /* 6 x the signed volume of the cone from the origin = its share of fraction */
}

static int same_point(cut_point p, cut_point q) { return p.lo == q.lo && p.hi == q.hi; }

void piola__fracture_copy_polygons(const double dist[4], int side, const int32_t ids[4],
                                   copy_polygons *out) {
  memset(out, 0, sizeof *out);
  cut_point exit_of[4], entry_of[4];
  int32_t crack_edges = 0;
  for (int k = 0; k < 4; ++k) {
    const int8_t *f = piola__cut_tet_face[k];
    cut_point pending_exit = {0, 0, 0};
    int have_exit = 0, first_entry_wait = 0;
    cut_point first_entry = {0, 0, 0};
    for (int e = 0; e < 3; ++e) {
      int a = f[e], b = f[(e + 1) % 3];
      int in_a = side * dist[a] > 0, in_b = side * dist[b] > 0;
      if (in_a) out->face[k][out->face_size[k]++] = corner(a);
      if (in_a != in_b) {
        cut_point x = crossing(dist, ids, a, b);
        out->face[k][out->face_size[k]++] = x;
        if (in_a) pending_exit = x, have_exit = 1;
        else if (have_exit) {
          exit_of[crack_edges] = pending_exit, entry_of[crack_edges++] = x;
          have_exit = 0;
        } else first_entry = x, first_entry_wait = 1;
      }
    }
    if (have_exit && first_entry_wait) exit_of[crack_edges] = pending_exit, entry_of[crack_edges++] = first_entry;
  }
  /* the crack: edges entry -> exit, chained end to start */
  if (crack_edges >= 3) {
    int used[4] = {0, 0, 0, 0};
    int cur = 0;
    used[0] = 1;
    out->crack[out->crack_size++] = entry_of[0];
    for (int32_t step = 1; step < crack_edges; ++step) {
      cut_point end = exit_of[cur];
      int next = -1;
      for (int32_t j = 0; j < crack_edges; ++j)
        if (!used[j] && same_point(entry_of[j], end)) next = j;
      if (next < 0) break;
      used[next] = 1;
      out->crack[out->crack_size++] = entry_of[next];
      cur = next;
    }
  }
  double v = polygon_volume(out->crack, out->crack_size);
  for (int k = 0; k < 4; ++k) v += polygon_volume(out->face[k], out->face_size[k]);
  out->fraction = v;
}
