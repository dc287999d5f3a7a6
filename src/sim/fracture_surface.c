/* The surface of each fragment of a cut solid, at the current positions: the boundary
 * faces of the original mesh clipped to each copy's material, and each cut copy's crack
 * polygon, fanned into triangles. Faces between two tets are never drawn: material on the
 * other side of such a face either touches this copy's (then they are one fragment and
 * the face is inside it) or has zero area there.
 *
 * A point is the same vertex in every copy of a fragment that names it the same way: a
 * corner by its node, a crack crossing by the nodes of its edge and the cut that made it
 * (copies sharing both nodes were cut together, so they computed the same crossing), a
 * point where two cracks meet on a face by the face's nodes and both cuts, one where three
 * meet inside a tet by its four nodes and the three cuts. So each fragment's surface is
 * closed wherever its cuts meet the body's surface through tets cut by the same plane. */
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "sim/fracture_internal.h"
#include "sim/world_internal.h"

/* A named point: its nodes in order of original vertex id (-1 after the last), the cuts
 * through it in order of event id (-1 after the last), its weights per node. */
typedef struct surface_point {
  int32_t fragment, node[4], event[FRACTURE_MAX_CUTS];
  double w[4];
  int32_t order;                 /* position in the emitted list */
} surface_point;

/* Compares names: fragment, first node, second node (a corner's own node again), first
 * cut, then the rest, so a solid whose tets are cut once numbers its vertices as by
 * (fragment, a, b, cut). */
static int same_name(const surface_point *p, const surface_point *q) {
  if (p->fragment != q->fragment) return p->fragment < q->fragment ? -1 : 1;
  const int32_t pk[7] = {p->node[0], p->node[1] >= 0 ? p->node[1] : p->node[0], p->event[0], p->node[2],
                         p->node[3], p->event[1], p->event[2]};
  const int32_t qk[7] = {q->node[0], q->node[1] >= 0 ? q->node[1] : q->node[0], q->event[0], q->node[2],
                         q->node[3], q->event[1], q->event[2]};
  for (int k = 0; k < 7; ++k)
    if (pk[k] != qk[k]) return pk[k] < qk[k] ? -1 : 1;
  return 0;
}

static int by_name(const void *pa, const void *pb) {
  const surface_point *p = pa, *q = pb;
  const int c = same_name(p, q);
  if (c) return c;
  return p->order < q->order ? -1 : p->order > q->order;
}

static int is_corner(const surface_point *p) { return p->node[1] < 0; }
/* a crossing of an edge by one crack */
static int is_edge_crossing(const surface_point *p) { return p->node[2] < 0 && p->node[1] >= 0; }

void piola_fracture_surface_free(piola_fracture_surface *s) {
  if (!s) return;
  free(s->positions), free(s->triangles), free(s->fragment_start);
  memset(s, 0, sizeof *s);
}

/* Appends polygon poly of copy c (its points, named, and a record of it); cuts: the
 * copy's cuts, ids: its original tet's vertex ids. */
static void emit(const solid_fracture *f, const int32_t *nodes, int32_t c, const copy_cut *cuts,
                 const int32_t ids[4], const cell_point *poly, int32_t size, surface_point *points,
                 int32_t *np, int32_t *polygon, int32_t *npoly) {
  if (size < 3) return;
  polygon[2 * *npoly] = *np, polygon[2 * *npoly + 1] = size, ++*npoly;
  for (int32_t i = 0; i < size; ++i) {
    surface_point *p = &points[(*np)++];
    p->fragment = f->fragment[c];
    int corner[4], n = 0, m = 0;
    for (int k = 0; k < 4; ++k)
      if (poly[i].corners >> k & 1) corner[n++] = k;
    for (int a = 1; a < n; ++a)
      for (int b = a; b > 0 && ids[corner[b]] < ids[corner[b - 1]]; --b) {
        int tmp = corner[b];
        corner[b] = corner[b - 1], corner[b - 1] = tmp;
      }
    for (int k = 0; k < 4; ++k) {
      p->node[k] = k < n ? nodes[4 * c + corner[k]] : -1;
      p->w[k] = k < n ? poly[i].w[corner[k]] : 0;
    }
    for (int j = 0; j < FRACTURE_MAX_CUTS; ++j)
      if (poly[i].cuts >> j & 1) {
        int b = m++;
        for (; b > 0 && p->event[b - 1] > cuts[j].event; --b) p->event[b] = p->event[b - 1];
        p->event[b] = cuts[j].event;
      }
    for (int j = m; j < FRACTURE_MAX_CUTS; ++j) p->event[j] = -1;
  }
}

/* edge crossings by fragment and the unordered pair of their nodes */
static int by_edge_name(const void *pa, const void *pb) {
  const surface_point *p = pa, *q = pb;
  if (p->fragment != q->fragment) return p->fragment < q->fragment ? -1 : 1;
  int32_t pl = p->node[0] < p->node[1] ? p->node[0] : p->node[1], ph = p->node[0] < p->node[1] ? p->node[1] : p->node[0];
  int32_t ql = q->node[0] < q->node[1] ? q->node[0] : q->node[1], qh = q->node[0] < q->node[1] ? q->node[1] : q->node[0];
  if (pl != ql) return pl < ql ? -1 : 1;
  return ph < qh ? -1 : ph > qh;
}

piola_status piola_world_solid_fracture_surface(const piola_world *w, int32_t solid,
                                                piola_fracture_surface *out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture surface: NULL argument");
  memset(out, 0, sizeof *out);
  const world_body *b = w ? piola__world_body_of(w, PIOLA_BODY_SOLID, solid) : NULL;
  if (!b || !b->fracture)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture surface: solid %d has no fracture state", (int)solid);
  return piola__fracture_surface_build(b, 0, out, NULL);
}

piola_status piola__fracture_surface_build(const world_body *b, double inset, piola_fracture_surface *out,
                                           fracture_surface_point **where) {
  memset(out, 0, sizeof *out);
  if (where) *where = NULL;
  const solid_fracture *f = b->fracture;
  const int32_t *nodes = piola_elastic_body_tets(b->solid);
  /* at most 4 faces and 3 cracks of CELL_POLYGON_MAX points per copy; a polygon's edge
   * between two corners gains at most one point, so the points at most double */
  const size_t cap = (4 + FRACTURE_MAX_CUTS) * CELL_POLYGON_MAX * (size_t)f->copy_count + 1;
  surface_point *raw = malloc(sizeof *raw * cap), *points = malloc(2 * sizeof *points * cap);
  surface_point *crossings = malloc(sizeof *crossings * cap);
  int32_t *polygon = malloc(2 * sizeof(int32_t) * cap);
  int32_t *tri = malloc(3 * sizeof(int32_t) * 2 * cap), *index = malloc(2 * sizeof(int32_t) * cap);
  int32_t *triangle_fragment = malloc(2 * sizeof(int32_t) * cap);
  if (!raw || !points || !crossings || !polygon || !tri || !index || !triangle_fragment) {
    free(raw), free(points), free(crossings), free(polygon), free(tri), free(index), free(triangle_fragment);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture surface: out of memory");
  }
  int32_t nraw = 0, npoly = 0;
  for (int32_t c = 0; c < f->copy_count; ++c) {
    const int32_t t = f->parent[c], *ids = f->tets + 4 * t;
    copy_cut cuts[FRACTURE_MAX_CUTS];
    const int32_t n = piola__fracture_copy_cuts(f, c, cuts);
    if (n == 0) {
      for (int k = 0; k < 4; ++k) {
        if (f->neighbor[4 * t + k] >= 0) continue;
        cell_point face[3];
        for (int i = 0; i < 3; ++i) {
          const int corner = piola__cut_tet_face[k][i];
          face[i] = (cell_point){(uint8_t)(1u << corner), 0, {0, 0, 0, 0}};
          face[i].w[corner] = 1;
        }
        emit(f, nodes, c, cuts, ids, face, 3, raw, &nraw, polygon, &npoly);
      }
    } else {
      /* inset: the level sets side * inset instead of 0 (the same edges are crossed) */
      for (int32_t j = 0; j < n; ++j)
        for (int k = 0; k < 4; ++k) cuts[j].dist[k] -= cuts[j].side * inset;
      cell_polygons poly;
      piola__fracture_cell_polygons(cuts, n, ids, &poly);
      for (int k = 0; k < 4; ++k)
        if (f->neighbor[4 * t + k] < 0)
          emit(f, nodes, c, cuts, ids, poly.face[k], poly.face_size[k], raw, &nraw, polygon, &npoly);
      for (int32_t j = 0; j < n; ++j)
        emit(f, nodes, c, cuts, ids, poly.crack[j], poly.crack_size[j], raw, &nraw, polygon, &npoly);
    }
  }
  /* A crack that ends inside the solid's surface (a crack front, a blade that does not reach
   * all the way) puts a point on an edge that a whole neighbour's boundary face has between
   * two corners: that face takes the point too, so the surface has no T-junction there. */
  int32_t ncross = 0;
  for (int32_t i = 0; i < nraw; ++i)
    if (is_edge_crossing(&raw[i])) crossings[ncross++] = raw[i];
  qsort(crossings, (size_t)ncross, sizeof *crossings, by_edge_name);
  int32_t np = 0, nt = 0;
  for (int32_t g = 0; g < npoly; ++g) {
    const int32_t first = polygon[2 * g], size = polygon[2 * g + 1], base = np;
    int32_t apex = 0;
    for (int32_t i = 0; i < size; ++i) {
      const surface_point *p = &raw[first + i], *q = &raw[first + (i + 1) % size];
      points[np] = *p, points[np].order = np, ++np;
      if (!is_corner(p) || !is_corner(q) || ncross == 0) continue;
      const surface_point key = {p->fragment, {p->node[0], q->node[0], -1, -1}, {-1, -1, -1}, {0, 0, 0, 0}, 0};
      const surface_point *hit = bsearch(&key, crossings, (size_t)ncross, sizeof *crossings, by_edge_name);
      if (!hit) continue;
      if (apex == 0) apex = np - base;
      points[np] = *hit, points[np].order = np, ++np;
    }
    const int32_t n = np - base;
    for (int32_t i = 1; i + 1 < n; ++i) {
      int32_t *t3 = tri + 3 * (size_t)nt;
      t3[0] = base + apex, t3[1] = base + (apex + i) % n, t3[2] = base + (apex + i + 1) % n;
      triangle_fragment[nt++] = raw[first].fragment;
    }
  }
  free(raw), free(crossings), free(polygon);
  /* one vertex per distinct name, numbered in order of fragment */
  qsort(points, (size_t)np, sizeof *points, by_name);
  int32_t nv = 0;
  out->positions = malloc(3 * sizeof(double) * (size_t)(np > 0 ? np : 1));
  out->triangles = malloc(3 * sizeof(int32_t) * (size_t)(nt > 0 ? nt : 1));
  out->fragment_start = calloc((size_t)f->fragment_count + 1, sizeof(int32_t));
  int32_t *fill = calloc((size_t)f->fragment_count + 1, sizeof(int32_t));
  fracture_surface_point *at = where ? malloc(sizeof *at * (size_t)(np > 0 ? np : 1)) : NULL;
  if (!out->positions || !out->triangles || !out->fragment_start || !fill || (where && !at)) {
    free(points), free(tri), free(index), free(triangle_fragment), free(fill), free(at);
    piola_fracture_surface_free(out);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture surface: out of memory");
  }
  for (int32_t i = 0; i < np; ++i) {
    const surface_point *p = &points[i];
    if (i == 0 || same_name(p, &points[i - 1]) != 0) {
      if (is_edge_crossing(p)) { /* as a + t (b - a), the form a single cut always had */
        const double *xa = b->x + 3 * (size_t)p->node[0], *xb = b->x + 3 * (size_t)p->node[1];
        for (int k = 0; k < 3; ++k) out->positions[3 * (size_t)nv + k] = xa[k] + p->w[1] * (xb[k] - xa[k]);
      } else {
        for (int k = 0; k < 3; ++k) {
          double sum = 0;
          for (int j = 0; j < 4 && p->node[j] >= 0; ++j) sum += p->w[j] * b->x[3 * (size_t)p->node[j] + k];
          out->positions[3 * (size_t)nv + k] = sum;
        }
      }
      if (at) {
        fracture_surface_point *q = &at[nv];
        for (int j = 0; j < 4; ++j) q->node[j] = p->node[j], q->w[j] = p->w[j];
      }
      ++nv;
    }
    index[p->order] = nv - 1;
  }
  /* triangles grouped by fragment, in emission order within each */
  for (int32_t i = 0; i < nt; ++i) out->fragment_start[triangle_fragment[i] + 1]++;
  for (int32_t g = 0; g < f->fragment_count; ++g) out->fragment_start[g + 1] += out->fragment_start[g];
  for (int32_t i = 0; i < nt; ++i) {
    int32_t g = triangle_fragment[i];
    int32_t slot = out->fragment_start[g] + fill[g]++;
    for (int k = 0; k < 3; ++k) out->triangles[3 * (size_t)slot + k] = index[tri[3 * (size_t)i + k]];
  }
  out->fragment_count = f->fragment_count;
  out->vertex_count = nv;
  out->triangle_count = nt;
  free(points), free(tri), free(index), free(triangle_fragment), free(fill);
  if (where) *where = at;
  return PIOLA_OK;
}
