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

/* ------------------------------------------------------------------ copies cut several times
 *
 * A copy's material is its tet on its side of each of its cuts: a convex cell. Each face
 * is clipped by every cut, and each cut's crack polygon (the single-plane one above) by
 * the others (Sutherland-Hodgman, keeping the orientation), so the polygons close the cell
 * as the faces and one crack do. A point made by clipping lies where the segment it
 * splits lies: on the smallest face of the tet holding both ends (their corners joined)
 * and on the cuts through both ends, plus the clipping cut. */

int32_t piola__fracture_copy_cuts(const solid_fracture *f, int32_t c, copy_cut out[FRACTURE_MAX_CUTS]) {
  if (f->event[c] < 0) return 0;
  out[0].event = f->event[c], out[0].side = f->side[c];
  memcpy(out[0].dist, f->dist + 4 * (size_t)c, sizeof out[0].dist);
  int32_t n = 1;
  for (int j = 0; j < FRACTURE_MAX_CUTS - 1; ++j) {
    const size_t slot = (size_t)(FRACTURE_MAX_CUTS - 1) * (size_t)c + (size_t)j;
    if (f->more_event[slot] < 0) break;
    out[n].event = f->more_event[slot], out[n].side = f->more_side[slot];
    memcpy(out[n].dist, f->more_dist + 4 * slot, sizeof out[n].dist);
    ++n;
  }
  return n;
}

static double det3(const double a[3], const double b[3], const double c[3]) {
  return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
         a[2] * (b[0] * c[1] - b[1] * c[0]);
}

/* p's weights from its corners and cuts alone (canonical order: corners by original id,
 * cuts by event), or fallback where they do not determine a point (a degenerate crossing). */
static void settle_weights(const copy_cut *cuts, const int32_t ids[4], cell_point *p, const double fallback[4]) {
  int corner[4], plane[FRACTURE_MAX_CUTS], nc = 0, np = 0;
  for (int k = 0; k < 4; ++k)
    if (p->corners >> k & 1) corner[nc++] = k;
  for (int j = 0; j < FRACTURE_MAX_CUTS; ++j)
    if (p->cuts >> j & 1) plane[np++] = j;
  for (int i = 1; i < nc; ++i)
    for (int j = i; j > 0 && ids[corner[j]] < ids[corner[j - 1]]; --j) {
      int tmp = corner[j];
      corner[j] = corner[j - 1], corner[j - 1] = tmp;
    }
  for (int i = 1; i < np; ++i)
    for (int j = i; j > 0 && cuts[plane[j]].event < cuts[plane[j - 1]].event; --j) {
      int tmp = plane[j];
      plane[j] = plane[j - 1], plane[j - 1] = tmp;
    }
  double w[4] = {0, 0, 0, 0}, v[4] = {0, 0, 0, 0};
  int ok = nc == np + 1;
  if (ok && nc == 1) v[0] = 1;
  else if (ok && nc == 2) {
    const double *d = cuts[plane[0]].dist;
    const double t = d[corner[0]] / (d[corner[0]] - d[corner[1]]);
    v[0] = 1 - t, v[1] = t;
  } else if (ok) {
    /* the null vector of the cuts' rows over the corners, by cofactors */
    double row[3][4];
    for (int j = 0; j < np; ++j)
      for (int i = 0; i < nc; ++i) row[j][i] = cuts[plane[j]].dist[corner[i]];
    if (nc == 3) {
      v[0] = row[0][1] * row[1][2] - row[0][2] * row[1][1];
      v[1] = row[0][2] * row[1][0] - row[0][0] * row[1][2];
      v[2] = row[0][0] * row[1][1] - row[0][1] * row[1][0];
    } else {
      for (int i = 0; i < 4; ++i) {
        double m[3][3];
        for (int j = 0; j < 3; ++j)
          for (int q = 0, col = 0; q < 4; ++q)
            if (q != i) m[j][col++] = row[j][q];
        v[i] = (i % 2 ? -1 : 1) * det3(m[0], m[1], m[2]);
      }
    }
    double sum = 0;
    for (int i = 0; i < nc; ++i) sum += v[i];
    for (int i = 0; i < nc; ++i) v[i] /= sum;
  }
  for (int i = 0; i < nc && ok; ++i) ok = isfinite(v[i]) && v[i] >= -1e-9 && v[i] <= 1 + 1e-9;
  if (!ok) {
    memcpy(p->w, fallback, sizeof p->w);
    return;
  }
  for (int i = 0; i < nc; ++i) w[corner[i]] = v[i];
  memcpy(p->w, w, sizeof p->w);
}

/* poly (n points) clipped to the material side of cut j; returns the new size. */
static int32_t clip_by_cut(const cell_point *poly, int32_t n, const copy_cut *cuts, int j,
                           const int32_t ids[4], cell_point *out) {
  double g[CELL_POLYGON_MAX];
  for (int32_t i = 0; i < n; ++i) {
    g[i] = 0;
    for (int k = 0; k < 4; ++k) g[i] += cuts[j].dist[k] * poly[i].w[k];
    g[i] *= cuts[j].side;
  }
  int32_t m = 0;
  for (int32_t i = 0; i < n && m + 2 <= CELL_POLYGON_MAX; ++i) {
    const int32_t next = (i + 1) % n;
    if (g[i] > 0) out[m++] = poly[i];
    if ((g[i] > 0) != (g[next] > 0)) {
      const double t = g[i] / (g[i] - g[next]);
      double fallback[4];
      for (int k = 0; k < 4; ++k) fallback[k] = poly[i].w[k] + t * (poly[next].w[k] - poly[i].w[k]);
      cell_point p = {(uint8_t)(poly[i].corners | poly[next].corners),
                      (uint8_t)((poly[i].cuts & poly[next].cuts) | 1u << j), {0, 0, 0, 0}};
      settle_weights(cuts, ids, &p, fallback);
      out[m++] = p;
    }
  }
  return m < 3 ? 0 : m;
}

static double cell_polygon_volume(const cell_point *poly, int32_t n) {
  double sum = 0;
  for (int32_t i = 1; i + 1 < n; ++i)
    sum += det3(poly[0].w + 1, poly[i].w + 1, poly[i + 1].w + 1);
  return sum;
}

static cell_point from_cut_point(cut_point p, int j) {
  cell_point q = {(uint8_t)(1u << p.lo | 1u << p.hi), (uint8_t)(p.lo == p.hi ? 0 : 1u << j), {0, 0, 0, 0}};
  q.w[p.lo] += 1 - p.t;
  q.w[p.hi] += p.t;
  return q;
}

void piola__fracture_cell_polygons(const copy_cut *cuts, int32_t n, const int32_t ids[4], cell_polygons *out) {
  memset(out, 0, sizeof *out);
  cell_point buffer[CELL_POLYGON_MAX];
  double v = 0;
  for (int k = 0; k < 4; ++k) {
    cell_point *poly = out->face[k];
    for (int i = 0; i < 3; ++i) {
      const int corner = piola__cut_tet_face[k][i];
      poly[i] = (cell_point){(uint8_t)(1u << corner), 0, {0, 0, 0, 0}};
      poly[i].w[corner] = 1;
    }
    int32_t size = 3;
    for (int j = 0; j < n && size > 0; ++j) {
      size = clip_by_cut(poly, size, cuts, j, ids, buffer);
      memcpy(poly, buffer, sizeof(cell_point) * (size_t)size);
    }
    out->face_size[k] = size;
    v += cell_polygon_volume(poly, size);
  }
  for (int j = 0; j < n; ++j) {
    copy_polygons single;
    piola__fracture_copy_polygons(cuts[j].dist, cuts[j].side, ids, &single);
    cell_point *poly = out->crack[j];
    int32_t size = single.crack_size;
    for (int32_t i = 0; i < size; ++i) poly[i] = from_cut_point(single.crack[i], j);
    for (int other = 0; other < n && size > 0; ++other) {
      if (other == j) continue;
      size = clip_by_cut(poly, size, cuts, other, ids, buffer);
      memcpy(poly, buffer, sizeof(cell_point) * (size_t)size);
    }
    out->crack_size[j] = size;
    v += cell_polygon_volume(poly, size);
  }
  out->fraction = v;
}
